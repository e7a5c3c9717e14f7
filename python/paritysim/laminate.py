"""Laminates: materials, classical laminate plate theory, the piezoelectric bimorph, flexures.

The design layer of thesis §3.2.2 (joint springs), §3.3.1 (actuator constants "from a laminate
plate theory analysis", ref. [42] Wood, Steltz & Fearing 2005) and Chapter 4 (PC-MEMS layups).
All computation runs in Rust (``paritysim-laminate``); this module holds the data classes.

Units (mg-mm-ms-rad-V): lengths mm, force mN, mass mg, **moduli mN/mm² (= kPa; 1 GPa = 1e6)**,
density mg/mm³ (= g/cm³), thermal expansion 1/K, ``d31`` mm/V (1 pm/V = 1e-9 mm/V), field V/mm,
temperature differences K, curvature 1/mm, torsional stiffness mN·mm/rad.

Quick start::

    from paritysim import laminate as lam
    stack = lam.Layup.mobee()                 # the 18-layer stack of Fig. 4.27
    stack.total_thickness_mm, stack.areal_mass
    stack.thermal_curvature(lam.CURE_DELTA_T) # curl after the 200 °C cure
    act = lam.Bimorph.design_for()            # planform giving 467 mN/mm and 1.2 mN/V
    act.constants()                           # ActuatorConstants for the dynamics engine
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from . import _core
from ._errors import finite_reals, invalid, real, whole

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = [
    "CASTELLATED_FLEXURE_LENGTH_MM",
    "CURE_DELTA_T",
    "CURE_TEMPERATURE_C",
    "GPA",
    "KAPTON_YIELD_STRAIN",
    "MATERIAL_NAMES",
    "PM_PER_V",
    "PPM_PER_K",
    "ROOM_TEMPERATURE_C",
    "THESIS_ACTUATOR",
    "ActuatorConstants",
    "Bimorph",
    "Flexure",
    "Layer",
    "Layup",
    "Material",
    "Ply",
    "material",
]

FloatArray = npt.NDArray[np.float64]

GPA = 1.0e6
"""1 GPa in mN/mm²."""
PM_PER_V = 1.0e-9
"""1 pm/V in mm/V."""
PPM_PER_K = 1.0e-6
"""1 ppm/K in 1/K."""

_C = _core.laminate_constants()
CURE_TEMPERATURE_C: float = _C["cure_temperature_c"]
"""Lamination cure temperature, °C (§4.4.2: 200 °C, 340 kPa, 1 h)."""
ROOM_TEMPERATURE_C: float = _C["room_temperature_c"]
"""Room temperature of the cool-down example, °C."""
CURE_DELTA_T: float = _C["cure_delta_t"]
"""Cure to room temperature, K (−180)."""
KAPTON_YIELD_STRAIN: float = _C["kapton_yield_strain"]
"""Yield strain of Kapton HN polyimide (≈3 %, DuPont datasheet)."""
CASTELLATED_FLEXURE_LENGTH_MM: tuple[float, float] = (
    _C["castellated_flexure_length_min"],
    _C["castellated_flexure_length_max"],
)
"""Flexure length of Mobee's castellated joints, mm (§4.4.3: 20–40 µm)."""
MATERIAL_NAMES: tuple[str, ...] = tuple(_core.laminate_material_names())
"""Keys of the material library."""

# Colours of the stack drawing, by material class.
_COLOURS = {
    "composite": "#3a3a3a",
    "polymer": "#e8743b",
    "adhesive": "#9fd0e8",
    "metal": "#b08d57",
    "piezo": "#7f9f5f",
}
_METAL_COLOURS = {"titanium": "#9aa4ad", "brass": "#c9a43a", "steel": "#7d8a96"}


def _vec3(x: Sequence[float] | FloatArray | None, field: str) -> FloatArray:
    """Three resultants ``(x, y, xy)``, or an ``InvalidParameterError`` naming ``field``."""
    if x is None:
        return np.zeros(3)
    try:
        v = np.asarray(x, dtype=np.float64).ravel()
    except (TypeError, ValueError) as exc:
        raise invalid(field, repr(x)[:60], "three numbers (x, y, xy)") from exc
    if v.size != 3 or isinstance(x, str | bytes):
        raise invalid(field, repr(x)[:60], "three numbers (x, y, xy)")
    return np.ascontiguousarray(v)


def _voltages(voltages: Sequence[float] | FloatArray | None) -> FloatArray:
    """One voltage per layer (V), or an ``InvalidParameterError`` naming ``voltages``."""
    if voltages is None:
        return np.zeros(0)
    try:
        return np.asarray(voltages, dtype=np.float64).ravel()
    except (TypeError, ValueError) as exc:
        raise invalid("voltages", repr(voltages)[:60], "one number (V) per layer") from exc


# ------------------------------------------------------------------ materials


def _f(x: Any, field: str) -> float:
    """``float(x)``, or an ``InvalidParameterError`` naming ``field`` (never a bare ValueError)."""
    return real(field, x)


def _finite_result(data: dict[str, Any], inputs: dict[str, Any]) -> None:
    """An overflow (a result that came back NaN/None for finite inputs, issue 34) is an
    ``InvalidParameterError`` naming the input of largest magnitude (relative to 1)."""
    bad = [k for k, v in data.items() if v is None or (np.asarray(v).dtype.kind == "f" and not np.isfinite(np.asarray(v, dtype=float)).all())]
    if bad:
        name = max(inputs, key=lambda k: abs(math.log(abs(float(inputs[k])))) if float(inputs[k]) else 0.0)
        raise invalid(name, inputs[name], f"a value for which {', '.join(bad)} stay finite (they overflow here)")


def _num(x: Any) -> Any:
    """numpy scalars unwrapped; anything else passed on unchanged."""
    return x.item() if isinstance(x, np.generic) else x


def _wire(field: str, x: Any) -> float | None:
    """A number for the JSON read by ``_core``, or an ``InvalidParameterError`` naming
    ``field``. JSON has no NaN: a non-finite value travels as null and Rust's range check
    names it."""
    value = real(field, x)
    return value if math.isfinite(value) else None


def _material_json(m: Any, field: str = "material") -> str:
    if not isinstance(m, Material):
        raise invalid(field, repr(m), "a Material")
    return json.dumps(m._wire_dict())


def _layers_json(layers: Sequence[Layer]) -> str:
    """The layup as the JSON list of layer records read by ``_core``, numbers checked with
    their dotted path (``layers[i].plies[j].thickness``)."""
    out = []
    for i, layer in enumerate(layers):
        plies = []
        for j, p in enumerate(layer.plies):
            at = f"layers[{i}].plies[{j}]"
            m = material(p.material) if isinstance(p.material, str) else p.material
            if not isinstance(m, Material):
                raise invalid(f"{at}.material", repr(m), "a Material or a library key")
            plies.append({
                "material": m._wire_dict(),
                "thickness": _wire(f"{at}.thickness", p.thickness),
                "angle": _wire(f"{at}.angle", p.angle),
            })
        out.append({"name": str(layer.name), "plies": plies})
    return json.dumps(out)


@dataclass(frozen=True)
class Material:
    """A validated orthotropic ply material (axis 1 = fibre / roll direction).

    ``e1``, ``e2``, ``g12`` mN/mm²; ``nu12`` dimensionless; ``density`` mg/mm³; ``alpha1``,
    ``alpha2`` 1/K; ``d31`` mm/V and ``max_field`` V/mm for piezoelectric plies (else None);
    ``category`` one of composite, polymer, adhesive, metal, piezo.

    Raises ``InvalidParameterError`` naming the field for non-physical values (``E <= 0``,
    ``nu12`` outside (-1, 0.5) for isotropic or ``nu12**2 >= e1/e2`` for orthotropic plies).
    """

    name: str
    category: str
    e1: float
    e2: float
    g12: float
    nu12: float
    density: float
    alpha1: float
    alpha2: float
    d31: float | None = None
    max_field: float | None = None

    def __post_init__(self) -> None:
        _core.laminate_check_material(json.dumps(self._wire_dict()))

    def _wire_dict(self) -> dict[str, Any]:
        d = self.to_dict()
        for key, value in d.items():
            if key not in ("name", "class") and value is not None:
                d[key] = _wire(key, value)
        if not isinstance(d["class"], str):
            raise invalid("class", repr(d["class"]), "a material class name")
        d["name"] = str(d["name"])
        return d

    def to_dict(self) -> dict[str, Any]:
        """The dict understood by the ``_core.laminate_*`` functions."""
        return {
            "name": self.name,
            "class": self.category,
            "e1": _num(self.e1),
            "e2": _num(self.e2),
            "g12": _num(self.g12),
            "nu12": _num(self.nu12),
            "density": _num(self.density),
            "alpha1": _num(self.alpha1),
            "alpha2": _num(self.alpha2),
            "d31": None if self.d31 is None else _num(self.d31),
            "max_field": None if self.max_field is None else _num(self.max_field),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Material:
        """Inverse of :meth:`to_dict`."""
        return cls(
            name=d["name"],
            category=d["class"],
            e1=d["e1"],
            e2=d["e2"],
            g12=d["g12"],
            nu12=d["nu12"],
            density=d["density"],
            alpha1=d["alpha1"],
            alpha2=d["alpha2"],
            d31=d.get("d31"),
            max_field=d.get("max_field"),
        )

    @classmethod
    def isotropic(
        cls,
        name: str,
        e: float,
        nu: float,
        density: float,
        alpha: float = 0.0,
        category: str = "metal",
    ) -> Material:
        """Isotropic material: ``e`` mN/mm², ``nu`` in (-1, 0.5), ``density`` mg/mm³, ``alpha`` 1/K."""
        g = e / (2.0 * (1.0 + nu)) if 1.0 + nu != 0.0 else float("inf")  # nu12 is rejected first
        return cls(name, category, e, e, g, nu, density, alpha, alpha)

    @classmethod
    def library(cls, key: str) -> Material:
        """A library material by key (see :data:`MATERIAL_NAMES`); sources in the Rust docs."""
        return cls.from_dict(_core.laminate_material(key))

    @property
    def is_piezo(self) -> bool:
        """True for piezoelectric plies."""
        return self.d31 is not None


def material(key: str) -> Material:
    """Shorthand for :meth:`Material.library`: ``pzt_5h``, ``cf_prepreg_ud``, ``polyimide``,
    ``pyralux_adhesive``, ``brass``, ``titanium``, ``spring_steel``, ``polyester`` (aliases such
    as ``kapton``, ``ti``, ``pet`` are accepted)."""
    return Material.library(key)


# ------------------------------------------------------------------ plies, layers, layups


@dataclass(frozen=True)
class Ply:
    """One ply: a material, a thickness (mm) and an angle (rad) of axis 1 from the laminate x."""

    material: Material
    thickness: float
    angle: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        """Dict form for ``_core``."""
        material = self.material.to_dict() if isinstance(self.material, Material) else self.material
        return {"material": material, "thickness": _num(self.thickness), "angle": _num(self.angle)}


@dataclass(frozen=True)
class Layer:
    """A named material layer: one ply or a pre-cured sub-stack (plies bottom to top)."""

    name: str
    plies: tuple[Ply, ...]

    @classmethod
    def single(cls, name: str, mat: Material | str, thickness: float, angle: float = 0.0) -> Layer:
        """A single-ply layer; ``mat`` may be a library key."""
        m = material(mat) if isinstance(mat, str) else mat
        return cls(name, (Ply(m, thickness, angle),))

    @classmethod
    def cf_0_90_0(cls, name: str = "CF", thickness: float = 0.1, angle: float = 0.0) -> Layer:
        """The cured 0-90-0 carbon-fibre layer of §4.4.2 (three equal UD plies), ``thickness`` mm."""
        return cls.from_dict(_core.laminate_cf_0_90_0(name, thickness, angle))

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Layer:
        """Inverse of :meth:`to_dict`."""
        return cls(
            d["name"],
            tuple(Ply(Material.from_dict(p["material"]), p["thickness"], p["angle"]) for p in d["plies"]),
        )

    def to_dict(self) -> dict[str, Any]:
        """Dict form for ``_core``."""
        return {"name": self.name, "plies": [p.to_dict() for p in self.plies]}

    @property
    def thickness(self) -> float:
        """Total thickness, mm."""
        return float(sum(p.thickness for p in self.plies))

    @property
    def category(self) -> str:
        """Material class of the first ply."""
        return self.plies[0].material.category


class Layup:
    """A stack of named layers, listed **bottom to top**; ``z = 0`` is the geometric mid-plane.

    Raises ``GeometryError`` for an empty stack and ``InvalidParameterError`` (field
    ``layers[i].plies[j].thickness`` etc.) for bad plies.
    """

    def __init__(self, layers: Iterable[Layer]) -> None:
        self._layers: tuple[Layer, ...] = tuple(layers)
        self._json = _layers_json(self._layers)
        self._summary: dict[str, Any] = _core.laminate_summary(self._json)

    # -- constructors
    @classmethod
    def from_plies(cls, plies: Iterable[tuple[str, Material | str, float, float]]) -> Layup:
        """From ``(name, material, thickness mm, angle rad)`` tuples, one single-ply layer each."""
        layers = []
        for i, ply in enumerate(plies):
            if isinstance(ply, str | bytes) or not isinstance(ply, Sequence) or len(ply) != 4:
                raise invalid(f"plies[{i}]", repr(ply)[:60], "a tuple (name, material, thickness mm, angle rad)")
            n, m, t, a = ply
            layers.append(Layer.single(n, m, t, a))
        return cls(layers)

    @classmethod
    def _preset(cls, name: str) -> Layup:
        return cls(Layer.from_dict(d) for d in _core.laminate_preset(name))

    @classmethod
    def mobee(cls) -> Layup:
        """The Mobee 18-layer stack of Fig. 4.27 (§4.2, §4.4.2), layer 1 (brass) at the bottom."""
        return cls._preset("mobee")

    @classmethod
    def mobee_without_titanium(cls) -> Layup:
        """Layers 1–17 of the Mobee stack: symmetric, hence flat after the cure."""
        return cls._preset("mobee_without_titanium")

    @classmethod
    def linkage_sublaminate(cls) -> Layup:
        """The CF–A–PI–A–CF linkage sublaminate (§4.4.1, Fig. 4.25b)."""
        return cls._preset("linkage_sublaminate")

    @classmethod
    def bimorph_mobee(cls) -> Layup:
        """Mobee's actuator (§4.4.2): 127 µm PZT / Pyralux / 100 µm 0-90-0 CF / Pyralux / 127 µm PZT."""
        return cls._preset("bimorph_mobee")

    @classmethod
    def bimorph_wood(cls, t_pzt: float = 0.127, t_cf: float = 0.04) -> Layup:
        """PZT–CF–PZT layup of Wood et al. 2005 (unidirectional CF core at 0°), thicknesses mm."""
        return cls(Layer.from_dict(d) for d in _core.laminate_wood_layup(t_pzt, t_cf))

    # -- geometry
    @property
    def layers(self) -> tuple[Layer, ...]:
        """Layers, bottom to top."""
        return self._layers

    def __len__(self) -> int:
        return len(self._layers)

    def __repr__(self) -> str:
        return f"Layup({len(self)} layers, {1e3 * self.total_thickness_mm:.1f} µm)"

    @property
    def total_thickness_mm(self) -> float:
        """Total thickness, mm."""
        return float(self._summary["total_thickness"])

    @property
    def areal_mass(self) -> float:
        """Areal mass, mg/mm²."""
        return float(self._summary["areal_mass"])

    @property
    def layer_bounds(self) -> FloatArray:
        """``(n, 2)`` array of ``(z_bottom, z_top)`` per layer, mm."""
        return np.asarray(self._summary["layer_bounds"])

    @property
    def is_symmetric(self) -> bool:
        """Mirror-symmetric stacking (then ``B = 0`` and no thermal curvature)."""
        return bool(self._summary["is_symmetric"])

    def summary(self) -> dict[str, Any]:
        """Totals, per-layer data and the cure curvature (see ``_core.laminate_summary``)."""
        return dict(self._summary)

    # -- CLPT
    def abd(self) -> FloatArray:
        """The 6×6 ``[A B; B D]`` matrix (A mN/mm, B mN, D mN·mm)."""
        return _core.laminate_abd(self._json)

    def response(
        self,
        n: Sequence[float] | FloatArray | None = None,
        m: Sequence[float] | FloatArray | None = None,
        delta_t: float = 0.0,
        voltages: Sequence[float] | FloatArray | None = None,
    ) -> dict[str, FloatArray]:
        """Mid-plane ``strain`` and ``curvature`` (1/mm) under resultants ``n`` (mN/mm), ``m``
        (mN), a temperature change ``delta_t`` (K) and one voltage per layer (V, piezo layers only).
        """
        return _core.laminate_response(self._json, _vec3(n, "n"), _vec3(m, "m"), _f(delta_t, "delta_t"), _voltages(voltages))

    def thermal_curvature(self, delta_t: float = CURE_DELTA_T) -> FloatArray:
        """Curvature ``(κx, κy, κxy)`` (1/mm) after a uniform temperature change ``delta_t`` (K)
        from the stress-free state; default: cooling from the 200 °C cure to 20 °C (§4.5.3)."""
        return self.response(delta_t=delta_t)["curvature"]

    def ply_stresses(
        self,
        n: Sequence[float] | FloatArray | None = None,
        m: Sequence[float] | FloatArray | None = None,
        delta_t: float = 0.0,
        voltages: Sequence[float] | FloatArray | None = None,
    ) -> dict[str, np.ndarray]:
        """Stresses (mN/mm², laminate axes) at the bottom and top face of every ply."""
        return _core.laminate_ply_stresses(self._json, _vec3(n, "n"), _vec3(m, "m"), _f(delta_t, "delta_t"), _voltages(voltages))

    # -- drawing
    def plot(self, ax: Axes | None = None, to_scale: bool = True) -> Axes:
        """Draw the stack like Fig. 4.27c: one band per layer, bottom to top, coloured by
        material, labelled with the layer name and thickness in µm, with the total thickness
        dimensioned on the left.

        ``to_scale=True`` (default) draws every layer at its real thickness (µm axis); labels
        sit in evenly spaced slots joined to their layer by leader lines, so thin adhesive and
        film layers stay readable. ``to_scale=False`` gives every layer the same height."""
        import matplotlib.pyplot as plt
        from matplotlib.patches import Patch, Rectangle

        if ax is None:
            _, ax = plt.subplots(figsize=(6.0, 0.35 * len(self) + 1.2))
        total = sum(layer.thickness for layer in self._layers) * 1e3
        heights = [layer.thickness * 1e3 if to_scale else total / len(self) for layer in self._layers]
        slot = total / len(self)
        y = 0.0
        seen: dict[str, str] = {}
        for k, (layer, h) in enumerate(zip(self._layers, heights, strict=True)):
            colour = _COLOURS.get(layer.category, "#cccccc")
            lname = layer.plies[0].material.name.lower()
            for key, c in _METAL_COLOURS.items():
                if layer.category == "metal" and key in lname:
                    colour = c
            ax.add_patch(Rectangle((0.0, y), 1.0, h, facecolor=colour, edgecolor="k", linewidth=0.4))
            label_y = (k + 0.5) * slot
            ax.annotate(
                f"{layer.name}  ({layer.thickness * 1e3:.1f} µm)",
                xy=(1.0, y + h / 2),
                xytext=(1.12, label_y),
                va="center",
                fontsize=7,
                arrowprops={"arrowstyle": "-", "color": "0.5", "lw": 0.5, "shrinkA": 0, "shrinkB": 0},
            )
            seen.setdefault(layer.plies[0].material.name, colour)
            y += h
        # Total thickness, dimensioned beside the stack.
        ax.annotate("", xy=(-0.06, 0.0), xytext=(-0.06, y), arrowprops={"arrowstyle": "<->", "lw": 1.0})
        ax.text(-0.09, y / 2, f"total {total:.1f} µm", rotation=90, ha="right", va="center", fontsize=8)
        ax.set_xlim(-0.3, 1.75)
        ax.set_ylim(0.0, y)
        ax.set_xticks([])
        if to_scale:
            ax.set_ylabel("z from bottom (µm, to scale)")
            ax.yaxis.set_label_position("right")
            ax.yaxis.tick_right()
        else:
            ax.set_yticks([])
        for side in ("top", "bottom", "left"):
            ax.spines[side].set_visible(False)
        ax.set_title(f"{len(self)}-layer stack, {total:.1f} µm, {self.areal_mass:.3f} mg/mm²", fontsize=10)
        ax.legend(
            handles=[Patch(facecolor=c, edgecolor="k", label=n) for n, c in seen.items()],
            loc="upper left",
            bbox_to_anchor=(0.0, -0.01),
            ncol=2,
            fontsize=7,
            frameon=False,
        )
        return ax


# ------------------------------------------------------------------ actuator


@dataclass(frozen=True)
class ActuatorConstants:
    """Zeroth-order actuator of §3.2.2: ``F = force_per_volt · V − stiffness · x``.

    ``stiffness_mn_per_mm`` mN/mm, ``force_per_volt_mn_per_v`` mN/V; what the dynamics engine uses.
    """

    stiffness_mn_per_mm: float
    force_per_volt_mn_per_v: float

    @property
    def free_deflection_per_volt(self) -> float:
        """Unloaded deflection per volt, mm/V."""
        return self.force_per_volt_mn_per_v / self.stiffness_mn_per_mm


THESIS_ACTUATOR = ActuatorConstants(
    _C["thesis_stiffness_mn_per_mm"],
    _C["thesis_force_per_volt_mn_per_v"],
)
"""The thesis' actuator (§3.3.1): 467 mN/mm, 120 mN at 100 V."""


@dataclass(frozen=True)
class Bimorph:
    """Piezoelectric bending actuator after Wood, Steltz & Fearing 2005 (ref. [42]).

    Active length ``length`` (mm), rigid ``extension`` (mm), ``base_width`` (mm) and taper
    ``width_ratio`` (tip / base width). Drive: piezo layers above the mid-plane see ``+V``, those
    below ``−V``. Raises ``GeometryError`` if the layup has no piezo layer.
    """

    layup: Layup
    length: float
    extension: float = 0.0
    base_width: float = 1.0
    width_ratio: float = 1.0
    _data: dict[str, Any] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        d = _core.laminate_bimorph(
            self.layup._json,
            _f(self.length, "length"),
            _f(self.extension, "extension"),
            _f(self.base_width, "base_width"),
            _f(self.width_ratio, "width_ratio"),
            np.zeros(0),
        )
        _finite_result(d, {"length": self.length, "extension": self.extension, "base_width": self.base_width, "width_ratio": self.width_ratio})
        object.__setattr__(self, "_data", d)

    @classmethod
    def design_for(
        cls,
        target: ActuatorConstants = THESIS_ACTUATOR,
        width_ratio: float = 0.5,
        extension_ratio: float = 0.5,
        layup: Layup | None = None,
    ) -> Bimorph:
        """The planform that gives ``target`` with ``layup`` (default: Mobee's actuator layup),
        taper ``width_ratio`` and ``extension_ratio = extension / length``."""
        lay = Layup.bimorph_mobee() if layup is None else layup
        d = _core.laminate_bimorph_design(
            lay._json,
            _f(target.stiffness_mn_per_mm, "stiffness_mn_per_mm"),
            _f(target.force_per_volt_mn_per_v, "force_per_volt_mn_per_v"),
            _f(width_ratio, "width_ratio"),
            _f(extension_ratio, "extension_ratio"),
        )
        return cls(lay, d["length"], d["extension"], d["base_width"], d["width_ratio"])

    @property
    def stiffness(self) -> float:
        """Output stiffness, mN/mm."""
        return float(self._data["stiffness"])

    @property
    def force_per_volt(self) -> float:
        """Blocked force per drive volt, mN/V (signed like the deflection)."""
        return float(self._data["force_per_volt"])

    @property
    def free_deflection_per_volt(self) -> float:
        """Free output deflection per volt, mm/V."""
        return float(self._data["free_deflection_per_volt"])

    @property
    def curvature_per_volt(self) -> float:
        """Free curvature per volt, 1/(mm·V)."""
        return float(self._data["curvature_per_volt"])

    @property
    def max_voltage(self) -> float:
        """Largest drive amplitude allowed by the plies' ``max_field``, V."""
        return float(self._data["max_voltage"])

    @property
    def active_mass(self) -> float:
        """Mass of the active part (areal mass × planform), mg."""
        return float(self._data["active_mass"])

    @property
    def effective_mass(self) -> float:
        """The active part's mass reflected to the output point (mg): Rayleigh's estimate
        ``m_eff = ∫ μ(x) (w(x) / δ)² dx`` with the static deflection shape ``w`` under a force at
        the end of the rigid, massless extension (curvature ``M(x) / (D b(x))``, linear taper
        ``b(x)``, ``μ ∝ b``), ``δ = w(L) + w'(L) L_ext``. A uniform cantilever without extension
        gives the classical ``33/140`` of its mass. What ``actuator.mass_mg`` takes
        (:meth:`paritysim.Actuator.from_laminate` with ``mass=True``)."""
        n = 4001
        x = np.linspace(0.0, self.length, n)
        width = 1.0 + (self.width_ratio - 1.0) * x / self.length  # relative to the base
        curvature = (self.length + self.extension - x) / width  # M / (D b), D and F cancel
        dx = x[1] - x[0]
        slope = np.concatenate(([0.0], np.cumsum(0.5 * (curvature[1:] + curvature[:-1]) * dx)))
        w = np.concatenate(([0.0], np.cumsum(0.5 * (slope[1:] + slope[:-1]) * dx)))
        delta = w[-1] + slope[-1] * self.extension
        shape = width * (w / delta) ** 2
        mean_width = 0.5 * (1.0 + self.width_ratio)
        integral = float(np.sum(0.5 * (shape[1:] + shape[:-1]) * dx))
        return self.active_mass * integral / (mean_width * self.length)

    @property
    def tip_width(self) -> float:
        """Width at the end of the active part, mm."""
        return float(self._data["tip_width"])

    def _at(self, voltage: float | npt.ArrayLike) -> dict[str, Any]:
        v = np.asarray(voltage, dtype=np.float64)
        d = _core.laminate_bimorph(
            self.layup._json,
            _f(self.length, "length"),
            _f(self.extension, "extension"),
            _f(self.base_width, "base_width"),
            _f(self.width_ratio, "width_ratio"),
            np.ascontiguousarray(v.ravel()),
        )
        d["shape"] = v.shape
        return d

    def free_deflection(self, voltage: float | npt.ArrayLike) -> Any:
        """Free deflection (mm) at drive amplitude(s) ``voltage`` (V); ``OutOfDomainError``
        beyond :attr:`max_voltage`."""
        d = self._at(voltage)
        out = d["free_deflection"].reshape(d["shape"])
        return float(out) if out.ndim == 0 else out

    def blocked_force(self, voltage: float | npt.ArrayLike) -> Any:
        """Blocked force (mN) at drive amplitude(s) ``voltage`` (V)."""
        d = self._at(voltage)
        out = d["blocked_force"].reshape(d["shape"])
        return float(out) if out.ndim == 0 else out

    def constants(self) -> ActuatorConstants:
        """Constants for the dynamics engine (force per volt as a magnitude)."""
        return ActuatorConstants(self.stiffness, abs(self.force_per_volt))


# ------------------------------------------------------------------ flexures


@dataclass(frozen=True)
class Flexure:
    """Thin-film flexure hinge: ``width`` (along the axis), free ``length`` and ``thickness`` (mm).

    Stiffness ``E w t³ / (12 L)`` (mN·mm/rad), the Euler-beam linear spring of §3.2.2 — valid
    only while :meth:`max_strain` stays below the film's yield strain (≈3 % for Kapton); large
    folds (e.g. 90° assembly folds) exceed it by far. Default material: 7.5 µm Kapton.
    """

    width: float
    length: float
    thickness: float = 0.0075
    material: Material = field(default_factory=lambda: material("polyimide"))
    _data: dict[str, Any] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        d = _core.laminate_flexure(_material_json(self.material), _f(self.width, "width"), _f(self.thickness, "thickness"), _f(self.length, "length"))
        object.__setattr__(self, "_data", d)

    @classmethod
    def castellated(
        cls,
        joint_width: float,
        n_segments: int,
        flexure_length: float = 0.03,
        flexure_fraction: float = 1.0,
        thickness: float = 0.0075,
        mat: Material | None = None,
    ) -> Flexure:
        """Castellated folding joint (§4.4.3, 20–40 µm flexure length): the equivalent straight
        flexure of width ``joint_width · flexure_fraction``; ``n_segments`` castellations."""
        m = material("polyimide") if mat is None else mat
        d = _core.laminate_castellated_joint(
            _material_json(m), _f(joint_width, "joint_width"), whole("n_segments", n_segments), _f(flexure_fraction, "flexure_fraction"), _f(thickness, "thickness"), _f(flexure_length, "flexure_length")
        )
        return cls(d["flexure_width"], flexure_length, thickness, m)

    @property
    def stiffness(self) -> float:
        """Euler-beam torsional stiffness, mN·mm/rad."""
        return float(self._data["stiffness"])

    @property
    def plate_stiffness(self) -> float:
        """Plane-strain (wide flexure) stiffness, mN·mm/rad."""
        return float(self._data["plate_stiffness"])

    @property
    def within_thesis_range(self) -> bool:
        """Flexure length within the castellated 20–40 µm of §4.4.3."""
        lo, hi = CASTELLATED_FLEXURE_LENGTH_MM
        return lo - 1e-12 <= self.length <= hi + 1e-12

    def max_strain(self, angle: float | npt.ArrayLike) -> Any:
        """Surface strain ``t |θ| / (2 L)`` at joint angle(s) ``angle`` (rad)."""
        out = float(self._data["strain_per_rad"]) * np.abs(np.asarray(angle, dtype=np.float64))
        return float(out) if out.ndim == 0 else out

    def elastic_limit_angle(self, yield_strain: float = KAPTON_YIELD_STRAIN) -> float:
        """Joint angle (rad) at which the surface strain reaches ``yield_strain``."""
        if not (np.isfinite(yield_strain) and yield_strain > 0):
            raise invalid("yield_strain", yield_strain, "finite and > 0")
        return float(yield_strain / self._data["strain_per_rad"])

    def torque(self, angle: float | npt.ArrayLike) -> Any:
        """Linear restoring torque ``−k θ`` (mN·mm) at angle(s) ``angle`` (rad)."""
        theta = finite_reals("angle", angle)  # a NaN or text angle is named, not passed on
        out = -self.stiffness * theta
        return float(out) if out.ndim == 0 else out
