"""Hover trim: the drive for which cycle-averaged lift equals weight and the cycle-averaged body
torques vanish (issue 17).

The device is run on the clamped body (``body.mode = "clamped"``: the flight model held by the
stand, which reports the wrench it holds) to its periodic steady state; the cycle means of the
lift (``lift_mean``) and of the wings' torques about the centre of mass
(``body_torque_{roll,yaw,pitch}_mean``) are the residuals. The knobs are spec paths
(:func:`paritysim.spec_paths`) solved by :func:`scipy.optimize.least_squares` (bounded
trust-region, finite differences).

Default knobs: the actuator amplitude (V) and DC offset (V), solved against lift = weight and
zero pitch torque: a single actuator driving both wings cannot set roll or yaw (a left-right
symmetric device has none by symmetry; an asymmetric one keeps a residual, reported). The DC
offset must act as a force: a spec with ``dc_offset = "ignore"`` (the §3.4 piezo bias) is
trimmed with ``dc_offset = "as_force"`` and the offset starting from 0 V, so the trimmed DC is
the force-producing part of the drive. With a Drag PARITY drivetrain add
``"drivetrain.arm_ratio"`` (the whippletree pivot, q3 of eq. 5.1) and the ``"yaw"`` equation to
trim the lift asymmetry too; with a drive per wing (``dual_linear``, ``dual_four_bar``) add
``"actuator.side_gain[0]"`` (the left drive's gain) instead. Trim needs lift: a wing with
``stroke_drag`` aerodynamics (eq. 2.16) or none is refused, naming ``wings[i].aero.kind``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..devices import as_simulation
from ..spec import Simulation, SpecLike

__all__ = ["EQUATIONS", "Trim", "trim"]

#: Residual name -> metric (the lift's target is the weight, the torques' zero).
EQUATIONS = {"lift": "lift_mean", "roll": "body_torque_roll_mean", "yaw": "body_torque_yaw_mean", "pitch": "body_torque_pitch_mean"}

#: Knobs the default trim uses, with their bounds.
AMPLITUDE, OFFSET = "actuator.waveform.amplitude_v", "actuator.waveform.offset_v"
_BOUNDS = {AMPLITUDE: (1e-3, 1e4), OFFSET: (-1e4, 1e4), "drivetrain.arm_ratio": (0.05, 20.0), "actuator.side_gain[0]": (0.0, 1e3), "actuator.side_gain[1]": (0.0, 1e3)}


@dataclass(frozen=True)
class Trim:
    """The outcome of :func:`trim`.

    Attributes
    ----------
    spec:
        The trimmed spec (the input's body mode kept).
    knobs:
        Knob path -> trimmed value (spec units: V, 1).
    residuals:
        Equation -> residual at the trim: ``lift`` is lift − weight (mN), ``roll``/``yaw``/
        ``pitch`` the cycle-mean wing torques on the airframe about its centre of mass (mN·mm),
        every equation, solved or not.
    scaled:
        The residuals over their scales (weight, weight × force radius): dimensionless.
    weight_mn:
        Weight of body and wings (mN).
    lift_mn:
        Cycle-mean lift at the trim (mN).
    solved:
        The equations the knobs were solved for.
    converged:
        Whether every solved scaled residual is below ``tol``.
    evaluations:
        Clamped steady-state runs used.
    """

    spec: Simulation
    knobs: dict[str, float]
    residuals: dict[str, float]
    scaled: dict[str, float]
    weight_mn: float
    lift_mn: float
    solved: tuple[str, ...]
    converged: bool
    evaluations: int
    tol: float = field(default=1e-4)

    def __str__(self) -> str:
        knobs = ", ".join(f"{k} = {v:.6g}" for k, v in self.knobs.items())
        res = ", ".join(f"{k} {v:+.2e}" for k, v in self.residuals.items())
        return f"trim ({'converged' if self.converged else 'NOT converged'}, {self.evaluations} runs): {knobs}; residuals {res} (mN, mN·mm)"


def _weight(body: dict[str, Any]) -> tuple[float, float]:
    """Weight (mN) and the torque scale's length (mm) of a canonical body."""
    mass = float(body["mass_mg"]) + float(sum(body["wing_mass_mg"]))
    g = float(np.linalg.norm(body["gravity_mm_per_ms2"]))
    return mass * g, float(body["force_radius_mm"])


def _clamped(spec: Simulation) -> tuple[Simulation, dict[str, Any]]:
    from . import body_of, with_body

    clamped = with_body(spec, mode="clamped")
    return clamped, body_of(clamped)


def _metrics(spec: Simulation, deadline: Any = None) -> dict[str, float]:
    from ..simulation import simulate

    # The transient, not the default shooting: the root finder differences these metrics in
    # the knobs (eps 1e-6), and with shooting it stalled (pitch residual 3.9e-3 mN·mm instead
    # of 5.6e-10 on the §3.4 PARITY trim; each run re-picks its frozen step grid, so the
    # metrics are not smooth at that scale). Measured when shooting became the default.
    if deadline is not None:
        m = deadline.run(simulate, spec, record_cycles=1, steady_state="transient", progress=False).metrics
    else:
        m = simulate(spec, record_cycles=1, steady_state="transient", progress=False).metrics
    missing = [metric for metric in EQUATIONS.values() if metric not in m]
    if missing:  # a device whose clamped run reports no lift or body torque
        from .._errors import invalid

        raise invalid("spec", spec.name, f"a device whose clamped run reports {', '.join(missing)} (trim's residuals)")
    return {name: float(m[metric]) if m[metric] is not None else math.nan for name, metric in EQUATIONS.items()}


def trim(
    spec: SpecLike,
    knobs: Sequence[str] | None = None,
    equations: Sequence[str] | None = None,
    *,
    initial: Sequence[float] | None = None,
    tol: float = 1e-4,
    max_evaluations: int = 80,
    max_wall_ms: float = 600_000.0,
    progress: bool = True,
) -> Trim:
    """Finds the drive of ``spec`` for which cycle-averaged lift equals weight and the
    cycle-averaged body torques ``equations`` vanish (the spec's ``body`` section gives mass,
    inertia and geometry; no section: the default HMF-class airframe).

    Parameters
    ----------
    knobs:
        Spec paths to solve for; default amplitude and DC offset of the actuator waveform.
    equations:
        Residuals to drive to zero, names of :data:`EQUATIONS`; default the first
        ``len(knobs)`` of ``("lift", "pitch", "yaw", "roll")``.
    initial:
        Starting values of the knobs; default the spec's (offset 0 V when the spec ignores its
        DC offset).
    tol:
        Convergence bound on each solved residual over its scale (weight for lift, weight ×
        ``body.force_radius_mm`` for a torque).
    max_evaluations:
        Cap on residual evaluations per solver stage (each a clamped steady state; the
        finite-difference Jacobian's runs come on top).
    max_wall_ms:
        Wall-time budget of the whole trim (default 10 min): each run gets what is left as its
        ``options.max_wall_ms``; when it is spent, ``IntegrationError`` naming ``max_wall_ms``.
    progress:
        A trim that takes more than a few seconds shows a bar on stderr (wall time against
        ``max_wall_ms``, runs done); ``False`` turns it off.

    Raises
    ------
    InvalidParameterError
        Unknown knob path or equation name, a spec without an actuator, a wing without lift
        (``wings[i].aero.kind`` stroke_drag or none), or a drive the model rejects (the message
        names the field).
    """
    from .._errors import finite_reals, invalid, real, suggest, whole

    spec = as_simulation(spec)
    tol = real("tol", tol)
    if not (math.isfinite(tol) and 0.0 < tol <= 1.0):
        raise invalid("tol", tol, "in (0, 1] (a residual over its scale)")
    max_evaluations = whole("max_evaluations", max_evaluations, 1, 100_000)
    from .._budget import Deadline

    deadline = Deadline("max_wall_ms", max_wall_ms)
    if knobs is not None:
        knobs = _trim_names("knobs", knobs)
    if equations is not None:
        equations = _trim_names("equations", equations)
    if spec.actuator is None:
        raise invalid("actuator", "None", "an actuator to trim (the drive is what trim solves for)")
    if spec.actuator.waveform.kind != "sine" and knobs is None:
        raise invalid("actuator.waveform.kind", spec.actuator.waveform.kind, "'sine' for the default knobs (or name the knobs)")
    knobs = tuple(knobs) if knobs is not None else (AMPLITUDE, OFFSET)
    if spec.actuator.dc_offset == "ignore" and OFFSET in knobs:
        spec = spec.replace(actuator=spec.actuator.replace(dc_offset="as_force", waveform=spec.actuator.waveform.replace(offset_v=0.0)))
    order = ("lift", "pitch", "yaw", "roll")
    equations = tuple(equations) if equations is not None else order[: len(knobs)]
    for e in equations:
        if e not in EQUATIONS:
            raise invalid("equations", repr(e), suggest(str(e), EQUATIONS, what="an equation"))
    if not knobs or len(equations) < len(knobs):
        raise invalid("equations", len(equations), f"at least one equation per knob ({len(knobs)} knobs)")
    for i, wing in enumerate(spec.wings):
        # Trim balances the cycle-mean lift against the weight: a wing without a lift model
        # (eq. 2.16's stroke drag, or none) makes no lift, and the clamped run reports none.
        kind = None if wing.aero is None else wing.aero.kind
        if kind is None or kind == "stroke_drag":
            raise invalid(
                f"wings[{i}].aero.kind",
                repr(kind),
                "an aerodynamic model with lift (blade_element, whitney_wood2010, ...): trim balances lift against weight, and a stroke_drag wing (eq. 2.16) or a wing without aero makes no lift",
            )
    clamped, body = _clamped(spec)
    weight, radius = _weight(body)
    if not weight > 0.0:  # the residuals are scaled by the weight
        raise invalid("body.gravity_mm_per_ms2", body["gravity_mm_per_ms2"], "a non-zero gravity (trim balances lift against weight; the default is 9.81e-3 mm/ms²)")
    scales = {e: (weight if e == "lift" else weight * radius) for e in EQUATIONS}
    paths = {row[0]: row[3] for row in _path_values(clamped)}
    for k in knobs:
        if k not in paths:
            raise invalid("knobs", repr(k), suggest(k, paths, listed_by="ps.spec_paths(spec)", what="a parameter path of this spec"))
        if not isinstance(paths[k], float):  # a name, a flag or a count (JSON integers are counts)
            raise invalid("knobs", repr(k), f"a continuous number to solve for ({k} = {paths[k]!r} is discrete or not a number)")
    if initial is not None:
        x0 = np.atleast_1d(finite_reals("initial", initial))
        if x0.shape != (len(knobs),):
            raise invalid("initial", list(x0.ravel())[:8], f"{len(knobs)} values, one per knob")
    else:
        x0 = np.array([float(paths[k]) for k in knobs], dtype=float)
    lo = np.array([_BOUNDS.get(k, (-np.inf, np.inf))[0] for k in knobs])
    hi = np.array([_BOUNDS.get(k, (-np.inf, np.inf))[1] for k in knobs])
    x0 = np.clip(x0, lo + 1e-12, hi - 1e-12)
    cache: dict[tuple[float, ...], dict[str, float]] = {}
    from .._progress import LongRun

    bar = LongRun("trim", progress, deadline.ms)

    def evaluate(x: np.ndarray) -> dict[str, float]:
        key = tuple(float(v) for v in x)
        if key not in cache:
            r = _metrics(clamped.with_paths(dict(zip(knobs, key, strict=True))), deadline)
            r["lift"] -= weight
            cache[key] = r
            bar.done()
        return cache[key]

    def scaled(x: np.ndarray) -> np.ndarray:
        r = evaluate(x)
        return np.array([r[e] / scales[e] for e in equations])

    from scipy.optimize import least_squares

    with bar:
        x = x0
        if len(equations) == len(knobs):
            # Square system: MINPACK's hybrid method (one finite-difference Jacobian, then
            # Broyden updates) needs far fewer steady states than a least-squares search.
            from scipy.optimize import root

            fit = root(lambda v: scaled(np.clip(v, lo, hi)), x0, method="hybr", options={"xtol": 1e-10, "maxfev": max_evaluations, "eps": 1e-6})
            x = np.clip(fit.x, lo, hi)
        if len(equations) != len(knobs) or not np.all(np.abs(scaled(x)) < tol):
            try:
                fit = least_squares(scaled, x, bounds=(lo, hi), x_scale=np.maximum(np.abs(x0), 1.0), diff_step=1e-5, xtol=1e-10, ftol=1e-12, max_nfev=max_evaluations)
            except ValueError as exc:  # scipy's: residuals not finite at the start (an undefined metric)
                raise invalid("initial", [float(v) for v in x], f"a drive where every residual ({', '.join(equations)}) is defined ({exc})") from exc
            x = fit.x
        r = evaluate(x)
    values = dict(zip(knobs, (float(v) for v in x), strict=True))
    trimmed = spec.with_paths(values)
    s = {e: r[e] / scales[e] for e in EQUATIONS}
    return Trim(
        spec=trimmed,
        knobs=values,
        residuals=dict(r),
        scaled=s,
        weight_mn=weight,
        lift_mn=r["lift"] + weight,
        solved=equations,
        converged=bool(all(abs(s[e]) < tol for e in equations)),
        evaluations=len(cache),
        tol=tol,
    )


def _trim_names(field: str, value: Any) -> tuple[str, ...]:
    from .._errors import invalid

    names = (value,) if isinstance(value, str) else tuple(value) if isinstance(value, Sequence) else None
    if names is None or not all(isinstance(n, str) for n in names):
        raise invalid(field, repr(value)[:60], "a sequence of names (str)")
    return names


def _path_values(spec: Simulation) -> list[tuple[str, str, str, Any]]:
    import json

    from .. import _core

    return [(p, u, a, json.loads(v)) for p, u, a, v in _core.spec_paths(spec.to_json())]
