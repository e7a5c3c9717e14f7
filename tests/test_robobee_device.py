"""The RoboBee-class device of the library (`robobee_dual_linear`: two wings, a linear drive per
wing): it loads with a provenance entry per value, runs to a converged orbit, sweeps, and its
stroke resonance is the driven oscillator's √(K/M) of its own parameters."""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest

import paritysim as ps

NAME = "robobee_dual_linear"


def test_it_loads_with_a_source_or_an_estimate_for_every_value() -> None:
    spec = ps.devices.load(NAME)
    assert spec.drivetrain.kind == "dual_linear" and len(spec.wings) == 2
    info = ps.devices.info(NAME)
    assert info.stated_in == "the sources" and "Stated in the sources" in str(info)
    # Every stated value names its source (authors and year, or the issue that describes it).
    for line in info.stated:
        assert re.search(r"(Ma|Wood).*20\d\d|issue 35", line), line
    # Every value that is not stated says it is an estimate or where it follows from.
    for line in info.choices:
        assert re.search(r"representative|stated|assumption|from_blocked_force|Wing.from_planform", line), line
    # The stated numbers are the spec's.
    assert spec.drivetrain.transmission_ratio == 2.67
    assert spec.actuator.waveform.frequency_hz == 120.0
    # A flat wing: the perpendicular-axis theorem Iyy = Ixx + Izz.
    inertia = spec.wings[0].inertia
    assert inertia[1][1] == pytest.approx(inertia[0][0] + inertia[2][2], rel=1e-12)


def test_it_runs_to_a_converged_symmetric_orbit_and_sweeps() -> None:
    spec = ps.devices.load(NAME)
    result = ps.simulate(spec)
    assert result.converged
    left, right = result.metrics["left_stroke_amplitude"], result.metrics["right_stroke_amplitude"]
    # Identical wings on identical drives: the two sides are one motion.
    assert left == pytest.approx(right, rel=1e-9)
    assert 0.3 < left < 1.2  # rad: flapping, neither stalled nor past the stops
    assert result.metrics["lift_mean"] > 0
    rows = ps.sweep(spec, {"actuator.waveform.amplitude_v": [60.0, 100.0, 140.0]}, progress=False)
    assert (rows["status"] == "ok").all()
    amplitudes = rows["left_stroke_amplitude"].to_numpy()
    assert np.all(np.diff(amplitudes) > 0)  # more voltage, more stroke


def test_its_resonance_is_root_k_over_m_of_its_own_parameters() -> None:
    """Without air and with the wings held at ψ = 0, each side is `M q̈ + b q̇ + K q = F sin ωt`
    with `M = Ixx τ²` (the wing's inertia about the stroke axis through φ = −τ q) and
    `K = K1 + k_s τ²` (the actuator and the stroke flexure): its amplitude peaks at
    `ω0 √(1 − 2ζ²)`, `ω0 = √(K/M)`, `ζ = b / (2√(K M))`."""
    spec = ps.devices.load(NAME)
    tau = spec.drivetrain.transmission_ratio
    ixx = spec.wings[0].inertia[0][0]
    k = spec.actuator.stiffness + spec.wings[0].springs.stroke.stiffness * tau**2
    m = ixx * tau**2 + spec.actuator.mass_mg
    zeta = 0.05
    b = zeta * 2.0 * math.sqrt(k * m)
    f_peak = math.sqrt(k / m) * math.sqrt(1.0 - 2.0 * zeta**2) / (2.0 * math.pi) * 1e3  # Hz
    vacuum = spec.replace(
        wings=tuple(dataclasses.replace(w, aero=None) for w in spec.wings),
        configuration=ps.Configuration("drag_parity_fixed"),
        actuator=dataclasses.replace(spec.actuator, damping=b, waveform=dataclasses.replace(spec.actuator.waveform, amplitude_v=5.0)),
        options=dataclasses.replace(spec.options, samples_per_cycle=400, steady_tol=1e-10),
    )
    freqs = f_peak + np.linspace(-4.0, 4.0, 9)
    rows = ps.sweep(vacuum, {"actuator.waveform.frequency_hz": list(freqs)}, progress=False)
    amp = rows["left_stroke_amplitude"].to_numpy()
    i = int(np.argmax(amp))
    assert 0 < i < len(freqs) - 1
    c = np.polyfit(freqs[i - 1 : i + 2], amp[i - 1 : i + 2], 2)
    f_sim = -c[1] / (2 * c[0])
    # The resonance curve near its peak is a parabola to O(Δf²/(ζ f)²); 1 Hz steps give ~1e-3.
    assert f_sim == pytest.approx(f_peak, rel=2e-3)
    # And the peak amplitude is the driven oscillator's F / (b ω_d), ω_d = ω0 √(1 − ζ²), through φ = τ q.
    force = spec.actuator.force_per_volt * 5.0
    omega0 = math.sqrt(k / m)
    assert amp.max() == pytest.approx(tau * force / (b * omega0 * math.sqrt(1 - zeta**2)), rel=5e-3)
