"""``paritysim.calibrate``: fit model parameters to target metrics or a measured trajectory.

The thesis fitted its model to high-speed video (§3.3.3); this is the same workflow. Each
residual evaluation runs simulations in Rust with the GIL released, so the finite-difference
Jacobian columns run in parallel threads (``workers``).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np
import polars as pl
from scipy.optimize import least_squares

from ._budget import Deadline
from ._errors import invalid, real, suggest, whole
from ._exceptions import ParitysimError
from ._progress import LongRun
from .simulation import simulate
from .spec import Simulation

__all__ = ["CalibrationResult", "calibrate"]

@dataclass(frozen=True)
class CalibrationResult:
    """Fitted ``values``, final ``residuals`` (model − target, scaled), ``cost`` (½Σr²),
    optimiser ``success``/``message``, every evaluation in ``iterations`` and the model's outputs
    at the fit (``None`` for a metric the device does not define, e.g. a fixed wing's rotation
    phase lag). ``repr`` is one summary line; :meth:`summary` a short table."""

    values: dict[str, float]
    residuals: np.ndarray
    cost: float
    success: bool
    message: str
    iterations: pl.DataFrame
    model_outputs: dict[str, float | None]

    def __repr__(self) -> str:
        fitted = ", ".join(f"{k}={v:.6g}" for k, v in self.values.items())
        state = "converged" if self.success else "not converged"
        return f"CalibrationResult({fitted}; cost={self.cost:.3g}, {state}, {len(self.iterations)} evaluations)"

    def summary(self) -> str:
        """The fitted values, the scaled residuals and the optimiser's message, one per line."""
        lines = [repr(self), f"  message: {self.message}"]
        lines += [f"  {k:<40} {v:.9g}" for k, v in self.values.items()]
        lines.append("  scaled residuals: " + ", ".join(f"{r:.3g}" for r in np.atleast_1d(self.residuals)[:8]))
        return "\n".join(lines)


def calibrate(
    model: Simulation | Callable[..., Mapping[str, float]],
    targets: Mapping[str, float] | pl.DataFrame,
    free: Mapping[str, tuple[float, float]],
    *,
    x0: Mapping[str, float] | None = None,
    scale: Mapping[str, float] | None = None,
    workers: int = 2,
    max_nfev: int = 100,
    xtol: float = 1e-10,
    diff_step: float = 1e-4,
    max_wall_ms: float = 600_000.0,
    progress: bool = True,
) -> CalibrationResult:
    """Least-squares fit of the ``free`` parameters (name -> (low, high)).

    ``model``: a :class:`Simulation` (names are the spec paths of :func:`paritysim.spec_paths`,
    the same language as :func:`paritysim.sweep`; outputs are the simulation metrics) or a callable ``f(**values)``
    returning a mapping of outputs.

    ``diff_step``: finite-difference step as a fraction of each parameter's bound range.
    Simulation outputs (sampled peaks, steady-state detection) carry small discontinuities,
    so the step must be well above round-off.

    ``targets``: ``{output: value}`` (residual ``(model − target)/scale``, scale defaults to
    ``max(|target|, 1e-12)``), or a DataFrame with ``time_ms`` and columns of the trajectory to
    match (e.g. ``right_phi``), compared on the recorded window after aligning time origins.

    ``max_wall_ms`` (default 10 min) bounds the whole fit: each simulation gets what is left as
    its ``options.max_wall_ms`` (a callable model is checked between evaluations); when it is
    spent, ``IntegrationError`` naming ``max_wall_ms``.

    ``progress`` (default True): a fit that takes more than a few seconds shows a bar on stderr
    (wall time against ``max_wall_ms``, runs done); ``False`` turns it off.
    """
    diff_step = real("diff_step", diff_step)
    if not (math.isfinite(diff_step) and 0 < diff_step < 0.5):
        raise invalid("diff_step", diff_step, "in (0, 0.5)")
    xtol = real("xtol", xtol)
    if not (math.isfinite(xtol) and 0 < xtol < 1):
        raise invalid("xtol", xtol, "in (0, 1)")
    max_nfev = whole("max_nfev", max_nfev, 1, 1_000_000)
    workers = whole("workers", workers, 1, 1024)
    deadline = Deadline("max_wall_ms", max_wall_ms)
    if not isinstance(model, Simulation) and not callable(model):
        raise invalid("model", type(model).__name__, "a paritysim.Simulation or a callable f(**values) -> outputs")
    if not isinstance(free, Mapping):
        raise invalid("free", type(free).__name__, "a mapping {name: (low, high)}")
    for field_name, given in (("x0", x0), ("scale", scale)):
        if given is not None and not isinstance(given, Mapping):
            raise invalid(field_name, type(given).__name__, "a mapping {name: value}")
    names = list(free)
    if not names:
        raise invalid("free", "{}", "at least one parameter with (low, high) bounds")
    bounds = []
    for n in names:
        pair = free[n]
        if isinstance(pair, str | bytes) or not isinstance(pair, Sequence | np.ndarray) or len(pair) != 2:
            raise invalid(f"free.{n}", repr(pair)[:60], "a (low, high) pair of finite bounds")
        bounds.append((real(f"free.{n}", pair[0]), real(f"free.{n}", pair[1])))
    lo = np.array([b[0] for b in bounds])
    hi = np.array([b[1] for b in bounds])
    for n, a, b in zip(names, lo, hi, strict=True):
        if not (math.isfinite(a) and math.isfinite(b) and a < b):
            raise invalid(f"free.{n}", (float(a), float(b)), "finite bounds with low < high")
    start = np.array([real(f"x0.{n}", (x0 or {}).get(n, 0.5 * (a + b))) for n, a, b in zip(names, lo, hi, strict=True)])
    for n, v, a, b in zip(names, start, lo, hi, strict=True):
        if not (math.isfinite(v) and a <= v <= b):
            raise invalid(f"x0.{n}", float(v), f"within the bounds [{a}, {b}]")
    trajectory_target = isinstance(targets, pl.DataFrame)
    if not trajectory_target and not isinstance(targets, Mapping):
        raise invalid("targets", type(targets).__name__, "a mapping {output: value} or a DataFrame with time_ms and trajectory columns")

    if isinstance(model, Simulation):
        base = model
        # Validate every path (unknown: the nearest valid one) before running anything.
        base.with_paths({n: float(v) for n, v in zip(names, start, strict=True)})

        def outputs(values: dict[str, float]) -> dict[str, Any]:
            result = deadline.run(simulate, base.with_paths(values), progress=False)
            out: dict[str, Any] = dict(result.metrics)
            if trajectory_target:
                out["__trajectory__"] = result.trajectory
            return out
    else:

        def outputs(values: dict[str, float]) -> dict[str, Any]:
            deadline.remaining_ms()
            out = model(**values)
            if not isinstance(out, Mapping):
                raise invalid("model", type(out).__name__, "a callable returning a mapping {output: value}")
            return dict(out)

    if trajectory_target:
        columns = [c for c in targets.columns if c != "time_ms"]
        t_target = targets["time_ms"].to_numpy() - targets["time_ms"][0]

        def residual_of(out: dict[str, Any]) -> np.ndarray:
            traj = out["__trajectory__"]
            t = traj["time_ms"].to_numpy() - traj["time_ms"][0]
            res = []
            for c in columns:
                if c not in traj.columns:  # polars' ColumnNotFoundError otherwise
                    raise invalid(f"targets.{c}", "<unknown column>", suggest(c, traj.columns, what="a trajectory column"))
                sim = np.interp(t_target, t, traj[c].to_numpy())
                res.append((sim - targets[c].to_numpy()) / max(float(np.abs(targets[c].to_numpy()).max()), 1e-12))
            return np.concatenate(res)
    else:
        keys = list(targets)
        if not keys:
            raise invalid("targets", "{}", "at least one output to fit")
        goal = np.array([real(f"targets.{k}", targets[k]) for k in keys])
        scales = np.array([real(f"scale.{k}", (scale or {}).get(k, max(abs(g), 1e-12))) for k, g in zip(keys, goal, strict=True)])
        for k, g, sc in zip(keys, goal, scales, strict=True):
            if not math.isfinite(g):
                raise invalid(f"targets.{k}", float(g), "a finite number")
            if not (math.isfinite(sc) and sc > 0):
                raise invalid(f"scale.{k}", float(sc), "finite and > 0")

        def residual_of(out: dict[str, Any]) -> np.ndarray:
            available = sorted(k for k in out if not k.startswith("__") and out[k] is not None)
            missing = [k for k in keys if k not in out]
            if missing:
                raise invalid(f"targets.{missing[0]}", "<unknown output>", suggest(missing[0], available, listed_by="simulate(spec).metrics"))
            undefined = [k for k in keys if out[k] is None]
            if undefined:  # e.g. a fixed wing's rotation phase lag: no number to fit to
                raise invalid(f"targets.{undefined[0]}", "None (undefined for this device)", "an output this device computes (`simulate(spec).metrics` has a number for it)")
            return (np.array([float(out[k]) for k in keys]) - goal) / scales

    log: list[dict[str, float]] = []
    lock = threading.Lock()

    def evaluate(x: np.ndarray) -> np.ndarray:
        values = dict(zip(names, (float(v) for v in x), strict=True))
        r = residual_of(outputs(values))
        with lock:
            log.append({**values, "cost": 0.5 * float(r @ r)})
            bar.done()
        return r

    pool = ThreadPoolExecutor(max_workers=max(1, workers))
    bar = LongRun("calibrate", progress, deadline.ms)

    def jacobian(x: np.ndarray, *_: Any) -> np.ndarray:
        steps = diff_step * (hi - lo)
        # step inwards at the upper bound
        signed = np.where(x + steps > hi, -steps, steps)
        f0 = evaluate(x)
        columns = list(pool.map(lambda i: evaluate(np.where(np.arange(len(x)) == i, x + signed, x)), range(len(x))))
        return np.column_stack([(c - f0) / s for c, s in zip(columns, signed, strict=True)])

    try:
        with bar:
            fit = least_squares(evaluate, start, jac=jacobian, bounds=(lo, hi), x_scale="jac", max_nfev=max_nfev, xtol=xtol)
    except ValueError as exc:
        if isinstance(exc, ParitysimError):
            raise
        # scipy's own checks (e.g. residuals not finite at the start: an output the model
        # returned as NaN): a typed error naming what the fit started from (issue 34).
        raise invalid("x0", {n: float(v) for n, v in zip(names, start, strict=True)}, f"a start where the model's outputs are finite numbers ({exc})") from exc
    finally:
        pool.shutdown()
    values = dict(zip(names, (float(v) for v in fit.x), strict=True))
    final = outputs(values)
    return CalibrationResult(
        values=values,
        residuals=np.asarray(fit.fun),
        cost=float(fit.cost),
        success=bool(fit.success),
        message=str(fit.message),
        iterations=pl.DataFrame(log),
        model_outputs={k: None if v is None else float(v) for k, v in final.items() if not k.startswith("__")},
    )
