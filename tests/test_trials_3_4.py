"""§3.4 rotating wings: symmetry, passive rotation and inertial coupling, computed by the model."""

from __future__ import annotations

import dataclasses
import importlib
import math

import numpy as np
import pytest

import paritysim as ps
# paritysim.trials.section_3_4 is the trial function; the module is loaded by name
s34 = importlib.import_module("paritysim.trials.section_3_4")

P = s34.params(hinge_stiffness=2.5, max_cycles=80)


def test_identical_wings_are_mirror_images_with_no_net_roll_or_yaw() -> None:
    spec = s34.device(P, "PARITY", "Uncut")
    spec = spec.replace(wings=(spec.wings[0], spec.wings[0]))
    df = ps.simulate(spec).trajectory
    np.testing.assert_allclose(df["left_phi"], df["right_phi"], atol=1e-9)
    np.testing.assert_allclose(df["left_psi"], df["right_psi"], atol=1e-9)
    scale = np.abs(df["right_roll_aero"].to_numpy()).max()
    assert np.abs(df["roll_total"].to_numpy()).max() < 1e-7 * scale
    assert np.abs(df["yaw_total"].to_numpy()).max() < 1e-7 * scale


def test_cut_wing_parity_roll_imbalance_below_hmf() -> None:
    rms = {d: s34.summarize(ps.simulate(s34.device(P, d, "1-Cut")))["roll_imbalance_rms"] for d in ("HMF", "PARITY")}
    assert rms["PARITY"] < 0.5 * rms["HMF"]


def test_passive_rotation_lags_stroke() -> None:
    m = ps.simulate(s34.device(P, "PARITY", "Uncut")).metrics
    for wing in ("left", "right"):
        lag = math.degrees(m[f"{wing}_rotation_phase_lag"])
        assert 45.0 <= lag <= 135.0, (wing, lag)


def test_flipping_ixz_flips_the_inertially_driven_rotation() -> None:
    """With drag about the stroke axis only, ψ is driven by inertial coupling alone. The kinetic
    energy ½ωᵀIω with ω = (φ̇ cos ψ, −φ̇ sin ψ, ψ̇) is invariant under (Ixz, ψ) → (−Ixz, −ψ), and
    the hinge spring is even in ψ, so ψ must change sign and φ must not change."""
    hinge = ps.Springs(hinge=ps.Spring(stiffness=2.5))

    def run(ixz: float) -> ps.SimulationResult:
        wing = ps.Wing.from_moments(49.0, 50.5, 1.56, ixz, springs=hinge, aero=ps.Aero(kind="stroke_drag", omega1=46.8, coefficient=3.46))
        spec = s34.device(P, "HMF", "Uncut").replace(wings=(wing, wing))
        # the same fixed number of cycles for both runs: only the symmetry differs between them
        return ps.simulate(spec, min_cycles=40, max_cycles=40, steady_tol=1e-30, rtol=1e-10, atol=1e-12)

    plus, minus = run(4.2).trajectory, run(-4.2).trajectory
    assert np.abs(plus["right_psi"].to_numpy()).max() > 0.05
    # dense-output interpolation noise is ~1e-7 (docs/findings.md §4); a wrong sign would differ by the signal (> 0.05)
    np.testing.assert_allclose(minus["right_psi"], -plus["right_psi"].to_numpy(), atol=1e-6)
    np.testing.assert_allclose(minus["right_phi"], plus["right_phi"], atol=1e-6)


def test_unknown_parameter_is_rejected() -> None:
    with pytest.raises(ps.InvalidParameterError, match="hinge"):
        s34.params(hinge=1.0)


def test_the_trials_inputs_are_checked_by_name() -> None:
    # A typo in `aero` ran the blade element; device/summarize raised KeyError/AttributeError;
    # whitney_wood_omegas(nan) returned NaNs.
    for kwargs, field in (({"aero": "foo"}, "aero"), ({"model": "dickinson"}, "model"), ({"dc_offset": "none"}, "dc_offset")):
        with pytest.raises(ps.InvalidParameterError) as info:
            s34.params(**kwargs)
        assert info.value.field == field
    p = s34.params(hinge_stiffness=2.5)
    for args, field in ((("FOO", "Uncut"), "drivetrain"), (("PARITY", "3-Cut"), "trial")):
        with pytest.raises(ps.InvalidParameterError) as info:
            s34.device(p, *args)
        assert info.value.field == field
    with pytest.raises(ps.InvalidParameterError) as info:
        s34.summarize(s34.device(p, "PARITY", "Uncut"))  # a spec, not its run
    assert info.value.field == "result"
    for bad in (float("nan"), -1.0, 0.0):
        with pytest.raises(ps.InvalidParameterError) as info:
            s34.whitney_wood_omegas(bad)
        assert info.value.field == "omega3"


def test_the_pinned_hinge_reaches_a_rotation_outside_the_first_bracket() -> None:
    # brentq's fixed bracket [1.5, 6] raised scipy's ValueError for 90 deg.
    p = s34.params(target_rotation_deg=90.0, max_cycles=80)
    k = s34.hinge_stiffness(p)
    rotation = ps.simulate(s34.device(p, "PARITY", "Uncut", hinge=k), progress=False).metrics["right_rotation_amplitude"]
    assert math.degrees(rotation) == pytest.approx(90.0, abs=0.05)
    with pytest.raises(ps.InvalidParameterError) as info:
        s34.hinge_stiffness(s34.params(target_rotation_deg=-5.0, max_cycles=80))
    assert info.value.field == "target_rotation_deg"
