"""The engine from Python: examples end to end, TOML round trip, typed errors, hypothesis."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import polars as pl
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import paritysim as ps
from paritysim.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("name", ["hmf", "drag_parity"])
def test_examples_run_end_to_end(name: str) -> None:
    spec = ps.load_spec(EXAMPLES / f"{name}.toml")
    result = ps.simulate(spec, max_cycles=30)
    df = result.trajectory
    assert isinstance(df, pl.DataFrame) and df.height == 2 * 200 + 1
    for col in ("time_ms", "left_phi", "right_phi", "left_roll_aero", "left_roll_inertial", "roll_total", "actuator_force", "actuator_power"):
        assert col in df.columns
    assert all(np.isfinite(df[c].to_numpy()).all() for c in df.columns)
    m = result.metrics
    assert 0.2 < m["left_stroke_amplitude"] < 1.2
    # the actuator injects exactly what the wings dissipate per steady cycle (energy balance)
    assert m["work_actuator_per_cycle"] > 0
    assert m["work_actuator_per_cycle"] == pytest.approx(-m["work_aero_per_cycle"], rel=1e-3)
    assert result.cycle["time_ms"][-1] - result.cycle["time_ms"][0] == pytest.approx(result.period_ms)


def test_toml_round_trip(tmp_path: Path) -> None:
    spec = ps.load_spec(EXAMPLES / "drag_parity.toml")
    path = spec.save(tmp_path / "copy.toml")
    assert ps.load_spec(path) == spec


def test_hmf_strokes_stay_equal_and_parity_balances_drag() -> None:
    """Table 3.2's central claim, computed: with a cut left wing the HMF's peak drag torques
    differ by the drag ratio, PARITY's by far less."""
    ratio = 0.6
    peaks = {}
    for name in ("hmf", "drag_parity"):
        spec = ps.load_spec(EXAMPLES / f"{name}.toml")
        left = dataclasses.replace(spec.wings[0], aero=dataclasses.replace(spec.wings[0].aero, omega1=31.3 * ratio))
        spec = spec.replace(wings=(left, spec.wings[1]))
        if spec.drivetrain is not None and spec.drivetrain.kind != "hmf_four_bar":
            # eq. 2.15 (no reach limit: the lighter wing strokes further than the linkage allows)
            spec = spec.replace(drivetrain=ps.Drivetrain.linear_differential(2.5, 2.5, balance_spring=20.0))
        r = ps.simulate(spec, max_cycles=100)
        if name == "hmf":
            np.testing.assert_allclose(r.trajectory["left_phi"], r.trajectory["right_phi"], atol=1e-12)
        peaks[name] = 1 - r.metrics["left_roll_aero_peak"] / r.metrics["right_roll_aero_peak"]
    assert peaks["hmf"] == pytest.approx(1 - ratio, rel=1e-6)
    assert abs(peaks["drag_parity"]) < 0.5 * peaks["hmf"]


def test_invalid_specs_name_the_field() -> None:
    spec = ps.load_spec(EXAMPLES / "drag_parity.toml")
    bad_inertia = dataclasses.replace(spec.wings[0], inertia=((1.0, 0, 0), (0, -1.0, 0), (0, 0, 1.0)))
    with pytest.raises(ps.InvalidParameterError, match=r"wings\[0\]\.inertia"):
        ps.simulate(spec.replace(wings=(bad_inertia, spec.wings[1])))
    with pytest.raises(ps.InvalidParameterError, match="frequency_hz"):
        ps.simulate(spec.replace(actuator=dataclasses.replace(spec.actuator, waveform=ps.Waveform(frequency_hz=0.0))))
    with pytest.raises(ps.ConstraintError):
        ps.simulate(spec.replace(configuration=ps.Configuration(name=None, rows=((0, 1, 0, 0, 0, 0), (0, 2, 0, 0, 0, 0)), c0=(0, 0))))
    with pytest.raises(ps.ConstraintError, match="violates"):
        ps.simulate(spec, initial_p=(0.1, 0, 0, 0.1, 0.2, 0))
    with pytest.raises(ps.InvalidParameterError, match="configuration"):
        ps.simulate(spec.replace(configuration=ps.Configuration(name="hmf2")))
    with pytest.raises(ps.InvalidParameterError, match="unknown field|known field"):
        ps.Simulation.from_dict({**spec.to_dict(), "wingz": []})


def test_integration_error_carries_time_and_state() -> None:
    spec = ps.load_spec(EXAMPLES / "drag_parity.toml")
    loud = spec.replace(actuator=dataclasses.replace(spec.actuator, waveform=ps.Waveform(amplitude_v=5000.0)))
    with pytest.raises(ps.IntegrationError) as info:
        ps.simulate(loud)
    assert 0 < info.value.time < 50 and len(info.value.state) == 14


def test_cli_run_writes_trajectory_and_plot(tmp_path: Path) -> None:
    assert main(["run", str(EXAMPLES / "hmf.toml"), "--out", str(tmp_path), "--quiet"]) == 0
    df = pl.read_parquet(tmp_path / "hmf_trajectory.parquet")
    assert "left_phi" in df.columns and df.height > 100
    assert (tmp_path / "hmf.png").read_bytes()[:4] == b"\x89PNG"
    assert "left_stroke_amplitude" in pl.read_csv(tmp_path / "hmf_metrics.csv").columns


floats = st.floats(allow_nan=True, allow_infinity=True, width=64)
reasonable = st.floats(-1e3, 1e3)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    ixx=st.one_of(floats, st.floats(0.1, 100)),
    izz=st.one_of(floats, st.floats(0.1, 10)),
    ixz=st.one_of(floats, st.floats(-2, 2)),
    omega=st.one_of(floats, st.floats(0, 60)),
    freq=st.one_of(floats, st.floats(1, 400)),
    volts=st.one_of(floats, st.floats(0, 200)),
    config=st.sampled_from(["hmf_fixed", "drag_parity_fixed", "drag_parity", "hmf", "dual_parity", "nonsense"]),
    k2=st.one_of(floats, st.floats(0, 600)),
    alpha2=st.one_of(st.floats(0, 4), floats),
    samples=st.sampled_from([lambda: (), lambda: (0.0,), lambda: (0.0, 1.0, 5.0)]),
)
def test_random_specs_raise_typed_errors_or_return_finite_results(ixx, izz, ixz, omega, freq, volts, config, k2, alpha2, samples) -> None:  # type: ignore[no-untyped-def]
    spec = ps.load_spec(EXAMPLES / "drag_parity.toml")
    wing = ps.Wing(inertia=((ixx, 0, ixz), (0, ixx, 0), (ixz, 0, izz)), shoulder=ps.Shoulder(alpha2=alpha2, alpha3=0.0), aero=ps.Aero(omega1=omega, coefficient=3.46))
    times = samples()
    waveform = ps.Waveform(amplitude_v=volts, frequency_hz=freq) if not times or freq != freq else ps.Waveform(kind="sampled", times_ms=times, voltages_v=tuple(volts for _ in times), period_ms=6.0)
    try:
        drivetrain = ps.Drivetrain.hmf_four_bar() if config.startswith("hmf") else ps.Drivetrain.linkage_differential(balance_spring=k2)
        s = spec.replace(wings=(wing, wing), configuration=ps.Configuration(name=config), drivetrain=drivetrain,
                         actuator=dataclasses.replace(spec.actuator, waveform=waveform))
        r = ps.simulate(s, max_cycles=4, min_cycles=1, samples_per_cycle=16, max_steps=20_000)
    except ps.ParitysimError as exc:
        assert str(exc)
        return
    for c in r.trajectory.columns:
        assert np.isfinite(r.trajectory[c].to_numpy()).all(), c
    assert all(v is None or math.isfinite(v) for v in r.metrics.values())


def test_actuator_from_laminate_feeds_the_engine() -> None:
    """Issue 9 hand-off: a laminate-designed bimorph drives a simulation with its own constants."""
    from paritysim import laminate

    bimorph = laminate.Bimorph.design_for(laminate.THESIS_ACTUATOR)
    act = ps.Actuator.from_laminate(bimorph)
    assert act.stiffness == pytest.approx(467.0, rel=1e-3)
    assert act.force_per_volt == pytest.approx(1.2, rel=1e-3)
    spec = ps.load_spec(EXAMPLES / "hmf.toml").replace(actuator=act)
    assert ps.simulate(spec).metrics["left_stroke_amplitude"] > 0.1


def test_blade_element_rotating_wings_run_and_rotate() -> None:
    """Configuration #1 (hmf, psi free) with the §3.2.4 blade-element model and a hinge spring:
    the wings rotate passively and everything stays finite (issue 6 builds on this)."""
    spec = ps.load_spec(EXAMPLES / "hmf.toml")
    springs = ps.Springs(hinge=ps.Spring(stiffness=3.0))  # joint 6 (psi)
    aero = ps.Aero(kind="blade_element", omega1=46.8, omega2=0.587, omega3=17.5, omega4=0.712)
    wing = ps.Wing.from_moments(ixx=29.0, iyy=30.0, izz=1.5, ixz=2.0, springs=springs, aero=aero)
    rotating = spec.replace(wings=(wing, wing), configuration=ps.Configuration("hmf"))
    r = ps.simulate(rotating, max_cycles=60)
    assert r.metrics["left_rotation_amplitude"] > 0.1
    np.testing.assert_allclose(r.trajectory["left_psi"], r.trajectory["right_psi"], atol=1e-9)
    with pytest.raises(ps.InvalidParameterError, match="model"):
        ps.simulate(rotating.replace(wings=(dataclasses.replace(wing, aero=dataclasses.replace(aero, model="nope")),) * 2))


@pytest.mark.parametrize(("frequency_hz", "amplitude_v"), [(150.0, 50.0), (300.0, 100.0)])
def test_last_sample_lands_on_the_window_end(frequency_hz: float, amplitude_v: float) -> None:
    """Regression: t_start + window·k/n rounded one ulp past the window end at some drive
    frequencies, and the solver returned one sample short."""
    spec = ps.load_spec(EXAMPLES / "hmf.toml")
    spec = spec.replace(actuator=dataclasses.replace(spec.actuator, waveform=ps.Waveform(amplitude_v=amplitude_v, frequency_hz=frequency_hz)))
    r = ps.simulate(spec, max_cycles=40)
    assert r.trajectory.height == 2 * 200 + 1


@pytest.mark.parametrize("name", ["drag_parity", "hmf"])
def test_asked_columns_and_metrics_are_the_full_runs_values(name: str) -> None:
    """`columns=` / `metrics=` build only what is asked: the same numbers as the full run
    (to round-off: the lean samples do the full samples' arithmetic), only those names, in the
    asked order; unknown names are errors naming the selection."""
    spec = ps.load_spec(EXAMPLES / f"{name}.toml")
    full = ps.simulate(spec)
    asked = ["imbalance_peak_pct", "right_roll_aero_peak", "left_stroke_amplitude"]
    lean = ps.simulate(spec, columns=["left_phi"], metrics=asked)
    assert list(lean.metrics) == asked
    for m in asked:
        assert lean.metrics[m] == pytest.approx(full.metrics[m], rel=1e-12, abs=1e-12)
    assert lean.trajectory.columns == ["time_ms", "left_phi"]
    np.testing.assert_allclose(lean.trajectory["left_phi"], full.trajectory["left_phi"], rtol=0, atol=1e-12)
    metrics_only = ps.simulate(spec, columns=[], metrics=asked[:1])
    assert metrics_only.trajectory.height == 0 and list(metrics_only.metrics) == asked[:1]
    with pytest.raises(ps.InvalidParameterError, match=r"metrics.*imbalance_peak_pct"):
        ps.simulate(spec, metrics=["imbalance_peak_pc"])
    with pytest.raises(ps.InvalidParameterError, match=r"columns.*left_phi"):
        ps.simulate(spec, columns=["left_ph"])
