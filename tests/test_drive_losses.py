"""An actuator and drivetrain with mass and losses (issue 35 item 2): actuator damping `b1`,
whippletree damping `b2`, hinge damping `bψ`, the actuator's effective mass `m` reflected through
the transmission, cubic actuator stiffness; checked against closed forms (energy dissipated per
cycle, the driven damped oscillator's resonance curve, `√(K / M_eff)`, the harmonic-balance
backbone of a hardening spring), not against the code's own numbers."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import paritysim as ps

T = 2.5  # transmission ratio (rad/mm)
INERTIA = 29.0  # stroke inertia of each wing (mg·mm²)
K1 = 467.0  # actuator stiffness (mN/mm)
FPV = 1.2  # force per volt (mN/V)


def vacuum(
    *,
    volts: float = 20.0,
    freq: float = 150.0,
    mass: float = 0.0,
    damping: float = 0.0,
    cubic: float = 0.0,
    balance_damping: float = 0.0,
    balance_spring: float = 0.0,
    arm_ratio: float = 1.0,
    formulation: str | None = None,
) -> ps.Simulation:
    """Two fixed stroke-only wings without aerodynamics on the linear map (eq. 2.15): with equal
    arms `q1` is a driven oscillator `M q̈1 + b1 q̇1 + K1 q1 + K1c q1³ = F0 sin ωt` with
    `M = m + 2 I T²` (φ = −T q1 on both wings), and `q2` stays at rest."""
    wing = ps.Wing(inertia=((INERTIA, 0, 0), (0, INERTIA, 0), (0, 0, 1.0)), aero=None)
    spec = ps.Simulation(
        wings=(wing, wing),
        configuration=ps.Configuration("drag_parity_fixed"),
        drivetrain=dataclasses.replace(
            ps.Drivetrain.linear_differential(T, 2.5, arm_ratio=arm_ratio, balance_spring=balance_spring),
            balance_damping=balance_damping,
        ),
        actuator=ps.Actuator(
            ps.Waveform(amplitude_v=volts, frequency_hz=freq),
            FPV,
            K1,
            mass_mg=mass,
            damping=damping,
            cubic_stiffness=cubic,
        ),
        options=ps.Options(samples_per_cycle=400),
    )
    if formulation is not None:
        spec = spec.replace(formulation=formulation)
    return spec


def one_cycle_integral(result: ps.SimulationResult, integrand: np.ndarray) -> float:
    """`∮ integrand dt` over the last recorded period (rectangle rule on the uniform samples of
    one period: exact to round-off for a smooth periodic integrand)."""
    t = result.trajectory["time_ms"].to_numpy()
    period = 1.0 / (result.spec.actuator.waveform.frequency_hz * 1e-3)
    last = t >= t[-1] - period - 1e-9
    dt = np.diff(t[last])
    return float(np.sum(integrand[last][:-1] * dt))


@pytest.mark.parametrize(
    "which",
    ["actuator", "balance", "hinge"],
)
def test_each_damper_dissipates_its_closed_form_per_cycle(which: str) -> None:
    """The actuator's work per cycle less the air's is what the damper dissipates, `∮ b q̇² dt`
    from the recorded rates (springs and inertia return their energy; in vacuum the air takes
    nothing)."""
    if which == "actuator":
        spec = vacuum(damping=15.0, volts=40.0)
        rates = ["q1_dot"]
        b = 15.0
    elif which == "balance":
        # Unequal arms couple q2 to the drive; b2 is the only loss.
        spec = vacuum(balance_damping=0.4, balance_spring=20.0, arm_ratio=1.6, volts=40.0)
        rates = ["q2_dot"]
        b = 0.4
    else:
        # The §3.4 PARITY's rotating wings with bψ on both hinges: the aerodynamic work is a
        # metric of its own, so the balance is W_actuator + W_aero = ∮ bψ (ψ̇L² + ψ̇R²) dt.
        base = ps.devices.load("sreetharan2012_3_4_parity")
        b = 0.5
        wings = tuple(dataclasses.replace(w, springs=dataclasses.replace(w.springs, hinge_damping=b)) for w in base.wings)
        spec = base.replace(wings=wings)
        rates = ["left_psi_dot", "right_psi_dot"]
    result = ps.simulate(spec, max_cycles=400, columns=[*rates])
    df = result.trajectory
    dissipated = sum(one_cycle_integral(result, b * df[c].to_numpy() ** 2) for c in rates)
    work = result.metrics["work_actuator_per_cycle"] + result.metrics["work_aero_per_cycle"]
    assert dissipated > 1e-2 * result.metrics["work_actuator_per_cycle"]
    assert work == pytest.approx(dissipated, rel=1e-6)


def resonance_amplitude(omega: np.ndarray, force: float, stiffness: float, mass: float, damping: float) -> np.ndarray:
    """`|q1|` of `M q̈ + b q̇ + K q = F sin ωt`: `F / √((K − M ω²)² + (b ω)²)`."""
    return force / np.sqrt((stiffness - mass * omega**2) ** 2 + (damping * omega) ** 2)


@pytest.mark.parametrize("formulation", [None, "null_space"])
def test_damped_device_follows_the_analytic_resonance_curve(formulation: str | None) -> None:
    """A linear damped vacuum device with an actuator mass: stroke amplitude over frequency is
    `T F0 / √((K1 − M ω²)² + (b1 ω)²)` with `M = m + 2 I T²`, on the drivetrain-coordinate
    (lanes) and the general form."""
    mass, b1, volts = 40.0, 30.0, 10.0
    freqs = np.linspace(80.0, 260.0, 10)
    # 4000 samples per cycle: the sampled peak-to-peak is within (π/4000)²/2 = 3e-7 of the
    # sinusoid's.
    spec = vacuum(mass=mass, damping=b1, volts=volts, formulation=formulation)
    spec = spec.replace(options=dataclasses.replace(spec.options, samples_per_cycle=4000))
    df = ps.sweep(spec, {"actuator.waveform.frequency_hz": freqs}, metrics=["left_stroke_amplitude"], progress=False)
    assert (df["status"] == "ok").all()
    omega = 2 * math.pi * freqs * 1e-3
    expected = T * resonance_amplitude(omega, FPV * volts, K1, mass + 2 * INERTIA * T**2, b1)
    np.testing.assert_allclose(df["left_stroke_amplitude"].to_numpy(), expected, rtol=1e-6)


def peak_frequency(spec: ps.Simulation, freqs: np.ndarray) -> tuple[float, float]:
    """The frequency (Hz) and stroke amplitude of the largest response: a parabola through the
    sweep's three points around its maximum."""
    df = ps.sweep(spec, {"actuator.waveform.frequency_hz": freqs}, metrics=["left_stroke_amplitude"], progress=False)
    assert (df["status"] == "ok").all()
    a = df["left_stroke_amplitude"].to_numpy()
    i = int(np.clip(np.argmax(a), 1, len(a) - 2))
    c = np.polyfit(freqs[i - 1 : i + 2], a[i - 1 : i + 2], 2)
    f = -c[1] / (2 * c[0])
    return float(f), float(np.polyval(c, f))


def test_reflected_actuator_mass_shifts_the_natural_frequency() -> None:
    """The resonance of a lightly damped device moves as `√(K1 / (m + 2 I T²))` predicts when the
    actuator gains a mass `m` (the mass reflected through the transmission: `m / T²` per
    radian of stroke), on both forms that take it."""
    b1 = 2.0
    for formulation in (None, "null_space"):
        for mass in (0.0, 150.0):
            m_eff = mass + 2 * INERTIA * T**2
            f0 = math.sqrt(K1 / m_eff) / (2 * math.pi) * 1e3
            zeta = b1 / (2 * math.sqrt(K1 * m_eff))
            f_peak = f0 * math.sqrt(1 - 2 * zeta**2)  # displacement resonance of a damped oscillator
            freqs = f_peak * np.linspace(0.985, 1.015, 7)
            f, _ = peak_frequency(vacuum(mass=mass, damping=b1, volts=2.0, formulation=formulation), freqs)
            assert f == pytest.approx(f_peak, rel=2e-4), (formulation, mass)


def harmonic_balance_peak(volts: float, cubic: float, b1: float, m_eff: float) -> tuple[float, float]:
    """The peak of the harmonic-balance (first-harmonic) response of
    `M q̈ + b q̇ + K q + Kc q³ = F sin ωt`: the amplitude `A` at ω solves
    `A² ((K + ¾ Kc A² − M ω²)² + (b ω)²) = F²` (a cubic in `A²`, one positive root when the
    curve does not fold); its maximum lies near the backbone `M ω² = K + ¾ Kc A²`. Returns
    (peak frequency in Hz, peak amplitude A in mm) from a fine grid and a parabola."""
    force = FPV * volts
    omega0 = math.sqrt(K1 / m_eff)
    omegas = omega0 * np.linspace(0.9, 1.3, 4001)
    amplitude = np.empty_like(omegas)
    for i, w in enumerate(omegas):
        d = K1 - m_eff * w**2
        # x ((d + c x)² + (b w)²) = F² with c = ¾ Kc: c² x³ + 2 c d x² + (d² + b²w²) x − F² = 0.
        c = 0.75 * cubic
        roots = np.roots([c * c, 2 * c * d, d * d + (b1 * w) ** 2, -(force**2)])
        real = roots[(abs(roots.imag) < 1e-12 * abs(roots).max()) & (roots.real > 0)].real
        assert len(real) == 1, "the harmonic-balance curve folds: pick more damping"
        amplitude[i] = math.sqrt(real[0])
    k = int(np.argmax(amplitude))
    cfit = np.polyfit(omegas[k - 2 : k + 3], amplitude[k - 2 : k + 3], 2)
    w_peak = -cfit[1] / (2 * cfit[0])
    return w_peak / (2 * math.pi) * 1e3, float(np.polyval(cfit, w_peak))


def test_cubic_stiffness_raises_the_peak_frequency_with_voltage_as_the_backbone_predicts() -> None:
    """A hardening actuator (`K1c > 0`): the resonance rises with drive voltage, by the
    harmonic-balance backbone `ω² ≈ ω0² + ¾ (K1c / M) A²` (sign and size, with the damping's
    small offset from the backbone); the linear device's peak does not move."""
    b1, cubic = 40.0, 200.0
    m_eff = 2 * INERTIA * T**2
    f0 = math.sqrt(K1 / m_eff) / (2 * math.pi) * 1e3
    zeta = b1 / (2 * math.sqrt(K1 * m_eff))
    f_linear = f0 * math.sqrt(1 - 2 * zeta**2)
    peaks = {}
    for volts in (8.0, 20.0):
        f_hb, a_hb = harmonic_balance_peak(volts, cubic, b1, m_eff)
        freqs = f_hb + np.linspace(-3.0, 3.0, 9)
        f, stroke = peak_frequency(vacuum(damping=b1, cubic=cubic, volts=volts, freq=f_hb), freqs)
        peaks[volts] = f
        # Backbone by hand: ω² − ω_lin² ≈ ¾ (K1c / M) A² at the peak amplitude.
        backbone = math.sqrt((2 * math.pi * f_linear * 1e-3) ** 2 + 0.75 * cubic / m_eff * a_hb**2) / (2 * math.pi) * 1e3
        assert f_hb == pytest.approx(backbone, abs=0.02 * (backbone - f_linear) + 0.05)
        # The simulated shift from the linear peak: positive and harmonic balance's to 5 %.
        assert f - f_linear > 0
        assert f - f_linear == pytest.approx(f_hb - f_linear, rel=0.05), (volts, f, f_hb, f_linear)
        assert stroke / T == pytest.approx(a_hb, rel=0.02)
    assert peaks[20.0] > peaks[8.0] + 3.0
    # Linear: the peak stays at ω0 √(1 − 2ζ²) at both voltages.
    for volts in (8.0, 20.0):
        f, _ = peak_frequency(vacuum(damping=b1, volts=volts), f_linear + np.linspace(-3.0, 3.0, 9))
        assert f == pytest.approx(f_linear, rel=2e-4)


def test_zero_terms_are_the_default_spec() -> None:
    """The new fields default to zero and a spec that spells the zeros out is the same spec (the
    bit-for-bit check against the previous engine is in docs/findings.md)."""
    spec = ps.devices.load("sreetharan2012_3_3_parity")
    assert spec.actuator.mass_mg == 0.0 and spec.actuator.damping == 0.0 and spec.actuator.cubic_stiffness == 0.0
    assert all(w.springs.hinge_damping == 0.0 for w in spec.wings)
    explicit = spec.replace(actuator=dataclasses.replace(spec.actuator, mass_mg=0.0, damping=0.0, cubic_stiffness=0.0))
    a = ps.simulate(spec, columns=[]).metrics
    b = ps.simulate(explicit, columns=[]).metrics
    assert a == b


def test_lanes_are_bit_identical_with_the_new_terms(monkeypatch: pytest.MonkeyPatch) -> None:
    """A sweep over the new terms on the linear map gives the scalar bits at lane widths 1 and
    4 (the lanes take the drive load and its Jacobian from the same generic code)."""
    spec = vacuum(volts=30.0, freq=170.0, balance_spring=15.0, arm_ratio=1.3).replace(
        wings=tuple(dataclasses.replace(w, aero=ps.Aero(omega1=31.3, coefficient=1.0)) for w in vacuum().wings)
    )
    grid = {
        "actuator.damping": [0.0, 5.0, 20.0],
        "actuator.mass_mg": [0.0, 60.0],
        "actuator.cubic_stiffness": [0.0, 3e3],
        "drivetrain.balance_damping": [0.0, 0.3],
    }
    metrics = ["left_stroke_amplitude", "q2_amplitude", "work_actuator_per_cycle"]
    out = {}
    for lanes in ("1", "4"):
        monkeypatch.setenv("PARITYSIM_LANES", lanes)
        df = ps.sweep(spec, grid, metrics=metrics, threads=1, progress=False)
        assert (df["status"] == "ok").all()
        out[lanes] = df.select(metrics).to_numpy()
    assert out["1"].tobytes() == out["4"].tobytes()


@pytest.mark.parametrize(
    ("path", "value", "field"),
    [
        ("actuator.mass_mg", -1.0, "mass_mg"),
        ("actuator.damping", float("nan"), "damping"),
        ("actuator.cubic_stiffness", -3.0, "cubic_stiffness"),
        ("drivetrain.balance_damping", -0.1, "balance_damping"),
        ("wings[0].springs.hinge_damping", -0.5, "hinge_damping"),
    ],
)
def test_bad_values_are_typed_errors_naming_the_field(path: str, value: float, field: str) -> None:
    spec = vacuum()
    data = spec.to_dict()
    node = data
    keys = path.replace("[0]", ".0").split(".")
    for k in keys[:-1]:
        node = node[int(k)] if k.isdigit() else node[k]
    node[keys[-1]] = value
    with pytest.raises(ps.InvalidParameterError, match=field):
        ps.simulate(ps.Simulation.from_dict(data), columns=[])


def test_balance_terms_need_a_whippletree() -> None:
    spec = ps.devices.load("sreetharan2012_3_3_hmf_four_bar")
    assert spec.drivetrain.kind == "hmf_four_bar"
    with pytest.raises(ps.InvalidParameterError, match="balance_damping"):
        data = spec.to_dict()
        data["drivetrain"]["balance_damping"] = 0.1
        ps.simulate(ps.Simulation.from_dict(data), columns=[])


def test_actuator_mass_is_refused_in_free_flight() -> None:
    spec = ps.devices.load("sreetharan2012_3_3_parity")
    if not hasattr(ps, "Body"):
        pytest.skip("no body")
    flying = spec.replace(
        actuator=dataclasses.replace(spec.actuator, mass_mg=5.0),
        body=ps.Body(mode="roll"),
    )
    with pytest.raises(ps.InvalidParameterError, match="mass_mg"):
        ps.simulate(flying, max_cycles=2)


def test_actuator_from_blocked_force() -> None:
    """Blocked force F_b at V and free deflection δ: stiffness F_b / δ, force per volt F_b / V;
    the §3.3.1 actuator is 120 mN blocked at 100 V with 467 mN/mm, δ = 0.257 mm."""
    a = ps.Actuator.from_blocked_force(blocked_force_mn=120.0, free_deflection_mm=120.0 / 467.0, voltage_v=100.0, damping=3.0)
    assert a.stiffness == pytest.approx(467.0, rel=1e-12)
    assert a.force_per_volt == pytest.approx(1.2, rel=1e-12)
    assert a.damping == 3.0
    with pytest.raises(ps.InvalidParameterError, match="free_deflection_mm"):
        ps.Actuator.from_blocked_force(blocked_force_mn=120.0, free_deflection_mm=0.0, voltage_v=100.0)


@pytest.mark.parametrize("name", ["sreetharan2012_3_3_hmf_four_bar", "sreetharan2012_3_3_parity_linkage"])
def test_actuator_mass_through_a_nonlinear_linkage_agrees_between_forms(name: str) -> None:
    """Through a rod-crank linkage (`φ̈ = J q̈ + h`, `J` varying) the two forms model the mass
    independently: drivetrain coordinates add `m` to `M_q`; the general form adds
    `J⁻ᵀ diag(m) J⁻¹` to the strokes' mass matrix and `J⁻ᵀ diag(m) J⁻¹ h` to their forces. Their
    orbits agree to the integration tolerance, and the mass moves the orbit."""
    base = ps.devices.load(name)
    heavy = base.replace(actuator=dataclasses.replace(base.actuator, mass_mg=200.0, damping=4.0))
    metrics = ["left_stroke_amplitude", "right_stroke_amplitude", "work_actuator_per_cycle", "q2_amplitude"]
    fast = ps.simulate(heavy, columns=[], metrics=metrics).metrics
    general = ps.simulate(heavy.replace(formulation="null_space"), columns=[], metrics=metrics).metrics
    light = ps.simulate(base, columns=[], metrics=metrics).metrics
    for m in metrics:
        assert general[m] == pytest.approx(fast[m], rel=1e-6, abs=1e-9), m
    assert abs(fast["left_stroke_amplitude"] / light["left_stroke_amplitude"] - 1) > 1e-2


def test_stroke_plane_form_with_losses_equals_the_general_form() -> None:
    """The §3.4 PARITY with every loss but the mass runs the closed-form stroke-plane equations
    (analytic Jacobian with the drive's slope at the state, its damping and `−bψ`); the
    projection formulation runs the general equations: same orbit to the tolerance."""
    base = ps.devices.load("sreetharan2012_3_4_parity")
    wings = tuple(dataclasses.replace(w, springs=dataclasses.replace(w.springs, hinge_damping=0.3)) for w in base.wings)
    spec = base.replace(
        wings=wings,
        actuator=dataclasses.replace(base.actuator, damping=6.0, cubic_stiffness=2e3),
        drivetrain=dataclasses.replace(base.drivetrain, balance_damping=0.5),
    )
    metrics = ["left_stroke_amplitude", "right_rotation_amplitude", "work_actuator_per_cycle", "work_aero_per_cycle"]
    lean = ps.simulate(spec, columns=[], metrics=metrics).metrics
    general = ps.simulate(spec.replace(formulation="projection"), columns=[], metrics=metrics).metrics
    plain = ps.simulate(base, columns=[], metrics=metrics).metrics
    for m in metrics:
        assert lean[m] == pytest.approx(general[m], rel=1e-6), m
    assert lean["work_actuator_per_cycle"] > plain["work_actuator_per_cycle"] * 1.01 or abs(lean["left_stroke_amplitude"] / plain["left_stroke_amplitude"] - 1) > 1e-2


def test_sensitivities_by_the_new_terms_equal_the_resonance_curve_derivatives() -> None:
    """`ps.sensitivity` by `actuator.damping` and `actuator.mass_mg` (spec paths from the
    schema; the linear map's analytic Jacobian with the new terms) against closed forms of the
    driven damped oscillator, `D = (K − M ω²)² + (b ω)²`: the work per cycle
    `W = π b ω F² / D` (an integral, not a sampled peak) with `∂W/∂b = π ω F² (D − 2 b² ω²) / D²`
    and `∂W/∂m = 2 π b ω³ F² (K − M ω²) / D²`; the stroke amplitude `A = T F / √D` with
    `∂A/∂m = A ω² (K − M ω²) / D` (off resonance, where the sampled peak's phase dependence is
    below 1e-4 of it)."""
    mass, b1, volts, freq = 40.0, 30.0, 10.0, 120.0
    spec = vacuum(mass=mass, damping=b1, volts=volts, freq=freq)
    spec = spec.replace(options=dataclasses.replace(spec.options, samples_per_cycle=4000))
    metrics = ["work_actuator_per_cycle", "left_stroke_amplitude"]
    result = ps.sensitivity(spec, params=["actuator.damping", "actuator.mass_mg"], metrics=metrics)
    w = 2 * math.pi * freq * 1e-3
    m_eff = mass + 2 * INERTIA * T**2
    force = FPV * volts
    k = K1 - m_eff * w * w
    d = k**2 + (b1 * w) ** 2
    work, a = math.pi * b1 * w * force**2 / d, T * force / math.sqrt(d)
    assert result.jacobian["value"][0] == pytest.approx(work, rel=1e-7)
    derivative = result.derivative
    assert derivative("work_actuator_per_cycle", "actuator.damping") == pytest.approx(math.pi * w * force**2 * (d - 2 * (b1 * w) ** 2) / d**2, rel=1e-5)
    assert derivative("work_actuator_per_cycle", "actuator.mass_mg") == pytest.approx(2 * math.pi * b1 * w**3 * force**2 * k / d**2, rel=1e-5)
    assert derivative("left_stroke_amplitude", "actuator.mass_mg") == pytest.approx(a * w * w * k / d, rel=1e-3)


def test_bimorph_effective_mass_is_rayleighs() -> None:
    """A uniform cantilever without extension reflects 33/140 of its mass to its tip (Rayleigh
    with the static shape w ∝ 3L x² − x³); a rigid extension moves the output point further per
    unit of beam motion, so less; a taper that thins the tip lowers it too. `from_laminate(mass=True)`
    puts it in `mass_mg` with the laminate's stiffness and force per volt."""
    from paritysim import laminate as lam

    uniform = lam.Bimorph(lam.Layup.bimorph_wood(), length=9.0, base_width=2.0)
    assert uniform.effective_mass == pytest.approx(33 / 140 * uniform.active_mass, rel=1e-6)
    extended = lam.Bimorph(lam.Layup.bimorph_wood(), length=9.0, extension=4.0, base_width=2.0)
    # Closed form with extension e: w = (L+e) x²/2 − x³/6, δ = w(L) + w'(L) e.
    L, e = 9.0, 4.0
    x = np.linspace(0.0, L, 200001)
    w = (L + e) * x**2 / 2 - x**3 / 6
    delta = (L + e) * L**2 / 2 - L**3 / 6 + ((L + e) * L - L**2 / 2) * e
    expected = extended.active_mass * np.trapezoid((w / delta) ** 2, x) / L
    assert extended.effective_mass == pytest.approx(expected, rel=1e-6)
    assert extended.effective_mass < uniform.effective_mass
    tapered = lam.Bimorph(lam.Layup.bimorph_wood(), length=9.0, base_width=2.0, width_ratio=0.5)
    assert tapered.effective_mass < 33 / 140 * tapered.active_mass
    a = ps.Actuator.from_laminate(extended, mass=True, damping=2.0)
    assert a.mass_mg == extended.effective_mass and a.damping == 2.0
    assert a.stiffness == pytest.approx(extended.stiffness) and a.force_per_volt == pytest.approx(abs(extended.force_per_volt))


@pytest.mark.parametrize(("tau2", "volts", "hz"), [(0.0, 60.0, 120.0), (25.0, 80.0, 150.0)])
def test_one_wing_with_mass_and_losses_equals_an_independent_scipy_integration(tau2: float, volts: float, hz: float) -> None:
    """The one-wing device (`single_linear`, φ = P(σ) = τ1 σ + τ2 σ³/3, σ = −q1) with an
    actuator of mass `m`, damping `b1` and cubic stiffness `K1c`. Lagrange's equation in σ,
    written here from scratch: `(I P'² + m) σ̈ + I P' P'' σ̇² = −F − K1 σ − K1c σ³ − b1 σ̇
    + P' (τ_aero − k_s φ)`; solve_ivp (DOP853) from rest against the engine's steady state."""
    from scipy.integrate import solve_ivp

    inertia, omega_c, k_stroke, fpv, k1, tau1 = 60.0, 10.0 * 3.46, 5.0, 1.2, 300.0, 2.67
    mass, b1, k1c = 25.0, 6.0, 2.0e3
    wing = ps.devices.load("sreetharan2012_3_3_parity").to_dict()["wings"][0]
    wing["inertia"] = [[inertia, 0.0, 0.0], [0.0, inertia, 0.0], [0.0, 0.0, 3.0]]
    wing["aero"] = {"kind": "stroke_drag", "omega1": 10.0, "coefficient": 3.46}
    wing["springs"]["stroke"]["stiffness"] = k_stroke
    spec = ps.Simulation.from_dict(
        {
            "wings": [wing],
            "configuration": {"name": "single_wing_fixed"},
            "drivetrain": {"kind": "single_linear", "transmission_ratio": tau1, "cubic_ratio": tau2},
            "actuator": {
                "force_per_volt": fpv,
                "stiffness": k1,
                "mass_mg": mass,
                "damping": b1,
                "cubic_stiffness": k1c,
                "waveform": {"kind": "sine", "amplitude_v": volts, "frequency_hz": hz},
            },
            "options": {"rtol": 1e-10, "atol": 1e-12, "steady_tol": 1e-9, "samples_per_cycle": 4000},
        }
    )
    omega = 2.0 * math.pi * hz / 1000.0

    def rhs(t: float, y: np.ndarray) -> list[float]:
        s, v = y
        p1, p2 = tau1 + tau2 * s * s, 2.0 * tau2 * s
        phi = tau1 * s + tau2 * s**3 / 3.0
        phi_dot = p1 * v
        aero = -omega_c * phi_dot * abs(phi_dot)
        force = fpv * volts * math.sin(omega * t)
        drive = -force - k1 * s - k1c * s**3 - b1 * v
        return [v, (drive + p1 * (aero - k_stroke * phi) - inertia * p1 * p2 * v * v) / (inertia * p1 * p1 + mass)]

    period = 1000.0 / hz
    cycles = 60
    sol = solve_ivp(rhs, (0.0, cycles * period), [0.0, 0.0], method="DOP853", rtol=1e-11, atol=1e-13, dense_output=True)
    assert sol.success
    amplitudes = []
    for k in (cycles - 2, cycles - 1):
        s = sol.sol(np.linspace(k * period, (k + 1) * period, 20001))[0]
        phi = tau1 * s + tau2 * s**3 / 3.0
        amplitudes.append(0.5 * (phi.max() - phi.min()))
    assert abs(amplitudes[0] - amplitudes[1]) < 1e-8 * amplitudes[1]
    result = ps.simulate(spec)
    assert result.converged
    assert result.metrics["wing_stroke_amplitude"] == pytest.approx(amplitudes[1], rel=1e-6)
