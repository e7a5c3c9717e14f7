"""Device and simulation specs: frozen dataclasses mirroring the Rust types.

A spec is plain data: build it in Python, load it from TOML (:func:`load_spec`), save it
(:meth:`Simulation.save`). Validation happens in Rust when the spec is used
(:meth:`Simulation.validate`, :func:`paritysim.simulate`), with errors naming the dotted field
path (``wings[0].inertia``) and the allowed range.

Units: mg-mm-ms-rad-V; names carry the unit where it could be misread (``frequency_hz``).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from . import _core
from ._errors import invalid

__all__ = [
    "Actuator",
    "Aero",
    "Configuration",
    "Drivetrain",
    "Options",
    "Shoulder",
    "Simulation",
    "Spring",
    "TunableHinge",
    "Waveform",
    "Wing",
    "load_spec",
]


@dataclass(frozen=True)
class Shoulder:
    """Spherical five-bar shoulder (§2.3.3): ``0 <= alpha3 < alpha2 <= pi`` (rad)."""

    alpha2: float = math.pi / 2
    alpha3: float = 0.0


@dataclass(frozen=True)
class Spring:
    """Joint torsion spring ``tau = k (g - g0) + k3 (g - g0)^3`` (mN·mm/rad, mN·mm/rad³, rad)."""

    stiffness: float = 0.0
    cubic: float = 0.0
    rest_angle: float = 0.0


@dataclass(frozen=True)
class Aero:
    """Wing aerodynamics (Ω in mg·mm²).

    ``kind = "stroke_drag"``: ``tau = -omega1 * coefficient * sgn(phi_dot) phi_dot^2`` about the
    stroke axis; ``coefficient = 1`` is eq. 2.16, ``coefficient = C_N(90°)`` is eq. 3.8 for a
    fixed wing (docs/errata.md#12).

    ``kind = "blade_element"``: the quasi-steady model of §3.2.4 (eqs. 3.8-3.11) with
    ``omega1..omega4`` (e.g. from :meth:`paritysim.Planform.omegas` or Table 3.3), coefficient
    ``model`` (``dickinson1999`` or ``whitney_wood2010``), rotational damping coefficient
    ``rotational_damping`` (None: the aero crate's cited default) and ``normal_force_law``
    (``coefficient`` or ``unit``).
    """

    kind: str = "stroke_drag"
    omega1: float = 31.3
    coefficient: float = 1.0
    omega2: float = 0.0
    omega3: float = 0.0
    omega4: float = 0.0
    model: str = "dickinson1999"
    rotational_damping: float | None = None
    normal_force_law: str = "coefficient"


@dataclass(frozen=True)
class TunableHinge:
    """The tunable wing hinge of §2.5.1: ``V = ½ (k0 + k1 θ + k2 θ²) ψ²`` (mN·mm/rad); stiffer
    with deviation. Validated in Rust (``k(θ) > 0`` for every θ)."""

    k0: float
    k1: float = 0.0
    k2: float = 0.0


@dataclass(frozen=True)
class Wing:
    """A wing: inertia tensor about the spherical centre in frame 6 (mg·mm², 3×3), shoulder,
    six joint springs (joints 1..6; None = no springs) and aerodynamics (None = vacuum)."""

    inertia: tuple[tuple[float, float, float], ...]
    shoulder: Shoulder = field(default_factory=Shoulder)
    springs: tuple[Spring, ...] | None = None
    aero: Aero | None = None
    tunable_hinge: TunableHinge | None = None

    @classmethod
    def from_moments(cls, ixx: float, iyy: float, izz: float, ixz: float = 0.0, **kwargs: Any) -> Wing:
        """A wing from the Table 3.3 moments ``Ixx, Iyy, Izz, Ixz`` (mg·mm²)."""
        inertia = ((ixx, 0.0, ixz), (0.0, iyy, 0.0), (ixz, 0.0, izz))
        return cls(inertia=inertia, **kwargs)


@dataclass(frozen=True)
class Drivetrain:
    """A planar drivetrain spec (§2.3-2.4) plus its balance-beam spring K2 (mN·mm/rad).

    ``kind``: ``hmf_four_bar`` (1 DOF), ``linear_differential`` (eq. 2.15) or
    ``linkage_differential`` (the §3.3.2 linkage). Use the constructors; ``.evaluate`` maps
    actuator coordinates to stroke angles through the Rust kinematics.
    """

    kind: str = "linkage_differential"
    crank_mm: float = 0.4
    rod_mm: float = 0.8
    whippletree_length_mm: float = 5.0
    arm_ratio: float = 1.0
    transmission_ratio: float = 2.5
    arm_length_mm: float = 2.5
    balance_stiffness: float = 0.0

    def __post_init__(self) -> None:
        self.kinematics()  # validates kind and lengths in Rust
        if not (math.isfinite(self.balance_stiffness) and self.balance_stiffness >= 0):
            raise invalid("balance_stiffness", self.balance_stiffness, "finite and >= 0 (mN mm/rad)")

    @classmethod
    def hmf_four_bar(cls, crank_mm: float = 0.4, rod_mm: float = 0.8) -> Drivetrain:
        """HMF four-bar (§2.3.1): 400 µm of actuator stroke gives 60° with the defaults."""
        return cls(kind="hmf_four_bar", crank_mm=crank_mm, rod_mm=rod_mm)

    @classmethod
    def linear_differential(cls, transmission_ratio: float, arm_length_mm: float, arm_ratio: float = 1.0, balance_stiffness: float = 0.0) -> Drivetrain:
        """Eq. 2.15 with ratio T (rad/mm), mean arm L (mm), arm ratio hL/hR."""
        return cls(kind="linear_differential", transmission_ratio=transmission_ratio, arm_length_mm=arm_length_mm, arm_ratio=arm_ratio, balance_stiffness=balance_stiffness)

    @classmethod
    def linkage_differential(
        cls, crank_mm: float = 0.4, rod_mm: float = 0.8, whippletree_length_mm: float = 5.0, arm_ratio: float = 1.0, balance_stiffness: float = 0.0
    ) -> Drivetrain:
        """The Drag PARITY linkage (§3.3.2 lengths by default; arm ratio hL/hR of §2.4.2)."""
        return cls(kind="linkage_differential", crank_mm=crank_mm, rod_mm=rod_mm, whippletree_length_mm=whippletree_length_mm, arm_ratio=arm_ratio, balance_stiffness=balance_stiffness)

    def kinematics(self) -> _core.Drivetrain:
        """The native kinematic object (validates the parameters)."""
        if self.kind == "hmf_four_bar":
            return _core.Drivetrain.hmf_four_bar(self.crank_mm, self.rod_mm)
        if self.kind == "linear_differential":
            return _core.Drivetrain.linear_differential(self.transmission_ratio, self.arm_length_mm, self.arm_ratio)
        if self.kind == "linkage_differential":
            return _core.Drivetrain.linkage_differential(self.crank_mm, self.rod_mm, self.whippletree_length_mm, self.arm_ratio)
        raise invalid("drivetrain.kind", repr(self.kind), "one of hmf_four_bar, linear_differential, linkage_differential")

    @property
    def dof(self) -> int:
        """Degrees of freedom (1 or 2)."""
        return self.kinematics().dof

    @property
    def name(self) -> str:
        """Kind name."""
        return self.kind

    def evaluate(self, q1: Any, q2: Any) -> dict[str, np.ndarray]:
        """Stroke angles, Jacobian and Hessian over paired arrays (see ``paritysim.kinematics``)."""
        return self.kinematics().evaluate(np.ascontiguousarray(q1, dtype=np.float64), np.ascontiguousarray(q2, dtype=np.float64))


@dataclass(frozen=True)
class Waveform:
    """Drive voltage. ``sine``: ``offset_v + amplitude_v sin(2π frequency_hz t + phase)`` (eq. 3.24);
    ``sampled``: one period of samples (``times_ms``, ``voltages_v``, ``period_ms``)."""

    kind: str = "sine"
    amplitude_v: float = 100.0
    frequency_hz: float = 110.0
    offset_v: float = 0.0
    phase: float = 0.0
    times_ms: tuple[float, ...] | None = None
    voltages_v: tuple[float, ...] | None = None
    period_ms: float | None = None


@dataclass(frozen=True)
class Actuator:
    """Zeroth-order piezo actuator (§3.2.2): force = force_per_volt (mN/V) × V(t), in parallel
    with ``stiffness`` (mN/mm). ``dc_offset``: ``as_force`` or ``ignore`` (docs/errata.md#14)."""

    waveform: Waveform = field(default_factory=Waveform)
    force_per_volt: float = 1.2
    stiffness: float = 467.0
    dc_offset: str = "as_force"

    @classmethod
    def from_laminate(cls, bimorph: Any, waveform: Waveform | None = None, dc_offset: str = "as_force") -> Actuator:
        """An actuator whose constants come from laminate plate theory.

        ``bimorph`` is a :class:`paritysim.laminate.Bimorph` (or anything with ``stiffness`` in
        mN/mm and ``force_per_volt`` in mN/V, e.g. ``ActuatorConstants``).
        """
        stiffness = getattr(bimorph, "stiffness", None)
        force = getattr(bimorph, "force_per_volt", None)
        if stiffness is None or force is None:  # ActuatorConstants
            stiffness, force = bimorph.stiffness_mn_per_mm, bimorph.force_per_volt_mn_per_v
        # The sign of d31 only sets the direction of q1; the engine takes the magnitude.
        return cls(waveform=waveform or Waveform(), force_per_volt=abs(float(force)), stiffness=float(stiffness), dc_offset=dc_offset)


@dataclass(frozen=True)
class Configuration:
    """Constraints ``C p = c0``: a Table 3.1 ``name`` or explicit ``rows`` / ``c0``."""

    name: str | None = "drag_parity_fixed"
    rows: tuple[tuple[float, ...], ...] | None = None
    c0: tuple[float, ...] | None = None


@dataclass(frozen=True)
class Options:
    """Integration and steady-state options (see the Rust ``SimulationOptions``)."""

    method: str = "dop853"
    rtol: float = 1e-8
    atol: float = 1e-10
    max_steps: int = 1_000_000
    min_cycles: int = 3
    max_cycles: int = 300
    steady_tol: float = 1e-7
    samples_per_cycle: int = 200
    record_cycles: int = 1
    duration_ms: float | None = None
    initial_p: tuple[float, ...] | None = None
    initial_p_dot: tuple[float, ...] | None = None
    perturbation: dict[str, Any] | None = None
    #: "transient" (cycle-to-cycle simulation) or "shooting" (Newton on the stroboscopic map).
    steady_state: str = "transient"


@dataclass(frozen=True)
class Simulation:
    """A complete, runnable spec: device (wings, configuration, drivetrain, actuator) + options."""

    wings: tuple[Wing, ...]
    configuration: Configuration = field(default_factory=Configuration)
    drivetrain: Drivetrain | None = None
    actuator: Actuator | None = None
    formulation: str = "auto"
    options: Options = field(default_factory=Options)
    name: str = ""

    @functools.cached_property
    def _device_dict(self) -> dict[str, Any]:
        return self._build_device_dict()

    @functools.cached_property
    def _options_dict(self) -> dict[str, Any]:
        return _strip_none(dataclasses.asdict(self.options))

    def device_dict(self) -> dict[str, Any]:
        """The device part as the plain dict the Rust core reads (cached: specs are frozen)."""
        return self._device_dict

    def _build_device_dict(self) -> dict[str, Any]:
        d = _strip_none(dataclasses.asdict(self))
        d.pop("options", None)
        d.pop("name", None)
        cfg = d.pop("configuration", {})
        d["configuration"] = cfg["name"] if cfg.get("name") else {"rows": cfg.get("rows", []), "c0": cfg.get("c0")}
        if d["configuration"] == {"rows": [], "c0": None}:
            d.pop("configuration")
        return d

    def options_dict(self) -> dict[str, Any]:
        """The options as a plain dict (cached)."""
        return self._options_dict

    def validate(self) -> Simulation:
        """Validates in Rust; returns self or raises a ``ParitysimError`` naming the field."""
        _core.validate_device(self.device_dict())
        return self

    def replace(self, **changes: Any) -> Simulation:
        """A copy with top-level fields replaced (``dataclasses.replace``)."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Everything, as plain data (what :meth:`save` writes)."""
        return _strip_none(dataclasses.asdict(self))

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Simulation:
        """Inverse of :meth:`to_dict`; unknown keys raise ``InvalidParameterError``."""
        return _build(cls, data, "")

    def save(self, path: str | Path) -> Path:
        """Writes the spec as TOML."""
        import tomli_w

        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(tomli_w.dumps(self.to_dict()))
        return path


def load_spec(path: str | Path) -> Simulation:
    """Loads a :class:`Simulation` from a TOML file."""
    with open(path, "rb") as f:
        data = tomllib.load(f)
    return Simulation.from_dict(data)


def _strip_none(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _strip_none(v) for k, v in x.items() if v is not None}
    if isinstance(x, list | tuple):
        return [_strip_none(v) for v in x]
    return x


_NESTED: dict[tuple[type, str], Any] = {}


def _build(cls: type, data: Any, path: str) -> Any:
    """Recursively builds dataclasses from plain data, naming unknown fields by path."""
    if not isinstance(data, dict):
        raise invalid(path or "spec", repr(data), "a table")
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - set(fields))
    if unknown:
        raise invalid(f"{path + '.' if path else ''}{unknown[0]}", "<unknown field>", f"a known field; valid fields: {', '.join(fields)}")
    kwargs: dict[str, Any] = {}
    for name, value in data.items():
        sub = f"{path}.{name}" if path else name
        kwargs[name] = _convert(cls, name, value, sub)
    return cls(**kwargs)


def _convert(cls: type, name: str, value: Any, path: str) -> Any:
    nested = {
        (Simulation, "configuration"): Configuration,
        (Simulation, "drivetrain"): Drivetrain,
        (Simulation, "actuator"): Actuator,
        (Simulation, "options"): Options,
        (Actuator, "waveform"): Waveform,
        (Wing, "shoulder"): Shoulder,
        (Wing, "aero"): Aero,
        (Wing, "tunable_hinge"): TunableHinge,
    }
    if (cls, name) in nested:
        return _build(nested[(cls, name)], value, path)
    if (cls, name) == (Simulation, "wings"):
        return tuple(_build(Wing, w, f"{path}[{i}]") for i, w in enumerate(value))
    if (cls, name) == (Wing, "springs"):
        return tuple(_build(Spring, s, f"{path}[{i}]") for i, s in enumerate(value))
    if isinstance(value, list):
        return tuple(tuple(v) if isinstance(v, list) else v for v in value)
    return value
