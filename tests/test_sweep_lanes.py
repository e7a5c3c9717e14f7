"""SIMD-lane sweeps (issue 12 item 5): ``PARITYSIM_LANES`` sets the lane width of the chained
shooting points of linear-map fixed-wing devices; every width must give the one-by-one result
bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

import paritysim as ps

METRICS = ["delta_tau_peak", "tau_r_peak", "tau_l_peak", "imbalance_instantaneous_pct", "imbalance_peak_pct"]


def linear_map_design(steady_state: str = "shooting") -> ps.Simulation:
    """The issue 12 design-sweep device (eq. 2.15 with T = L = 2.5, eq. 2.16 drag, 120 mN at 110 Hz)."""

    def wing(omega: float) -> ps.Wing:
        return ps.Wing(inertia=((29.0, 0, 0), (0, 29.0, 0), (0, 0, 1.0)), aero=ps.Aero(omega1=omega, coefficient=1.0))

    return ps.Simulation(
        wings=(wing(31.3), wing(31.3)),
        configuration=ps.Configuration("drag_parity_fixed"),
        drivetrain=ps.Drivetrain.linear_differential(2.5, 2.5, balance_spring=0.0),
        actuator=ps.Actuator(ps.Waveform(amplitude_v=100.0, frequency_hz=110.0), 1.2, 467.0),
        options=ps.Options(samples_per_cycle=400, steady_state=steady_state),
    )


OMEGA_K2 = {"wings.left.omega_ratio": np.linspace(0.3, 1.0, 3), "drivetrain.balance_spring": np.linspace(0.0, 100.0, 12)}


def run(monkeypatch: pytest.MonkeyPatch, lanes: str, threads: int, axes: dict[str, np.ndarray] = OMEGA_K2) -> np.ndarray:
    monkeypatch.setenv("PARITYSIM_LANES", lanes)
    df = ps.sweep(
        linear_map_design(),
        axes,
        metrics=METRICS,
        threads=threads,
        progress=False,
    )
    assert (df["status"] == "ok").all()
    return df.select(METRICS).to_numpy()


def test_every_lane_width_gives_the_one_by_one_sweep_bit_for_bit(monkeypatch: pytest.MonkeyPatch) -> None:
    scalar = run(monkeypatch, "1", 1)
    # Table 3.2 identities hold on every row (independent of the lanes): Δτ = |τR − τL| at the
    # peaks' scale, imbalance_peak = 100 (τR − τL)/τR.
    peak = 100 * (scalar[:, 1] - scalar[:, 2]) / scalar[:, 1]
    np.testing.assert_allclose(scalar[:, 4], peak, rtol=1e-12, atol=1e-12)
    for lanes, threads in [("2", 1), ("4", 2), ("3", 2)]:
        other = run(monkeypatch, lanes, threads)
        assert np.array_equal(scalar, other), f"lanes {lanes}, threads {threads}"


def test_a_drive_amplitude_sweep_in_lanes_is_the_one_by_one_sweep_bit_for_bit(monkeypatch: pytest.MonkeyPatch) -> None:
    # Neighbours that differ in amplitude or force per volt take their forces from the same
    # table of the drive's sines (lanes/linear_stroke.rs, DriveTables): the same bits.
    axes = {"actuator.waveform.amplitude_v": np.linspace(60.0, 140.0, 6), "actuator.force_per_volt": [1.1, 1.2]}
    scalar = run(monkeypatch, "1", 1, axes)
    assert np.array_equal(scalar, run(monkeypatch, "4", 1, axes))


def test_a_bad_lane_width_is_a_named_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PARITYSIM_LANES", "9")
    with pytest.warns(RuntimeWarning, match="failed"):
        df = ps.sweep(linear_map_design(), {"drivetrain.balance_spring": [0.0, 10.0]}, metrics=METRICS, progress=False)
    # Every point is a row carrying the error, which names the variable and its range.
    assert (df["status"] == "error").all()
    assert all("PARITYSIM_LANES" in e and "[1, 4]" in e for e in df["error"])
