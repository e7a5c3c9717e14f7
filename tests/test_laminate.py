"""paritysim.laminate: CLPT, bimorph, flexures, PC-MEMS stacks; typed errors; plotting.

Independent references are derived here (plate stiffness, Timoshenko's 1925 bimetal formula,
the parallel bimorph of Smits et al. 1991) or quoted from the thesis (467 mN/mm, 120 mN at
100 V, Mobee layer counts, 200 °C cure, 20–40 µm castellated flexures).
"""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import paritysim as ps
from paritysim import laminate as lam


def timoshenko(t1: float, e1: float, a1: float, t2: float, e2: float, a2: float, dt: float) -> float:
    """Bimetal curvature (Timoshenko 1925), layer 1 at the bottom; positive when the top stretches."""
    m, n, h = t1 / t2, e1 / e2, t1 + t2
    return 6 * (a2 - a1) * dt * (1 + m) ** 2 / (h * (3 * (1 + m) ** 2 + (1 + m * n) * (m * m + 1 / (m * n))))


# ------------------------------------------------------------------ materials and errors


def test_library_materials_round_trip() -> None:
    assert set(lam.MATERIAL_NAMES) >= {"pzt_5h", "cf_prepreg_ud", "polyimide", "pyralux_adhesive", "brass"}
    for key in lam.MATERIAL_NAMES:
        m = lam.material(key)
        assert lam.Material.from_dict(m.to_dict()) == m
        assert m.e1 > 0 and m.density > 0
    pzt = lam.material("pzt_5h")
    assert pzt.is_piezo and pzt.d31 == pytest.approx(-320 * lam.PM_PER_V)
    assert lam.material("kapton") == lam.material("polyimide")
    assert lam.material("polyimide").e1 == pytest.approx(2.5 * lam.GPA)


@pytest.mark.parametrize("nu", [0.5, 0.7, -1.0, -2.0, float("nan")])
def test_poisson_ratio_out_of_range_is_a_typed_error(nu: float) -> None:
    with pytest.raises(ps.InvalidParameterError) as exc:
        lam.Material.isotropic("x", 1e6, nu, 1.0)
    assert exc.value.field == "nu12"
    assert isinstance(exc.value, ValueError)


def test_other_non_physical_inputs_are_typed_errors() -> None:
    with pytest.raises(ps.InvalidParameterError) as exc:
        lam.Material.isotropic("x", -1.0, 0.3, 1.0)
    assert exc.value.field == "e1"
    with pytest.raises(ps.InvalidParameterError) as exc:
        lam.Material("o", "composite", 10e6, 1e6, 0.5e6, 5.0, 1.5, 0.0, 0.0)
    assert exc.value.field == "nu12"
    with pytest.raises(ps.InvalidParameterError) as exc:
        lam.Material("x", "cheese", 1e6, 1e6, 0.4e6, 0.3, 1.0, 0.0, 0.0)
    assert exc.value.field == "class"
    with pytest.raises(ps.InvalidParameterError) as exc:
        lam.material("unobtainium")
    assert exc.value.field == "material"
    with pytest.raises(ps.InvalidParameterError) as exc:
        lam.Layup.from_plies([("ok", "brass", 0.01, 0.0), ("bad", "brass", -0.01, 0.0)])
    assert exc.value.field == "layers[1].plies[0].thickness"
    with pytest.raises(ps.GeometryError):
        lam.Layup([])
    with pytest.raises(ps.ShapeError):
        lam.Layup.bimorph_wood().response(voltages=[1.0])
    with pytest.raises(ps.InvalidParameterError) as exc:
        lam.Layup.bimorph_wood().response(voltages=[0.0, 5.0, 0.0])
    assert exc.value.field == "voltages[1]"
    with pytest.raises(ps.GeometryError):
        lam.Bimorph(lam.Layup.linkage_sublaminate(), length=9.0)
    with pytest.raises(ps.InvalidParameterError):
        lam.Flexure(width=0.0, length=0.03)


# ------------------------------------------------------------------ CLPT


def test_single_isotropic_ply_reproduces_plate_stiffness() -> None:
    e, nu, t = 110 * lam.GPA, 0.34, 0.0125
    lay = lam.Layup([lam.Layer.single("B", lam.Material.isotropic("b", e, nu, 8.5), t)])
    abd = lay.abd()
    assert abd.shape == (6, 6)
    d = e * t**3 / (12 * (1 - nu**2))
    assert abd[3, 3] == pytest.approx(d, rel=1e-12)
    assert abd[3, 4] == pytest.approx(nu * d, rel=1e-12)
    assert abd[0, 0] == pytest.approx(e * t / (1 - nu**2), rel=1e-12)
    assert np.abs(abd[:3, 3:]).max() < 1e-12 * abd[0, 0] * t
    assert lay.summary()["beam_bending_stiffness"] == pytest.approx(e * t**3 / 12, rel=1e-10)


def test_rotating_a_ply_by_90_degrees_swaps_e1_and_e2() -> None:
    cf = lam.material("cf_prepreg_ud")
    a0 = lam.Layup([lam.Layer.single("0", cf, 0.05, 0.0)]).abd()
    a90 = lam.Layup([lam.Layer.single("90", cf, 0.05, math.pi / 2)]).abd()
    assert a90[0, 0] == pytest.approx(a0[1, 1], rel=1e-12)
    assert a90[1, 1] == pytest.approx(a0[0, 0], rel=1e-12)
    denom = 1 - cf.nu12**2 * cf.e2 / cf.e1
    assert a0[0, 0] == pytest.approx(cf.e1 * 0.05 / denom, rel=1e-12)


names = st.sampled_from(lam.MATERIAL_NAMES)
plies = st.lists(
    st.tuples(names, st.floats(0.005, 0.2), st.floats(-math.pi, math.pi)),
    min_size=1,
    max_size=4,
)


@settings(max_examples=30, deadline=None)
@given(plies, st.floats(-250, 250))
def test_symmetric_layups_have_no_coupling_and_stay_flat(half: list[tuple[str, float, float]], dt: float) -> None:
    layers = [lam.Layer.single(f"{i}", k, t, a) for i, (k, t, a) in enumerate(half)]
    lay = lam.Layup(layers + layers[::-1])
    assert lay.is_symmetric
    abd = lay.abd()
    scale = math.sqrt(np.abs(abd[:3, :3]).max() * np.abs(abd[3:, 3:]).max())
    assert np.abs(abd[:3, 3:]).max() < 1e-12 * scale
    assert np.abs(lay.thermal_curvature(dt)).max() * lay.total_thickness_mm < 1e-15


def test_bimetal_matches_timoshenko() -> None:
    b = lam.Material.isotropic("b", 110 * lam.GPA, 0.3, 8.5, 19.9e-6)
    ti = lam.Material.isotropic("ti", 100 * lam.GPA, 0.3, 4.5, 9.5e-6)
    lay = lam.Layup([lam.Layer.single("B", b, 0.0125), lam.Layer.single("Ti", ti, 0.0508)])
    k = lay.thermal_curvature(lam.CURE_DELTA_T)
    kt = timoshenko(0.0125, b.e1, b.alpha1, 0.0508, ti.e1, ti.alpha1, lam.CURE_DELTA_T)
    assert k[0] == pytest.approx(kt, rel=1e-10)
    assert k[1] == pytest.approx(kt, rel=1e-10)


def test_ply_stresses_integrate_to_the_applied_resultants() -> None:
    stack = lam.Layup.mobee()
    n, m = np.array([5.0, -2.0, 1.0]), np.array([0.3, 0.1, -0.05])
    s = stack.ply_stresses(n=n, m=m, delta_t=lam.CURE_DELTA_T)
    z0, z1 = s["z_bottom"][:, None], s["z_top"][:, None]
    sb, st_ = s["stress_bottom"], s["stress_top"]
    t = z1 - z0
    np.testing.assert_allclose(((sb + st_) * t / 2).sum(axis=0), n, atol=1e-9)
    np.testing.assert_allclose(((sb * (2 * z0 + z1) + st_ * (z0 + 2 * z1)) * t / 6).sum(axis=0), m, atol=1e-9)


# ------------------------------------------------------------------ PC-MEMS stacks


def test_mobee_stack_summary_and_cure_curvature() -> None:
    s = lam.Layup.mobee()
    assert len(s) == 18
    assert s.total_thickness_mm == pytest.approx(5 * 0.1 + 2 * 0.0075 + 2 * 0.0125 + 0.0508 + 8 * 0.0125)
    rho = {k: lam.material(k).density for k in ("cf_prepreg_ud", "polyimide", "brass", "titanium", "pyralux_adhesive")}
    expect = (
        0.5 * rho["cf_prepreg_ud"]
        + 0.015 * rho["polyimide"]
        + 0.025 * rho["brass"]
        + 0.0508 * rho["titanium"]
        + 0.1 * rho["pyralux_adhesive"]
    )
    assert s.areal_mass == pytest.approx(expect, rel=1e-12)
    classes = s.summary()["layer_class"]
    assert classes.count("composite") == 5 and classes.count("adhesive") == 8
    assert not s.is_symmetric
    k = s.thermal_curvature()
    assert np.all(np.abs(k[:2]) > 1e-4)
    for flat in (lam.Layup.mobee_without_titanium(), lam.Layup.linkage_sublaminate()):
        assert flat.is_symmetric
        assert np.abs(flat.thermal_curvature()).max() < 1e-15
    assert s.layer_bounds.shape == (18, 2)
    assert s.layer_bounds[0, 0] == pytest.approx(-s.total_thickness_mm / 2)


def test_plot_draws_every_layer() -> None:
    s = lam.Layup.mobee()
    ax = s.plot()
    assert len(ax.patches) == 18
    assert "18-layer" in ax.get_title()
    fig, ax2 = plt.subplots()
    assert s.plot(ax=ax2, to_scale=True) is ax2
    assert ax2.get_ylim()[1] == pytest.approx(690.8)
    plt.close("all")


# ------------------------------------------------------------------ bimorph


def test_parallel_bimorph_matches_smits() -> None:
    e, t_p, d31 = 62 * lam.GPA, 0.127, -320 * lam.PM_PER_V
    pzt = lam.Material("p", "piezo", e, e, e / 2.62, 0.31, 7.8, 0.0, 0.0, d31, 2000.0)
    lay = lam.Layup([lam.Layer.single("bot", pzt, t_p), lam.Layer.single("top", pzt, t_p)])
    L, w, h = 10.0, 2.0, 2 * t_p
    b = lam.Bimorph(lay, length=L, base_width=w)
    v = np.array([25.0, 50.0, 100.0])
    np.testing.assert_allclose(b.free_deflection(v), 3 * abs(d31) * v * L**2 / h**2, rtol=1e-10)
    np.testing.assert_allclose(b.blocked_force(v), 3 * e * w * h * abs(d31) * v / (4 * L), rtol=1e-10)


@settings(max_examples=25, deadline=None)
@given(st.floats(-250, 250), st.floats(-250, 250), st.floats(3, 20), st.floats(0, 8), st.floats(0.3, 1.5))
def test_bimorph_is_linear_in_voltage(v1: float, v2: float, length: float, ext: float, wr: float) -> None:
    b = lam.Bimorph(lam.Layup.bimorph_wood(), length=length, extension=ext, base_width=2.0, width_ratio=wr)
    d = b.free_deflection(np.array([v1, v2, (v1 + v2) / 2]))
    assert d[2] == pytest.approx((d[0] + d[1]) / 2, abs=1e-12 * (abs(d[0]) + abs(d[1]) + 1e-12))
    assert b.blocked_force(v1) == pytest.approx(b.stiffness * d[0], rel=1e-10, abs=1e-12)


def test_design_reproduces_the_thesis_constants() -> None:
    t = lam.THESIS_ACTUATOR
    assert (t.stiffness_mn_per_mm, t.force_per_volt_mn_per_v) == (467.0, 1.2)
    b = lam.Bimorph.design_for()
    assert b.stiffness == pytest.approx(467.0, rel=1e-10)
    assert b.blocked_force(100.0) == pytest.approx(120.0, rel=1e-10)
    assert b.free_deflection(100.0) == pytest.approx(120.0 / 467.0, rel=1e-10)
    c = b.constants()
    assert c.force_per_volt_mn_per_v == pytest.approx(1.2) and c.free_deflection_per_volt == pytest.approx(1.2 / 467)
    assert b.length == pytest.approx(12.30, abs=0.01) and b.base_width == pytest.approx(3.97, abs=0.01)
    assert b.extension == pytest.approx(0.5 * b.length)
    with pytest.raises(ps.OutOfDomainError):
        b.free_deflection([100.0, 300.0])
    wood = lam.Bimorph.design_for(layup=lam.Layup.bimorph_wood(0.127, 0.04), width_ratio=1.0, extension_ratio=0.0)
    assert wood.stiffness == pytest.approx(467.0) and wood.width_ratio == 1.0


# ------------------------------------------------------------------ flexures


def test_flexure_stiffness_and_caveat() -> None:
    f = lam.Flexure(width=1.0, length=0.03)
    assert f.stiffness == pytest.approx(2.5e6 * 0.0075**3 / (12 * 0.03), rel=1e-12)
    assert f.plate_stiffness == pytest.approx(f.stiffness / (1 - 0.34**2), rel=1e-12)
    assert f.max_strain(math.pi / 2) == pytest.approx(0.0075 * math.pi / 2 / 0.06)
    assert f.max_strain(math.pi / 2) > 6 * lam.KAPTON_YIELD_STRAIN
    lim = f.elastic_limit_angle()
    assert f.max_strain(lim) == pytest.approx(lam.KAPTON_YIELD_STRAIN)
    assert f.torque(0.1) == pytest.approx(-0.1 * f.stiffness)
    assert f.within_thesis_range
    with pytest.raises(ps.InvalidParameterError):
        f.elastic_limit_angle(0.0)


def test_castellated_joint() -> None:
    lo, hi = lam.CASTELLATED_FLEXURE_LENGTH_MM
    assert (lo, hi) == (0.02, 0.04)
    j20 = lam.Flexure.castellated(2.0, 8, lo)
    j40 = lam.Flexure.castellated(2.0, 8, hi)
    assert j20.stiffness / j40.stiffness == pytest.approx(2.0)
    assert j20.stiffness == pytest.approx(lam.Flexure(2.0, lo).stiffness)
    assert lam.Flexure.castellated(2.0, 8, 0.03, flexure_fraction=0.5).stiffness == pytest.approx(
        0.5 * lam.Flexure(2.0, 0.03).stiffness
    )
    assert not lam.Flexure.castellated(2.0, 8, 0.1).within_thesis_range
    with pytest.raises(ps.InvalidParameterError) as exc:
        lam.Flexure.castellated(2.0, 0, 0.03)
    assert exc.value.field == "n_segments"


def test_non_numeric_laminate_fields_are_typed_errors_naming_the_field() -> None:
    with pytest.raises(ps.InvalidParameterError) as exc:
        lam.Material("x", "metal", "stiff", 1.0e6, 4.0e5, 0.3, 1.0, 0.0, 0.0)  # type: ignore[arg-type]
    assert exc.value.field == "e1"
    kapton = lam.material("kapton")
    with pytest.raises(ps.InvalidParameterError) as exc:
        lam.Layup([lam.Layer("k", (lam.Ply(kapton, "thin"),))]).abd()  # type: ignore[arg-type]
    assert exc.value.field == "layers[0].plies[0].thickness"


def test_non_numeric_bimorph_geometry_is_a_typed_error() -> None:
    layup = lam.Bimorph.design_for().layup
    with pytest.raises(ps.InvalidParameterError) as exc:
        lam.Bimorph(layup, "long")  # type: ignore[arg-type]
    assert exc.value.field == "length"


def test_unknown_record_keys_are_typed_errors_naming_the_nearest_field() -> None:
    import json

    from paritysim import _core

    record = lam.material("brass").to_dict()
    record["densty"] = record.pop("density")
    with pytest.raises(ps.InvalidParameterError) as exc:
        _core.laminate_check_material(json.dumps(record))
    assert exc.value.field == "material.densty"
    assert "did you mean `density`" in str(exc.value)
    layers = [{"name": "b", "plies": [{"material": lam.material("brass").to_dict(), "thickness": 0.01, "angel": 0.0}]}]
    with pytest.raises(ps.InvalidParameterError) as exc:
        _core.laminate_abd(json.dumps(layers))
    assert exc.value.field == "layers.angel"
    assert "did you mean `angle`" in str(exc.value)


def test_malformed_inputs_are_named() -> None:
    # Each was a bare ValueError (unpacking, float conversion) or a silent NaN.
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.laminate.Layup.from_plies([("a", "polyimide")])  # type: ignore[list-item]
    assert info.value.field == "plies[0]"
    mobee = ps.laminate.Layup.mobee()
    for kwargs, field in (({"n": "x"}, "n"), ({"n": [1.0, 2.0]}, "n"), ({"m": [1.0, "a", 3.0]}, "m"), ({"voltages": ["q"]}, "voltages")):
        with pytest.raises(ps.InvalidParameterError) as info:
            mobee.response(**kwargs)  # type: ignore[arg-type]
        assert info.value.field == field
    flexure = ps.laminate.Flexure(width=1.0, length=0.1)
    assert flexure.torque(0.2) == pytest.approx(-0.2 * flexure.stiffness)
    with pytest.raises(ps.InvalidParameterError) as info:
        flexure.torque(float("nan"))
    assert info.value.field == "angle"
