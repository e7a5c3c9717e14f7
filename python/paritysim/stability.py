"""Stability of flapping (thesis §2.6), disturbance rejection (§2.7), and the Floquet analysis
of the full nonlinear model.

Linearised model (§2.6)
    :func:`hill_monodromy`, :func:`hill_floquet`, :func:`region` and :func:`stability_chart`
    analyse ``x'' + β0|cos t| x' + κ x = 0`` (eq. 2.25, period π) and place points in the
    regions of Fig. 2.13 (Region I with the corrected bound of docs/errata.md#9);
    :func:`brockett` and :func:`brockett_hill` are eqs. 2.57-2.58; :func:`hill_parameters`
    maps physical parameters to (β0, κ1, κ2) with the factors of docs/errata.md#7.
Disturbance rejection (§2.7)
    :func:`lti_transfer` is eq. 2.59; :func:`linearise` derives β* and κ0 from a device's
    periodic orbit; :func:`disturbance_response` measures the same transfer on the nonlinear
    model (a sinusoidal roll torque on the wings, body roll torque out).
Full nonlinear model
    :func:`floquet` finds the periodic orbit by shooting and returns its Floquet multipliers;
    :func:`k2_sweep` repeats that over the balance-beam stiffness K2.

Plots: :func:`plot_fig2_13`, :func:`plot_chart_map`, :func:`plot_bode`, :func:`plot_k2_sweep`.
Units: mg-mm-ms-rad; frequencies in Hz, rates in 1/ms.
"""

from __future__ import annotations

import json
import math
import os
import re
from dataclasses import dataclass, field
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import polars as pl
from matplotlib.figure import Figure

from . import _core
from ._errors import chunked, invalid, of_kind, real, reals, sized, whole
from .devices import as_simulation
from .spec import Simulation, SpecLike, schema

__all__ = [
    "FloquetResult",
    "brockett",
    "brockett_hill",
    "disturbance_response",
    "floquet",
    "hill_floquet",
    "hill_monodromy",
    "hill_parameters",
    "hill_solution",
    "k2_sweep",
    "linearise",
    "lti_transfer",
    "plot_bode",
    "plot_chart_map",
    "plot_fig2_13",
    "plot_k2_sweep",
    "region",
    "stability_chart",
]

#: Region names of Fig. 2.13 by index.
REGIONS = {1: "I", 2: "II", 3: "III", 4: "IV"}
#: ``region_name`` of points whose largest multiplier is within its error of the unit circle.
MARGINAL = "marginal"
#: ``region_name`` of a chart point whose analysis failed (see :func:`stability_chart`).
FAILED = "failed"


def _f64(x: Any, name: str) -> np.ndarray:
    a = np.ascontiguousarray(np.atleast_1d(reals(name, x)))
    if a.ndim != 1:
        raise invalid(name, f"array of shape {a.shape}", "a scalar or a 1-D array")
    return a


# ------------------------------------------------------------------ §2.6: eq. 2.25


def hill_monodromy(beta0: float, kappa: float, t0: float = -math.pi / 2) -> np.ndarray:
    """Monodromy matrix ``M(t0) = Π(t0 + π, t0)`` of eq. 2.25 (2×2; eq. 2.30).

    At ``t0 = -π/2`` and ``kappa = 0`` it is eq. 2.50; its determinant is ``e^{-2 beta0}``
    (eq. 2.45) for every ``kappa`` and ``t0``.
    """
    return _core.stability_hill_monodromy(real("beta0", beta0), real("kappa", kappa), real("t0", t0))


#: Wall budget of `hill_solution` by default (ms).
HILL_SOLUTION_MAX_WALL_MS = 60_000.0


def hill_solution(beta0: float, kappa: float, t: Any, t0: float = -math.pi / 2, *, max_wall_ms: float = HILL_SOLUTION_MAX_WALL_MS) -> np.ndarray:
    """Solution matrices ``Π(t_i, t0)`` (eq. 2.33) at each ``t_i >= t0``, shape ``(n, 2, 2)``.

    Each ``t_i`` is integrated from ``t0`` (within 1e4 of it), so many late times take a while:
    Ctrl-C stops the call between two of them and ``max_wall_ms`` (default 60 s) bounds it
    (``IntegrationError`` naming ``max_wall_ms``).
    """
    from ._budget import Deadline, exceeded

    times = _f64(t, "t")
    b, k, start = real("beta0", beta0), real("kappa", kappa), real("t0", t0)
    deadline = Deadline("max_wall_ms", max_wall_ms)
    sized("t", f"{times.size} times", times.size, 32, "the solution matrices")
    # A chunk of times per native call (its nested output holds ~700 bytes per time while it
    # runs: 7 GB for 1e7 times), each within what is left of the one budget.
    try:
        out = chunked(lambda x: {"m": _core.stability_hill_solution(b, k, start, x, deadline.remaining_ms())}, [times], ("t",))
    except _core.IntegrationError as exc:
        if getattr(exc, "field", None) == "max_wall_ms":
            raise exceeded("max_wall_ms", deadline.ms) from exc
        raise
    return np.asarray(out["m"], dtype=np.float64).reshape(times.size, 2, 2)


def hill_floquet(beta0: float, kappa: float) -> dict[str, Any]:
    """Floquet analysis of eq. 2.25 at one point.

    Returns a dict: ``monodromy`` (at t0 = -π/2), ``a`` (half trace), ``b`` (determinant),
    ``multipliers`` (complex, eq. 2.37), ``spectral_radius``, ``region`` (1-4, Fig. 2.13),
    ``multiplier_error`` and ``marginal`` (see :func:`stability_chart`) and ``stable``
    (Region I and not marginal).
    """
    raw: dict[str, Any] = _core.stability_hill_floquet(real("beta0", beta0), real("kappa", kappa))
    raw["multipliers"] = _complex(raw["multipliers"])
    return raw


def region(a: Any, b: Any) -> np.ndarray:
    """Region (1-4) of Fig. 2.13 for half trace ``a`` and determinant ``b`` (arrays).

    Region I is ``b <= 1, |a| <= (1 + b)/2`` (docs/errata.md#9; the printed Region III bound
    ``a > (b - 1)/2`` would mark stable systems unstable).
    """
    half_trace, det = _f64(a, "a"), _f64(b, "b")
    if half_trace.size != det.size:
        err = _core.ShapeError(f"shape mismatch: `a` has {half_trace.size} elements but `b` has {det.size}; they must match")
        err.field = "b"  # type: ignore[attr-defined]
        raise err
    return _core.stability_region(half_trace, det)


def stability_chart(beta0: Any, kappa: Any, *, brockett: bool = True, max_wall_ms: float = 600_000.0) -> pl.DataFrame:
    """Floquet stability over the grid ``beta0 × kappa`` (computed in parallel in Rust).

    Returns one row per point (β0 outer, κ inner): ``beta0, kappa, a, b, spectral_radius,
    region`` (1-4, of the computed ``a``, ``b``), ``stable`` (Region I and not marginal),
    ``multiplier_error`` (error estimate of the multipliers' moduli: round-off of the
    monodromy and its Liouville residual, eq. 2.45), ``marginal`` (``|max|ρ| − 1|`` within
    that error: the undamped line β0 = 0 and the κ = 0 line), ``error`` (null, or the message
    of a point whose analysis failed: its solution overflows, e.g. κ = -1e6; such a point has
    ``region`` 0, ``region_name`` ``failed``, NaN numbers, and the other points are kept),
    ``region_name`` (I-IV, ``marginal`` or ``failed``) and, with ``brockett=True``,
    ``brockett_bounded`` (Brockett's guarantee of eqs. 2.57-2.58; false where it does not
    apply, κ <= 0, or the point failed).

    Up to 4M points; Ctrl-C stops it and ``max_wall_ms`` (default 10 min) bounds it
    (``IntegrationError`` naming ``max_wall_ms``).
    """
    raw = _core.stability_chart(_f64(beta0, "beta0"), _f64(kappa, "kappa"), real("max_wall_ms", max_wall_ms), bool(brockett))
    error_index, messages = raw.pop("error_index"), raw.pop("error")
    bounded = raw.pop("brockett_bounded", None)  # eqs. 2.57-2.58 at every point, in the chart's budget
    errors = pl.Series("error", [], dtype=pl.String).extend_constant(None, raw["beta0"].size)
    if messages:
        errors = errors.scatter(error_index, messages)
    df = pl.DataFrame(raw).with_columns(pl.col("region").cast(pl.Int8), errors)
    df = df.with_columns(
        pl.when(pl.col("region") == 0)
        .then(pl.lit(FAILED))
        .when(pl.col("marginal"))
        .then(pl.lit(MARGINAL))
        .otherwise(pl.col("region").replace_strict(REGIONS, default=None, return_dtype=pl.String))
        .alias("region_name"),
    )
    if bounded is not None:
        df = df.with_columns(pl.Series("brockett_bounded", bounded))
    return df


def brockett(delta: float, period: float, damping_integral: float = 0.0) -> dict[str, Any]:
    """Brockett's criterion (eqs. 2.56-2.58) for ``x'' + g(t) x' + x = 0`` with ``|g| <= 2 delta``
    and period ``period``: ``bounded`` is True when all solutions are guaranteed bounded (a
    False guarantees nothing); ``n`` and ``interval`` are the integer and interval of eq. 2.57."""
    return _core.stability_brockett(real("delta", delta), real("period", period), real("damping_integral", damping_integral))


def brockett_hill(beta0: float, kappa: float) -> dict[str, Any]:
    """Brockett's criterion for eq. 2.25 (κ > 0), after rescaling time by √κ."""
    return _core.stability_brockett_hill(real("beta0", beta0), real("kappa", kappa))


def hill_parameters(
    *,
    inertia: float,
    drag: float,
    transmission_ratio: float,
    arm_length_mm: float,
    k1: float,
    k2: float,
    stroke_amplitude: float,
    frequency_hz: float,
) -> dict[str, float]:
    """(β0, κ1, κ2) of §2.6.1 from physical parameters, with docs/errata.md#7's factors.

    ``β0 = 2 Ω Φ / I`` (Φ = T·A the stroke amplitude in rad; the printed ``2ΩA/I`` lacks T),
    ``κ1 = K1/(2 I T² ω0²)``, ``κ2 = K2/(2 I T² L² ω0²)``. Also returns eq. 2.59's
    ``beta_star = (2/π) β0 ω0`` (1/ms), ``kappa0 = κ2 ω0²`` (1/ms²) and ``omega0`` (rad/ms).
    Units: inertia and drag Ω in mg·mm², T in rad/mm, L in mm, K1 in mN/mm, K2 in mN·mm/rad.
    """
    return _core.stability_hill_parameters(
        real("inertia", inertia), real("drag", drag), real("transmission_ratio", transmission_ratio), real("arm_length_mm", arm_length_mm), real("k1", k1), real("k2", k2), real("stroke_amplitude", stroke_amplitude), real("frequency_hz", frequency_hz)
    )


# ------------------------------------------------------------------ §2.7 and the nonlinear model


def lti_transfer(beta_star: float, kappa0: float, frequency_hz: Any) -> np.ndarray:
    """Eq. 2.59, ``κ0 / (s² + β* s + κ0)`` at ``s = 2πi f`` (s in rad/ms): complex array."""
    return _core.stability_lti_transfer(real("beta_star", beta_star), real("kappa0", kappa0), _f64(frequency_hz, "frequency_hz"))


def _device(spec: SpecLike) -> str:
    """The spec as the JSON text the Rust core reads."""
    return as_simulation(spec).to_json()


@dataclass(frozen=True)
class FloquetResult:
    """Periodic orbit and Floquet multipliers of a device (see :func:`floquet`).

    Attributes
    ----------
    multipliers:
        Complex Floquet multipliers, largest modulus first (finite-difference monodromy:
        moduli below ~1e-6 are at its resolution).
    monodromy:
        Jacobian of the stroboscopic map over ``coordinates`` (the integrated coordinates and
        rates, e.g. ``q1, q2, q1_dot, q2_dot``).
    stability:
        ``asymptotic``, ``marginal`` (largest |ρ| within ``max(1e-5, monodromy_uncertainty)``
        of 1) or ``unstable``.
    monodromy_uncertainty:
        Largest entry of the difference between the monodromy and its check (the variational
        equations' against central differences at ``fd_step``; for switched devices without
        an analytic Jacobian, differences at ``fd_step`` against ``2 fd_step``): an error
        estimate.
    orbit_cycles:
        Drive cycles per orbit (``period_ms`` covers them): 2 for a period-doubled orbit.
    slowest_decay_ms:
        ``T / -ln|ρ|`` of the slowest decaying multiplier (None if none decays).
    growth_time_ms:
        ``T / ln|ρ|max`` of an unstable orbit (None otherwise).
    whippletree_multipliers:
        Multipliers of the (q2, q2_dot) block of ``monodromy`` for a device whose whippletree
        angle ``q2`` is free (the Drag and Dual PARITY; exact for a symmetric orbit, see
        ``whippletree_coupling``), else None (an HMF, or a Lift PARITY whose constraints hold q2).
    coordinates:
        Names of the monodromy's rows, physical: ``q1`` (actuator, mm), ``q2`` (whippletree
        angle, rad), wing angles such as ``left_psi``, and their rates (``q2_dot``). The
        rotating-wing devices (§3.4, §2.5) integrate null-space coordinates (``p = N x``); their
        monodromy is read in these names (linear-map strokes as ``q1, q2``), or kept over
        ``x<i>`` when the names do not determine ``x``. :attr:`frame` names the coordinate that
        carries each mode; :attr:`dominant_mode` and :attr:`neutral_modes` the ones the verdict
        turns on.

    ``repr`` is one line; :attr:`frame` has every multiplier.
    """

    multipliers: np.ndarray
    spectral_radius: float
    stability: str
    slowest_decay_ms: float | None
    growth_time_ms: float | None
    max_exponent_per_ms: float
    period_ms: float
    orbit_cycles: int
    coordinates: list[str]
    orbit_state: np.ndarray
    monodromy: np.ndarray = field(repr=False)
    whippletree_multipliers: np.ndarray | None
    whippletree_coupling: float | None
    monodromy_uncertainty: float
    method: str
    newton_iterations: int
    cycles_simulated: int
    residual: float

    @property
    def asymptotically_stable(self) -> bool:
        """All multipliers strictly inside the unit circle."""
        return self.stability == "asymptotic"

    @property
    def frame(self) -> pl.DataFrame:
        """The multipliers as a DataFrame, largest modulus first: ``re, im, modulus,
        exponent_per_ms`` (Re ln ρ / T), ``kind`` (``neutral`` within the marginal tolerance of
        |ρ| = 1, ``growing`` or ``decaying``) and ``mode``/``mode_share``: the coordinate that
        carries most of the mode's eigenvector of ``monodromy`` and its share of the squared norm
        (coordinates in their own units: mm for ``q1``, rad for angles)."""
        values, vectors = np.linalg.eig(self.monodromy)
        order = np.argsort(-np.abs(values), kind="stable")
        values, vectors = values[order], vectors[:, order]
        modulus = np.abs(values)
        with np.errstate(divide="ignore"):
            exponent = np.where(modulus > 0, np.log(np.where(modulus > 0, modulus, 1.0)) / self.period_ms, -np.inf)
        tol = self._neutral_tolerance
        kind = np.where(np.abs(modulus - 1.0) <= tol, "neutral", np.where(modulus > 1.0, "growing", "decaying"))
        weights = np.abs(vectors) ** 2
        weights /= np.maximum(weights.sum(axis=0), 1e-300)
        dominant = np.argmax(weights, axis=0)
        return pl.DataFrame(
            {
                "re": values.real,
                "im": values.imag,
                "modulus": modulus,
                "exponent_per_ms": exponent,
                "kind": kind.tolist(),
                "mode": [self.coordinates[i] for i in dominant],
                "mode_share": weights[dominant, np.arange(len(dominant))],
            }
        )

    @property
    def _neutral_tolerance(self) -> float:
        # The `stability` verdict's marginal band (see the class docstring).
        return max(1e-5, self.monodromy_uncertainty)

    @property
    def dominant_mode(self) -> str:
        """The coordinate carrying the largest multiplier's mode (e.g. ``q2``: the whippletree)."""
        return str(self.frame["mode"][0])

    @property
    def neutral_modes(self) -> list[str]:
        """The coordinates carrying the neutral multipliers (|ρ| = 1 within the tolerance): a
        free direction of the orbit, such as the whippletree angle ``q2`` without a balance spring."""
        frame = self.frame
        return frame.filter(pl.col("kind") == "neutral")["mode"].to_list()

    def __repr__(self) -> str:
        radius = f"|ρ|max = {self.spectral_radius:.6g} ({self.dominant_mode})"
        neutral = self.neutral_modes
        extra = f", neutral: {', '.join(neutral)}" if neutral else ""
        whippletree = ""
        if self.whippletree_multipliers is not None:
            whippletree = ", whippletree |ρ| = " + ", ".join(f"{abs(m):.4g}" for m in self.whippletree_multipliers)
        doubled = f" ({self.orbit_cycles} drive cycles)" if self.orbit_cycles > 1 else ""
        return (
            f"FloquetResult({self.stability}: {radius}{extra}{whippletree}; period {self.period_ms:.4g} ms{doubled}, "
            f"{len(self.multipliers)} multipliers over {', '.join(self.coordinates)}; .frame for every mode)"
        )


#: The shooting options of :func:`floquet` (``ShootingOptions`` of the Rust core) and the kind
#: of value each takes: `_shooting` checks the kind by name before serialising (JSON has no NaN,
#: and serde's type errors named only ``options``); the core checks the ranges and names the
#: option.
SHOOTING_OPTIONS: dict[str, str] = {
    "method": "name",
    "rtol": "number",
    "atol": "number",
    "max_steps": "count",
    "t0": "number",
    "warmup_cycles": "count",
    "warmup_tol": "number",
    "max_newton": "count",
    "tol": "number",
    "fd_step": "number",
    "fallback_cycles": "count",
    "orbit_cycles": "count",
}


def _shooting(options: dict[str, Any]) -> str | None:
    """Options as the JSON record read by ``_core``, each of `SHOOTING_OPTIONS` checked for its
    kind by name (an ``InvalidParameterError`` naming it). None values are dropped (the Rust
    defaults apply); other names travel as given for Rust to reject with the key."""
    given: dict[str, Any] = {}
    for name, value in options.items():
        kind = SHOOTING_OPTIONS.get(name)
        if value is None:
            continue
        if kind in ("number", "count"):
            value = of_kind(name, value, kind)
        elif name == "method":
            methods = [m["const"] for m in schema()["$defs"]["Method"]["oneOf"]]  # the spec's own list
            if value not in methods:
                raise invalid(name, repr(value), " or ".join(f'"{m}"' for m in methods))
        given[name] = value
    return json.dumps(given, default=lambda o: o.item() if isinstance(o, np.generic) else repr(o)) if given else None


def _strings(name: str, values: Any) -> pl.Series:
    """A text column from ``_core``, whose converter hands an all-None column over as NaN."""
    return pl.Series(name, [v if isinstance(v, str) else None for v in values], dtype=pl.String)


def _complex(pairs: Any) -> np.ndarray:
    """``[re, im]`` pairs (last axis) from ``_core`` as a complex array."""
    a = np.asarray(pairs, dtype=float)
    if a.ndim == 0 or a.shape[-1] != 2:
        return a.astype(complex)
    return a[..., 0] + 1j * a[..., 1]


def _attributed(call: Any, options: dict[str, Any]) -> Any:
    """``call()``; a failure naming no field (no periodic orbit, a spent budget) is attributed to
    the option it names (``options.tol``, ``options.max_steps``, ...) or else to ``spec``: the
    device has no orbit these options find (issue 34: such errors named nothing)."""
    try:
        return call()
    except _core.ParitysimError as exc:
        if not getattr(exc, "field", None):
            text = str(exc)
            named = re.search(r"`options\.([a-z_]+)`", text)
            given = [k for k in options if options[k] is not None and re.search(rf"\b{k}\b", text)]
            exc.field = f"options.{named.group(1)}" if named else f"options.{given[0]}" if given else "spec"  # type: ignore[attr-defined]
        raise


def _finite_floquet(raw: dict[str, Any], options: dict[str, Any]) -> None:
    """A Floquet result with non-finite numbers (a finite-difference step below round-off)
    is an error naming the option responsible (``fd_step``) or the spec."""
    numbers = [raw[k] for k in ("spectral_radius", "max_exponent_per_ms", "period_ms", "monodromy_uncertainty", "residual")]
    if any(v is None or not math.isfinite(float(v)) for v in numbers) or not np.isfinite(np.asarray(raw["monodromy"], dtype=float)).all():
        field = "options.fd_step" if options.get("fd_step") is not None else "spec"
        raise invalid(field, options.get("fd_step", "<spec>"), "a finite-difference step giving a finite monodromy (the result overflowed or was undefined)")


def floquet(spec: SpecLike, **options: Any) -> FloquetResult:
    """Periodic orbit of a driven device by shooting, and its Floquet multipliers.

    Newton on the stroboscopic map over one drive period (cycle-to-cycle simulation as the
    fallback, which finds stable orbits only), then the monodromy over the integrated
    coordinates and rates (work integrals excluded): the variational equations', checked by
    central differences of the map; for a device with blade-element switches and no analytic
    Jacobian (the §2.5 Lift and Dual PARITY), the central differences, checked at twice the
    step (the variational equations miss the jumps at the switches: docs/findings.md §30).
    When the one-cycle orbit is flip-unstable (a multiplier below −1), the orbit of two drive
    cycles is analysed instead if it is not unstable (``orbit_cycles`` says which; the Lift
    PARITY settles on such a period-doubled orbit). ``options``: ``rtol`` (1e-12),
    ``atol`` (1e-14), ``method``, ``max_steps``, ``t0`` (section time, ms), ``warmup_cycles``
    (20), ``warmup_tol``, ``max_newton`` (20), ``tol`` (1e-10), ``fd_step`` (1e-5),
    ``fallback_cycles`` (2000), ``orbit_cycles`` (drive cycles per orbit, 1-8; default: 1, or
    2 as above).

    Raises
    ------
    ConstraintError
        Without an actuator (no period).
    IntegrationError
        When no orbit is found (``.state`` holds the best state).
    """
    device = _device(spec)
    raw = _attributed(lambda: _core.stability_floquet(device, _shooting(options)), options)
    _finite_floquet(raw, options)
    coordinates, monodromy = list(raw["coordinates"]), raw["monodromy"]
    whippletree = None if raw["whippletree_multipliers"] is None else _complex(raw["whippletree_multipliers"])
    coupling = raw["whippletree_coupling"]
    basis = _core.stability_coordinate_basis(device)
    if basis is not None:  # null-space coordinates x: named, and the monodromy read, physically
        coordinates, monodromy = _physical(json.loads(device), np.asarray(basis, dtype=float).T, monodromy)
        if whippletree is None and "q2" in coordinates:
            whippletree, coupling = _whippletree_block(monodromy, coordinates)
    return FloquetResult(
        multipliers=_complex(raw["multipliers"]),
        spectral_radius=float(raw["spectral_radius"]),
        stability=str(raw["stability"]),
        slowest_decay_ms=raw["slowest_decay_ms"],
        growth_time_ms=raw["growth_time_ms"],
        max_exponent_per_ms=float(raw["max_exponent_per_ms"]),
        period_ms=float(raw["period_ms"]),
        orbit_cycles=int(raw["orbit_cycles"]),
        coordinates=coordinates,
        orbit_state=raw["orbit_state"],
        monodromy=monodromy,
        whippletree_multipliers=whippletree,
        whippletree_coupling=coupling,
        monodromy_uncertainty=float(raw["monodromy_uncertainty"]),
        method=str(raw["method"]),
        newton_iterations=int(raw["newton_iterations"]),
        cycles_simulated=int(raw["cycles_simulated"]),
        residual=float(raw["residual"]),
    )


def _physical(spec: dict[str, Any], basis: np.ndarray, monodromy: np.ndarray) -> tuple[list[str], np.ndarray]:
    """Names for null-space coordinates ``x`` (``p = p_part + N x``, ``basis`` = N, 6 × n) and
    the monodromy over them: the wing angles ``left_psi, ...`` that the basis moves, with the
    strokes of a linear-map drivetrain (eq. 2.15) as its coordinates ``q1, q2`` (``q = J⁻¹ φ``).
    Coordinates the constraints tie together (``left_theta = right_theta``) count once. When the
    named coordinates do not determine ``x`` one to one, ``x<i>`` is kept."""
    n = basis.shape[1]
    sides = ("left", "right") if len(spec.get("wings", [])) == 2 else ("wing", "unused")
    names = [f"{side}_{angle}" for side in sides for angle in ("phi", "theta", "psi")]
    rows, labels = list(basis), list(names)
    drivetrain = spec.get("drivetrain") or {}
    if drivetrain.get("kind") == "linear_differential" and sides[0] == "left":
        from . import kinematics

        drive = Simulation.from_dict(spec).drivetrain
        jacobian = kinematics.drivetrain_map(drive, q1=[0.0], q2=[0.0])["jacobian"][0]
        q = np.linalg.solve(jacobian, np.vstack([basis[0], basis[3]]))
        rows = [q[0], q[1], *(basis[i] for i in (1, 2, 4, 5))]
        labels = ["q1", "q2", *(names[i] for i in (1, 2, 4, 5))]
    kept: list[np.ndarray] = []
    kept_names: list[str] = []
    for row, label in zip(rows, labels, strict=True):
        norm = float(np.linalg.norm(row))
        if norm < 1e-9:
            continue  # a coordinate the constraints hold fixed
        if any(abs(abs(float(row @ k)) - norm * float(np.linalg.norm(k))) < 1e-9 * norm for k in kept):
            continue  # tied to one already named
        kept.append(row)
        kept_names.append(label)
    transform = np.array(kept)
    if transform.shape != (n, n) or abs(np.linalg.det(transform)) < 1e-9:
        return [f"x{i}" for i in range(n)] + [f"x{i}_dot" for i in range(n)], monodromy
    both = np.kron(np.eye(2), transform)  # positions and rates alike
    physical = both @ monodromy @ np.linalg.inv(both)
    return kept_names + [f"{c}_dot" for c in kept_names], physical


def _whippletree_block(monodromy: np.ndarray, coordinates: list[str]) -> tuple[np.ndarray, float]:
    """Multipliers of the (q2, q2_dot) block and its largest coupling to the other coordinates,
    as the core computes them in drivetrain coordinates (exact for a symmetric orbit)."""
    i, j = coordinates.index("q2"), coordinates.index("q2_dot")
    block = monodromy[np.ix_([i, j], [i, j])]
    others = [k for k in range(len(coordinates)) if k not in (i, j)]
    coupling = max(float(np.abs(monodromy[np.ix_([i, j], others)]).max()), float(np.abs(monodromy[np.ix_(others, [i, j])]).max()))
    values = np.linalg.eigvals(block)
    return values[np.argsort(-np.abs(values), kind="stable")].astype(complex), coupling


def k2_sweep(spec: SpecLike, k2: Any, **options: Any) -> pl.DataFrame:
    """:func:`floquet` over balance-beam stiffnesses ``k2`` (mN·mm/rad), in parallel in Rust.

    Columns: ``k2, spectral_radius, whippletree_radius`` (null without a whippletree block),
    ``max_exponent_per_ms, slowest_decay_ms`` (null when nothing decays), ``stability``,
    ``moduli`` (list column: |ρ| of every multiplier, largest first) and ``error``: a K2 that
    fails (invalid, no orbit) is a row with its error message there and nulls elsewhere, as
    in :func:`paritysim.sweep`; the others are kept. The points run on the sweep engine's own
    thread pool (``PARITYSIM_THREADS``).
    """
    raw = _attributed(lambda: _core.stability_k2_sweep(_device(spec), _f64(k2, "k2"), _shooting(options)), options)
    numeric = ["spectral_radius", "whippletree_radius", "max_exponent_per_ms", "slowest_decay_ms"]
    return pl.DataFrame(
        {
            "k2": raw["k2"],
            **{name: pl.Series(name, raw[name], dtype=pl.Float64) for name in numeric},
            "stability": _strings("stability", raw["stability"]),
            "moduli": pl.Series("moduli", [list(np.abs(_complex(row))) for row in raw["multipliers"]], dtype=pl.List(pl.Float64)),
            "error": _strings("error", raw["error"]),
        }
    ).with_columns(pl.col(numeric).fill_nan(None))


#: Orbit samples of `linearise` (its cycle averages), also used by `disturbance_response`.
_LINEARISE_SAMPLES = 2000
#: Bytes `linearise` holds per orbit sample (a state, its time and the averaged terms; the
#: issue 34 reproducer allocated 112 GB for 1e9 samples), with a margin.
_BYTES_PER_ORBIT_SAMPLE = 256
#: Bytes `disturbance_response` holds per sample of a measurement window (two windows, two
#: signs of the disturbance, a state and its time each), with a margin.
_BYTES_PER_WINDOW_SAMPLE = 512
#: Peak bytes per frequency of `disturbance_response` (10^6 failing frequencies: 1.15 GB).
_BYTES_PER_RESPONSE_ROW = 1200


def linearise(spec: SpecLike, samples: int = _LINEARISE_SAMPLES, **options: Any) -> dict[str, Any]:
    """Places a fixed-wing Drag PARITY device on the charts of §2.6-2.7 from its periodic orbit.

    Returns ``physical`` (inertia, drag Ω·C, T, L, K1, K2, stroke amplitude Φ, frequency),
    ``hill`` (β0, κ1, κ2; docs/errata.md#7), and three eq. 2.59 models (``beta_star`` in 1/ms,
    ``kappa0`` in 1/ms²): ``lti`` (cycle-averaged aerodynamic damping and K2 of the
    whippletree mode, as §2.7 builds it), ``lti_sinusoidal`` (the same for sinusoidal
    flapping) and ``lti_averaged`` (cycle average of the full model's variational equation,
    which adds the linkage's ``geometric_stiffness`` in mN·mm/rad).
    """
    n = whole("samples", samples, 8, 10**9)
    sized("samples", n, n, _BYTES_PER_ORBIT_SAMPLE, "the orbit samples")
    return _attributed(lambda: _core.stability_linearise(_device(spec), _shooting(options), n), options)  # type: ignore[no-any-return]


def disturbance_response(
    spec: SpecLike,
    frequency_hz: Any,
    amplitude: float = 0.1,
    *,
    settle_cycles: int | None = None,
    max_window_cycles: int | None = None,
    samples_per_cycle: int | None = None,
    **options: Any,
) -> pl.DataFrame:
    """Body roll response of the nonlinear model to a wing roll disturbance torque, with eq. 2.59.

    A torque ``amplitude · sin(2π f t)`` (mN·mm) is applied as stroke torques ``(-d/2, +d/2)``
    on the two wings, starting on the periodic orbit; after ``settle_cycles`` the complex
    amplitude of the body roll torque (wing momentum balance) at ``f`` is divided by that of
    the disturbance (± runs differenced). Fixed-wing devices only.

    Columns: ``frequency_hz, gain, phase_rad`` (nonlinear), ``lti_gain, lti_phase_rad``
    (eq. 2.59 from :func:`linearise`'s ``lti``; null for a 1-DOF drivetrain, which has no
    whippletree mode), ``lti_averaged_gain``, ``drift`` (change
    between two consecutive windows: a settled, stable response has drift << 1) and
    ``window_ms`` and ``error`` (a frequency that fails is a row with its error message and
    nulls elsewhere; the others are kept).
    """
    freqs = _f64(frequency_hz, "frequency_hz")
    amplitude = real("amplitude", amplitude)
    if not (math.isfinite(amplitude) and amplitude > 0):  # before the runs, which would blame each frequency
        raise invalid("amplitude", amplitude, "finite and > 0 (mN·mm)")
    # One row per frequency (its result or error text): measured 1.15 kB each at peak.
    sized("frequency_hz", f"<{freqs.size} frequencies>", freqs.size, _BYTES_PER_RESPONSE_ROW, "the response rows")
    if settle_cycles is not None:
        settle_cycles = whole("settle_cycles", settle_cycles, 0, 100_000)
    if max_window_cycles is not None:
        max_window_cycles = whole("max_window_cycles", max_window_cycles, 1, 10_000)
    if samples_per_cycle is not None:
        samples_per_cycle = whole("samples_per_cycle", samples_per_cycle, 16, 10**9)
    per_window = (samples_per_cycle or 400) * (max_window_cycles or 12)
    parallel = max(1, min(freqs.size, os.cpu_count() or 1))
    sized("samples_per_cycle" if samples_per_cycle is not None else "max_window_cycles", samples_per_cycle or max_window_cycles, per_window * parallel, _BYTES_PER_WINDOW_SAMPLE, "the measurement windows")
    dist = {"settle_cycles": settle_cycles, "max_window_cycles": max_window_cycles, "samples_per_cycle": samples_per_cycle}
    device = _device(spec)
    shooting = _shooting(options)
    raw = _attributed(lambda: _core.stability_disturbance_response(device, freqs, amplitude, shooting, _shooting(dist)), {**options, **dist})
    h = _complex(raw["transfer"])
    lti = avg = np.full(freqs.size, np.nan + 0j)
    _, n_dof = _core.validate_spec(device)
    if n_dof == 2:  # eq. 2.59 models the whippletree mode of a 2-DOF (Drag PARITY) drivetrain
        lin = _attributed(lambda: _core.stability_linearise(device, shooting, _LINEARISE_SAMPLES), options)
        lti = lti_transfer(lin["lti"]["beta_star"], lin["lti"]["kappa0"], freqs)
        avg = lti_transfer(lin["lti_averaged"]["beta_star"], lin["lti_averaged"]["kappa0"], freqs)
    return pl.DataFrame(
        {
            "frequency_hz": freqs,
            "gain": np.abs(h),
            "phase_rad": np.angle(h),
            "lti_gain": np.abs(lti),
            "lti_phase_rad": np.angle(lti),
            "lti_averaged_gain": np.abs(avg),
            "drift": raw["drift"],
            "window_ms": raw["window_ms"],
            "error": _strings("error", raw["error"]),
        }
    ).with_columns(pl.col("gain", "phase_rad", "lti_gain", "lti_phase_rad", "lti_averaged_gain", "drift", "window_ms").fill_nan(None))


# ------------------------------------------------------------------ plots


_REGION_COLOURS = {1: "#4daf4a", 2: "#e41a1c", 3: "#377eb8", 4: "#984ea3"}


def _chart(chart: Any, columns: tuple[str, ...]) -> pl.DataFrame:
    """``chart`` when it is a frame with ``columns`` (as :func:`stability_chart` returns it),
    else an ``InvalidParameterError`` naming ``chart`` and the columns a plot needs."""
    needed = "a frame from stability_chart, with the columns " + ", ".join(columns)
    if not isinstance(chart, pl.DataFrame):
        raise invalid("chart", type(chart).__name__, needed)
    missing = [c for c in columns if c not in chart.columns]
    if missing:
        raise invalid("chart", f"<a frame without {', '.join(missing)}>", needed)
    return chart


def plot_fig2_13(chart: pl.DataFrame | None = None, points: dict[str, tuple[float, float]] | None = None) -> Figure:
    """Fig. 2.13: the (a, b) plane of the monodromy matrix with Regions I-IV.

    Boundaries: ``b = 1``, ``a = ±(1 + b)/2`` (docs/errata.md#9; the printed ``(b - 1)/2`` dashed
    for comparison) and the double-root parabola ``b = a²``. ``chart`` (from
    :func:`stability_chart`) is scattered coloured by region; ``points`` maps labels to (a, b).
    """
    if chart is not None:
        chart = _chart(chart, ("a", "b", "region"))
    fig, ax = plt.subplots(figsize=(7.5, 6), constrained_layout=True)
    a = np.linspace(-2.5, 2.5, 801)
    b_grid = np.linspace(-0.5, 2.5, 601)
    aa, bb = np.meshgrid(a, b_grid)
    reg = region(aa.ravel(), bb.ravel()).reshape(aa.shape)
    from matplotlib.colors import ListedColormap

    cmap = ListedColormap([_REGION_COLOURS[i] for i in (1, 2, 3, 4)])
    ax.pcolormesh(a, b_grid, reg, cmap=cmap, vmin=0.5, vmax=4.5, alpha=0.18, shading="auto")
    ax.axhline(1.0, color="k", lw=1.0)
    ax.plot((1 + b_grid) / 2, b_grid, "k", lw=1.0, label="$a = \\pm(1+b)/2$ (docs/errata.md#9)")
    ax.plot(-(1 + b_grid) / 2, b_grid, "k", lw=1.0)
    ax.plot((b_grid - 1) / 2, b_grid, "k--", lw=0.8, label="printed $a = (b-1)/2$")
    ax.plot(a, a**2, "k:", lw=1.0, label="double root $b = a^2$")
    for idx, (x, y) in {1: (0.0, 0.35), 2: (0.0, 1.8), 3: (1.8, 0.8), 4: (-1.8, 0.8)}.items():
        ax.text(x, y, REGIONS[idx], fontsize=16, ha="center", va="center", weight="bold")
    if chart is not None and chart.height:
        for idx in (1, 2, 3, 4):
            sub = chart.filter(pl.col("region") == idx)
            if sub.height:
                ax.scatter(sub["a"], sub["b"], s=2, color=_REGION_COLOURS[idx], label=f"chart points, Region {REGIONS[idx]}")
    for i, (label, (x, y)) in enumerate((points or {}).items()):
        ax.plot([x], [y], "k*", ms=12)
        ax.annotate(label, (x, y), textcoords="offset points", xytext=(8, 10 + 16 * i), arrowprops={"arrowstyle": "-", "lw": 0.5})
    ax.set_xlim(-2.5, 2.5)
    ax.set_ylim(-0.5, 2.5)
    ax.set_xlabel("half trace $a = \\mathrm{tr}\\,M/2$ (-)")
    ax.set_ylabel("determinant $b = \\det M$ (-)")
    ax.legend(loc="upper left", fontsize=8, markerscale=4)
    ax.set_title("Fig. 2.13: stability in the trace-determinant plane (Region I stable)")
    return fig


def plot_chart_map(chart: pl.DataFrame, points: dict[str, tuple[float, float]] | None = None) -> Figure:
    """The stability chart as a map over (β0, κ): log10 of the spectral radius (per period π),
    the Region I boundary, Brockett's guaranteed region, and optional labelled (β0, κ) points.
    A chart with one value on an axis (a line or a point of the plane) has no cells or
    boundaries to draw: its points are drawn in the same colours, the stable and guaranteed
    ones marked."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    chart = _chart(chart, ("beta0", "kappa", "spectral_radius", "stable"))
    grid = chart.unique(["beta0", "kappa"], keep="first", maintain_order=True).sort("beta0", "kappa")
    beta = np.unique(grid["beta0"].to_numpy())
    kap = np.unique(grid["kappa"].to_numpy())
    shape = (beta.size, kap.size)
    if grid.height == 0 or grid.height != beta.size * kap.size:
        raise invalid("chart", f"<{chart.height} points over {beta.size} beta0 x {kap.size} kappa>", "a whole beta0 x kappa grid as stability_chart returns it (at least one point)")
    fig, ax = plt.subplots(figsize=(8, 6), constrained_layout=True)
    log_rho = np.log10(grid["spectral_radius"].to_numpy())
    flat = min(shape) < 2  # an axis with one value: cells of no width and no contours, so the points are drawn
    if flat:
        mesh: Any = ax.scatter(grid["beta0"], grid["kappa"], c=log_rho, marker="s", s=60, cmap="RdBu_r", vmin=-2, vmax=2)
        kept = grid.filter(pl.col("stable"))
        ax.scatter(kept["beta0"], kept["kappa"], marker="o", s=150, facecolors="none", edgecolors="k")
        if "brockett_bounded" in grid.columns:
            kept = grid.filter(pl.col("brockett_bounded"))
            ax.scatter(kept["beta0"], kept["kappa"], marker="+", s=60, color="0.3")
        handles: list[Any] = [
            Line2D([], [], color="k", marker="o", markerfacecolor="none", lw=0, label="Region I (stable)"),
            Line2D([], [], color="0.3", marker="+", lw=0, label="Brockett: bounded guaranteed"),
        ]
    else:
        mesh = ax.pcolormesh(beta, kap, log_rho.reshape(shape).T, cmap="RdBu_r", vmin=-2, vmax=2, shading="auto")
        stable = grid["stable"].to_numpy().reshape(shape).T.astype(float)
        ax.contour(beta, kap, stable, levels=[0.5], colors="k", linewidths=1.2)
        if "brockett_bounded" in grid.columns:
            guaranteed = grid["brockett_bounded"].to_numpy().reshape(shape).T.astype(float)
            if guaranteed.any():
                ax.contourf(beta, kap, guaranteed, levels=[0.5, 1.5], colors="none", hatches=["//"])
                ax.contour(beta, kap, guaranteed, levels=[0.5], colors="0.3", linewidths=0.8, linestyles="--")
        handles = [
            Line2D([], [], color="k", lw=1.2, label="Region I boundary (stable inside)"),
            Patch(facecolor="none", edgecolor="0.3", hatch="//", label="Brockett: bounded guaranteed"),
        ]
    fig.colorbar(mesh, ax=ax, label="$\\log_{10}\\max|\\rho|$ per period $\\pi$ (-)")
    for label, (x, y) in (points or {}).items():
        ax.plot([x], [y], "k*", ms=12)
        ax.annotate(label, (x, y), textcoords="offset points", xytext=(6, 6))
    # Points whose analysis failed (overflow) are blank in the map: mark them.
    failed = grid.filter(pl.col("error").is_not_null()) if "error" in grid.columns else grid.clear()
    if failed.height:
        ax.scatter(failed["beta0"], failed["kappa"], marker="x", s=14, color="k")
        handles.append(Line2D([], [], color="k", marker="x", lw=0, label=f"analysis failed ({failed.height} points, see `error`)"))
    ax.legend(
        handles=handles,
        loc="upper right",
        fontsize=8,
    )
    ax.set_xlabel("damping $\\beta_0$ (-)")
    ax.set_ylabel("stiffness $\\kappa$ (-)")
    ax.set_title("Fig. 2.13 as a map: Floquet stability of eq. 2.25 over $(\\beta_0, \\kappa)$")
    return fig


def plot_bode(
    curves: dict[str, tuple[np.ndarray, np.ndarray]],
    measured: dict[str, pl.DataFrame] | None = None,
    mark_hz: float | None = 300.0,
) -> Figure:
    """Bode magnitude plot of eq. 2.59: ``curves`` maps labels to (frequency_hz, complex H);
    ``measured`` maps labels to :func:`disturbance_response` frames (nonlinear points, drawn in
    the colour of the curve with the same label, if any)."""
    fig, ax = plt.subplots(figsize=(8.5, 6), constrained_layout=True)
    colours = {}
    for label, (f, h) in curves.items():
        (line,) = ax.loglog(f, np.abs(h), label=f"eq. 2.59: {label}")
        colours[label] = line.get_color()
    for label, df in (measured or {}).items():
        ax.loglog(df["frequency_hz"], df["gain"], "o", color=colours.get(label), label=f"nonlinear model: {label}")
    if mark_hz is not None:
        ax.axvline(mark_hz, color="0.5", lw=0.8, ls=":", label=f"{mark_hz:g} Hz")
    ax.set_xlabel("disturbance frequency (Hz)")
    ax.set_ylabel("$|\\tau/\\tau_d|$ (-)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("§2.7, eq. 2.59: wing roll disturbance to body roll torque")
    return fig


def plot_k2_sweep(frames: dict[str, pl.DataFrame]) -> Figure:
    """Whippletree-mode multiplier |ρ| per drive period vs K2 for each labelled sweep."""
    fig, ax = plt.subplots(figsize=(8, 5.5), constrained_layout=True)
    for label, df in frames.items():
        col = "whippletree_radius" if df["whippletree_radius"].null_count() < df.height else "spectral_radius"
        ax.semilogx(df["k2"], df[col], "o-", ms=3, label=label)
    ax.axhline(1.0, color="k", lw=1.0, ls="--", label="$|\\rho| = 1$")
    ax.set_xlabel("balance-beam stiffness $K_2$ (mN·mm/rad)")
    ax.set_ylabel("whippletree multiplier $|\\rho|$ per drive period (-)")
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Floquet multiplier of the whippletree mode of the full nonlinear model vs $K_2$")
    return fig
