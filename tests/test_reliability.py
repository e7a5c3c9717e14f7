"""Hostile but fair input to the design-layer APIs (issue 14): every outcome is a finite result or a
``ParitysimError`` naming the field, never another exception type, an overflow or a silent NaN."""

from __future__ import annotations

import math
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
