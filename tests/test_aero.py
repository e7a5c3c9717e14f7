"""Python-level aero: planforms, Ω1..Ω4, inertia, coefficients and blade-element moments.

Checks that the Python facade agrees with closed forms and with the Rust results (the same
numbers through two routes), and that bad inputs raise the typed exceptions.
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import paritysim as ps
from paritysim import _core, aero
from paritysim.planform import AIR_DENSITY, Planform

H = 0.5 * AIR_DENSITY


def test_air_density_is_1_2_kg_per_m3_in_mg_per_mm3() -> None:
    assert AIR_DENSITY == pytest.approx(1.2e-3)
    assert aero.AIR_DENSITY == AIR_DENSITY


def test_rectangle_closed_forms_and_section_3_3_2_check() -> None:
    span, area = 16.0, 51.4
    c = area / span
    p = Planform.rectangle(span, c)
    o = p.omegas()
    assert p.area == pytest.approx(area)
    assert p.span == pytest.approx(span)
    assert p.mean_chord == pytest.approx(c)
    assert o["omega1"] == pytest.approx(H * c * span**4 / 4, rel=1e-12)
    assert o["omega1"] == pytest.approx(31.58, abs=0.01)  # §3.3.2: "about 31.6"; thesis wing 31.3
    assert o["omega3"] == pytest.approx(H * c**2 * span**3 / 3, rel=1e-12)
    assert o["omega4"] == pytest.approx(0.0, abs=1e-15)
    assert o["omega2"] == pytest.approx(H * span * c**4 / 4, rel=1e-12)
    # Leading edge 0.5 mm ahead of the hinge: Ω4 = ½ρ l c R³/3; Ω1 unchanged.
    q = p.translated(dx=0.5)
    assert q.omegas()["omega4"] == pytest.approx(H * 0.5 * c * span**3 / 3, rel=1e-12)
    assert q.omegas()["omega1"] == pytest.approx(o["omega1"], rel=1e-13)
    # Ω scale as length⁵.
    assert p.scaled(2.0).omegas()["omega1"] == pytest.approx(32 * o["omega1"], rel=1e-12)
    # density is explicit
    assert p.omegas(rho=2 * AIR_DENSITY)["omega1"] == pytest.approx(2 * o["omega1"], rel=1e-13)


def test_chord_and_leading_edge_queries() -> None:
    p = Planform.semi_ellipse(12.0, 4.0, root_offset=1.0, le_offset=0.3, segments=512)
    z = np.array([[1.0 + 6.0, 50.0], [0.5, 4.0]])
    c = p.chord(z)
    le = p.leading_edge(z)
    assert c.shape == z.shape
    assert c[0, 0] == pytest.approx(4.0, rel=1e-5)
    assert c[0, 1] == 0.0 and np.isnan(le[0, 1]) and np.isnan(le[1, 0])
    assert le[0, 0] == pytest.approx(0.3)
    assert p.area == pytest.approx(np.pi * 6.0 * 4.0 / 2 * 512 / np.pi * np.sin(np.pi / 512), rel=1e-12)


def test_triangle_inertia_closed_form() -> None:
    r, c0, sigma = 9.0, 4.0, 2e-3
    p = Planform.from_points([[0.0, 0.0], [r, 0.0], [0.0, -c0]])
    i = p.inertia(areal_density=sigma)
    assert i["mass"] == pytest.approx(sigma * c0 * r / 2)
    assert i["ixx"] == pytest.approx(sigma * c0 * r**3 / 12)
    assert i["izz"] == pytest.approx(sigma * c0**3 * r / 12)
    assert i["iyy"] == pytest.approx(i["ixx"] + i["izz"])
    assert i["ixz"] == pytest.approx(sigma * c0**2 * r**2 / 24)  # −∫xz dm > 0 behind the hinge
    t = i["tensor"]
    assert t.shape == (3, 3) and t[0, 2] == t[2, 0] == pytest.approx(i["ixz"])
    # Spar along the leading edge and a point mass.
    j = p.inertia(sigma, line_masses=[[0.0, 0.0, r, 0.0, 0.01]], point_masses=[[1.0, -1.0, 0.05]])
    assert j["ixx"] == pytest.approx(i["ixx"] + 0.01 * r**3 / 3 + 0.05)
    assert j["izz"] == pytest.approx(i["izz"] + 0.05)
    assert j["ixz"] == pytest.approx(i["ixz"] + 0.05)


def test_hmf_like_matches_table_3_3_roughly() -> None:
    o = Planform.hmf_like(16.6).omegas()
    t = aero.TABLE_3_3["left"]
    for k in ("omega1", "omega2", "omega3", "omega4"):
        assert o[k] == pytest.approx(t[k], rel=0.15)
    for row in aero.TABLE_3_3.values():
        assert row["iyy"] == pytest.approx(row["ixx"] + row["izz"], abs=0.1)  # table rounding


def test_planform_is_immutable_picklable_and_plots() -> None:
    p = Planform.hmf_like(10.0, segments=32)
    with pytest.raises(AttributeError):
        p.area = 3.0  # type: ignore[misc]
    with pytest.raises(ValueError):
        p.points[0, 0] = 1.0
    q = pickle.loads(pickle.dumps(p))
    assert q == p and hash(q) == hash(p)
    assert "Planform" in repr(p)
    ax = p.plot()
    assert ax.get_xlabel().startswith("z")
    assert len(ax.patches) == 1


def test_python_matches_rust_integrals() -> None:
    # Same outline via the constructor route and the from_points route.
    a = Planform.semi_ellipse(14.0, 4.0, 0.8, 0.2, 64)
    b = Planform.from_points(a.points[::-1])  # reversed orientation
    for k, v in a.omegas().items():
        assert b.omegas()[k] == pytest.approx(v, rel=1e-13)
    props = _core.aero_planform_properties(np.ascontiguousarray(a.points), AIR_DENSITY, None)
    assert props["omega1"] == pytest.approx(H * props["integrals"]["z3"], rel=1e-14)


# ---------------------------------------------------------------- errors


def test_bad_outlines_raise_geometry_error() -> None:
    with pytest.raises(ps.GeometryError, match="self-intersecting"):
        Planform.from_points([[1.0, 0.0], [5.0, -2.0], [5.0, 0.0], [1.0, -2.0]])
    with pytest.raises(ps.GeometryError, match="open"):
        Planform.from_points([[1.0, 0.0], [6.0, 0.0], [6.0, -2.0], [1.0, -2.0], [1.0, -0.5]], closure_tolerance=0.01)
    with pytest.raises(ps.GeometryError, match="wrong side of the spherical centre"):
        Planform.from_points([[-1, 0], [6, 0], [6, -2]])
    with pytest.raises(ps.GeometryError, match="wrong side of the hinge line"):
        Planform.from_points([[0, 0], [10, 0], [10, 3], [0, 3]])
    with pytest.raises(ps.InvalidParameterError, match="behind the hinge line") as info:
        Planform.rectangle(10.0, 3.0, le_offset=3.0)
    assert info.value.field == "le_offset"
    with pytest.raises(ps.GeometryError, match="zero area"):
        Planform.from_points([[1, 0], [2, -1], [3, -2]])
    # GeometryError is a ValueError and a ParitysimError.
    assert issubclass(ps.GeometryError, ValueError) and issubclass(ps.GeometryError, ps.ParitysimError)


def test_bad_numbers_raise_invalid_parameter_error() -> None:
    p = Planform.rectangle(10.0, 3.0)
    with pytest.raises(ps.InvalidParameterError, match="rho") as e:
        p.omegas(rho=-1.2e-3)
    assert getattr(e.value, "field", None) == "rho"
    with pytest.raises(ps.InvalidParameterError, match="span"):
        Planform.rectangle(-1.0, 3.0)
    with pytest.raises(ps.InvalidParameterError) as e:
        Planform.from_points([[1.0, 0.0], [float("nan"), -1.0], [3.0, -2.0]])
    assert getattr(e.value, "field", None) == "points[1]"
    with pytest.raises(ps.InvalidParameterError, match="areal_density"):
        p.inertia(areal_density=-1.0)
    with pytest.raises(ps.InvalidParameterError, match="model"):
        aero.coefficients(0.3, model="bogus")
    with pytest.raises(ps.InvalidParameterError, match=r"alpha\[1\]"):
        aero.coefficients([0.1, 4.0])
    with pytest.raises(ps.InvalidParameterError, match="omega1"):
        aero.moments([0.0, 1.0, 1.0, 0.0], phi_dot=0.3)
    with pytest.raises(ps.InvalidParameterError, match="normal_force_law"):
        aero.moments(aero.TABLE_3_3["left"], phi_dot=0.3, normal_force_law="half")
    with pytest.raises(ps.InvalidParameterError, match="phi_dot"):
        aero.moments(aero.TABLE_3_3["left"], phi_dot=[0.3, np.inf])
    with pytest.raises(ps.ShapeError):
        Planform.from_points([1.0, 2.0, 3.0])
    with pytest.raises(ps.ShapeError):
        p.inertia(1e-3, point_masses=[[1.0, 2.0]])


# ---------------------------------------------------------------- coefficients


def test_dickinson_fits_in_degrees_at_0_45_90() -> None:
    deg = np.array([0.0, 45.0, 90.0])
    c = aero.coefficients(np.radians(deg))
    cd = 1.92 - 1.55 * np.cos(np.radians(2.04 * deg - 9.82))
    cl = 0.225 + 1.58 * np.sin(np.radians(2.13 * deg - 7.20))
    np.testing.assert_allclose(c["drag"], cd, rtol=1e-13)
    np.testing.assert_allclose(c["lift"], cl, rtol=1e-12)
    np.testing.assert_allclose(c["drag"], [0.392710, 1.703746, 3.460875], atol=2e-6)
    # Eq. 3.7 in closed form: 0.05, 0.255 and 0.46 of the chord.
    np.testing.assert_allclose(c["center_of_pressure"], 0.82 * deg / 180.0 + 0.05, rtol=1e-14)
    np.testing.assert_allclose(aero.center_of_pressure(np.radians(deg)), [0.05, 0.255, 0.46], rtol=1e-14)


def test_center_of_pressure_takes_the_coefficients_range() -> None:
    # It computed eq. 3.7 on its own for any angle (2.66 chords behind the edge at 10 rad).
    for bad, field in ((10.0, "alpha"), (-1.0, "alpha"), ([0.1, 4.0], "alpha[1]")):
        with pytest.raises(ps.InvalidParameterError, match="pi") as info:
            aero.center_of_pressure(bad)
        assert info.value.field == field, info.value.field


def test_dickinson_past_90_degrees_mirrors_the_printed_fit() -> None:
    """docs/errata.md#P2: past α = 90° (leading edge trailing) the printed eqs. 3.5-3.6 are not
    used; the coefficients are the flat-plate mirror image of the printed fit at π − α:
    C_L(α) = −C_L,fit(π − α), C_D(α) = C_D,fit(π − α). The printed fit itself is evaluated here
    independently (degrees, as published)."""
    deg = np.linspace(90.5, 180.0, 180)
    c = aero.coefficients(np.radians(deg))
    mirror = 180.0 - deg
    cd = 1.92 - 1.55 * np.cos(np.radians(2.04 * mirror - 9.82))
    cl = 0.225 + 1.58 * np.sin(np.radians(2.13 * mirror - 7.20))
    np.testing.assert_allclose(c["drag"], cd, rtol=1e-12)
    np.testing.assert_allclose(c["lift"], -cl, rtol=1e-12, atol=1e-14)
    # a departure, not the print: the fit evaluated as printed past 90° differs
    printed_cl = 0.225 + 1.58 * np.sin(np.radians(2.13 * deg - 7.20))
    assert np.abs(printed_cl - c["lift"]).max() > 0.5
    # C_N is continuous at 90°, C_L jumps by 2 C_L,fit(90°) = 0.20 (the fit has C_L(90°) = 0.10 ≠ 0)
    at = aero.coefficients(np.radians([90.0 - 1e-9, 90.0 + 1e-9]))
    assert abs(at["normal"][1] - at["normal"][0]) < 1e-8
    assert at["lift"][0] - at["lift"][1] == pytest.approx(2 * (0.225 + 1.58 * np.sin(np.radians(2.13 * 90 - 7.20))), rel=1e-6)


# ---------------------------------------------------------------- moments


def test_moments_vectorise_and_match_rust_single_states() -> None:
    p = Planform.hmf_like(16.6)
    t = np.linspace(0, 9.09, 50)
    w = 2 * np.pi * 0.11
    phi, phi_dot = 0.87 * np.sin(w * t), 0.87 * w * np.cos(w * t)
    psi = -1.0 * np.cos(w * t)
    m = aero.moments(p.omegas(), phi=phi, psi=psi, phi_dot=phi_dot)
    assert m["torque_wing"].shape == (50, 3) and m["torque_body"].shape == (50, 3)
    for i in (3, 17, 40):
        one = aero.moments(p.omegas(), phi[i], 0.0, psi[i], phi_dot[i], 0.0, 0.0)
        for k in ("normal", "tangential", "rotational", "alpha"):
            assert float(one[k]) == pytest.approx(m[k][i], rel=1e-14)
    # Without deviation the wind-relative coordinates are the plain ones and α = π/2 + ψ sgn φ̇.
    np.testing.assert_allclose(m["phi_dot_rw"], phi_dot, rtol=1e-14)
    np.testing.assert_allclose(m["psi_rw"], psi, rtol=1e-14)
    mask = np.abs(phi_dot) > 1e-9
    np.testing.assert_allclose(m["alpha"][mask], np.pi / 2 + psi[mask] * np.sign(phi_dot[mask]), atol=1e-12)
    # Lift points along +roll (stroke axis) through the stroke with the leading edge leading.
    assert (m["lift"][mask, 0] >= 0).all()
    # Drag torque about roll opposes the stroke velocity.
    assert (m["drag_torque"][mask, 0] * phi_dot[mask] < 0).all()
    # Body-axis torque is the wing-frame torque rotated by R_x(φ) R_z(ψ) (θ = 0).
    for i in range(50):
        cf, sf, cp, sp = np.cos(phi[i]), np.sin(phi[i]), np.cos(psi[i]), np.sin(psi[i])
        r = np.array([[1, 0, 0], [0, cf, -sf], [0, sf, cf]]) @ np.array([[cp, -sp, 0], [sp, cp, 0], [0, 0, 1]])
        np.testing.assert_allclose(m["torque_body"][i], r @ m["torque_wing"][i], atol=1e-12)


def test_moments_flip_with_stroke_velocity_and_errata_12_law() -> None:
    o = aero.TABLE_3_3["left"]
    m = aero.moments(o, phi_dot=[0.5, -0.5])
    assert m["normal"][0] == pytest.approx(-m["normal"][1])
    assert m["rotational"][0] * 0.5 < 0  # drives ψ opposite to φ̇: leading edge leads
    unit = aero.moments(o, phi_dot=0.5, normal_force_law="unit")
    assert float(unit["normal"]) == pytest.approx(-o["omega1"] * 0.25)
    assert float(m["normal"][0]) / float(unit["normal"]) == pytest.approx(
        float(aero.coefficients(np.pi / 2)["normal"])
    )


def test_moments_name_an_unknown_omegas_key() -> None:
    # A misspelt `force` dropped the lift and drag outputs without a word.
    omegas = dict(Planform.hmf_like().omegas())
    omegas["forse"] = omegas.pop("force")
    with pytest.raises(ps.InvalidParameterError, match="did you mean `force`") as info:
        aero.moments(omegas, 0.1, 0.0, 0.3, 0.5)
    assert info.value.field == "omegas['forse']"
    assert "lift" not in aero.moments(aero.TABLE_3_3["left"], 0.1, 0.0, 0.3, 0.5)  # Table 3.3's own keys still read
