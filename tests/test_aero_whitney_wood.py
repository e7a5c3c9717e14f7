"""The Whitney & Wood 2010 aero model (issue 32 item 2): its planform parameters against
quadrature of the chord distribution, the reduction to the thesis' blade element with every
added term off, the energy balance with added mass and rotational lift, flight and trim, and
its typed errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

import paritysim as ps
from paritysim import flight
from paritysim.planform import AIR_DENSITY, Planform

DEVICE = "sreetharan2012_3_4_parity"


def _device() -> ps.Simulation:
    return ps.devices.load(DEVICE)


OFF = {"rotational_lift": 0.0, "translational_added_mass": 0.0, "rotational_added_mass": 0.0}


def _hmf_shape() -> dict[str, float]:
    """Ω3 and Ω5..Ω8 of the HMF-like planform (the §3.4 wings' shape)."""
    p = Planform.hmf_like()
    return {"omega3": p.omegas()["omega3"], **p.quasi_steady_omegas()}


def whitney_wood(spec: ps.Simulation, model: str = "dickinson1999", **terms: float) -> ps.Simulation:
    """``spec`` with every blade-element wing on the Whitney & Wood 2010 model: the same
    Ω1..Ω4 and coefficients, Ω5..Ω8 of the HMF-like planform scaled by the wing's Ω3 over its
    own (the Table 3.3 wings have no outline; all five are ½ρ × mm⁵ integrals of one shape)."""
    shape = _hmf_shape()
    wings = []
    for w in spec.wings:
        a = w.aero
        scale = a.omega3 / shape["omega3"]
        ww = ps.Aero(
            kind="whitney_wood2010",
            omega1=a.omega1,
            omega2=a.omega2,
            omega3=a.omega3,
            omega4=a.omega4,
            **{k: scale * shape[k] for k in ("omega5", "omega6", "omega7", "omega8")},
            model=model,
            rotational_damping=a.rotational_damping,
            normal_force_law=a.normal_force_law,
            **terms,
        )
        wings.append(w.replace(aero=ww))
    return spec.replace(wings=tuple(wings))


def test_planform_parameters_are_the_added_mass_and_rotational_lift_integrals_of_the_chord() -> None:
    """Ω5..Ω8 of a semi-elliptic wing (chord varies along the span) against scipy quadrature of
    its chord c(z) and leading edge l(z); with them the flat plate's added inertia: translation
    normal to the plate (stroke about x̂) `∫ ρπc²/4 z² dz = π/2 Ω3`, pure rotation about the
    hinge `∫ (ρπc²/4 x_m² + ρπc⁴/128) dz = π/2 Ω6 + π/64 Ω7`."""
    span, chord, root, le = 14.0, 4.0, 2.0, 1.2
    p = Planform.semi_ellipse(span, chord, root, le, segments=4096)
    q = p.quasi_steady_omegas()
    o = p.omegas()

    def c(z: float) -> float:  # the ellipse itself: the polygon converges as segments⁻²
        u = 2.0 * (z - root) / span - 1.0
        return chord * math.sqrt(max(0.0, 1.0 - u * u))

    def integral(f) -> float:  # type: ignore[no-untyped-def]
        return 0.5 * AIR_DENSITY * quad(f, root, root + span, limit=200)[0]

    xm = lambda z: le - c(z) / 2  # noqa: E731
    expected = {
        "omega5": integral(lambda z: z * c(z) ** 2 * xm(z)),
        "omega6": integral(lambda z: c(z) ** 2 * xm(z) ** 2),
        "omega7": integral(lambda z: c(z) ** 4),
        "omega8": integral(lambda z: z * c(z) * (le - c(z) / 4) * (0.75 * c(z) - le)),
    }
    for k, v in expected.items():
        assert q[k] == pytest.approx(v, rel=2e-5), k
    rho = AIR_DENSITY
    translation = quad(lambda z: rho * math.pi * c(z) ** 2 / 4 * z * z, root, root + span, limit=200)[0]
    assert math.pi / 2 * o["omega3"] == pytest.approx(translation, rel=2e-5)
    rotation = quad(lambda z: rho * math.pi * (c(z) ** 2 / 4 * xm(z) ** 2 + c(z) ** 4 / 128), root, root + span, limit=200)[0]
    assert math.pi / 2 * q["omega6"] + math.pi / 64 * q["omega7"] == pytest.approx(rotation, rel=2e-5)
    # from_planform fills all eight.
    w = ps.Wing.from_planform(p, mass_mg=0.5, aero_model=ps.Aero(kind="whitney_wood2010"))
    assert w.aero.omega8 == q["omega8"] and w.aero.omega3 == o["omega3"]


def test_with_every_added_term_off_it_is_the_thesis_blade_element() -> None:
    base = _device()
    a = ps.simulate(base)
    b = ps.simulate(whitney_wood(base, **OFF))
    for k, v in a.metrics.items():
        if isinstance(v, float) and math.isfinite(v):
            assert b.metrics[k] == pytest.approx(v, rel=1e-12, abs=1e-13), k
    ta, tb = a.trajectory, b.trajectory
    for col in ("left_phi", "right_psi", "roll_total", "work_aero"):
        np.testing.assert_allclose(tb[col].to_numpy(), ta[col].to_numpy(), rtol=1e-12, atol=1e-13)


def test_energy_balance_with_added_mass_and_rotational_lift() -> None:
    """Over any stretch of the recorded run the actuator's and the air's work equal the change
    of stored (spring + kinetic, the added mass' included) energy; over a steady cycle the
    actuator supplies what the air takes."""
    r = ps.simulate(whitney_wood(_device()), record_cycles=2)
    t = r.trajectory
    work = (t["work_actuator"] + t["work_aero"]).to_numpy()
    energy = t["mechanical_energy"].to_numpy()
    scale = float(np.max(np.abs(t["work_actuator"].to_numpy() - t["work_actuator"][0])))
    for i, j in [(0, len(t) // 3), (len(t) // 5, len(t) - 1), (7, 8)]:
        assert (work[j] - work[i]) == pytest.approx(energy[j] - energy[i], abs=1e-5 * scale), (i, j)
    m = r.metrics
    assert m["work_actuator_per_cycle"] > 0
    assert m["work_actuator_per_cycle"] == pytest.approx(-m["work_aero_per_cycle"], rel=1e-3)


def test_rotational_lift_in_a_whole_run_is_its_closed_form() -> None:
    """Along a simulated cycle (rotational lift on, added mass off) the engine's aerodynamic
    torques minus the blade element's (eqs. 3.8-3.11 at the same states) are the rotational
    lift's closed form `2π k_R W ω_z (−(¾Ω3 − Ω4), 0, Ω8)` with `W = |φ̇|`, `ω_z = ψ̇` on
    the stroke plane, projected on the φ axis `(cos ψ, −sin ψ, 0)` and the hinge `ẑ`."""
    k = 0.8
    spec = whitney_wood(_device(), rotational_lift=k, translational_added_mass=0.0, rotational_added_mass=0.0)
    cycle = ps.simulate(spec).cycle
    for side, wing in zip(("left", "right"), spec.wings, strict=True):
        a = wing.aero
        phi, psi = cycle[f"{side}_phi"].to_numpy(), cycle[f"{side}_psi"].to_numpy()
        phi_dot, psi_dot = cycle[f"{side}_phi_dot"].to_numpy(), cycle[f"{side}_psi_dot"].to_numpy()
        assert np.max(np.abs(cycle[f"{side}_theta"].to_numpy())) < 1e-12  # a stroke-plane device
        blade = ps.aero.moments([a.omega1, a.omega2, a.omega3, a.omega4], phi, 0.0, psi, phi_dot, 0.0, psi_dot, model=a.model)["torque_wing"]
        lift = 2 * math.pi * k * np.abs(phi_dot) * psi_dot
        tau_x, tau_z = -lift * (0.75 * a.omega3 - a.omega4), lift * a.omega8
        scale = np.max(np.abs(cycle[f"{side}_tau_aero_phi"].to_numpy()))
        expected_phi = np.cos(psi) * (blade[:, 0] + tau_x) - np.sin(psi) * blade[:, 1]
        np.testing.assert_allclose(cycle[f"{side}_tau_aero_phi"].to_numpy(), expected_phi, rtol=0, atol=1e-9 * scale)
        np.testing.assert_allclose(cycle[f"{side}_tau_aero_psi"].to_numpy(), blade[:, 2] + tau_z, rtol=0, atol=1e-9 * scale)
        assert np.max(np.abs(tau_x)) > 0.05 * scale  # the term is not negligible here


def test_added_terms_change_the_device() -> None:
    """Each added term changes the §3.4 device's strokes and lift (numbers in the report)."""
    base = _device()
    off = ps.simulate(whitney_wood(base, **OFF)).metrics
    mass = ps.simulate(whitney_wood(base, rotational_lift=0.0)).metrics
    full = ps.simulate(whitney_wood(base)).metrics
    for m in (off, mass, full):
        assert 0.1 < m["left_stroke_amplitude"] < 1.5
        assert 0.1 < m["lift_mean"] < 5.0
    assert abs(mass["left_stroke_amplitude"] / off["left_stroke_amplitude"] - 1) > 0.05
    assert abs(full["lift_mean"] / mass["lift_mean"] - 1) > 0.01


def test_flight_and_trim_run_the_model() -> None:
    """A clamped body with the model reports lift = the sum of the wings' (the force metrics
    include the rotational lift), and trim brings its mean lift to the weight."""
    spec = whitney_wood(_device())
    clamped = ps.simulate(flight.with_body(spec, mode="clamped")).metrics
    assert clamped["lift_mean"] == pytest.approx(clamped["left_lift_mean"] + clamped["right_lift_mean"], rel=1e-9)
    t = flight.trim(spec)
    assert t.converged, t
    m = ps.simulate(flight.with_body(t.spec, mode="clamped")).metrics
    assert abs(m["lift_mean"] - t.weight_mn) < t.tol * t.weight_mn


@pytest.mark.parametrize(
    ("field", "value", "text"),
    [
        ("rotational_lift", -1.0, "[0, 10]"),
        ("translational_added_mass", 11.0, "[0, 10]"),
        ("omega6", -0.5, "omega6"),
        ("omega5", 1e3, "sqrt(omega3 omega6)"),
    ],
)
def test_bad_input_names_the_field_and_range(field: str, value: float, text: str) -> None:
    spec = whitney_wood(_device())
    wing = spec.wings[1]
    bad = spec.replace(wings=(spec.wings[0], wing.replace(aero=wing.aero.replace(**{field: value}))))
    with pytest.raises(ps.InvalidParameterError) as exc:
        ps.simulate(bad, max_cycles=2)
    message = str(exc.value)
    assert f"wings[1].aero.{field}" in message or f"aero.{field}" in message, message
    assert text in message, message


def test_sweeps_over_the_model_fields_match_single_runs() -> None:
    """A sweep over a Whitney & Wood field (and the hinge) gives the single runs' metrics."""
    spec = whitney_wood(_device())
    grid = {"wings[1].aero.rotational_lift": [0.0, 1.0], "wings[1].springs.hinge.stiffness": [2.0, 3.0]}
    df = ps.sweep(spec, grid, metrics=["lift_mean", "right_stroke_amplitude"], threads=1, progress=False)
    assert df.height == 4
    for row in df.iter_rows(named=True):
        k, h = row["wings[1].aero.rotational_lift"], row["wings[1].springs.hinge.stiffness"]
        one = ps.simulate(spec.with_paths({"wings[1].aero.rotational_lift": k, "wings[1].springs.hinge.stiffness": h})).metrics
        assert row["lift_mean"] == pytest.approx(one["lift_mean"], rel=1e-9)
        assert row["right_stroke_amplitude"] == pytest.approx(one["right_stroke_amplitude"], rel=1e-9)


def test_every_form_runs_the_model_alike() -> None:
    """Fixed wings: the drivetrain-coordinate form (stroke torque, added stroke inertia π/2 Ω3)
    equals the general null-space form; rotating wings: the stroke-plane form (auto) equals
    the projection form (eq. 3.20) to the solver's accuracy."""
    spec = whitney_wood(_device())
    fixed = spec.replace(configuration=ps.Configuration("drag_parity_fixed"))
    a = ps.simulate(fixed).metrics
    b = ps.simulate(fixed.with_paths({"formulation": "null_space"})).metrics
    for k in ("left_stroke_amplitude", "right_stroke_amplitude", "work_aero_per_cycle"):
        assert a[k] == pytest.approx(b[k], rel=1e-8), k
    no_mass = ps.simulate(whitney_wood(_device(), translational_added_mass=0.0).replace(configuration=ps.Configuration("drag_parity_fixed"))).metrics
    assert no_mass["left_stroke_amplitude"] != pytest.approx(a["left_stroke_amplitude"], rel=1e-3)
    c = ps.simulate(spec).metrics
    d = ps.simulate(spec.with_paths({"formulation": "projection"})).metrics
    for k in ("left_stroke_amplitude", "right_rotation_amplitude", "lift_mean"):
        assert c[k] == pytest.approx(d[k], rel=1e-5), k
