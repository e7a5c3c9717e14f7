"""§2.5 Lift/Dual PARITY exploration: constraints hold and the tunable hinge acts as described."""

from __future__ import annotations

import numpy as np

import paritysim as ps
from paritysim.trials import section_2_5 as s25

FAST = dict(hinge_stiffness=2.5, max_cycles=60)


def test_lift_parity_couples_deviation_and_stroke() -> None:
    r = ps.simulate(s25.device("lift_parity", "1-Cut", hinge_k2=20.0, **FAST), max_cycles=40)
    df = r.trajectory
    np.testing.assert_allclose(df["left_theta"], df["right_theta"], atol=1e-12)
    np.testing.assert_allclose(df["left_phi"], df["right_phi"], atol=1e-12)
    assert np.abs(df["right_theta"].to_numpy()).max() > 1e-3  # deviation is free and moves


def test_tunable_hinge_stiffens_with_deviation_and_reduces_rotation() -> None:
    """§2.5.1: "a stiffer wing hinge results in less wing rotation"; with k2 > 0 the hinge is
    stiffer wherever the wing deviates."""
    amp = {}
    for k2 in (0.0, 40.0):
        m = ps.simulate(s25.device("lift_parity", "Uncut", hinge_k2=k2, **FAST), max_cycles=40).metrics
        amp[k2] = m["right_rotation_amplitude"]
    assert amp[40.0] < amp[0.0]


def test_hinge_validation_is_typed() -> None:
    import pytest

    with pytest.raises(ps.InvalidParameterError, match=r"tunable_hinge\.stiffness_slope"):
        spec = s25.device("lift_parity", "Uncut", hinge_k2=1.0, **FAST)
        bad = ps.Wing.from_moments(49, 50.5, 1.56, 4.2, aero=spec.wings[0].aero, tunable_hinge=ps.TunableHinge(1.0, 5.0, 1.0))
        ps.simulate(spec.replace(wings=(bad, bad)))


def test_lift_parity_1cut_is_a_period_doubled_orbit_and_the_result_says_so() -> None:
    """The shipped §2.5 Lift PARITY 1-Cut device settles on an orbit that repeats every second
    wingbeat (its period-1 orbit lost stability through a flip). The run converges on it and
    records both wingbeats: the state one wingbeat into the window differs, two wingbeats in
    it returns."""
    spec = ps.devices.load("sreetharan2012_2_5_lift_parity_1cut")
    r = ps.simulate(spec, columns=["left_theta", "left_psi", "left_theta_dot", "left_psi_dot"])
    assert r.converged and r.orbit_cycles == 2
    n = spec.options.samples_per_cycle
    df = r.cycle
    assert df.height == 2 * n + 1
    for name in ("left_theta", "left_psi", "left_theta_dot", "left_psi_dot"):
        v = df[name].to_numpy()
        scale = np.abs(v).max()
        assert abs(v[2 * n] - v[0]) < 1e-5 * scale, name
    one_beat = max(abs(df[c][n] - df[c][0]) / np.abs(df[c].to_numpy()).max() for c in ("left_theta", "left_psi"))
    assert one_beat > 1e-2
    # A sweep says which points doubled; the §3.4 Drag PARITY baseline does not.
    rows = ps.sweep(spec, {"wings[*].tunable_hinge.stiffness_curvature": [20.0]}, metrics=["right_rotation_amplitude"], progress=False)
    assert rows["orbit_cycles"].to_list() == [2]
    assert abs(rows["right_rotation_amplitude"][0] - r.metrics["right_rotation_amplitude"]) < 1e-9
    base = ps.simulate(ps.devices.load("sreetharan2012_3_4_parity_1cut"), columns=[], metrics=["right_rotation_amplitude"])
    assert base.orbit_cycles == 1


def test_dual_parity_1cut_is_a_period_1_orbit_though_its_transient_alternates() -> None:
    """The §2.5 Dual PARITY 1-Cut transient approaches its orbit alternating from cycle to
    cycle (a multiplier in (−1, 0)), so the engine also tries the two-cycle map; the orbit it
    finds repeats every wingbeat, and is reported as period 1 with a one-wingbeat window."""
    spec = ps.devices.load("sreetharan2012_2_5_dual_parity_1cut")
    r = ps.simulate(spec, columns=["left_theta", "right_psi"])
    assert r.converged and r.orbit_cycles == 1
    n = spec.options.samples_per_cycle
    assert r.cycle.height == n + 1
    # The window closes on its start: one wingbeat is the whole orbit.
    for name in ("left_theta", "right_psi"):
        v = r.cycle[name].to_numpy()
        assert abs(v[-1] - v[0]) < 1e-6 * np.abs(v).max(), name
