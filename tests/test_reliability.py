"""Hostile but fair input to the design-layer APIs (issue 14): every outcome is a finite result or a
``ParitysimError`` naming the field, never another exception type, an overflow or a silent NaN."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import paritysim as ps
from paritysim import laminate

# Any float a user could type, including the edges that broke things: 1e300, 5e-324, nan, inf.
ANY_FLOAT = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 5e-324, 1e-300, 1e300, 1e308, -1e308, math.nan, math.inf]),
    st.floats(min_value=1e-4, max_value=50.0),  # plausible sizes, so some calls succeed
)
ANY_ARG = st.one_of(ANY_FLOAT, st.integers(min_value=-(2**70), max_value=2**70), st.sampled_from(["3", None, True, [1.0], "wide"]))


def _finite(value: Any) -> bool:
    """Every number reachable in a result (floats, arrays, dict values, properties) is finite."""
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    if isinstance(value, (list, tuple)):
        return all(_finite(v) for v in value)
    if isinstance(value, np.ndarray):
        return value.dtype.kind not in "fc" or bool(np.isfinite(value).all())
    if isinstance(value, (float, complex)):
        return math.isfinite(abs(value))
    return True


def _outcome(call: Callable[[], Any], properties: tuple[str, ...] = ()) -> str:
    try:
        result = call()
        values = [result] + [getattr(result, p)() if callable(getattr(result, p)) else getattr(result, p) for p in properties]
    except ps.InvalidParameterError as exc:
        assert getattr(exc, "field", None), f"invalid-parameter error without a field: {exc!r}"
        return "typed"
    except (ps.OutOfDomainError, ps.GeometryError, ps.SingularError) as exc:
        assert str(exc)  # a valid input the model cannot evaluate there (joint limit, outline)
        return "typed"
    assert _finite(values), f"non-finite result {values!r}"
    return "finite"


SETTINGS = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@SETTINGS
@given(width=ANY_ARG, length=ANY_ARG, thickness=ANY_ARG)
def test_flexure(width: Any, length: Any, thickness: Any) -> None:
    _outcome(lambda: laminate.Flexure(width, length, thickness), ("stiffness", "plate_stiffness", "elastic_limit_angle"))


@SETTINGS
@given(tip=ANY_ARG, segments=st.one_of(st.integers(min_value=-(2**65), max_value=2**65), ANY_ARG))
def test_hmf_like_planform(tip: Any, segments: Any) -> None:
    if isinstance(segments, int) and 4 <= segments <= 1_000_000:
        segments = min(segments, 512)  # valid counts are exercised below, cheaply
    _outcome(lambda: ps.Planform.hmf_like(tip, segments=segments), ("area", "span", "mean_chord"))


@SETTINGS
@given(span=ANY_ARG, chord=ANY_ARG, root=ANY_ARG, lead=ANY_ARG)
def test_rectangle_planform(span: Any, chord: Any, root: Any, lead: Any) -> None:
    _outcome(lambda: ps.Planform.rectangle(span, chord, root, lead), ("area", "mean_chord"))


@SETTINGS
@given(alpha2=ANY_ARG, alpha3=ANY_ARG, phi=ANY_ARG, theta=ANY_ARG)
def test_shoulder_pose(alpha2: Any, alpha3: Any, phi: Any, theta: Any) -> None:
    _outcome(lambda: ps.kinematics.shoulder_pose(alpha2, alpha3, phi, theta))


@SETTINGS
@given(q1=ANY_FLOAT, q2=ANY_FLOAT)
def test_linear_differential_map(q1: float, q2: float) -> None:
    drive = ps.Drivetrain.linear_differential(3.05, 2.5)
    _outcome(lambda: ps.kinematics.drivetrain_map(drive, [q1], q2))


def test_reproducers_name_their_field() -> None:
    """The issue's reproducers, each now a typed error naming the field."""
    cases: list[tuple[Callable[[], Any], str]] = [
        (lambda: ps.Planform.hmf_like(16.6, segments=-1), "segments"),
        (lambda: ps.Planform.hmf_like(1e300), "tip_radius"),
        (lambda: laminate.Flexure(1e300, 0.03, 7.5), "width"),
        (lambda: laminate.Flexure(3, 2, 5e-324), "thickness"),
        (lambda: ps.kinematics.drivetrain_map(ps.Drivetrain.linear_differential(3.05, 2.5), [1e308], 0.0), "q1"),
        (lambda: ps.kinematics.shoulder_pose("2.0", 1.0, 0.0, 0.0), "alpha2"),
        (lambda: ps.Planform.semi_ellipse(3, 3, segments=2.5), "segments"),
        (lambda: ps.kinematics.drivetrain_map(ps.Drivetrain.linear_differential(3.05, 2.5), ["x"]), "q1"),
        (lambda: ps.kinematics.drivetrain_map(ps.Drivetrain.linear_differential(3.05, 2.5), [{}]), "q1"),
        (lambda: ps.stability.lti_transfer(1.0, 0.5, ["x"]), "frequency_hz"),
    ]
    for call, field in cases:
        with pytest.raises(ps.ParitysimError) as info:
            call()
        assert field in str(getattr(info.value, "field", "")), (field, info.value)


def test_finest_documented_outline_is_exact() -> None:
    """``segments = 10**6`` (the documented maximum) ran past 60 s; the polygon area is exact."""
    n = 10**6
    p = ps.Planform.semi_ellipse(3.0, 3.0, segments=n)
    assert p.area == pytest.approx(math.pi * 9.0 / 4.0 * n / math.pi * math.sin(math.pi / n), rel=1e-9)


def test_lti_transfer_is_finite_at_extreme_magnitudes() -> None:
    """Eq. 2.59 by its polar form: the textbook complex quotient under/overflowed to NaN."""
    import numpy as np

    tiny = ps.stability.lti_transfer(1e-300, 1e-300, [1e-300])
    assert np.isfinite(tiny).all() and abs(tiny[0] - 1.0) < 1e-12  # κ0 / κ0 at f -> 0
    huge = ps.stability.lti_transfer(1e308, 1e5, [53.0])
    w = 2 * np.pi * 53.0 * 1e-3
    assert np.isfinite(huge).all() and abs(huge[0]) == pytest.approx(1e5 / (1e308 * w), rel=1e-9)


EXAMPLES = __import__("pathlib").Path(__file__).resolve().parents[1] / "examples"
FAST = {"max_cycles": 5, "samples_per_cycle": 40}


def test_reproducers_6_8_9_typed_named_or_absent(tmp_path: Any) -> None:
    """Reproducers 6 (not a ParitysimError), 8 (absurd magnitudes failing late) and 9 (the NaN
    phase lag of fixed wings)."""
    spec = ps.load_spec(EXAMPLES / "hmf.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\n[actuator\n')
    cases: list[tuple[Callable[[], Any], str]] = [
        (lambda: ps.load_spec(bad), "spec"),
        (lambda: ps.Simulation.from_dict({"name": "x"}), "wings"),
        (lambda: ps.simulate(spec, record_cyles=3), "record_cyles"),
        (lambda: ps.simulate(spec.with_paths({"actuator.waveform.amplitude_v": 1e300})), "amplitude_v"),
        (lambda: ps.simulate(spec.with_paths({"wings[0].aero.omega1": 1e300})), "omega1"),
        (lambda: ps.simulate(42), "spec"),
    ]
    for call, field in cases:
        with pytest.raises(ps.ParitysimError) as info:
            call()
        assert field in str(getattr(info.value, "field", "")), (field, info.value)
    # A spec's dict runs like the spec (it raised AttributeError).
    assert ps.simulate(spec.to_dict(), **FAST).metrics == ps.simulate(spec, **FAST).metrics
    lags = {k: v for k, v in ps.simulate(spec, **FAST).metrics.items() if k.endswith("rotation_phase_lag")}
    assert lags and all(v is None for v in lags.values())  # fixed wings: undefined, not NaN


def test_a_rod_crank_driven_past_its_reach_names_the_amplitude_and_its_bound() -> None:
    """Drag PARITY at 300 V: the rod top is lifted past the reach of the rod-crank during the
    transient. The error keeps its class and `.time`/`.state` and names the amplitude; the
    state where it stopped has q1 at the closed-form reach sqrt(L2² + 2 L2 L3) − L2, and the
    allowed range is the static bound reach · stiffness / force_per_volt."""
    import re

    spec = ps.load_spec(EXAMPLES / "drag_parity.toml")
    with pytest.raises(ps.IntegrationError) as info:
        ps.simulate(spec.with_paths({"actuator.waveform.amplitude_v": 300.0}), **FAST)
    err = info.value
    assert err.field == "actuator.waveform.amplitude_v" and err.kind == "Integration"
    crank, rod = spec.drivetrain.crank_mm, spec.drivetrain.rod_mm
    reach = math.sqrt(rod**2 + 2 * rod * crank) - rod
    assert abs(err.state[0]) == pytest.approx(reach, rel=1e-6)
    field, value, allowed = err.problems[0]
    bound = float(re.search(r"\|amplitude\| < ([0-9.]+) V", allowed).group(1))
    assert bound == pytest.approx(reach * spec.actuator.stiffness / spec.actuator.force_per_volt, rel=1e-5)
    assert (field, value) == ("actuator.waveform.amplitude_v", "300")
    # The shipped drive (100 V) stays well inside it and runs.
    assert spec.actuator.waveform.amplitude_v < bound
    ps.simulate(spec, **FAST)


def test_the_same_failure_in_a_sweep_row_names_the_amplitude() -> None:
    spec = ps.load_spec(EXAMPLES / "drag_parity.toml")
    df = ps.sweep(spec, {"actuator.waveform.amplitude_v": [100.0, 300.0]}, options=FAST, progress=False)
    assert df["status"].to_list() == ["ok", "error"]
    assert df["error_kind"][1] == "Integration" and "most responsible: `actuator.waveform.amplitude_v`" in df["error"][1]


def test_shoulder_joint_limit_names_phi_with_the_eq_2_10_bound() -> None:
    """Outside the joint limit the pose names ``phi`` and the bound |sin φ| <= |sin(α3 − α2) /
    cos(θ + α2)|; just inside that bound the pose solves (the bound is the solver's limit)."""
    alpha2, alpha3, theta = 1.0, 0.8, 0.3
    bound = math.asin(abs(math.sin(alpha3 - alpha2) / math.cos(theta + alpha2)))
    ps.kinematics.shoulder_pose(alpha2, alpha3, bound * (1 - 1e-9), theta)
    with pytest.raises(ps.OutOfDomainError) as info:
        ps.kinematics.shoulder_pose(alpha2, alpha3, bound * (1 + 1e-6), theta)
    assert info.value.field == "phi" and f"{bound:.6f}" in info.value.problems[0][2]


def test_degenerate_link_angles_and_arms_are_rejected_before_running() -> None:
    hmf = ps.load_spec(EXAMPLES / "hmf.toml")
    parity = ps.load_spec(EXAMPLES / "drag_parity.toml")
    for spec, path, value in [
        (parity, "wings[0].shoulder.alpha2", 1e-300),
        (parity, "drivetrain.whippletree_length_mm", 5e-324),
        (parity, "drivetrain.arm_ratio", 5e-324),
        (hmf, "wings[0].inertia[0][0]", 1e308),
    ]:
        with pytest.raises(ps.InvalidParameterError) as info:
            ps.simulate(spec.with_paths({path: value}), **FAST)
        assert info.value.field == path, (path, info.value)


def test_eq_2_59_at_zero_frequency_names_the_frequency() -> None:
    with pytest.raises(ps.SingularError) as info:
        ps.stability.lti_transfer(1.0, 0.0, [50.0, 0.0])
    assert info.value.field == "frequency_hz[1]"


# ----------------------------------------------------------------------------- issue 34

HMF_FAST = {"max_cycles": 5, "samples_per_cycle": 40}


def _shared_sweep(checkpoint: Any, values: list[float]) -> Any:
    spec = ps.load_spec(EXAMPLES / "hmf.toml")
    return ps.sweep(spec, {"actuator.frequency_hz": values}, metrics=["left_stroke_amplitude"], options=HMF_FAST, threads=1, chunk_size=1, checkpoint=checkpoint, progress=False)


def test_two_threads_sharing_a_checkpoint_both_return_their_tables(tmp_path: Any) -> None:
    """Issue 34's lost table: two sweeps on one checkpoint at once; one raised FileNotFoundError
    from `finish()` (it unlinked parts the other had removed). Both return every row, and the
    final table holds the rows of both (neither replaced the other's)."""
    import polars as pl
    import threading

    for attempt in range(3):
        path = tmp_path / f"shared{attempt}.parquet"
        grids = [[100.0, 105.0, 110.0, 115.0], [112.5, 117.5, 122.5, 127.5]]
        out: dict[int, Any] = {}
        barrier = threading.Barrier(2)

        def run(i: int, path: Any = path, grids: Any = grids, out: Any = out, barrier: Any = barrier) -> None:
            barrier.wait()
            try:
                out[i] = _shared_sweep(path, grids[i])
            except BaseException as exc:  # noqa: BLE001 - reported below
                out[i] = exc

        threads = [threading.Thread(target=run, args=(i,)) for i in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for i in range(2):
            assert isinstance(out[i], pl.DataFrame), out[i]
            assert out[i]["actuator.frequency_hz"].to_list() == grids[i] and (out[i]["status"] == "ok").all()
        saved = pl.read_parquet(path)
        assert sorted(saved["actuator.frequency_hz"].to_list()) == sorted(grids[0] + grids[1])
        assert not path.with_name(path.name + ".parts").exists()


def test_two_processes_sharing_a_checkpoint_both_finish(tmp_path: Any) -> None:
    import os
    import subprocess
    import sys

    import polars as pl

    path = tmp_path / "shared.parquet"
    script = (
        "import sys, paritysim as ps\n"
        f"spec = ps.load_spec({str(EXAMPLES / 'hmf.toml')!r})\n"
        "values = [float(v) for v in sys.argv[2].split(',')]\n"
        f"df = ps.sweep(spec, {{'actuator.frequency_hz': values}}, metrics=['left_stroke_amplitude'], options={HMF_FAST!r}, threads=1, chunk_size=1, checkpoint=sys.argv[1], progress=False)\n"
        "assert df.height == len(values) and (df['status'] == 'ok').all()\n"
        "print('ok', df.height)\n"
    )
    grids = ["100,105,110,115,120", "102.5,107.5,112.5,117.5,122.5"]
    procs = [subprocess.Popen([sys.executable, "-c", script, str(path), g], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env={**os.environ}) for g in grids]
    for p in procs:
        out, err = p.communicate(timeout=240)
        assert p.returncode == 0, err[-2000:]
        assert out.strip() == "ok 5"
    saved = pl.read_parquet(path)
    assert saved.height == 10 and saved["actuator.frequency_hz"].n_unique() == 10


def test_checkpoint_paths_that_cannot_hold_a_table_name_checkpoint(tmp_path: Any) -> None:
    spec = ps.load_spec(EXAMPLES / "hmf.toml")
    a_file = tmp_path / "file.txt"
    a_file.write_text("x")
    garbage = tmp_path / "garbage.parquet"
    garbage.write_text("not parquet")
    for bad in [tmp_path, a_file / "study.parquet", garbage, 42, b"x.parquet"]:
        with pytest.raises(ps.InvalidParameterError) as info:
            ps.sweep(spec, {"actuator.frequency_hz": [100.0]}, options=HMF_FAST, checkpoint=bad, progress=False)
        assert info.value.field == "checkpoint", (bad, info.value)
    # A missing directory is created (documented behaviour), and the table lands there.
    deep = tmp_path / "new" / "dir" / "study.parquet"
    ps.sweep(spec, {"actuator.frequency_hz": [100.0]}, options=HMF_FAST, checkpoint=deep, progress=False)
    assert deep.exists()


_LIMITED = r"""
import resource, sys
import numpy as np
import paritysim as ps
from paritysim import stability
parity = ps.load_spec(sys.argv[1] + "/drag_parity.toml")
# What this process maps now plus 1 GB: the reproducers' allocations (1-112 GB) cannot succeed,
# so an unchecked one aborts the process (a Rust allocation failure) instead of raising.
vm = int(next(l for l in open("/proc/self/status") if l.startswith("VmSize")).split()[1]) * 1024
resource.setrlimit(resource.RLIMIT_AS, (vm + (1 << 30), resource.RLIM_INFINITY))
try:
    eval(sys.argv[2])
    print("result")
except ps.ParitysimError as e:
    print("typed", getattr(e, "field", None))
"""

SIZE_REPRODUCERS = {
    "stability.linearise(parity, samples=10**9)": "samples",
    "stability.disturbance_response(parity, [50.0], 0.1, samples_per_cycle=2**40)": "samples_per_cycle",
    "stability.disturbance_response(parity, [50.0], 0.1, samples_per_cycle=2**24, max_window_cycles=10000)": "samples_per_cycle",
    "ps.kinematics.drivetrain_map(ps.Drivetrain.linkage_differential(), np.zeros(10**7))": "q1",
    "ps.aero.moments(ps.aero.TABLE_3_3['left'], phi_dot=np.zeros(10**7))": "phi_dot",
    "stability.hill_solution(1.0, 0.2, np.zeros(10**8))": "t",
    # The fuzz (seed 34, case 1909): 10^7 frequencies held ~11.5 GB of rows; SIGABRT.
    "stability.disturbance_response(parity, np.zeros(10**7), 0.1, samples_per_cycle=32)": "frequency_hz",
}


@pytest.mark.parametrize("call", list(SIZE_REPRODUCERS))
def test_size_arguments_are_refused_before_allocating(call: str) -> None:
    """Issue 34's aborts: each call, in a process with 1 GB of address space to spare, is a
    typed error naming its size argument (the process aborted: a 112 GB allocation for
    ``samples=10**9``)."""
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-c", _LIMITED, str(EXAMPLES), call], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, (proc.returncode, proc.stderr[-1500:])
    assert proc.stdout.split() == ["typed", SIZE_REPRODUCERS[call]], proc.stdout + proc.stderr[-1500:]


def test_array_paths_hold_their_output_not_twenty_times_it() -> None:
    """``drivetrain_map`` over 1e6 points (112 MB of output) peaked at 2.1 GB; chunked, the
    peak stays within output + inputs + a few chunks, and the values equal a short call's."""
    import subprocess
    import sys

    script = r"""
import resource, numpy as np, paritysim as ps
drive = ps.Drivetrain.linkage_differential()
q1 = np.linspace(-0.05, 0.05, 10**6)
small = ps.kinematics.drivetrain_map(drive, q1[:1000], 0.1)
ps.aero.moments(ps.aero.TABLE_3_3["left"], phi_dot=q1[:1000])
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
out = ps.kinematics.drivetrain_map(drive, q1, 0.1)
mid = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
assert all(np.array_equal(out[k][:1000], small[k]) for k in small)
del out
m = ps.aero.moments(ps.aero.TABLE_3_3["left"] | {"force": 1.0}, phi_dot=q1)
after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(mid - before, after - before)
"""
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-1500:]
    drive_peak, moments_peak = (int(v) for v in proc.stdout.split())
    assert drive_peak < 3 * 112e6, drive_peak  # output 112 MB (14 floats a point)
    assert moments_peak < 3 * 208e6, moments_peak  # output 208 MB (26 floats a point)


_CTRL_C_CHILD = r"""
import sys, time
import numpy as np
import paritysim as ps
from paritysim import stability
flight = ps.load_spec(sys.argv[1] + "/free_flight.toml")
calls = {
    "hill_solution": lambda: stability.hill_solution(1.0, 0.2, np.linspace(0, 9990, 10**4)),
    "controller": lambda: ps.simulate(flight, controller=lambda t, b: {}, control_rate_hz=1000, max_cycles=100000, min_cycles=100000, max_steps=10**8, max_wall_ms=600000.0),
}
print("ready", flush=True)
try:
    calls[sys.argv[2]]()
    print("finished", flush=True)
except KeyboardInterrupt:
    print(f"interrupted {time.monotonic()!r}", flush=True)
"""


@pytest.mark.parametrize("kind", ["hill_solution", "controller"])
def test_ctrl_c_stops_the_calls_that_ignored_it(kind: str) -> None:
    """Issue 34's hangs: Ctrl-C was ignored for 52 s (Hill solutions) and 57 s (a Python
    controller at 1 kHz). SIGINT 0.5 s in: the child reports the interrupt; the latency bound
    here only tells reacted from ignored on a loaded machine (measured: benchmarks/fuzz_report.py)."""
    import signal
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, "-c", _CTRL_C_CHILD, str(EXAMPLES), kind], stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None
    assert proc.stdout.readline().strip() == "ready"
    time.sleep(0.5)
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=60)
    word, _, stamp = out.strip().partition(" ")
    assert word == "interrupted", out
    assert float(stamp) - sent < 0.5


def test_wall_budgets_of_hill_solution_and_continuation_name_max_wall_ms() -> None:
    """``hill_solution`` (52 s) and ``continuation`` (86 s, every point within its own 10 s) had
    no overall budget: with ``max_wall_ms`` they stop there, naming it."""
    start = time.monotonic()
    with pytest.raises(ps.IntegrationError) as info:
        ps.stability.hill_solution(1.0, 0.2, np.linspace(0, 9990, 10**4), max_wall_ms=300.0)
    assert info.value.field == "max_wall_ms" and time.monotonic() - start < 5.0
    slow = ps.load_spec(EXAMPLES / "hmf.toml").with_paths({"actuator.frequency_hz": 1e-3})
    start = time.monotonic()
    with pytest.raises(ps.IntegrationError) as info:
        ps.continuation(slow, "actuator.waveform.frequency_hz", 2e-3, start=1e-3, max_wall_ms=500.0)
    assert info.value.field == "max_wall_ms" and time.monotonic() - start < 5.0
    for bad in (0.0, -1.0, math.nan, 1e12):
        with pytest.raises(ps.InvalidParameterError) as info:
            ps.stability.hill_solution(1.0, 0.2, [1.0], max_wall_ms=bad)
        assert info.value.field == "max_wall_ms"


def _named(call: Callable[[], Any], field: str) -> None:
    with pytest.raises(ps.ParitysimError) as info:
        call()
    assert getattr(info.value, "field", None) == field, (field, info.value)


def test_silent_non_finite_values_are_typed_errors_naming_the_input() -> None:
    """Issue 34: NaN out of ``center_of_pressure(None)``, inf/NaN out of huge finite inputs,
    a NaN tolerance accepted."""
    left = ps.aero.TABLE_3_3["left"]
    _named(lambda: ps.aero.center_of_pressure(None), "alpha")
    _named(lambda: ps.aero.center_of_pressure(float("nan")), "alpha")
    _named(lambda: ps.aero.center_of_pressure([0.1, float("inf")]), "alpha[1]")
    _named(lambda: ps.aero.moments(left, phi_dot=1e200), "phi_dot")
    _named(lambda: ps.aero.moments(left, phi_dot=[1.0, 1e200], psi=0.2), "phi_dot[1]")
    _named(lambda: ps.Planform.hmf_like().inertia(point_masses=[[1e200, 1e200, 1e200]]), "point_masses")
    _named(lambda: ps.Planform.hmf_like().scaled(1e306), "factor")
    hmf = ps.load_spec(EXAMPLES / "hmf.toml")
    _named(lambda: ps.dynamics.wing_terms(hmf, [0.1, 0.1, 0.1], [1e200, 0.0, 0.0]), "p_dot[0]")
    _named(lambda: laminate.Bimorph(laminate.Layup.bimorph_mobee(), 10.0, width_ratio=1e308), "width_ratio")
    flight = ps.load_spec(EXAMPLES / "free_flight.toml")
    _named(lambda: ps.flight.trim(flight, tol=float("nan")), "tol")
    _named(lambda: ps.flight.trim(flight, max_evaluations=-1), "max_evaluations")
    # The valid neighbours still compute, finite.
    assert np.isfinite(ps.aero.center_of_pressure([0.0, math.pi])).all()
    assert all(np.isfinite(v).all() for v in ps.aero.moments(left, phi_dot=[1.0, 2.0], psi=0.2).values())


def test_foreign_exceptions_of_the_issue_are_typed_errors_naming_the_field(tmp_path: Any) -> None:
    hmf = ps.load_spec(EXAMPLES / "hmf.toml")
    one = {"actuator.frequency_hz": [100.0]}
    _named(lambda: ps.sweep(hmf, one, threads=-1, progress=False), "threads")
    _named(lambda: ps.sweep(hmf, one, threads="2", progress=False), "threads")
    _named(lambda: ps.sweep(hmf, one, options=[1], progress=False), "options")
    _named(lambda: ps.sweep(hmf, one, options={"max_cycles": object()}, progress=False), "options.max_cycles")
    _named(lambda: ps.sweep(hmf, one, metrics=[1], progress=False), "metrics")
    _named(lambda: ps.sweep(hmf, one, keep_cycle=5, progress=False), "keep_cycle")
    _named(lambda: ps.sweep(hmf, one, labels=5, progress=False), "labels")
    _named(lambda: hmf.with_paths({"actuator.frequency_hz": 1j}), "actuator.waveform.frequency_hz")
    _named(lambda: hmf.with_paths({"actuator.frequency_hz": object()}), "actuator.waveform.frequency_hz")
    latin = tmp_path / "latin.toml"
    latin.write_bytes("name = 'caf\xe9'\n".encode("latin-1"))
    _named(lambda: ps.load_spec(latin), "path")
    _named(lambda: ps.load_spec(tmp_path), "path")
    _named(lambda: ps.load_spec(tmp_path / "missing.toml"), "path")
    _named(lambda: ps.load_spec(42), "path")
    _named(lambda: hmf.save(tmp_path), "path")
    deep: dict[str, Any] = {}
    node = deep
    for _ in range(5000):
        node["a"] = {}
        node = node["a"]
    _named(lambda: ps.Simulation.from_dict(deep), "spec")
    target = {"left_stroke_amplitude": 0.6}
    _named(lambda: ps.calibrate(hmf, {"left_stroke_amplitude": "x"}, {"actuator.force_per_volt": (0.5, 2.0)}), "targets.left_stroke_amplitude")
    _named(lambda: ps.calibrate(hmf, target, {"actuator.force_per_volt": 5}), "free.actuator.force_per_volt")
    _named(lambda: ps.calibrate(hmf, target, {"actuator.force_per_volt": (0.5, 2.0)}, x0={"actuator.force_per_volt": 9.0}), "x0.actuator.force_per_volt")
    _named(lambda: ps.calibrate(hmf, target, {"actuator.force_per_volt": (0.5, 2.0)}, max_nfev=0), "max_nfev")
    _named(lambda: ps.Planform.from_points([[0, 0], [1], [1, 1]]), "points")
    _named(lambda: ps.Planform.hmf_like().scaled([1, 2]), "factor")
    _named(lambda: ps.Planform.hmf_like().cut(0.2, where=3), "where")
    _named(lambda: ps.aero.moments({"omega1": 1.0}), "omegas")
    _named(lambda: ps.aero.moments(ps.aero.TABLE_3_3["left"], phi=[1.0, 2.0], theta=[1.0, 2.0, 3.0]), "phi, theta, psi, phi_dot, theta_dot, psi_dot")
    _named(lambda: ps.aero.coefficients([0.1], model=None), "model")
    _named(lambda: ps.kinematics.drivetrain_map(None, 0.0), "drivetrain")
    _named(lambda: ps.dynamics.wing_terms(hmf, "abc", [0.0, 0.0, 0.0]), "p")
    _named(lambda: ps.dynamics.wing_terms(hmf, [0.0] * 3, [0.0] * 3, index="a"), "index")


def test_chunked_array_errors_name_the_element_of_the_whole_array() -> None:
    q1 = np.zeros(40_000)
    q1[30_001] = 50.0  # past the rod-crank's reach
    with pytest.raises(ps.OutOfDomainError) as info:
        ps.kinematics.drivetrain_map(ps.Drivetrain.linkage_differential(), q1)
    assert info.value.field == "q1[30001]"
    phi = np.zeros(40_000)
    phi[20_000] = math.nan
    _named(lambda: ps.aero.moments(ps.aero.TABLE_3_3["left"], phi=phi), "phi[20000]")


def test_trim_and_calibrate_have_a_wall_budget_naming_max_wall_ms() -> None:
    """One budget for the Python loops of runs: what is left goes to each run's
    ``options.max_wall_ms`` (the engine's budget), and the loop stops naming ``max_wall_ms``."""
    flight = ps.load_spec(EXAMPLES / "free_flight.toml")
    start = time.monotonic()
    with pytest.raises(ps.IntegrationError) as info:
        ps.flight.trim(flight, max_wall_ms=1.0)
    assert info.value.field == "max_wall_ms" and time.monotonic() - start < 10.0
    calls = []

    def slow_model(**values: float) -> dict[str, float]:
        calls.append(values)
        time.sleep(0.05)
        return {"y": values["x"] ** 2}

    with pytest.raises(ps.IntegrationError) as info:
        ps.calibrate(slow_model, {"y": 2.0}, {"x": (0.0, 3.0)}, max_wall_ms=120.0)
    assert info.value.field == "max_wall_ms" and 1 <= len(calls) <= 5
    _named(lambda: ps.calibrate(slow_model, {"y": 2.0}, {"x": (0.0, 3.0)}, max_wall_ms=math.nan), "max_wall_ms")


def test_a_second_sweep_on_a_finished_checkpoint_keeps_the_first_ones_rows(tmp_path: Any) -> None:
    """Found by the whole-surface fuzz: a sweep of another grid on a checkpoint another sweep
    had finished replaced its table. The table now holds both grids' rows (this sweep's first)."""
    import polars as pl

    path = tmp_path / "study.parquet"
    first = _shared_sweep(path, [100.0, 110.0])
    second = _shared_sweep(path, [120.0, 110.0])
    assert second["actuator.frequency_hz"].to_list() == [120.0, 110.0]
    saved = pl.read_parquet(path)
    assert saved["actuator.frequency_hz"].to_list() == [120.0, 110.0, 100.0]
    assert saved.filter(pl.col("actuator.frequency_hz") == 100.0)["left_stroke_amplitude"][0] == first["left_stroke_amplitude"][0]


def test_floquet_failures_name_the_option_or_the_spec() -> None:
    """Found by the whole-surface fuzz: an orbit not found at a tolerance below round-off named
    nothing, and ``fd_step = 5e-324`` returned None where a float was read (TypeError)."""
    parity = ps.load_spec(EXAMPLES / "drag_parity.toml")
    _named(lambda: ps.stability.floquet(parity, tol=1e-300), "options.tol")
    _named(lambda: ps.stability.floquet(parity, fd_step=5e-324), "options.fd_step")


def test_a_grid_of_python_objects_is_refused_naming_its_column(tmp_path: Any) -> None:
    """Found by the fuzz: with a checkpoint, a grid column of Python objects raised polars'
    ComputeError (an Object column cannot be written); refused up front, naming the column."""
    hmf = ps.load_spec(EXAMPLES / "hmf.toml")
    _named(lambda: ps.sweep(hmf, {"actuator.frequency_hz": [100.0, object()]}, checkpoint=tmp_path / "s.parquet", progress=False), "grid['actuator.frequency_hz'][1]")


def test_an_absolute_tolerance_below_1e_30_is_refused_naming_it() -> None:
    """Found by the fuzz (seed 37): ``options.atol = 5e-324`` (down to about 1e-200) was accepted
    and every step was rejected until 'step size underflow' at t = 0, naming no field."""
    parity = ps.load_spec(EXAMPLES / "drag_parity.toml")
    for tiny in (5e-324, 1e-200, 1e-31):
        with pytest.raises(ps.InvalidParameterError, match=r"options\.atol.*1e-30") as info:
            ps.simulate(parity, atol=tiny, max_cycles=2)
        assert info.value.field == "options.atol"
    assert ps.simulate(parity, atol=1e-30, max_cycles=2, min_cycles=1).cycles_run == 2


def test_more_array_paths_hold_their_output_not_a_hundred_times_it() -> None:
    """Found by the fuzz (seed 37): ``Planform.chord`` / ``leading_edge`` held ~200 bytes per
    point (2 GB for 1e7 points: an abort under a memory limit) and ``hill_solution`` ~700 bytes
    per time against 32 of output. Chunked, each peaks near its output; values unchanged."""
    import subprocess
    import sys

    script = r"""
import resource, numpy as np, paritysim as ps
from paritysim import _core
p = ps.Planform.hmf_like()
z = np.linspace(-1.0, 17.0, 2 * 10**6)
t = np.linspace(0.0, 10.0, 2 * 10**5)
small = _core.aero_planform_chord(p.points, z[:5000])
hill = np.asarray(_core.stability_hill_solution(1.0, 0.2, -np.pi / 2, t[:5000], None))
def peak(call):
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    out = call()
    return out, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 - before
chord, chord_peak = peak(lambda: p.chord(z))
assert np.array_equal(chord[:5000], small["chord"], equal_nan=True)
edge, edge_peak = peak(lambda: p.leading_edge(z))
assert np.array_equal(edge[:5000], small["leading_edge"], equal_nan=True)
m, hill_peak = peak(lambda: ps.stability.hill_solution(1.0, 0.2, t))
assert m.shape == (t.size, 2, 2) and np.array_equal(m[:5000], hill)
print(chord_peak, edge_peak, hill_peak)
"""
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-1500:]
    chord_peak, edge_peak, hill_peak = (int(v) for v in proc.stdout.split())
    assert chord_peak < 4 * 16e6 and edge_peak < 4 * 16e6, (chord_peak, edge_peak)  # 16 MB each (was ~400 MB)
    assert hill_peak < 6 * 6.4e6, hill_peak  # 6.4 MB (was ~140 MB)


def test_a_chart_with_brockett_stays_within_the_charts_cost_and_budget() -> None:
    """Found by the fuzz (seed 38): ``stability_chart(..., brockett=True)`` ran Brockett's test
    point by point through Python (49 µs each: 98 s for 2M points, past ``max_wall_ms``). Now in
    the chart's native call and budget: the column equals `brockett_hill` point by point, and
    costs a fraction of the chart."""
    beta0, kappa = np.linspace(-0.5, 3.0, 9), np.linspace(-1.0, 30.0, 11)
    df = ps.stability.stability_chart(beta0, kappa)
    expected = [k > 0 and r > 0 and ps.stability.brockett_hill(b, k)["bounded"] for b, k, r in df.select("beta0", "kappa", "region").iter_rows()]
    assert df["brockett_bounded"].to_list() == expected and any(expected) and not all(expected)
    big_b, big_k = np.linspace(0.0, 3.0, 300), np.linspace(0.1, 30.0, 300)
    start = time.perf_counter()
    ps.stability.stability_chart(big_b, big_k, brockett=False)
    plain = time.perf_counter() - start
    start = time.perf_counter()
    ps.stability.stability_chart(big_b, big_k, brockett=True)
    with_brockett = time.perf_counter() - start
    assert with_brockett < 1.5 * plain + 0.2, (plain, with_brockett)  # was plain + 4.4 s
