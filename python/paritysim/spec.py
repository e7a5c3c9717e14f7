"""Device and simulation specs: frozen dataclasses whose fields and defaults come from the Rust core.

The spec types live in Rust (``crates/spec``); their JSON Schema (``spec.schema.json``, also
:func:`schema`) is the single source of every field name, default, unit and range. The classes
here are generated from it at import time (:func:`_from_core`), so Python and Rust cannot drift;
they add constructors and conveniences only.

A spec is plain data: build it in Python, load it from TOML (:func:`load_spec`, parsed in Rust),
save it (:meth:`Simulation.save`). Validation happens in Rust when the spec is used
(:meth:`Simulation.validate`, :func:`paritysim.simulate`), reporting every invalid field with its
dotted path (``wings[0].aero.omega1``), allowed range and, for unknown keys, the nearest valid
name. Old spellings (``balance_stiffness``, ``springs`` as a list of six, ``tunable_hinge.k0``)
are accepted with a ``DeprecationWarning``.

Tagged kinds (``Drivetrain.kind``, ``Aero.kind``, ``Waveform.kind``) are flat classes here: the
fields of the chosen kind get that kind's defaults, the others stay ``None`` (setting one is an
unknown-field error naming the kind's fields).

Units: mg-mm-ms-rad-V; names carry the unit where it could be misread (``frequency_hz``).
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import numbers
import os
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union

import numpy as np

from . import _core

__all__ = [
    "Actuator",
    "Aero",
    "Body",
    "Configuration",
    "Drivetrain",
    "Options",
    "Shoulder",
    "Simulation",
    "Spring",
    "Springs",
    "TunableHinge",
    "Waveform",
    "Wing",
    "load_spec",
    "schema",
    "spec_paths",
]

_SCHEMA: dict[str, Any] = json.loads(_core.spec_schema())
_KIND_DEFAULTS: dict[str, Any] = json.loads(_core.spec_defaults())
_CLASSES: dict[str, type] = {}


def schema() -> dict[str, Any]:
    """The JSON Schema of a spec (a fresh copy); also shipped as ``paritysim/spec.schema.json``."""
    return json.loads(_core.spec_schema())


def _definition(name: str) -> dict[str, Any]:
    return _SCHEMA if name == "Simulation" else _SCHEMA["$defs"][name]


def _ref(prop: dict[str, Any]) -> str | None:
    """The definition a property refers to, through ``Option`` (anyOf null) and lists."""
    if "$ref" in prop:
        return str(prop["$ref"]).rsplit("/", 1)[1]
    for key in ("anyOf", "oneOf"):
        for branch in prop.get(key, []):
            found = _ref(branch)
            if found:
                return found
    if prop.get("type") == "array" and isinstance(prop.get("items"), dict):
        return _ref(prop["items"])
    return None


_MISSING = object()


@functools.cache
def _fields(name: str) -> tuple[tuple[str, Any, str | None, bool], ...]:
    """``(field, default JSON or _MISSING, referenced definition, is a list)`` of a definition
    (cached: every spec built from Rust's canonical data reads it once per class)."""
    d = _definition(name)
    if "oneOf" in d:  # a tagged enum: kind plus the union of the kinds' fields
        out: list[tuple[str, Any, str | None, bool]] = [("kind", _KIND_DEFAULTS[name]["kind"], None, False)]
        for variant in d["oneOf"]:
            for key, prop in variant["properties"].items():
                if all(key != f[0] for f in out):
                    out.append((key, None, _ref(prop), prop.get("type") == "array" and _ref(prop) is not None))
        return tuple(out)
    required = set(d.get("required", []))
    out = []
    for key, prop in d["properties"].items():
        default = prop["default"] if "default" in prop else (_MISSING if key in required else None)
        out.append((key, default, _ref(prop), prop.get("type") == "array" and _ref(prop) is not None))
    return tuple(out)


def _variant(name: str, kind: str) -> dict[str, Any] | None:
    for v in _definition(name).get("oneOf", []):
        if v["properties"]["kind"].get("const") == kind:
            return v
    return None


def _from_core(cls: type) -> type:
    """Makes ``cls`` a frozen dataclass with the fields and defaults of the Rust type of the same
    name (required fields first, then declaration order)."""
    specs = sorted(_fields(cls.__name__), key=lambda f: f[1] is not _MISSING)
    annotations: dict[str, Any] = {}
    for key, default, ref, _ in specs:
        annotations[key] = "Any"
        if default is _MISSING:
            continue
        if ref in _MODELS and isinstance(default, dict):
            setattr(cls, key, field(default_factory=functools.partial(_build_known, ref, default)))
        else:
            # Lists (vectors, tensors) as tuples: frozen and hashable like every spec value.
            setattr(cls, key, _tuples(default) if isinstance(default, list) else default)
    cls.__annotations__ = annotations
    built = dataclass(frozen=True)(cls)
    names = [key for key, *_ in specs]
    init = built.__init__

    @functools.wraps(init)
    def checked_init(self: Any, *args: Any, **kwargs: Any) -> None:
        for key in kwargs:
            if key not in names:  # a typed error with the nearest field, not a bare TypeError
                from ._errors import invalid, suggest

                raise invalid(f"{cls.__name__}.{key}", "<unknown field>", suggest(key, names))
        init(self, *args, **kwargs)

    built.__init__ = checked_init  # type: ignore[method-assign]
    if issubclass(built, _Tagged):
        built.__repr__ = _Tagged.kind_repr  # type: ignore[method-assign]
    _CLASSES[cls.__name__] = built
    return built


_MODELS = {"Simulation", "Wing", "Shoulder", "Spring", "Springs", "Aero", "TunableHinge", "Drivetrain", "Waveform", "Actuator", "Configuration", "Options", "Body"}


def _build_known(name: str, data: Any) -> Any:
    """Builds class ``name`` from canonical plain data (no validation: it came from Rust)."""
    cls = _CLASSES[name]
    if not isinstance(data, dict):
        return data
    kwargs: dict[str, Any] = {}
    for key, _, ref, is_list in _fields(name):
        if key not in data:
            continue
        value = data[key]
        if ref in _MODELS and value is not None:
            value = tuple(_build_known(ref, v) for v in value) if is_list else _build_known(ref, value)
        elif isinstance(value, list):
            value = _tuples(value)
        kwargs[key] = value
    return cls(**kwargs)


def _tuples(x: Any) -> Any:
    return tuple(_tuples(v) for v in x) if isinstance(x, list | tuple) else x


def _coerced(owner: str, changes: dict[str, Any]) -> dict[str, Any]:
    """``changes`` to fields of class ``owner`` as its constructors make them: a mapping for a
    section built as that section's class (``options={"rtol": 1e-6}``: an ``Options`` with
    the other fields at their defaults; an unknown key named), lists as tuples (frozen and
    hashable). A dict kept as a dict broke ``ps.simulate`` with an AttributeError."""
    fields = {key: (ref, is_list) for key, _, ref, is_list in _fields(owner)}
    out = {}
    for key, value in changes.items():
        ref, is_list = fields.get(key, (None, False))
        if ref in _MODELS and value is not None:
            value = tuple(_section(ref, v) for v in value) if is_list and isinstance(value, list | tuple) else _section(ref, value)
        elif isinstance(value, list):
            value = _tuples(value)
        out[key] = value
    return out


def _section(name: str, value: Any) -> Any:
    """``value`` as class ``name``: built from a mapping (see :func:`_coerced`), else as given."""
    if isinstance(value, Mapping):
        return _CLASSES[name](**_coerced(name, dict(value)))
    return value


class _Node:
    """Conveniences shared by every spec class."""

    def with_fields(self, path: str, **changes: Any) -> Any:
        """A copy with fields replaced; an unknown field raises ``InvalidParameterError`` naming
        ``path.<field>`` and the nearest valid field (the Rust core's edit distance)."""
        names = [f.name for f in dataclasses.fields(self)]  # type: ignore[arg-type]
        for key in changes:
            if key not in names:
                from ._errors import invalid, suggest

                raise invalid(f"{path}.{key}", "<unknown field>", suggest(key, names))
        return dataclasses.replace(self, **_coerced(type(self).__name__, changes))  # type: ignore[type-var]

    def to_dict(self) -> dict[str, Any]:
        """Plain data (``None`` fields left out), as the Rust core reads it."""
        return _strip_none(dataclasses.asdict(self))  # type: ignore[call-overload]

    def replace(self, **changes: Any) -> Any:
        """A copy with fields replaced (``dataclasses.replace``); a section may be given as a
        mapping (``options={"rtol": 1e-6}``: an ``Options`` with the others at their defaults)
        and a list as a tuple, as the constructors take them."""
        return dataclasses.replace(self, **_coerced(type(self).__name__, changes))  # type: ignore[type-var]


class _Tagged(_Node):
    """A flat view of a Rust tagged enum: the chosen kind's fields get its defaults."""

    def __post_init__(self) -> None:
        variant = _variant(type(self).__name__, self.kind)  # type: ignore[attr-defined]
        if variant is None:
            return  # unknown kind: Rust names it and the valid kinds when the spec is used
        for key, prop in variant["properties"].items():
            if key != "kind" and getattr(self, key) is None and "default" in prop:
                object.__setattr__(self, key, _tuples(prop["default"]))

    def kind_repr(self) -> str:
        """``Drivetrain(kind='hmf_four_bar', crank_mm=0.4, rod_mm=0.8)``: the kind's fields only."""
        names = ["kind", *self.kind_fields()]
        names += [f.name for f in dataclasses.fields(self) if f.name not in names and getattr(self, f.name) is not None]  # type: ignore[arg-type]
        return f"{type(self).__name__}({', '.join(f'{n}={getattr(self, n)!r}' for n in names)})"

    def kind_fields(self) -> list[str]:
        """The fields of this kind (besides ``kind``)."""
        variant = _variant(type(self).__name__, self.kind) or {"properties": {}}  # type: ignore[attr-defined]
        return [k for k in variant["properties"] if k != "kind"]


@_from_core
class Shoulder(_Node):
    """Spherical five-bar shoulder (§2.3.3): ``0 <= alpha3 < alpha2 <= pi`` (rad)."""


@_from_core
class Spring(_Node):
    """Joint torsion spring ``tau = k (g - g0) + k3 (g - g0)^3`` (mN·mm/rad, mN·mm/rad³, rad)."""


@_from_core
class Springs(_Node):
    """The six shoulder joint springs by joint: ``stroke`` (γ1 = φ), ``passive_s2``, ``passive_s3``,
    ``deviation`` (γ4 = θ), ``wing_deviation`` (γ5 = θ_w), ``hinge`` (γ6 = ψ); and the hinge's
    viscous damping ``hinge_damping`` bψ (mN·mm·ms/rad)."""

    @classmethod
    def from_joints(cls, springs: Any) -> Springs:
        """From six springs in joint order (the old list form)."""
        names = [f.name for f in dataclasses.fields(cls) if f.name != "hinge_damping"]  # type: ignore[arg-type]
        springs = list(springs)
        if len(springs) != len(names):
            from ._errors import invalid

            raise invalid("springs", f"{len(springs)} springs", f"exactly {len(names)} (joints 1..6) or named springs {', '.join(names)}")
        return cls(**{n: s if isinstance(s, Spring) else Spring(**s) for n, s in zip(names, springs, strict=True)})


@_from_core
class Aero(_Tagged):
    """Wing aerodynamics, tagged by ``kind`` (Ω in mg·mm²).

    ``stroke_drag``: ``tau = -omega1 * coefficient * sgn(phi_dot) phi_dot^2`` about the stroke
    axis; ``coefficient = 1`` is eq. 2.16, ``C_N(90°)`` is eq. 3.8 for a fixed wing (docs/errata.md#12).
    ``blade_element``: the quasi-steady model of §3.2.4 (eqs. 3.8-3.11) with ``omega1..omega4``,
    coefficient ``model``, ``rotational_damping`` (None: the aero crate's cited default) and
    ``normal_force_law``.
    ``whitney_wood2010``: Whitney & Wood 2010: the blade element's fields plus ``omega5..omega8``
    and the multipliers ``rotational_lift`` (rotational lift), ``translational_added_mass`` and
    ``rotational_added_mass`` (added mass, run as an added inertia tensor); all three 0 is the
    blade element (docs/concepts.md, Aero models).
    """


@_from_core
class TunableHinge(_Node):
    """The tunable wing hinge of §2.5.1: ``V = ½ k(θ) ψ²`` with ``k(θ) = stiffness_at_zero +
    stiffness_slope θ + stiffness_curvature θ²`` (validated in Rust: ``k(θ) > 0`` for every θ)."""


@_from_core
class Wing(_Node):
    """A wing: inertia tensor about the spherical centre in frame 6 (mg·mm², 3×3), shoulder,
    named joint springs (:class:`Springs`), aerodynamics (None = vacuum), tunable hinge."""

    def __post_init__(self) -> None:
        springs = self.springs  # type: ignore[attr-defined]
        if isinstance(springs, list | tuple):
            warnings.warn("Wing(springs=<6 springs in joint order>) is deprecated: use Springs(stroke=..., hinge=...)", DeprecationWarning, stacklevel=3)
            object.__setattr__(self, "springs", Springs.from_joints(springs))
        elif springs is None:
            object.__setattr__(self, "springs", Springs())
        elif isinstance(springs, Mapping):
            object.__setattr__(self, "springs", _build_known("Springs", dict(springs)))
        object.__setattr__(self, "inertia", _tuples(self.inertia))  # type: ignore[attr-defined]

    @classmethod
    def from_moments(cls, ixx: float, iyy: float, izz: float, ixz: float = 0.0, **kwargs: Any) -> Wing:
        """A wing from the Table 3.3 moments ``Ixx, Iyy, Izz, Ixz`` (mg·mm²)."""
        inertia = ((ixx, 0.0, ixz), (0.0, iyy, 0.0), (ixz, 0.0, izz))
        return cls(inertia=inertia, **kwargs)  # type: ignore[call-arg]

    @classmethod
    def from_planform(
        cls,
        planform: Any,
        *,
        mass_mg: float,
        line_masses: Any = (),
        point_masses: Any = (),
        hinge: Any = None,
        aero_model: Any = _core.AERO_DEFAULT_MODEL,
        air_density_mg_per_mm3: float = _core.AERO_AIR_DENSITY,
        **fields: Any,
    ) -> Wing:
        """A wing from its outline: inertia tensor and Ω1..Ω4 in one call.

        The inertia is :meth:`Planform.inertia` (about the spherical centre, frame of Fig. 3.10:
        ``Ixx = ∫z² dm``, ``Izz = ∫x² dm``, ``Iyy = Ixx + Izz``, ``Ixz = -∫xz dm``) and the
        aerodynamic parameters are :meth:`Planform.omegas` (eqs. 3.12-3.15), both exact for the
        polygon.

        Parameters
        ----------
        planform:
            A :class:`~paritysim.planform.Planform` (``[z, x]`` in mm, hinge line ``x = 0``).
        mass_mg:
            Mass of the membrane (mg, >= 0), spread uniformly over the planform: areal density
            ``mass_mg / planform.area``. Spars, veins and point masses come on top of it; the
            wing's total mass is the sum.
        line_masses:
            Spars and veins, each of uniform mass per length: rows
            ``[z0_mm, x0_mm, z1_mm, x1_mm, mass_mg]`` (a straight segment and its total mass), or
            ``("leading_edge", mass_mg)``: a spar along the membrane's leading edge ``x = l(z)``
            from root to tip (the outline edges facing ``+x``, centreline on the edge), its mass
            spread uniformly along that edge's length. A mapping ``{"leading_edge": mass_mg}``
            is the same as ``[("leading_edge", mass_mg)]``.
        point_masses:
            Rows ``[z_mm, x_mm, mass_mg]`` (glue, hinge parts).
        hinge:
            The ψ hinge: a stiffness (mN·mm/rad) or a :class:`Spring` for ``springs.hinge``
            (joint 6), or a :class:`TunableHinge` for ``tunable_hinge``; None keeps the
            ``springs`` given (default: no hinge spring).
        aero_model:
            A coefficient model of :data:`paritysim.aero.MODELS` (blade elements, eqs. 3.8-3.11,
            with the planform's Ω1..Ω4), ``"stroke_drag"`` (eq. 2.16 with its Ω1), an
            :class:`Aero` whose other fields are kept and whose Ω's are replaced (an
            ``Aero(kind="whitney_wood2010")`` gets Ω1..Ω8, :meth:`Planform.quasi_steady_omegas`),
            or None (vacuum).
        air_density_mg_per_mm3:
            Air density of the Ω's (1.2e-3 mg/mm³ = 1.2 kg/m³).
        fields:
            Other :class:`Wing` fields (``shoulder``, ``springs``, ``tunable_hinge``).

        Raises
        ------
        InvalidParameterError
            Naming the argument (``mass_mg``, ``line_masses[i]``, ``point_masses``, ``hinge``,
            ``aero_model``, ``air_density_mg_per_mm3``) and its range.
        """
        from ._errors import invalid, real
        from .aero import MODELS
        from .planform import Planform

        if not isinstance(planform, Planform):
            raise invalid("planform", type(planform).__name__, "a paritysim.Planform")
        for key in ("inertia", "aero"):
            if key in fields:
                raise invalid(f"Wing.from_planform.{key}", "<given>", "left out: it comes from the planform (use .replace afterwards)")
        m = real("mass_mg", mass_mg)
        if not (math.isfinite(m) and m >= 0):
            raise invalid("mass_mg", mass_mg, "finite and >= 0 (mg, the membrane's mass)")
        lines = _line_mass_rows(planform, line_masses)
        try:
            inertia = planform.inertia(m / planform.area, lines, point_masses)
        except _core.InvalidParameterError as exc:
            if getattr(exc, "field", None) == "mass":  # nothing has mass
                raise invalid("mass_mg", mass_mg, "> 0 when line_masses and point_masses add no mass (a wing needs mass)") from exc
            raise
        tensor = _tuples(np.asarray(inertia["tensor"], dtype=float).tolist())

        rho = real("air_density_mg_per_mm3", air_density_mg_per_mm3)
        if not (math.isfinite(rho) and rho > 0):
            raise invalid("air_density_mg_per_mm3", air_density_mg_per_mm3, "finite and > 0 (mg/mm^3; air is 1.2e-3)")
        aero: Aero | None
        if aero_model is None:
            aero = None
        else:
            omegas = planform.omegas(rho)
            if isinstance(aero_model, Aero):
                base = aero_model
            elif isinstance(aero_model, str) and aero_model in MODELS:
                base = Aero(kind="blade_element", model=aero_model)  # type: ignore[call-arg]
            elif aero_model == "stroke_drag":
                base = Aero(kind="stroke_drag")  # type: ignore[call-arg]
            else:
                allowed = ", ".join(repr(n) for n in (*MODELS, "stroke_drag"))
                raise invalid("aero_model", repr(aero_model)[:60], f"one of {allowed}, an Aero or None")
            kind = base.kind  # type: ignore[attr-defined]
            if kind == "whitney_wood2010":
                omegas = {**omegas, **planform.quasi_steady_omegas(rho)}
            names: tuple[str, ...] = ("omega1",)
            if kind in ("blade_element", "whitney_wood2010"):
                names = ("omega1", "omega2", "omega3", "omega4")
            if kind == "whitney_wood2010":
                names += ("omega5", "omega6", "omega7", "omega8")
            exact = {k: omegas[k] for k in names}
            if kind in ("blade_element", "whitney_wood2010"):
                exact["force_parameter"] = omegas["force"]  # ½ρ∬z²dA of this outline, not Ω1 / 12 mm
            aero = base.replace(**exact)

        if hinge is not None:
            if isinstance(hinge, TunableHinge):
                if fields.get("tunable_hinge") is not None:
                    raise invalid("hinge", repr(hinge), "left out when tunable_hinge is given (one hinge)")
                fields["tunable_hinge"] = hinge
            else:
                if isinstance(hinge, Spring):
                    spring = hinge
                elif isinstance(hinge, numbers.Real) and not isinstance(hinge, bool):
                    k = float(hinge)
                    if not (math.isfinite(k) and k >= 0):
                        raise invalid("hinge", hinge, "a stiffness >= 0 (mN·mm/rad), a Spring or a TunableHinge")
                    spring = Spring(stiffness=k)  # type: ignore[call-arg]
                else:
                    raise invalid("hinge", repr(hinge)[:60], "a stiffness >= 0 (mN·mm/rad), a Spring or a TunableHinge")
                springs = fields.get("springs")
                if springs is None:
                    springs = Springs()
                elif isinstance(springs, Mapping):
                    springs = _build_known("Springs", dict(springs))
                elif isinstance(springs, list | tuple):
                    springs = Springs.from_joints(springs)
                if springs.hinge is not None and springs.hinge != Springs().hinge and springs.hinge != spring:
                    # Two hinge springs: the one in springs was dropped without a word.
                    raise invalid("hinge", repr(hinge)[:60], f"left out when springs.hinge is given ({springs.hinge}): one hinge spring")
                fields["springs"] = springs.replace(hinge=spring)
        return cls(inertia=tensor, aero=aero, **fields)  # type: ignore[call-arg]


def _line_mass_rows(planform: Any, line_masses: Any) -> Any:
    """``line_masses`` of :meth:`Wing.from_planform` as rows ``[z0, x0, z1, x1, mg/mm]`` of
    :meth:`Planform.inertia` (each segment's mass spread uniformly along its length)."""
    from ._errors import finite_reals, invalid

    if isinstance(line_masses, Mapping):
        line_masses = list(line_masses.items())
    elif isinstance(line_masses, tuple | list) and len(line_masses) == 2 and isinstance(line_masses[0], str):
        line_masses = [line_masses]  # one ("leading_edge", mass_mg) pair, as the docs write it
    elif isinstance(line_masses, np.ndarray):
        line_masses = list(line_masses.reshape(-1, line_masses.shape[-1]) if line_masses.size else [])
    elif isinstance(line_masses, str) or not isinstance(line_masses, list | tuple):
        raise invalid("line_masses", repr(line_masses)[:60], 'rows [z0_mm, x0_mm, z1_mm, x1_mm, mass_mg] or ("leading_edge", mass_mg) pairs')
    rows: list[list[float]] = []
    for i, item in enumerate(line_masses):
        name = f"line_masses[{i}]"
        if isinstance(item, tuple | list) and len(item) == 2 and isinstance(item[0], str):
            if item[0] != "leading_edge":
                raise invalid(name, repr(item[0]), '"leading_edge" (or a row [z0_mm, x0_mm, z1_mm, x1_mm, mass_mg])')
            segments = planform._leading_edge_segments()
            mass = float(finite_reals(name, item[1]))
        else:
            row = finite_reals(name, item)
            if row.shape != (5,):
                raise invalid(name, repr(item)[:60], 'a row [z0_mm, x0_mm, z1_mm, x1_mm, mass_mg] or ("leading_edge", mass_mg)')
            segments, mass = row[None, :4], float(row[4])
        if mass < 0:
            raise invalid(name, mass, "a mass_mg >= 0")
        lengths = np.hypot(segments[:, 2] - segments[:, 0], segments[:, 3] - segments[:, 1])
        total = float(lengths.sum())
        if mass == 0:
            continue
        if not (math.isfinite(total) and total > 0):
            raise invalid(name, repr(item)[:60], "a segment of nonzero length (a point mass belongs in point_masses)")
        rows.extend([*seg, mass / total] for seg in segments.tolist())
    return np.array(rows, dtype=float).reshape(-1, 5)


@_from_core
class Drivetrain(_Tagged):
    """A planar drivetrain (§2.3-2.4), tagged by ``kind`` (the kinds registered in Rust:
    ``hmf_four_bar``, ``linear_differential``, ``linkage_differential``, ``dual_four_bar``: one
    four-bar and one drive per wing, beyond the thesis; ``single_linear`` and ``dual_linear``: one
    actuator, or one per wing, on a linear or odd-polynomial transmission
    ``φ = τ1 σ + τ2 σ³/3 + ...``, beyond the thesis), with the balance-beam
    spring ``balance_spring`` K2 (mN·mm/rad) and its preload ``balance_preload`` P (mN·mm; the
    whippletree settles at ``q2 = P / K2``) of the two differentials. ``.evaluate`` maps actuator
    coordinates to stroke angles through the Rust kinematics.
    """

    def __post_init__(self) -> None:
        super().__post_init__()
        self.kinematics()  # validates the lengths in Rust

    @classmethod
    def hmf_four_bar(cls, crank_mm: float | None = None, rod_mm: float | None = None) -> Drivetrain:
        """HMF four-bar (§2.3.1): 400 µm of actuator stroke gives 60° with the defaults (the Rust
        core's; ``None`` takes them)."""
        return cls(kind="hmf_four_bar", crank_mm=crank_mm, rod_mm=rod_mm)  # type: ignore[call-arg]

    @classmethod
    def dual_four_bar(cls, crank_mm: float | None = None, rod_mm: float | None = None) -> Drivetrain:
        """One HMF rod-crank and one drive per wing (``q1`` left, ``q2`` right; beyond the
        thesis): use with ``configuration = "drag_parity"``; ``actuator.side_gain`` and
        ``actuator.side_offset_v`` scale each side's drive."""
        return cls(kind="dual_four_bar", crank_mm=crank_mm, rod_mm=rod_mm)  # type: ignore[call-arg]

    @classmethod
    def single_linear(cls, transmission_ratio: float, cubic_ratio: float | None = None, higher_odd_ratios: Sequence[float] | None = None) -> Drivetrain:
        """One actuator, ``φ = τ1 σ + τ2 σ³/3 + a5 σ⁵ + ...`` with ``σ = −q1`` (τ1
        ``transmission_ratio`` in rad/mm, τ2 ``cubic_ratio`` in rad/mm³, ``higher_odd_ratios``
        the coefficients of σ⁵, σ⁷, σ⁹): a one-wing device (``configuration = "single_wing_fixed"``)
        or two tied wings (``hmf``, ``hmf_fixed``)."""
        return cls(kind="single_linear", transmission_ratio=transmission_ratio, cubic_ratio=cubic_ratio, higher_odd_ratios=_odd_ratios(higher_odd_ratios))  # type: ignore[call-arg]

    @classmethod
    def dual_linear(cls, transmission_ratio: float, cubic_ratio: float | None = None, higher_odd_ratios: Sequence[float] | None = None) -> Drivetrain:
        """A linear (or polynomial, as :meth:`single_linear`) drive per wing, ``φL = P(−q1)``,
        ``φR = P(−q2)`` (RoboBee-class): use with ``configuration = "drag_parity_fixed"`` or
        ``"drag_parity"``; ``actuator.side_gain`` and ``actuator.side_offset_v`` scale each side's
        drive."""
        return cls(kind="dual_linear", transmission_ratio=transmission_ratio, cubic_ratio=cubic_ratio, higher_odd_ratios=_odd_ratios(higher_odd_ratios))  # type: ignore[call-arg]

    @classmethod
    def linear_differential(cls, transmission_ratio: float, arm_length_mm: float, arm_ratio: float | None = None, balance_spring: float | None = None, balance_preload: float | None = None, cubic_ratio: float | None = None, higher_odd_ratios: Sequence[float] | None = None, **deprecated: float) -> Drivetrain:
        """Eq. 2.15 with ratio T (rad/mm), mean arm L (mm), arm ratio hL/hR, spring K2 and a
        preload torque P (mN·mm) on the whippletree; ``cubic_ratio`` τ2 (rad/mm³) and
        ``higher_odd_ratios`` make each side's transmission an odd polynomial of its rod-top
        displacement (0 and none: eq. 2.15)."""
        balance_spring = _balance(balance_spring, deprecated)
        return cls(kind="linear_differential", transmission_ratio=transmission_ratio, arm_length_mm=arm_length_mm, arm_ratio=arm_ratio, balance_spring=balance_spring, balance_preload=balance_preload, cubic_ratio=cubic_ratio, higher_odd_ratios=_odd_ratios(higher_odd_ratios))  # type: ignore[call-arg]

    @classmethod
    def linkage_differential(
        cls,
        crank_mm: float | None = None,
        rod_mm: float | None = None,
        whippletree_length_mm: float | None = None,
        arm_ratio: float | None = None,
        balance_spring: float | None = None,
        balance_preload: float | None = None,
        **deprecated: float,
    ) -> Drivetrain:
        """The Drag PARITY linkage (§3.3.2 lengths by default; arm ratio hL/hR of §2.4.2). ``None``
        takes the Rust core's default."""
        balance_spring = _balance(balance_spring, deprecated)
        return cls(kind="linkage_differential", crank_mm=crank_mm, rod_mm=rod_mm, whippletree_length_mm=whippletree_length_mm, arm_ratio=arm_ratio, balance_spring=balance_spring, balance_preload=balance_preload)  # type: ignore[call-arg]

    def kinematics(self) -> _core.Drivetrain:
        """The native kinematic object, built in Rust from this spec (validates the kind and
        the lengths)."""
        return _core.Drivetrain.from_spec(_dumps(self))

    @property
    def dof(self) -> int:
        """Degrees of freedom (1 or 2)."""
        return int(self.kinematics().dof)

    @property
    def name(self) -> str:
        """Kind name."""
        return str(self.kind)  # type: ignore[attr-defined]

    def evaluate(self, q1: Any, q2: Any) -> dict[str, np.ndarray]:
        """Stroke angles, Jacobian and Hessian over paired arrays (see ``paritysim.kinematics``)."""
        return self.kinematics().evaluate(np.ascontiguousarray(q1, dtype=np.float64), np.ascontiguousarray(q2, dtype=np.float64))  # type: ignore[no-any-return]


def _odd_ratios(value: Any) -> list[Any] | None:
    """``higher_odd_ratios`` of the drivetrain constructors as a list (None: none); the values
    themselves are checked with the spec."""
    if value is None:
        return None
    if isinstance(value, str | bytes | Mapping) or not isinstance(value, Sequence | np.ndarray):
        from ._errors import invalid

        raise invalid("drivetrain.higher_odd_ratios", repr(value)[:60], "None or a list of numbers (τ3, τ4, ... in rad/mm^5, rad/mm^7, ...)")
    return list(value)


def _balance(value: float | None, deprecated: dict[str, float]) -> float | None:
    if "balance_stiffness" in deprecated:
        warnings.warn("balance_stiffness= is deprecated: use balance_spring=", DeprecationWarning, stacklevel=3)
        value = deprecated.pop("balance_stiffness")
    if deprecated:  # a misspelt field: named with the nearest, as Drivetrain(kind=..., ...) does
        from ._errors import invalid, suggest

        key = next(iter(deprecated))
        names = [n for n in _field_names(Drivetrain) if n != "kind"]
        raise invalid(f"Drivetrain.{key}", "<unknown field>", suggest(key, names))
    return value


@_from_core
class Waveform(_Tagged):
    """Drive voltage, tagged by ``kind``. ``sine``: ``offset_v + amplitude_v sin(2π frequency_hz t
    + phase)`` (eq. 3.24); ``sampled``: one period of samples (``times_ms``, ``voltages_v``,
    ``period_ms``)."""


@_from_core
class Actuator(_Node):
    """Zeroth-order piezo actuator (§3.2.2): force = force_per_volt (mN/V) × V(t), in parallel
    with ``stiffness`` (mN/mm). ``dc_offset``: ``as_force`` or ``ignore`` (docs/errata.md#14)."""

    @classmethod
    def from_laminate(cls, bimorph: Any, waveform: Waveform | None = None, dc_offset: str | None = None, mass: bool = False, **fields: Any) -> Actuator:
        """An actuator whose constants come from laminate plate theory.

        ``bimorph`` is a :class:`paritysim.laminate.Bimorph` (or anything with ``stiffness`` in
        mN/mm and ``force_per_volt`` in mN/V, e.g. ``ActuatorConstants``). ``mass=True`` also
        sets ``mass_mg`` to the bimorph's ``effective_mass`` (its active mass reflected to the
        output point by Rayleigh's method); other fields (``damping``, ...) pass through.
        """
        from ._errors import invalid, real

        _derived_fields("Actuator.from_laminate", fields)
        if not isinstance(mass, bool):
            raise invalid("mass", repr(mass)[:60], "True (mass_mg from the bimorph's effective_mass) or False")
        stiffness = getattr(bimorph, "stiffness", None)
        force = getattr(bimorph, "force_per_volt", None)
        if stiffness is None or force is None:  # ActuatorConstants
            stiffness, force = getattr(bimorph, "stiffness_mn_per_mm", None), getattr(bimorph, "force_per_volt_mn_per_v", None)
        if stiffness is None or force is None:
            raise invalid("bimorph", repr(bimorph)[:60], "a paritysim.laminate.Bimorph (or an object with stiffness in mN/mm and force_per_volt in mN/V)")
        stiffness, force = real("bimorph.stiffness", stiffness), real("bimorph.force_per_volt", force)
        if mass:
            if "mass_mg" in fields:
                raise invalid("mass_mg", fields["mass_mg"], "left out when mass=True (it is the bimorph's effective_mass)")
            fields = {"mass_mg": real("bimorph.effective_mass", getattr(bimorph, "effective_mass", None)), **fields}
        # The sign of d31 only sets the direction of q1; the engine takes the magnitude.
        return cls(waveform=waveform or Waveform(), force_per_volt=abs(float(force)), stiffness=float(stiffness), **({} if dc_offset is None else {"dc_offset": dc_offset}), **fields)  # type: ignore[arg-type]

    @classmethod
    def from_blocked_force(
        cls,
        blocked_force_mn: float,
        free_deflection_mm: float,
        voltage_v: float,
        waveform: Waveform | None = None,
        **fields: Any,
    ) -> Actuator:
        """An actuator from its datasheet numbers: the blocked force ``F_b`` (mN) and the free
        deflection ``δ`` (mm) at the voltage ``V`` (V). A linear piezo is a force source in
        parallel with a spring, so ``stiffness = F_b / δ`` (mN/mm) and ``force_per_volt = F_b /
        V`` (mN/V); the §3.3.1 actuator is 120 mN blocked and 0.257 mm free at 100 V. Other
        fields (``mass_mg``, ``damping``, ``cubic_stiffness``, ``dc_offset``, ...) pass through.
        """
        from ._errors import invalid

        _derived_fields("Actuator.from_blocked_force", fields)
        for name, value in (("blocked_force_mn", blocked_force_mn), ("free_deflection_mm", free_deflection_mm), ("voltage_v", voltage_v)):
            if not (isinstance(value, numbers.Real) and math.isfinite(value) and value > 0):
                raise invalid(name, repr(value), "a finite number > 0")  # repr: a text "1" shows as '1'
        return cls(waveform=waveform or Waveform(), force_per_volt=float(blocked_force_mn) / float(voltage_v), stiffness=float(blocked_force_mn) / float(free_deflection_mm), **fields)


def _derived_fields(where: str, fields: Mapping[str, Any]) -> None:
    """Refuses, naming it, an Actuator field that ``where`` computes itself."""
    from ._errors import invalid

    for name in ("stiffness", "force_per_volt"):
        if name in fields:
            raise invalid(name, fields[name], f"left out of {where} (it computes {name})")


@_from_core
class Configuration(_Node):
    """Constraints ``C p = c0``: a Table 3.1 ``name`` or explicit ``rows`` / ``c0``; neither:
    unconstrained."""


@_from_core
class Body(_Node):
    """The airframe (issue 17, beyond the thesis): ``mode`` = ``fixed`` (the torque stand,
    unchanged results) | ``clamped`` | ``roll`` | ``yaw`` | ``pitch`` | ``roll_pitch_yaw`` |
    ``free``; mass, inertia, centre of mass, shoulders, gravity, mechanisms, set points and a PD
    controller as plain data (see docs/flight.md)."""

    def __post_init__(self) -> None:
        # The points of the airframe in [-1e3, 1e3] mm, as its centre of mass: a shoulder at
        # 1e308 mm ran and failed with a step-size underflow naming no field (the fuzz, seed 34).
        from ._errors import invalid

        for name in ("shoulders_mm", "wing_center_of_mass_mm"):
            rows = getattr(self, name, None)
            if not isinstance(rows, list | tuple):
                continue
            for i, row in enumerate(rows):
                for j, value in enumerate(row if isinstance(row, list | tuple) else ()):
                    if isinstance(value, numbers.Real) and not isinstance(value, bool) and not (-1e3 <= float(value) <= 1e3):
                        raise invalid(f"body.{name}[{i}][{j}]", value, "in [-1e3, 1e3] mm")


@_from_core
class Options(_Node):
    """Integration and steady-state options (defaults: the Rust engine's)."""


@_from_core
class Simulation(_Node):
    """A complete, runnable spec: device (wings, configuration, drivetrain, actuator) + options."""

    def __post_init__(self) -> None:
        if getattr(self, "actuator", None) is not None and getattr(self, "drivetrain", None) is None:
            from ._errors import invalid

            raise invalid("drivetrain", None, "a drivetrain when an actuator is given (the actuator acts on the wings through it), or no actuator")

    @functools.cached_property
    def _json(self) -> str:
        return _dumps(self)

    def to_json(self) -> str:
        """The spec as JSON text (what the Rust core reads; cached: specs are frozen)."""
        return self._json

    def validate(self) -> Simulation:
        """Validates in Rust; returns self or raises a ``ParitysimError`` naming every bad field."""
        _core.validate_spec(self.to_json())
        return self

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Simulation:
        """Inverse of :meth:`to_dict`, validated in Rust (unknown keys raise
        ``InvalidParameterError`` naming the key and the nearest valid one)."""
        if not isinstance(data, Mapping):
            from ._errors import invalid

            raise invalid("spec", repr(data)[:60], "a spec dict (a table of sections, see Simulation.to_dict())")
        canonical, notes = _core.spec_normalize(_dumps(data))
        return _canonical(canonical, notes)

    @classmethod
    def from_json(cls, text: str) -> Simulation:
        """From JSON text (validated in Rust)."""
        if not isinstance(text, str):
            from ._errors import invalid

            raise invalid("text", type(text).__name__, "JSON text (str)")
        canonical, notes = _core.spec_normalize(text)  # the document itself is `spec` in errors
        return _canonical(canonical, notes)

    def with_paths(self, values: Mapping[str, Any]) -> Simulation:
        """A copy with ``{path: value}`` applied; paths as listed by :func:`spec_paths` (aliases
        such as ``wings.left.omega_ratio`` included)."""
        if not isinstance(values, Mapping):
            from ._errors import invalid

            raise invalid("values", type(values).__name__, "a mapping {path: value}")
        for key in values:
            if not isinstance(key, str) or not key.strip():
                from ._errors import invalid

                raise invalid("values", repr(key)[:60], "parameter paths (non-empty text, see paritysim.spec_paths) as keys")
            if values[key] is None:
                # The core reads a null as "keep the value" (a sweep row that leaves a path out).
                from ._errors import invalid

                raise invalid(f"values[{key!r}]", "None", "a value for the path (to clear an optional field: Simulation.replace)")
        canonical, notes = _core.spec_apply(self.to_json(), _dumps(dict(values)))
        return _canonical(canonical, notes)

    def to_toml(self) -> str:
        """The spec as TOML (written by the Rust core)."""
        return _core.spec_to_toml(self.to_json())

    def save(self, path: str | Path) -> Path:
        """Writes the spec as TOML."""
        from ._errors import invalid

        if isinstance(path, bytes) or not isinstance(path, str | os.PathLike):
            raise invalid("path", repr(path)[:60], "a file path (str or os.PathLike)")
        path = Path(path)
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(self.to_toml(), encoding="utf-8")
        except OSError as exc:
            raise invalid("path", str(path), f"a writable file path ({exc.strerror or exc})") from exc
        return path


def _canonical(text: str, notes: list[str]) -> Simulation:
    for note in notes:
        warnings.warn(note, DeprecationWarning, stacklevel=3)
    return _build_known("Simulation", json.loads(text))  # type: ignore[no-any-return]


def load_spec(path: str | Path) -> Simulation:
    """Loads a :class:`Simulation` from a UTF-8 TOML file (parsed and validated in Rust).

    A file that cannot be read (missing, a directory, not UTF-8) raises
    ``InvalidParameterError`` naming ``path``."""
    return _load_spec(path, "path")


def _load_spec(path: Any, field: str) -> Simulation:
    """:func:`load_spec`, its file errors naming ``field`` (the argument that gave the path)."""
    from ._errors import invalid

    if isinstance(path, bytes) or not isinstance(path, str | os.PathLike):
        raise invalid(field, repr(path)[:60], "a TOML file path (str or os.PathLike)")
    file = Path(path)
    try:
        text = file.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise invalid(field, str(file), f"a UTF-8 text file ({exc.reason} at byte {exc.start})") from exc
    except OSError as exc:
        raise invalid(field, str(file), f"a readable TOML file ({exc.strerror or exc})") from exc
    canonical, notes = _core.spec_from_toml(text)
    return _canonical(canonical, notes)


#: What every ``spec`` argument of the Python API accepts (the one rule, :func:`as_simulation`).
SpecLike = Union["Simulation", Mapping[str, Any], str, "os.PathLike[str]"]
def spec_paths(spec: Simulation) -> Any:
    """Every parameter path of ``spec`` (the names :func:`paritysim.sweep`,
    :func:`paritysim.calibrate` and :meth:`Simulation.with_paths` accept) as a Polars DataFrame:
    ``path``, ``unit``, ``allowed`` (type and range) and ``value`` (JSON text).
    (``paritysim.spec_paths`` also takes a device's name or a file: ``devices.spec_paths``.)"""
    import polars as pl

    rows = _core.spec_paths(spec.to_json())
    return pl.DataFrame(rows, schema=["path", "unit", "allowed", "value"], orient="row")


def _plain(x: Any) -> Any:
    """JSON-ready data: numpy scalars unwrapped, non-finite floats as strings (so Rust names the
    field instead of failing to parse), dataclasses (spec objects) as their fields, ``None``
    values of mappings and dataclasses left out. One pass, no copies: the common leaves first
    (a spec's JSON in a sixth of the time ``dataclasses.asdict`` took)."""
    t = type(x)
    if t is float:
        return x if math.isfinite(x) else repr(x)
    if t is int or t is str or t is bool:
        return x
    if t is tuple or t is list:
        return [_plain(v) for v in x]
    if isinstance(x, _Node) or (dataclasses.is_dataclass(x) and not isinstance(x, type)):
        return {name: _plain(v) for name in _field_names(t) if (v := getattr(x, name)) is not None}
    if isinstance(x, Mapping):
        return {str(k): _plain(v) for k, v in x.items() if v is not None}
    if isinstance(x, list | tuple | np.ndarray):
        return [_plain(v) for v in x]
    if isinstance(x, np.generic):
        return _plain(x.item())
    if x is None:
        return x
    if isinstance(x, numbers.Integral):
        return int(x)
    if isinstance(x, numbers.Real):
        return _plain(float(x))
    # Not plain data (an object, a complex, a set, bytes): its text, so that Rust names the field
    # holding it and what it allows (a TypeError of the JSON encoder named nothing; issue 34).
    shown = repr(x)
    return f"<{type(x).__name__}> " + (shown if len(shown) <= 60 else shown[:57] + "...")


@functools.cache
def _field_names(cls: type) -> tuple[str, ...]:
    return tuple(f.name for f in dataclasses.fields(cls))


def _dumps(data: Any) -> str:
    try:
        return json.dumps(_plain(data), allow_nan=False)
    except RecursionError:
        from ._errors import invalid

        raise invalid("spec", "<data nested too deeply>", "a spec: plain data nested a few levels deep (see paritysim.schema())") from None


def _strip_none(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _strip_none(v) for k, v in x.items() if v is not None}
    if isinstance(x, list | tuple):
        return [_strip_none(v) for v in x]
    return x
