"""§3.3 and §2.4.2 trials: properties the model must compute (never thesis numbers pasted)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import polars as pl
import pytest

import paritysim as ps
from paritysim.trials import section_3_3 as s33

FAST = dict(samples_per_cycle=200)


@pytest.mark.parametrize("ratio", [0.85, 0.6, 0.35])
def test_hmf_imbalance_is_one_minus_the_drag_ratio(ratio: float) -> None:
    """A 1-DOF drivetrain moves both wings alike: drag torques stay in the ratio Ω^L/Ω^R."""
    p = s33.params(**FAST)
    m = s33.drag_metrics(ps.simulate(s33.device(p, "HMF", ratio * p.omega_r)))
    assert m["imbalance_peak_pct"] == pytest.approx(100 * (1 - ratio), rel=1e-9)
    assert m["imbalance_instantaneous_pct"] == pytest.approx(100 * (1 - ratio), rel=1e-9)


def test_parity_balances_total_torque_instantly_and_drag_far_better_than_hmf() -> None:
    p = s33.params(balance_stiffness=0.0, **FAST)
    cut = s33.TRIALS["2-Cut"] * p.omega_r
    parity = ps.simulate(s33.device(p, "PARITY", cut))
    cycle = parity.cycle
    total = (cycle["left_roll_aero"] + cycle["left_roll_inertial"] + cycle["right_roll_aero"] + cycle["right_roll_inertial"]).to_numpy()
    scale = np.abs(cycle["right_roll_aero"].to_numpy()).max()
    # massless whippletree with K2 = 0 and equal arms: the wings' total torques cancel at every instant
    assert np.abs(total).max() < 1e-8 * scale
    hmf = s33.drag_metrics(ps.simulate(s33.device(p, "HMF", cut)))
    par = s33.drag_metrics(parity)
    assert par["imbalance_peak_pct"] < 0.25 * hmf["imbalance_peak_pct"]


@pytest.mark.parametrize("arm_ratio", [0.5, 0.75])
def test_biased_whippletree_roll_torque_ratio_follows_the_arm_ratio(arm_ratio: float) -> None:
    _, ratio = s33.fig2_12(arm_ratio=arm_ratio, **FAST)
    assert ratio == pytest.approx(1 / arm_ratio, rel=1e-6)


def test_kick_recovers_within_one_wingstroke() -> None:
    _, recovery = s33.fig3_4(**FAST)
    cut = recovery.filter(pl.col("trial") != "Control")
    assert (cut["time_constant_ms"] < cut["period_ms"]).all()
    assert (cut["deviation_after_one_stroke"] < 0.05).all()


@pytest.mark.parametrize("tau", [0.07, 0.4, 1.3])
def test_recovery_fit_recovers_a_known_time_constant(tau: float) -> None:
    """Damped oscillator (oscillating decay: envelope peaks) and pure exponential (monotone
    decay), sampled like a trajectory, with noise 1e-7 of the peak (below the 1e-3 floor)."""
    t = np.linspace(0.0, 27.27, 40_001)
    rng = np.random.default_rng(3)
    noise = 1e-7 * rng.standard_normal(t.size)
    omega = np.pi / tau  # a peak of |e| every τ: seven above the floor
    oscillating = 2.5 * np.exp(-t / tau) * np.cos(omega * t + 0.3) + noise
    monotone = -1.7 * np.exp(-t / tau) + noise
    assert s33.recovery_time_constant(t, oscillating) == pytest.approx(tau, rel=0.01)
    assert s33.recovery_time_constant(t, monotone) == pytest.approx(tau, rel=1e-3)
    # without the floor the fit would reach the noise: with floor 1e-12 it is far off
    assert abs(s33.recovery_time_constant(t, monotone, floor=1e-12) / tau - 1) > 0.1


def test_recovery_fit_ignores_a_slower_component_after_the_first_decay() -> None:
    """A fast decay followed by a small slow bump (as the cut-wing kicks show): the fit covers the
    first decay down to the floor only."""
    t = np.linspace(0.0, 20.0, 2001)
    e = np.exp(-t / 0.4) + 2e-3 * np.exp(-((t - 5.0) ** 2)) * (t > 3.0)
    assert s33.recovery_time_constant(t, e) == pytest.approx(0.4, rel=1e-3)
    assert np.isnan(s33.recovery_time_constant(t[:2], e[:2]))
    assert s33.recovery_time_constant(t, np.exp(t / 5.0)[::-1]) == pytest.approx(5.0, rel=1e-6)


def test_recovery_time_constant_does_not_depend_on_the_tolerance() -> None:
    """Fig. 3.4 at rtol 1e-8 and 1e-11: the fit stops above the integration noise, so the time
    constants agree (they differed by ~2x when the fit reached 1e-6 of the first peak)."""
    _, loose = s33.fig3_4(rtol=1e-8, atol=1e-10)
    _, tight = s33.fig3_4(rtol=1e-11, atol=1e-13)
    np.testing.assert_allclose(loose["time_constant_ms"], tight["time_constant_ms"], rtol=1e-4)
    # the most damped trial (Control, largest drag) recovers fastest
    taus = dict(zip(tight["trial"], tight["time_constant_ms"], strict=True))
    assert taus["Control"] < taus["1-Cut"] < taus["2-Cut"]


def test_calibration_recovers_known_parameters() -> None:
    truth = {"inertia": 12.0, "drag_multiplier": 1.3}

    def model(inertia: float, drag_multiplier: float) -> dict[str, float]:
        p = s33.params(inertia=inertia, drag_multiplier=drag_multiplier, **FAST)
        hmf = s33.drag_metrics(ps.simulate(s33.device(p, "HMF", p.omega_r)))
        par = s33.drag_metrics(ps.simulate(s33.device(p, "PARITY", 0.599 * p.omega_r)))
        amplitude = ps.simulate(s33.device(p, "HMF", p.omega_r)).metrics["right_stroke_amplitude"]
        return {"tau": hmf["tau_r_peak"], "inst": par["imbalance_instantaneous_pct"], "amplitude": amplitude}

    target = model(**truth)
    fit = ps.calibrate(model, target, {"inertia": (2.0, 40.0), "drag_multiplier": (0.3, 3.0)}, x0={"inertia": 20.0, "drag_multiplier": 1.0})
    assert fit.success
    assert fit.values["inertia"] == pytest.approx(truth["inertia"], rel=1e-4)
    assert fit.values["drag_multiplier"] == pytest.approx(truth["drag_multiplier"], rel=1e-4)
    assert fit.iterations.height > 3 and "cost" in fit.iterations.columns


def test_calibrate_spec_paths_and_errors() -> None:
    spec = ps.load_spec(Path(__file__).resolve().parents[1] / "examples" / "hmf.toml")
    with pytest.raises(ps.InvalidParameterError, match="path"):
        ps.calibrate(spec, {"left_stroke_amplitude": 0.5}, {"actuator.nonsense": (0.0, 1.0)})
    with pytest.raises(ps.InvalidParameterError, match="free"):
        ps.calibrate(spec, {"left_stroke_amplitude": 0.5}, {"actuator.force_per_volt": (2.0, 1.0)})


def test_calibrate_a_fixed_wing_device_with_undefined_metrics() -> None:
    """Issue 33: a fixed wing's `*_rotation_phase_lag` is None; the fit must not crash on it."""
    spec = ps.devices.load("sreetharan2012_3_3_parity")
    fit = ps.calibrate(spec, {"left_stroke_amplitude": 0.6}, {"actuator.force_per_volt": (0.5, 2.0)})
    assert fit.model_outputs["left_rotation_phase_lag"] is None
    assert fit.model_outputs["left_stroke_amplitude"] == pytest.approx(0.6, abs=1e-4)
    assert repr(fit).startswith("CalibrationResult(actuator.force_per_volt=0.96") and "\n" not in repr(fit)
    with pytest.raises(ps.InvalidParameterError, match=r"targets\.left_rotation_phase_lag.*undefined"):
        ps.calibrate(spec, {"left_rotation_phase_lag": 0.1}, {"actuator.force_per_volt": (0.5, 2.0)})
    with pytest.raises(ps.InvalidParameterError, match="did you mean `left_stroke_amplitude`") as caught:
        ps.calibrate(spec, {"left_stroke_amplitud": 0.6}, {"actuator.force_per_volt": (0.5, 2.0)})
    assert str(caught.value).count("`") <= 12  # a handful of close names, not all 50 metrics
