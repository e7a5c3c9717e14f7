"""Planform.cut: exact Ω of the cut membrane against closed forms (eqs. 3.12-3.15)."""

from __future__ import annotations

import math

import pytest

import paritysim as ps

RHO = ps.planform.AIR_DENSITY


def rectangle_omegas(z0: float, z1: float, x_trailing: float, x_leading: float) -> dict[str, float]:
    """Ω1..Ω4 of the rectangle z in [z0, z1], x in [x_trailing, x_leading], integrated by hand."""
    h, c = 0.5 * RHO, x_leading - x_trailing
    abs3 = lambda x: abs(x) ** 3 * x / 4.0  # noqa: E731  antiderivative of |x|^3
    return {
        "omega1": h * c * (z1**4 - z0**4) / 4.0,
        "omega2": h * (z1 - z0) * (abs3(x_leading) - abs3(x_trailing)),
        "omega3": h * c * c * (z1**3 - z0**3) / 3.0,
        "omega4": h * x_leading * c * (z1**3 - z0**3) / 3.0,
    }


@pytest.mark.parametrize("fraction", [0.1, 0.3, 0.65])
def test_tip_cut_rectangle_has_the_omegas_of_the_shorter_rectangle(fraction: float) -> None:
    span, chord, root, le = 16.0, 3.2, 1.5, 0.4
    cut = ps.Planform.rectangle(span, chord, root, le).cut(fraction, where="tip")
    expected = rectangle_omegas(root, root + (1 - fraction) * span, le - chord, le)
    got = cut.omegas()
    for k, v in expected.items():
        assert got[k] == pytest.approx(v, rel=1e-12), k
    assert cut.tip_radius == pytest.approx(root + (1 - fraction) * span, rel=1e-14)


def test_trailing_cut_rectangle_has_the_omegas_of_the_narrower_rectangle() -> None:
    span, chord, le = 12.0, 4.0, 0.5
    cut = ps.Planform.rectangle(span, chord, 0.0, le).cut(0.25, where="trailing")
    expected = rectangle_omegas(0.0, span, le - 0.75 * chord, le)
    for k, v in expected.items():
        assert cut.omegas()[k] == pytest.approx(v, rel=1e-12), k


def test_area_measure_removes_that_fraction_of_the_area() -> None:
    wing = ps.Planform.hmf_like()
    for kept in (0.843, 0.568):  # the §3.3 cuts, stated as area kept
        cut = wing.cut(1 - kept, where="tip", measure="area")
        assert cut.area / wing.area == pytest.approx(kept, abs=1e-10)
        assert cut.omegas()["omega1"] < wing.omegas()["omega1"]


def test_semi_ellipse_tip_cut_matches_direct_integration() -> None:
    # Ω1 = ½ρ ∫ z³ c(z) dz over the kept span; c(z) of the polygon is piecewise linear, so
    # integrate the chord the Planform reports with a fine trapezoid rule as an independent check.
    import numpy as np

    wing = ps.Planform.semi_ellipse(span=15.0, max_chord=4.0, root_offset=1.0, segments=64)
    cut = wing.cut(0.4)
    z = np.linspace(cut.root_offset, cut.tip_radius, 400_001)
    omega1 = 0.5 * RHO * np.trapezoid(z**3 * wing.chord(z), z)
    assert cut.omegas()["omega1"] == pytest.approx(omega1, rel=1e-8)


def test_zero_fraction_is_the_same_planform_and_bad_input_is_typed() -> None:
    wing = ps.Planform.hmf_like()
    assert wing.cut(0.0) == wing
    for bad in (-0.1, 1.0, math.nan):
        with pytest.raises(ps.InvalidParameterError, match="fraction"):
            wing.cut(bad)
    with pytest.raises(ps.InvalidParameterError, match="where"):
        wing.cut(0.2, where="root")
    with pytest.raises(ps.InvalidParameterError, match="measure"):
        wing.cut(0.2, measure="volume")


@pytest.mark.parametrize("fraction", [0.01, 0.25, 0.9])
def test_a_trailing_cut_by_area_removes_that_fraction_of_the_area(fraction: float) -> None:
    # The root finder's far bracket left a sliver whose GeometryError ended every such cut.
    for outline in (ps.Planform.rectangle(10.0, 2.0), ps.Planform.hmf_like()):
        kept = outline.cut(fraction, "trailing", measure="area")
        assert kept.area == pytest.approx((1.0 - fraction) * outline.area, rel=1e-10)
    rectangle = ps.Planform.rectangle(10.0, 2.0)  # a rectangle cut at the back by area is cut by chord
    assert rectangle.cut(0.25, "trailing", measure="area").area == pytest.approx(rectangle.cut(0.25, "trailing").area, rel=1e-10)


def test_scaling_below_the_smallest_outline_names_the_argument() -> None:
    # A GeometryError naming `points` (a degenerate polygon) where the docstring promises the argument.
    for kwargs in ({"factor": 1e-300}, {"span_mm": 1e-9}, {"area_mm2": 1e-20}):
        with pytest.raises(ps.InvalidParameterError, match="1e-06 mm across") as info:
            ps.Planform.hmf_like().scaled(**kwargs)
        assert info.value.field == next(iter(kwargs))
