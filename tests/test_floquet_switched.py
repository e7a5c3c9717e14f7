"""Floquet multipliers of the switched free-deviation devices (§2.5 Lift and Dual PARITY).

Their variational equations run on a numerical Jacobian and miss the jumps at the blade
element's switches (docs/findings.md §30): the monodromy came out 0.61 (Lift) and 0.17 (Dual)
off central differences of the map, and ``ps.stability.floquet`` called both orbits
"marginal". The Lift PARITY also settles on a period-doubled orbit that the one-cycle shooting
did not analyse. Checked here against an independent formulation: ``ps.sensitivity``'s
monodromy, central differences of the period map on the shooting's fixed step grid, at the
orbit ``ps.simulate`` finds.
"""

from __future__ import annotations

import numpy as np
import pytest

import paritysim as ps

LIFT, DUAL = "sreetharan2012_2_5_lift_parity_1cut", "sreetharan2012_2_5_dual_parity_1cut"


def _with_balance_spring(name: str, k2: float) -> ps.Simulation:
    spec = ps.devices.load(name)
    return spec.with_paths({"drivetrain.balance_spring": k2})


def test_the_lift_parity_orbit_is_period_doubled_and_stable():
    spec = ps.devices.load(LIFT)
    run = ps.simulate(spec, columns=[])
    assert run.orbit_cycles == 2  # the engine's steady state covers two drive cycles
    result = ps.stability.floquet(spec)
    drive_period_ms = 1e3 / spec.actuator.waveform.frequency_hz
    assert result.orbit_cycles == 2
    assert result.period_ms == pytest.approx(2 * drive_period_ms, rel=1e-12)
    assert result.stability == "asymptotic" and result.spectral_radius < 0.5
    assert result.monodromy_uncertainty < 1e-5
    assert "(2 drive cycles)" in repr(result)
    # The one-cycle orbit exists but is flip-unstable: why the device doubles its period.
    one = ps.stability.floquet(spec, orbit_cycles=1)
    assert one.orbit_cycles == 1 and one.stability == "unstable"
    assert one.multipliers[0].real < -1.0 and abs(one.multipliers[0].imag) < 1e-9
    assert one.monodromy_uncertainty < 1e-5


@pytest.mark.parametrize("name", [LIFT, DUAL])
def test_switched_multipliers_agree_with_the_fixed_grid_map(name: str):
    """Two formulations of the monodromy: central differences of the adaptive period map
    (floquet) and of the fixed-grid map at the steady state of ps.simulate (sensitivity)."""
    spec = _with_balance_spring(name, 30.0)  # K2 > 0: an isolated orbit
    result = ps.stability.floquet(spec)
    reference = ps.sensitivity(spec, ["actuator.waveform.amplitude_v"]).multipliers
    ours = np.sort(np.abs(result.multipliers))[::-1][:3]
    theirs = np.sort(np.abs(reference))[::-1][:3]
    # The two maps differ by the grids' truncation (rtol 1e-12 adaptive, the run's grid fixed).
    assert ours == pytest.approx(theirs, abs=2e-4)
    assert result.monodromy_uncertainty < 1e-5
    assert result.stability == "asymptotic"


def test_orbit_cycles_out_of_range_is_named():
    with pytest.raises(ps.InvalidParameterError, match="orbit_cycles"):
        ps.stability.floquet(ps.devices.load(LIFT), orbit_cycles=9)
