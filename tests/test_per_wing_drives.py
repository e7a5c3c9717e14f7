"""One-wing devices, a linear drive per wing and polynomial transmissions (issue 35) against an
independent scipy integration of their equations of motion.

The one-wing device: a stroke-only wing (inertia ``I`` about the stroke axis, stroke drag
``τ = −Ω C φ̇|φ̇|``, a stroke spring ``k_s``) on one actuator (force ``F(t) = c V(t)``,
stiffness ``K1``) through ``φ = P(σ) = τ1 σ + τ2 σ³/3``, ``σ = −q1``. Lagrange's equation in
``σ`` (kinetic energy ``½ I P'(σ)² σ̇²``, written here from scratch, not from the engine):

    I P'² σ̈ + I P' P'' σ̇² = −F(t) − K1 σ + P' (τ_aero(φ̇) − k_s φ),   φ̇ = P' σ̇.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import paritysim as ps

INERTIA = 60.0  # mg mm², illustrative RoboBee-class wing about the stroke axis
OMEGA_C = 10.0 * 3.46  # Ω1 C of the stroke drag, mg mm²
K_STROKE = 5.0  # mN mm/rad, stroke flexure
FORCE_PER_VOLT = 1.2  # mN/V
K1 = 300.0  # mN/mm
TAU1 = 2.67  # rad/mm


def one_wing(tau2: float = 0.0, volts: float = 60.0, hz: float = 120.0) -> ps.Simulation:
    wing = ps.devices.load("sreetharan2012_3_3_parity").to_dict()["wings"][0]
    wing["inertia"] = [[INERTIA, 0.0, 0.0], [0.0, INERTIA, 0.0], [0.0, 0.0, 3.0]]
    wing["aero"] = {"kind": "stroke_drag", "omega1": 10.0, "coefficient": 3.46}
    wing["springs"]["stroke"]["stiffness"] = K_STROKE
    return ps.Simulation.from_dict(
        {
            "name": "one wing",
            "wings": [wing],
            "configuration": {"name": "single_wing_fixed"},
            "drivetrain": {"kind": "single_linear", "transmission_ratio": TAU1, "cubic_ratio": tau2},
            "actuator": {
                "force_per_volt": FORCE_PER_VOLT,
                "stiffness": K1,
                "waveform": {"kind": "sine", "amplitude_v": volts, "frequency_hz": hz},
            },
            "options": {"rtol": 1e-10, "atol": 1e-12, "steady_tol": 1e-9, "samples_per_cycle": 4000},
        }
    )


def scipy_amplitude(tau2: float, volts: float, hz: float, cycles: int = 80) -> float:
    """Stroke amplitude (max − min)/2 over the last cycle, from rest, by solve_ivp (DOP853)."""
    omega = 2.0 * math.pi * hz / 1000.0  # rad/ms

    def rhs(t: float, y: np.ndarray) -> list[float]:
        s, v = y
        p1 = TAU1 + tau2 * s * s
        p2 = 2.0 * tau2 * s
        phi = TAU1 * s + tau2 * s**3 / 3.0
        phi_dot = p1 * v
        aero = -OMEGA_C * phi_dot * abs(phi_dot)
        force = FORCE_PER_VOLT * volts * math.sin(omega * t)
        acc = (-force - K1 * s + p1 * (aero - K_STROKE * phi) - INERTIA * p1 * p2 * v * v) / (INERTIA * p1 * p1)
        return [v, acc]

    period = 1000.0 / hz
    sol = solve_ivp(rhs, (0.0, cycles * period), [0.0, 0.0], method="DOP853", rtol=1e-11, atol=1e-13, dense_output=True)
    assert sol.success
    amplitudes = []
    for k in (cycles - 2, cycles - 1):
        t = np.linspace(k * period, (k + 1) * period, 20001)
        s = sol.sol(t)[0]
        phi = TAU1 * s + tau2 * s**3 / 3.0
        amplitudes.append(0.5 * (phi.max() - phi.min()))
    # Settled: the last two cycles agree.
    assert abs(amplitudes[0] - amplitudes[1]) < 1e-8 * amplitudes[1]
    return amplitudes[1]


@pytest.mark.parametrize(("tau2", "volts", "hz"), [(0.0, 60.0, 120.0), (25.0, 80.0, 150.0), (-4.0, 50.0, 100.0)])
def test_one_wing_amplitude_equals_an_independent_scipy_integration(tau2: float, volts: float, hz: float) -> None:
    result = ps.simulate(one_wing(tau2, volts, hz))
    assert result.converged
    engine = result.metrics["wing_stroke_amplitude"]
    reference = scipy_amplitude(tau2, volts, hz)
    # The engine samples the recorded cycle (4000 points): its peak is within ~(π/4000)² of the
    # true one (measured 2e-8 linear, 5e-8 with τ2 = 25 at 8000 points).
    assert engine == pytest.approx(reference, rel=1e-6)
    assert "left_stroke_amplitude" not in result.metrics


def test_one_wing_runs_in_sweeps_and_stability() -> None:
    spec = one_wing(25.0)
    rows = ps.sweep(spec, {"actuator.waveform.amplitude_v": [40.0, 80.0]}, progress=False)
    for volts, amplitude in zip([40.0, 80.0], rows["wing_stroke_amplitude"].to_list(), strict=True):
        single = ps.simulate(spec.with_paths({"actuator.waveform.amplitude_v": volts}))
        # Rows continue from their neighbour's orbit: equal to the steady-state tolerance.
        assert amplitude == pytest.approx(single.metrics["wing_stroke_amplitude"], rel=1e-8)
    floquet = ps.stability.floquet(spec)
    # A damped 1-DOF oscillator: two multipliers inside the unit circle.
    assert len(floquet.multipliers) == 2
    assert max(abs(m) for m in floquet.multipliers) < 1.0
    # The §2.6–2.7 whippletree analysis refuses it with a typed error.
    with pytest.raises(ps.ConstraintError, match="fixed-wing device integrated in drivetrain coordinates"):
        ps.stability.linearise(spec)


def test_one_wing_errors_name_the_field() -> None:
    spec = one_wing().to_dict()
    spec["drivetrain"] = {"kind": "dual_linear"}
    with pytest.raises(ps.InvalidParameterError, match="drivetrain.kind"):
        ps.simulate(ps.Simulation.from_dict(spec))
    spec = one_wing().to_dict()
    spec["configuration"] = {"name": "hmf_fixed"}
    with pytest.raises(ps.InvalidParameterError, match="configuration.name"):
        ps.simulate(ps.Simulation.from_dict(spec))
    spec = one_wing().to_dict()
    spec["drivetrain"]["cubic_ratio"] = 2e4
    with pytest.raises(ps.InvalidParameterError, match="drivetrain.cubic_ratio"):
        ps.simulate(ps.Simulation.from_dict(spec))


def test_the_actuator_power_column_counts_both_drives() -> None:
    # It was the left side's: its cycle integral was half of work_actuator_per_cycle, its mean
    # half of actuator_power_mean.
    result = ps.simulate(ps.devices.load("robobee_dual_linear"), progress=False)
    cycle = result.cycle
    t, power = cycle["time_ms"].to_numpy(), cycle["actuator_power"].to_numpy()
    work = np.trapezoid(power, t)
    assert work == pytest.approx(result.metrics["work_actuator_per_cycle"], rel=1e-6)
    assert work / (t[-1] - t[0]) == pytest.approx(result.metrics["actuator_power_mean"], rel=1e-6)
    # And the rate of the work integral, sample by sample.
    total = result.trajectory
    rate = np.gradient(total["work_actuator"].to_numpy(), total["time_ms"].to_numpy())
    np.testing.assert_allclose(rate[5:-5], total["actuator_power"].to_numpy()[5:-5], atol=2e-2 * np.abs(power).max())
