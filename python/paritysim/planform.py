"""Wing planforms: outline polygons, Ω1..Ω4 (eqs. 3.12-3.15) and wing inertia (Table 3.3).

Frame (Fig. 3.1 / Fig. 3.10): points are ``[z, x]`` in mm. ``z`` runs spanwise along the wing
hinge from the spherical centre (every point needs ``z >= 0``); ``x`` runs chordwise and
increases toward the **leading edge**; the hinge line is ``x = 0``. A passively rotating wing
hangs behind its hinge (mostly ``x < 0``); an outline lying entirely at ``x >= 0`` is rejected
as being on the wrong side of the hinge line (mirror it, ``x -> -x``).

All integrals are exact for the polygon (slab decomposition + Gauss-Legendre, see the Rust
crate ``paritysim-aero``). Air density defaults to 1.2 kg/m³ = 1.2e-3 mg/mm³.
"""

from __future__ import annotations

import math

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from . import _core
from ._errors import chunked, invalid, real, reals, whole

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["AIR_DENSITY", "Planform"]

#: Air at sea level, 1.2 kg/m³ in mg/mm³.
AIR_DENSITY: float = _core.AERO_AIR_DENSITY

FloatArray = npt.NDArray[np.float64]


#: Largest |z|, |x| of an outline vertex (mm), as the Rust outline check allows.
_MAX_COORDINATE = 1e3
#: The smallest extent of an outline either way (mm), as `Planform.rectangle` takes it.
_MIN_EXTENT = 1e-6


def _shape_error(name: str, message: str) -> Exception:
    err = _core.ShapeError(message)
    err.field = name  # type: ignore[attr-defined]
    err.kind = "Shape"  # type: ignore[attr-defined]
    return err


def _as_points(points: npt.ArrayLike, name: str = "points") -> FloatArray:
    a = np.ascontiguousarray(reals(name, points))
    if a.ndim != 2 or a.shape[1] != 2:
        raise _shape_error(name, f"`{name}` must have shape (n, 2) of [z, x] in mm, got {a.shape}")
    return a


def _rows(values: Iterable[Sequence[float]] | npt.ArrayLike, cols: int, name: str) -> FloatArray:
    a = reals(name, values)
    if a.size == 0:
        return np.zeros((0, cols))
    if a.ndim == 1:
        a = a.reshape(1, -1)
    if a.ndim != 2 or a.shape[1] != cols:
        raise _shape_error(name, f"`{name}` must have shape (n, {cols}), got {a.shape}")
    return np.ascontiguousarray(a)


class Planform:
    """An immutable, validated wing outline with its exact area integrals.

    Build with :meth:`from_points`, :meth:`rectangle`, :meth:`semi_ellipse` or
    :meth:`hmf_like`. Invalid outlines raise ``GeometryError`` (self-intersecting, open,
    degenerate, wrong side of the spherical centre or of the hinge line); bad numbers raise
    ``InvalidParameterError`` naming the field; wrong array shapes raise ``ShapeError``.
    """

    __slots__ = ("_props",)
    _props: dict[str, Any]

    def __init__(self, points: npt.ArrayLike, *, closure_tolerance: float | None = None) -> None:
        pts = _as_points(points)
        tol = None if closure_tolerance is None else real("closure_tolerance", closure_tolerance)
        try:
            props = _core.aero_planform_properties(pts, AIR_DENSITY, tol)
        except _core.GeometryError as exc:  # an outline the model cannot use: its points
            if not getattr(exc, "field", None):
                exc.field = "points"  # type: ignore[attr-defined]
            raise
        props["vertices"].setflags(write=False)
        object.__setattr__(self, "_props", props)

    def __setattr__(self, name: str, value: object) -> None:
        raise AttributeError("Planform is immutable")

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_points(cls, points: npt.ArrayLike, closure_tolerance: float | None = None) -> Planform:
        """Outline vertices ``(n, 2)`` ``[z, x]`` in mm; the closing edge is implicit.

        With ``closure_tolerance`` (mm) the points are a traced outline whose last point must
        return to within that distance of the first (else ``GeometryError``: open outline).
        """
        return cls(points, closure_tolerance=closure_tolerance)

    @classmethod
    def rectangle(cls, span: float, chord: float, root_offset: float = 0.0, le_offset: float = 0.0) -> Planform:
        """``z`` in ``[root_offset, root_offset + span]``, ``x`` in ``[le_offset - chord, le_offset]`` (mm)."""
        return cls(_core.aero_planform_rectangle(real("span", span), real("chord", chord), real("root_offset", root_offset), real("le_offset", le_offset)))

    @classmethod
    def semi_ellipse(
        cls,
        span: float,
        max_chord: float,
        root_offset: float = 0.0,
        le_offset: float = 0.0,
        segments: int = 256,
    ) -> Planform:
        """Straight leading edge at ``x = le_offset``, elliptic trailing edge, zero chord at root
        and tip; a polygon of ``segments`` equal eccentric-angle steps (integrals converge to
        the ellipse's as ``segments**-2``)."""
        return cls(
            _core.aero_planform_semi_ellipse(
                real("span", span), real("max_chord", max_chord), real("root_offset", root_offset), real("le_offset", le_offset), whole("segments", segments)
            )
        )

    @classmethod
    def hmf_like(cls, tip_radius: float = 16.6, segments: int = 128) -> Planform:
        """A smooth HMF-like wing (Fig. 3.10) scaled to ``tip_radius`` mm; at 16.6 mm its
        Ω1..Ω4 are within 15 % of Table 3.3 (left wing). A stand-in, not the measured outline."""
        return cls(_core.aero_planform_hmf_like(real("tip_radius", tip_radius), whole("segments", segments)))

    # ------------------------------------------------------------------ geometry
    @property
    def points(self) -> FloatArray:
        """Validated vertices ``(n, 2)`` ``[z, x]`` (mm), counter-clockwise, read-only."""
        v: FloatArray = self._props["vertices"]
        return v

    @property
    def area(self) -> float:
        """Membrane area (mm²)."""
        return float(self._props["area"])

    @property
    def span(self) -> float:
        """Spanwise extent of the membrane, ``max z - min z`` (mm)."""
        return float(self._props["span"])

    @property
    def tip_radius(self) -> float:
        """Distance from the spherical centre to the tip, ``max z`` (mm)."""
        return float(self._props["tip_radius"])

    @property
    def root_offset(self) -> float:
        """Innermost membrane ``z`` (mm)."""
        return float(self._props["root_offset"])

    @property
    def mean_chord(self) -> float:
        """Area / span (mm)."""
        return float(self._props["mean_chord"])

    @property
    def centroid(self) -> FloatArray:
        """Area centroid ``[z, x]`` (mm)."""
        c: FloatArray = self._props["centroid"].copy()
        return c

    @property
    def integrals(self) -> dict[str, float]:
        """Density-free integrals: ``area, z1, x1, z2, x2, xz, z3, x3_abs, z2_c2, z2_lc``."""
        return dict(self._props["integrals"])

    def chord(self, z: npt.ArrayLike) -> FloatArray:
        """Chord ``c(z)`` (mm); 0 outside the span."""
        zz = reals("z", z)
        c: FloatArray = np.asarray(self._chord_table(zz)["chord"]).reshape(zz.shape)
        return c

    def leading_edge(self, z: npt.ArrayLike) -> FloatArray:
        """Leading edge ``l(z)`` (mm, signed distance ahead of the hinge line); NaN outside the span."""
        zz = reals("z", z)
        l_: FloatArray = np.asarray(self._chord_table(zz)["leading_edge"]).reshape(zz.shape)
        return l_

    def _chord_table(self, zz: FloatArray) -> dict[str, Any]:
        """``chord`` and ``leading_edge`` at the points ``zz``, a chunk at a time: the native call
        holds ~200 bytes per point while it runs (2 GB for 1e7 points; the fuzz, seed 37)."""
        flat = np.ascontiguousarray(zz, dtype=np.float64).ravel()
        return chunked(lambda x: _core.aero_planform_chord(self.points, x), [flat], ("z",))

    def scaled(self, factor: float | None = None, *, span_mm: float | None = None, area_mm2: float | None = None) -> Planform:
        """This outline scaled about the spherical centre: uniformly by ``factor``, or to a
        target spanwise extent ``span_mm`` (mm) and/or membrane area ``area_mm2`` (mm²).

        With both targets the two directions scale apart: ``z -> s_z z`` with
        ``s_z = span_mm / span`` (the spanwise extent :attr:`span`, so the root offset scales
        with it) and ``x -> s_x x`` with ``s_x = area_mm2 / (area s_z)`` (the chordwise scale
        that leaves the area at its target; the hinge line stays at ``x = 0``). With one target
        the scale is uniform (the shape and aspect ratio are kept): ``s = span_mm / span`` or
        ``s = sqrt(area_mm2 / area)``.

        Under ``(s_z, s_x)`` the parameters scale as (eqs. 3.12-3.15; :meth:`omegas`):
        ``Ω1 ∝ s_z⁴ s_x``, ``Ω2 ∝ s_z s_x⁴``, ``Ω3, Ω4 ∝ s_z³ s_x²``, ``force ∝ s_z³ s_x``,
        and at a fixed mass ``Ixx ∝ s_z²``, ``Izz ∝ s_x²``, ``Ixz ∝ s_z s_x``; uniform scaling
        gives ``s⁵`` for every Ω.

        Raises ``InvalidParameterError`` naming ``factor``, ``span_mm`` or ``area_mm2``: each
        finite and > 0, ``factor`` not together with a target, and the scaled outline within
        1e3 mm of the spherical centre.
        """
        if factor is not None and (span_mm is not None or area_mm2 is not None):
            raise invalid("factor", factor, "None when span_mm or area_mm2 is given (one or the other)")
        targets = {}
        for name, value in (("factor", factor), ("span_mm", span_mm), ("area_mm2", area_mm2)):
            if value is None:
                continue
            v = real(name, value)
            if not (math.isfinite(v) and v > 0):
                raise invalid(name, value, "finite and > 0" + {"factor": "", "span_mm": " (mm)", "area_mm2": " (mm^2)"}[name])
            targets[name] = v
        if not targets:
            raise invalid("factor", None, "a scale factor > 0, or a target span_mm and/or area_mm2")
        if "factor" in targets:
            sz = sx = targets["factor"]
        elif "span_mm" in targets and "area_mm2" in targets:
            sz = targets["span_mm"] / self.span
            sx = targets["area_mm2"] / (self.area * sz)
        elif "span_mm" in targets:
            sz = sx = targets["span_mm"] / self.span
        else:
            sz = sx = math.sqrt(targets["area_mm2"] / self.area)
        reach_z = float(np.abs(self.points[:, 0]).max())
        reach_x = float(np.abs(self.points[:, 1]).max())
        # The outline's bound (|z|, |x| <= 1e3 mm), named by the argument that sets each scale.
        if max(reach_z * sz, reach_x * sx) > _MAX_COORDINATE:
            uniform = _MAX_COORDINATE / max(reach_z, reach_x)  # the largest uniform scale
            if "factor" in targets:
                name, top = "factor", uniform
            elif "area_mm2" not in targets:
                name, top = "span_mm", uniform * self.span
            elif "span_mm" not in targets:
                name, top = "area_mm2", uniform**2 * self.area
            elif reach_z * sz > _MAX_COORDINATE:
                name, top = "span_mm", _MAX_COORDINATE / reach_z * self.span
            else:
                name, top = "area_mm2", _MAX_COORDINATE / reach_x * self.area * sz
            unit = {"factor": "", "span_mm": " mm", "area_mm2": " mm^2"}[name]
            raise invalid(name, targets[name], f"in (0, {top:.6g}]{unit} (the outline must stay within {_MAX_COORDINATE:g} mm)")
        # The smallest outline, as Planform.rectangle's (1e-6 mm across each way): a smaller
        # one is a degenerate polygon to the geometry (a GeometryError naming `points`).
        extent_z, extent_x = self.span, float(np.ptp(self.points[:, 1]))
        if min(extent_z * sz, extent_x * sx) < _MIN_EXTENT:
            name = next(n for n in ("factor", "span_mm", "area_mm2") if n in targets) if extent_z * sz < _MIN_EXTENT else ("area_mm2" if "area_mm2" in targets else next(iter(targets)))
            raise invalid(name, targets[name], f"large enough that the outline stays at least {_MIN_EXTENT:g} mm across (span {extent_z * sz:.3g} mm, chord {extent_x * sx:.3g} mm here)")
        return Planform(self.points * np.array([sz, sx]))

    def translated(self, dz: float = 0.0, dx: float = 0.0) -> Planform:
        """Shifted by ``dz`` (spanwise) and ``dx`` (toward the leading edge; moves the hinge line by ``-dx``)."""
        shift = np.array([real("dz", dz), real("dx", dx)])
        moved = self.points + shift
        for axis, name in enumerate(("dz", "dx")):
            if not (np.isfinite(moved[:, axis]).all() and np.abs(moved[:, axis]).max() <= _MAX_COORDINATE):
                raise invalid(name, float(shift[axis]), f"a shift keeping the outline within {_MAX_COORDINATE:g} mm")
        return Planform(moved)

    def cut(self, fraction: float, where: str = "tip", *, measure: str = "span") -> Planform:
        """The membrane left after cutting part of it away along a straight line.

        ``where="tip"`` removes the outboard part (``z`` beyond the cut line), as the 1-Cut and
        2-Cut wings of §3.4 (Fig. 3.10, "planform area removed from the distal extent");
        ``where="trailing"`` removes the rear part (``x`` behind the cut line).

        ``measure="span"``: ``fraction`` of the spanwise extent (tip) or of the chordwise extent
        (trailing) is removed. ``measure="area"``: the line is placed so that ``fraction`` of
        the *area* is removed (§3.3 states its cuts as area kept: 84.3 %, 56.8 %), solved by
        bracketing root finding to 1e-12 of the area. The result is a polygon, so its Ω1..Ω4
        and inertia integrals stay exact.

        Raises ``InvalidParameterError`` (``fraction``: ``0 <= fraction < 1``; ``where``;
        ``measure``) and ``GeometryError`` if the line would split the membrane in pieces.
        """
        if measure not in ("span", "area"):
            raise invalid("measure", repr(measure), '"span" or "area"')
        if where not in ("tip", "trailing"):
            raise invalid("where", repr(where), '"tip" or "trailing"')
        f = real("fraction", fraction)
        if not (math.isfinite(f) and 0.0 <= f < 1.0):
            raise invalid("fraction", fraction, "in [0, 1)")
        try:
            return self._cut(f, where, measure)
        except _core.GeometryError as exc:  # the line leaves no membrane, or splits it
            if not getattr(exc, "field", None):
                exc.field = "fraction"  # type: ignore[attr-defined]
            raise

    def _cut(self, f: float, where: str, measure: str) -> Planform:
        if measure == "span" or f == 0.0:
            return Planform(_core.aero_planform_cut(self.points, f, str(where)))
        from scipy.optimize import brentq

        target = (1.0 - f) * self.area

        def excess(s: float) -> float:
            try:
                kept = _core.aero_planform_properties(_core.aero_planform_cut(self.points, s, str(where)), AIR_DENSITY, None)
            except _core.GeometryError:  # a cut near the far edge leaves a sliver: no area
                return -target
            return float(kept["area"]) - target

        # Kept area falls continuously and monotonically from the full area (s = 0) to 0 (s -> 1).
        s = brentq(excess, 0.0, 1.0 - 1e-12, xtol=1e-14, rtol=1e-14)
        return Planform(_core.aero_planform_cut(self.points, float(s), str(where)))

    # ------------------------------------------------------------------ parameters
    def omegas(self, rho: float = AIR_DENSITY) -> dict[str, float]:
        """Ω1..Ω4 of eqs. 3.12-3.15 (mg·mm²) and ``force`` = ½ρ∬z²dA (mg·mm).

        ``rho`` in mg/mm³ (1.2e-3 for air). No force coefficient is folded in.
        Raises ``InvalidParameterError`` (``rho``) unless ``rho`` is finite and > 0.
        """
        r = real("rho", rho)
        if not (math.isfinite(r) and r > 0):
            raise invalid("rho", rho, "finite and > 0 (mg/mm^3; air is 1.2e-3)")
        p = _core.aero_planform_properties(self.points, r, None)
        for k in ("omega1", "omega2", "omega3", "omega4", "force"):
            if p[k] is None or not math.isfinite(float(p[k])):
                raise invalid("rho", rho, f"small enough that {k} is finite")
        return {k: float(p[k]) for k in ("omega1", "omega2", "omega3", "omega4", "force")}

    def quasi_steady_omegas(self, rho: float = AIR_DENSITY) -> dict[str, float]:
        """Ω5..Ω8 of the ``whitney_wood2010`` aero model (mg·mm²), with the mid-chord
        ``x_m = l - c/2``: ``omega5 = ½ρ∫ z c² x_m dz``, ``omega6 = ½ρ∫ c² x_m² dz``,
        ``omega7 = ½ρ∫ c⁴ dz``, ``omega8 = ½ρ∫ z c (l - c/4)(¾c - l) dz`` (exact for the polygon;
        docs/concepts.md, Aero models).

        Raises ``InvalidParameterError`` (``rho``) unless ``rho`` is finite and > 0.
        """
        r = real("rho", rho)
        if not (math.isfinite(r) and r > 0):
            raise invalid("rho", rho, "finite and > 0 (mg/mm^3; air is 1.2e-3)")
        p = _core.aero_planform_properties(self.points, r, None)
        return {k: float(p[k]) for k in ("omega5", "omega6", "omega7", "omega8")}

    def inertia(
        self,
        areal_density: float = 0.0,
        line_masses: Iterable[Sequence[float]] | npt.ArrayLike = (),
        point_masses: Iterable[Sequence[float]] | npt.ArrayLike = (),
    ) -> dict[str, Any]:
        """Mass properties about the spherical centre in the frame of Fig. 3.10.

        Parameters
        ----------
        areal_density:
            Membrane mass per area (mg/mm²).
        line_masses:
            Rows ``[z0, x0, z1, x1, linear_density]`` (mm, mg/mm): spars and veins.
        point_masses:
            Rows ``[z, x, mass]`` (mm, mg).

        Returns
        -------
        dict
            ``mass``, ``center_of_mass`` ``[z, x]``, ``ixx = ∫z²dm``, ``izz = ∫x²dm``,
            ``iyy = ixx + izz``, ``ixz = -∫xz dm`` (tensor element; positive for a wing behind
            its hinge, as in Table 3.3) and ``tensor`` (3, 3).
        """
        inputs = {
            "areal_density": np.array([[real("areal_density", areal_density)]]),
            "line_masses": _rows(line_masses, 5, "line_masses"),
            "point_masses": _rows(point_masses, 3, "point_masses"),
        }
        out: dict[str, Any] = _core.aero_planform_inertia(self.points, float(inputs["areal_density"][0, 0]), inputs["line_masses"], inputs["point_masses"])
        if not all(np.isfinite(np.asarray(v, dtype=float)).all() for v in out.values()):
            # An overflow of huge finite inputs (issue 34): name the largest one.
            name = max((k for k in inputs if inputs[k].size), key=lambda k: float(np.abs(inputs[k]).max()))
            raise invalid(name, float(np.abs(inputs[name]).max()), "small enough that the mass properties are finite (they overflow here)")
        return out

    def _leading_edge_segments(self) -> FloatArray:
        """The outline's edges facing the leading edge, rows ``[z0, x0, z1, x1]`` (mm): the edges
        whose outward normal points toward ``+x`` (run with decreasing ``z`` in the
        counter-clockwise outline), i.e. the boundary ``x = l(z)`` from root to tip. Root and
        tip edges running along ``x`` belong to neither edge and are left out."""
        v = self.points
        w = np.roll(v, -1, axis=0)
        if float(np.sum(v[:, 0] * w[:, 1] - w[:, 0] * v[:, 1])) < 0:  # clockwise: the other way round
            v, w = w, v
        upper = w[:, 0] < v[:, 0]
        return np.ascontiguousarray(np.hstack([v[upper], w[upper]]))

    # ------------------------------------------------------------------ display
    def plot(self, ax: Axes | None = None, *, hinge: bool = True, **kwargs: Any) -> Axes:
        """Draw the outline (z horizontal, x vertical as in Fig. 3.10) and the hinge line ``x = 0``.

        Extra keyword arguments go to ``Axes.fill``. Returns the Axes.
        """
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        pts = np.vstack([self.points, self.points[:1]])
        style: dict[str, Any] = {"facecolor": "0.85", "edgecolor": "k", "linewidth": 1.0}
        style.update(kwargs)
        ax.fill(pts[:, 0], pts[:, 1], **style)
        if hinge:
            ax.axhline(0.0, color="C3", linestyle="--", linewidth=1.0, label="hinge line (x = 0)")
            ax.plot([0.0], [0.0], marker="o", color="C3", linestyle="none", label="spherical centre")
        ax.set_xlabel("z (mm, spanwise)")
        ax.set_ylabel("x (mm, toward leading edge)")
        ax.set_aspect("equal", adjustable="datalim")
        return ax

    def __repr__(self) -> str:
        return (
            f"Planform(n={len(self.points)}, area={self.area:.4g} mm², span={self.span:.4g} mm, "
            f"tip_radius={self.tip_radius:.4g} mm)"
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Planform):
            return NotImplemented
        return self.points.shape == other.points.shape and bool(np.array_equal(self.points, other.points))

    def __hash__(self) -> int:
        return hash(self.points.tobytes())

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        return (Planform, (np.array(self.points),))
