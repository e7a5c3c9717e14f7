"""Free flight (issue 17, beyond the thesis): a spec with a [body] section runs through
ps.simulate and ps.sweep like any other; fixed bodies are the torque stand, bit for bit."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import paritysim as ps

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
FAST = {"max_cycles": 30, "samples_per_cycle": 40, "record_cycles": 3}


def _spec(**body: object) -> ps.Simulation:
    spec = ps.load_spec(EXAMPLES / "free_flight.toml")
    spec = spec.replace(options=dataclasses.replace(spec.options, **FAST))
    return spec.with_paths({f"body.{k}": v for k, v in body.items()})


def test_free_flight_reports_attitude_position_and_body_metrics() -> None:
    result = ps.simulate(_spec())
    df = result.trajectory
    for column in ("body_roll", "body_yaw", "body_pitch", "body_qw", "body_omega_roll", "body_x", "lift", "left_phi", "q2"):
        assert column in df.columns, column
    assert df.height == 3 * 40 + 1
    q = df.select(["body_qw", "body_qx", "body_qy", "body_qz"]).to_numpy()
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)
    metrics = result.metrics
    # The §3.4 wings lift more than the 60 mg airframe weighs: it climbs (+x is up).
    assert metrics["lift_to_weight"] > 1.0
    assert df["body_x"][-1] > df["body_x"][0]
    # No gimbal: the body is free to move in every direction.
    assert metrics["body_displacement"] > 0.0


def test_fixed_body_section_changes_nothing() -> None:
    plain = ps.load_spec(EXAMPLES / "drag_parity.toml")
    plain = plain.replace(options=dataclasses.replace(plain.options, max_cycles=5, samples_per_cycle=40))
    fixed = plain.replace(body=ps.spec.Body(mode="fixed", mass_mg=90.0))
    a, b = ps.simulate(plain), ps.simulate(fixed)
    # The body's mass only adds the ratio to its weight (stroke drag: no lift, so power only).
    weight = 90.0 * 9.81e-3
    extra = b.metrics.pop("actuator_power_per_weight")
    assert extra == pytest.approx(a.metrics["actuator_power_mean"] / weight, rel=1e-14)
    assert a.metrics == b.metrics
    assert a.trajectory.equals(b.trajectory)


def test_sweep_over_a_body_field() -> None:
    spec = _spec(mode="clamped")
    df = ps.sweep(spec, {"body.mass_mg": [60.0, 120.0]}, metrics=["lift_to_weight", "body_torque_roll_mean"], progress=False)
    assert (df["status"] == "ok").all()
    ratio = df["lift_to_weight"].to_list()
    # Clamped: the airframe's mass only sets the weight.
    assert abs(ratio[0] / ratio[1] - 2.0) < 1e-12
    direct = ps.simulate(spec).metrics["lift_to_weight"]
    assert np.float64(direct).tobytes() == np.float64(ratio[0]).tobytes()


def test_sweeps_over_body_modes_and_schedules() -> None:
    """ps.sweep runs body-mode specs like any other: one row per body mode (a string path),
    and over a set point's values (eq. 5.1's ln q3 on the stand), each row the same numbers as
    ps.simulate of that point."""
    spec = _spec(mode="clamped")
    df = ps.sweep(spec, {"body.mode": ["clamped", "roll", "yaw", "free"]}, metrics=["body_omega_roll_mean", "lift_to_weight"], progress=False)
    assert df["status"].to_list() == ["ok"] * 4
    lift = df["lift_to_weight"].to_list()
    assert len(set(lift)) > 1 and all(v > 1.0 for v in lift)
    assert df["body_omega_roll_mean"][0] == 0.0  # clamped: the body cannot turn
    q3 = ps.flight.with_body(spec, set_points=[{"input": "log_q3", "times_ms": [0.0], "values": [0.0]}])
    u = float(np.log(2.0))
    swept = ps.sweep(q3, {"body.set_points[0].values": [[0.0], [u]]}, metrics=["body_torque_roll_mean"], progress=False)
    assert swept["status"].to_list() == ["ok", "ok"]
    direct = ps.simulate(q3.with_paths({"body.set_points[0].values": [u]}))
    assert np.float64(direct.metrics["body_torque_roll_mean"]).tobytes() == np.float64(swept["body_torque_roll_mean"][1]).tobytes()


def test_log_q3_holds_the_torque_ratio_on_the_stand() -> None:
    """Eq. 5.1 from a spec: with ln q3 = u the stand's peak stroke-torque ratio of a symmetric
    device is e^u (the whippletree load of crates/flight/src/control.rs)."""
    spec = _spec(mode="clamped")
    left = spec.wings[0]
    spec = spec.replace(wings=(left, left))
    ratios = {}
    for q3 in (0.5, 2.0):
        s = ps.flight.with_body(spec, set_points=[{"input": "log_q3", "times_ms": [0.0], "values": [float(np.log(q3))]}])
        cyc = ps.simulate(s).cycle
        tau = {side: np.abs((cyc[f"{side}_roll_aero"] + cyc[f"{side}_roll_inertial"]).to_numpy()).max() for side in ("left", "right")}
        ratios[q3] = tau["left"] / tau["right"] / q3
    assert all(abs(r - 1.0) < 0.05 for r in ratios.values()), ratios


def test_dual_drive_fields_are_validated_by_name() -> None:
    """Per-side drive fields need the dual four-bar; side inputs need it; eq. 5.1 needs a
    whippletree: each error names its field."""
    spec = _spec(mode="roll")
    sided = spec.with_paths({"actuator.side_gain[1]": 1.2})  # a valid path: the check is the drivetrain's
    with pytest.raises(ps.InvalidParameterError, match=r"invalid `actuator\.side_gain` = \[1\.0, 1\.2\].*dual_four_bar"):
        ps.simulate(sided)
    with pytest.raises(ps.InvalidParameterError, match=r"invalid `body\.set_points\[0\]\.input`"):
        ps.simulate(ps.flight.with_body(spec, set_points=[{"input": "side_gain_left", "times_ms": [0.0], "values": [0.1]}]))
    dual = spec.replace(drivetrain=ps.spec.Drivetrain.dual_four_bar())
    with pytest.raises(ps.InvalidParameterError, match=r"invalid `body\.control\.input`"):
        ps.simulate(ps.flight.with_body(dual, control={"input": "log_q3", "kp": 1.0}))


def test_animation_writes_mp4_with_ffmpeg_and_falls_back_to_gif(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from paritysim.flight import plots as fplots

    run = ps.simulate(_spec(mode="free"), record_cycles=1, samples_per_cycle=12)
    if fplots.ffmpeg_path() is not None:
        mp4 = fplots.animate(run.trajectory, tmp_path / "a.mp4", frames=6)
        assert mp4.suffix == ".mp4" and mp4.read_bytes()[4:8] == b"ftyp"
    monkeypatch.setattr(fplots, "ffmpeg_path", lambda: None)
    with pytest.warns(UserWarning, match="no ffmpeg"):
        gif = fplots.animate(run.trajectory, tmp_path / "b.mp4", frames=6)
    assert gif.name == "b.gif" and gif.read_bytes()[:6] in (b"GIF87a", b"GIF89a")


def test_flight_pictures_name_bad_input(tmp_path: Path) -> None:
    # Each was polars' ColumnNotFoundError, an IndexError, a ZeroDivisionError or matplotlib's
    # ValueError.
    from paritysim.flight import plots as fplots

    fixed = ps.simulate(_spec(mode="fixed"), record_cycles=1, samples_per_cycle=12, progress=False).trajectory
    free = ps.simulate(_spec(mode="free"), record_cycles=1, samples_per_cycle=12, progress=False).trajectory
    cases = [
        (lambda: fplots.trajectory_3d({"a": fixed}), "frames['a']"),
        (lambda: fplots.trajectory_3d({"a": free.head(0)}), "frames['a']"),
        (lambda: fplots.trajectory_3d({"a": free}, arrows=-1), "arrows"),
        (lambda: fplots.attitude(free, 9.09), "frames"),  # a frame, not a mapping of them
        (lambda: fplots.attitude({"a": free}, 0), "period_ms"),
        (lambda: fplots.animate(fixed, tmp_path / "a.gif"), "df"),
        (lambda: fplots.animate(free, tmp_path / "a.gif", frames=0), "frames"),
        (lambda: fplots.animate(free, tmp_path / "a.gif", fps=0), "fps"),
        (lambda: fplots.animate(free, tmp_path / "a.gif", dpi=0), "dpi"),
        (lambda: fplots.animate(free, tmp_path / "a.xyz"), "path"),
    ]
    for call, field in cases:
        with pytest.raises(ps.InvalidParameterError) as info:
            call()
        assert info.value.field == field
    import matplotlib.pyplot as plt

    plt.close("all")


def test_inputs_that_could_not_act_are_refused() -> None:
    # Both ran and did nothing: a set point on a fixed body (the device alone) and q2_bias on a
    # configuration that ties the strokes (the HMF's whippletree cannot move).
    hmf = ps.devices.load("sreetharan2012_3_4_hmf")
    gain = {"input": "actuator_gain", "times_ms": [0.0], "values": [5.0]}
    with pytest.raises(ps.InvalidParameterError, match="clamped") as info:
        ps.simulate(ps.flight.with_body(hmf, set_points=[gain]), progress=False)
    assert info.value.field == "body.set_points"
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.simulate(ps.flight.with_body(hmf, control={"input": "actuator_gain", "kp": 1.0}), progress=False)
    assert info.value.field == "body.control"
    bias = {"input": "q2_bias", "times_ms": [0.0], "values": [0.5]}
    with pytest.raises(ps.InvalidParameterError, match="ties the strokes") as info:
        ps.simulate(ps.flight.with_body(hmf, mode="clamped", set_points=[bias]), progress=False)
    assert info.value.field == "body.set_points[0].input"
    # Where the whippletree is free the same bias acts: it rolls the clamped body.
    parity = ps.devices.load("sreetharan2012_3_4_parity")
    still = ps.simulate(ps.flight.with_body(parity, mode="clamped"), progress=False).metrics["body_torque_roll_mean"]
    biased = ps.simulate(ps.flight.with_body(parity, mode="clamped", set_points=[bias]), progress=False).metrics["body_torque_roll_mean"]
    assert abs(biased - still) > 1e-3


def test_trim_names_a_zero_gravity_and_a_discrete_knob() -> None:
    # A ZeroDivisionError (residuals scaled by the weight) and a ValueError from float('linear_differential').
    hmf = ps.devices.load("sreetharan2012_3_4_hmf")
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.flight.trim(ps.flight.with_body(hmf, mode="clamped", gravity_mm_per_ms2=[0.0, 0.0, 0.0]), progress=False)
    assert info.value.field == "body.gravity_mm_per_ms2"
    with pytest.raises(ps.InvalidParameterError, match="discrete") as info:
        ps.flight.trim(hmf, knobs=["drivetrain.kind", "actuator.waveform.offset_v"], progress=False)
    assert info.value.field == "knobs"
