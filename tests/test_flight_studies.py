"""Free flight from Python (issue 17): trim, attitude angles, and the physics the flight studies
(paritysim.trials.flight) rest on: mirror symmetry, a trimmed symmetric device that does not
turn, and the eq. 5.1 pivot bias turning the body both ways."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import polars as pl
import pytest

import paritysim as ps
from paritysim import flight
from paritysim.trials import section_3_4 as s34

HINGE = 2.5  # mN·mm/rad: near section_3_4's pinned value, fixed here so no test runs the pin
WINGBEATS = 10


def _device(drivetrain: str = "PARITY", right: str = "left", left: str = "left", arm_ratio: float = 1.0) -> ps.Simulation:
    """The §3.4 device with Table 3.3 wings by key (``"left"``, ``"right_1cut"``...)."""
    p = s34.params()
    spec = s34.device(p, drivetrain, "Uncut", hinge=HINGE)
    wings = {w: s34._wing(w, HINGE, p) for w in {left, right}}
    spec = spec.replace(wings=(wings[left], wings[right]))
    return spec.with_paths({"drivetrain.arm_ratio": arm_ratio}) if drivetrain == "PARITY" else spec


def _fly(spec: ps.Simulation, mode: str, wingbeats: int = WINGBEATS, **body: object) -> ps.SimulationResult:
    return ps.simulate(flight.with_body(spec, mode=mode, **body), record_cycles=wingbeats, samples_per_cycle=20)


@pytest.fixture(scope="module")
def symmetric_trim() -> flight.Trim:
    return flight.trim(_device("HMF"))


# ------------------------------------------------------------------ trim


def test_trim_residuals_are_below_the_tolerance(symmetric_trim: flight.Trim) -> None:
    """At the returned drive the clamped body's cycle-mean lift is the weight and its pitch torque
    vanishes, re-measured by an independent run of the trimmed spec."""
    t = symmetric_trim
    assert t.converged, t
    m = ps.simulate(flight.with_body(t.spec, mode="clamped")).metrics
    weight = 60.0 * 9.81e-3  # the default airframe: 60 mg, massless wings, 9.81 m/s²
    assert t.weight_mn == pytest.approx(weight, rel=1e-12)
    assert abs(m["lift_mean"] - weight) < t.tol * weight
    assert abs(m["body_torque_pitch_mean"]) < t.tol * weight * 12.0
    # The untrimmed device (100 V) lifts several times its weight: the trim did something.
    assert ps.simulate(flight.with_body(_device("HMF"), mode="clamped")).metrics["lift_to_weight"] > 2.0


def test_symmetric_device_trims_with_no_roll_or_yaw_torque(symmetric_trim: flight.Trim) -> None:
    """Mirror symmetry (z -> -z) makes the roll and yaw torques of a left-right symmetric device
    vanish at any drive; an asymmetric device keeps a yaw residual the two knobs cannot remove."""
    scale = symmetric_trim.weight_mn * 12.0
    assert abs(symmetric_trim.residuals["roll"]) < 1e-9 * scale
    assert abs(symmetric_trim.residuals["yaw"]) < 1e-9 * scale
    cut = flight.trim(_device("HMF", right="right_1cut"))
    assert cut.converged
    assert abs(cut.residuals["yaw"]) > 1e-2 * scale


def test_heavier_body_needs_more_amplitude(symmetric_trim: flight.Trim) -> None:
    heavy = flight.trim(flight.with_body(_device("HMF"), mass_mg=90.0))
    assert heavy.converged
    assert heavy.weight_mn == pytest.approx(1.5 * symmetric_trim.weight_mn, rel=1e-12)
    a0 = symmetric_trim.knobs["actuator.waveform.amplitude_v"]
    a1 = heavy.knobs["actuator.waveform.amplitude_v"]
    # Lift grows roughly with the square of the stroke velocity: 1.5 × the weight needs more
    # than 1× but less than 1.5× the amplitude.
    assert a0 < a1 < 1.5 * a0, (a0, a1)


def test_trim_rejects_bad_knobs_and_equations() -> None:
    spec = _device("HMF")
    with pytest.raises(ps.InvalidParameterError, match="knobs"):
        flight.trim(spec, knobs=("actuator.waveform.amplitude", "actuator.waveform.offset_v"))
    with pytest.raises(ps.InvalidParameterError, match="equations"):
        flight.trim(spec, equations=("lift", "spin"))
    with pytest.raises(ps.InvalidParameterError, match="equations"):
        flight.trim(spec, equations=("lift",))
    with pytest.raises(ps.InvalidParameterError, match="actuator"):
        flight.trim(spec.replace(actuator=None))


# ------------------------------------------------------------------ attitude angles


def _frame(q: np.ndarray) -> pl.DataFrame:
    return pl.DataFrame({"body_qw": q[:, 0], "body_qx": q[:, 1], "body_qy": q[:, 2], "body_qz": q[:, 3]})


@pytest.mark.parametrize("axis", ["roll", "yaw", "pitch"])
def test_twist_angle_follows_several_turns_and_sign_flips(axis: str) -> None:
    """A rotation by θ about one body axis has q = (cos θ/2, sin θ/2 â); the twist recovers θ
    over three turns, also where the quaternion flips to −q (the same attitude)."""
    theta = np.linspace(-3 * np.pi, 6 * np.pi, 400)
    q = np.zeros((theta.size, 4))
    q[:, 0] = np.cos(theta / 2)
    q[:, 1 + flight.AXES[axis]] = np.sin(theta / 2)
    q[150:] *= -1.0
    got = flight.twist_angle(_frame(q), axis)
    np.testing.assert_allclose(got - got[0], theta - theta[0], atol=1e-12)
    # A tilt of the stroke axis x̂ by θ (about y or z) is |θ| folded into [0, π]; roll none.
    tilt = flight.tilt_angle(_frame(q))
    expected = np.zeros_like(theta) if axis == "roll" else np.arccos(np.cos(theta))
    np.testing.assert_allclose(tilt, expected, atol=1e-6)


def test_attitude_angles_name_a_bad_axis_or_a_trajectory_without_a_body() -> None:
    q = np.array([[1.0, 0.0, 0.0, 0.0]])
    with pytest.raises(ps.InvalidParameterError, match='`axis` = \'w\': must be one of "roll", "yaw", "pitch"'):
        flight.twist_angle(_frame(q), "w")
    clamped = pl.DataFrame({"t": [0.0], "left_phi": [0.1]})  # a fixed-body run's columns
    for angle in (flight.tilt_angle, lambda df: flight.twist_angle(df, "yaw")):
        with pytest.raises(ps.InvalidParameterError, match="`df` = columns t, left_phi, ...: must be a free-flight trajectory"):
            angle(clamped)


# ------------------------------------------------------------------ physics of the studies


def test_mirrored_cut_wings_roll_and_yaw_oppositely() -> None:
    """Cutting the left instead of the right wing mirrors the device (z -> -z): body roll and yaw
    (axial x, y components) change sign with equal magnitude, on the gimbals and free."""
    for mode, drivetrain in (("roll", "HMF"), ("yaw", "PARITY"), ("free", "PARITY")):
        right_cut = _fly(_device(drivetrain, right="right_1cut"), mode).trajectory
        left_cut = _fly(_device(drivetrain, left="right_1cut"), mode).trajectory
        for axis in ("roll", "yaw"):
            a, b = flight.twist_angle(right_cut, axis), flight.twist_angle(left_cut, axis)
            if mode != "free" and axis != mode:
                assert np.abs(a).max() == 0.0 and np.abs(b).max() == 0.0  # a locked axis stays put
                continue
            scale = np.abs(a).max()
            assert scale > 1e-3, f"{mode}/{axis}: the cut wing turns the body ({scale} rad)"
            # 1e-5: the release state is each device's clamped steady state, converged to
            # steady_tol = 1e-7 separately; a non-mirrored response differs at O(1).
            np.testing.assert_allclose(b, -a, atol=1e-5 * scale, err_msg=f"{mode}/{axis}")


def _pitch_rate_halves(spec: ps.Simulation) -> tuple[float, float, dict[str, float | None]]:
    """Mean pitch rate over the first and the second half of a free flight of WINGBEATS."""
    r = _fly(spec, "free")
    w = r.trajectory["body_omega_pitch"].to_numpy()[:-1]  # whole wingbeats
    return float(w[: w.size // 2].mean()), float(w[w.size // 2 :].mean()), r.metrics


def test_trimmed_symmetric_device_does_not_rotate_in_free_flight(symmetric_trim: flight.Trim) -> None:
    """Released at its trim, the symmetric device does not turn: roll and yaw rates vanish by
    symmetry (< 1e-12 rad/ms); the pitch rate the release leaves (the wings' angular momentum
    at the clamped steady state goes to the body) decays instead of growing, and lift stays at
    the weight. A DC mis-trim of ±10 V (a pitch torque) makes the pitch rate grow instead: the
    bound can fail."""
    early, late, m = _pitch_rate_halves(symmetric_trim.spec)
    assert abs(m["body_omega_roll_mean"]) < 1e-12
    assert abs(m["body_omega_yaw_mean"]) < 1e-12
    assert abs(late) < 0.5 * abs(early), (early, late)
    assert abs(late) < 2e-3  # rad/ms, a wingbeat mean
    assert m["lift_to_weight"] == pytest.approx(1.0, abs=0.05)
    dc = symmetric_trim.knobs["actuator.waveform.offset_v"]
    for delta in (-10.0, 10.0):
        e, lt, _ = _pitch_rate_halves(symmetric_trim.spec.with_paths({"actuator.waveform.offset_v": dc + delta}))
        assert abs(lt) > 1.5 * abs(e) and abs(lt) > 2e-3, (delta, e, lt)  # grows


def test_pivot_bias_q3_and_its_inverse_roll_the_body_oppositely() -> None:
    """Eq. 5.1: the pivot biased to τL/τR = q3 (arm ratio 1/q3) turns a symmetric PARITY on the
    roll gimbal; q3 and 1/q3 are mirror images, so the rolls are opposite and equal, and q3 = 1
    does not roll at all."""
    roll = {q3: flight.twist_angle(_fly(_device("PARITY", arm_ratio=1.0 / q3), "roll").trajectory, "roll") for q3 in (0.5, 1.0, 2.0)}
    assert np.abs(roll[1.0]).max() < 1e-12
    scale = np.abs(roll[2.0]).max()
    assert scale > 1e-2
    np.testing.assert_allclose(roll[0.5], -roll[2.0], atol=1e-5 * scale)  # as the mirrored cut
    rate = {q3: np.mean(np.gradient(roll[q3])) for q3 in (0.5, 2.0)}
    assert np.sign(rate[0.5]) == -np.sign(rate[2.0]) != 0


# ------------------------------------------------------------------ the studies' outputs


@pytest.mark.slow
def test_flight_trials_write_claims_figures_and_an_animation(reproduced: Path) -> None:
    from paritysim import claims as cl

    for trial in ("flight_trim", "flight_cut_wing", "flight_eq5_1", "flight_dual_drive"):
        found, _ = cl.load(reproduced / f"{trial}.claims.json")
        assert found and all(c.ok is not None for c in found), trial
        assert (reproduced / f"{trial}.png").read_bytes()[:4] == b"\x89PNG"
    # The animation: MP4 when an ffmpeg was found (the `video` extra), else the GIF fallback.
    movie = next(p for p in (reproduced / "flight_free_hmf_1cut.mp4", reproduced / "flight_free_hmf_1cut.gif") if p.exists()).read_bytes()
    assert (movie[4:8] == b"ftyp" or movie[:6] in (b"GIF87a", b"GIF89a")) and len(movie) < 2_000_000
    report = (reproduced / "report.md").read_text()
    assert "## Beyond the thesis: the §3.4 device in flight" in report
    assert math.isfinite(float(pl.read_csv(reproduced / "flight_trim.csv")["amplitude_v"][0]))


def test_stroke_synchronous_q3_has_a_mean_roll_torque_a_constant_one_has_none() -> None:
    """§2.4.2 and the split cycle, from specs: on the stand a constant ln q3 leaves no cycle-mean
    roll torque (well below 1 % of the synchronous one), the stroke-synchronous ±ln q3
    (paritysim.trials.flight.stroke_synchronous) has one, and −u mirrors it."""
    from paritysim.trials import flight as studies

    spec = flight.with_body(_device("PARITY"), mode="clamped")
    orbit = ps.simulate(spec, samples_per_cycle=200)
    phases = studies._reversals(orbit)
    u = float(np.log(1.2))

    def mean(points: list[dict[str, object]]) -> float:
        return float(ps.simulate(flight.with_body(spec, set_points=points)).metrics["body_torque_roll_mean"])

    constant = mean([{"input": "log_q3", "times_ms": [0.0], "values": [u]}])
    plus = mean([studies.stroke_synchronous(u, phases, orbit.period_ms)])
    minus = mean([studies.stroke_synchronous(-u, phases, orbit.period_ms)])
    assert abs(plus) > 0.1, plus
    assert abs(constant) < 1e-2 * abs(plus), (constant, plus)
    assert abs(plus + minus) < 1e-6 * abs(plus), (plus, minus)
