"""``paritysim.calibrate``: fit model parameters to target metrics, a measured trajectory, or a
measured table of operating points (``data=``, ``params=``: `TableCalibrationResult`).

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
from ._calibrate_table import Measured, TableCalibrationResult, _column, calibrate_table, check_jacobian, check_names, measured, not_finite
from ._errors import invalid, real, suggest, whole
from ._exceptions import ParitysimError
from ._progress import LongRun
from .simulation import simulate
from .spec import Simulation

__all__ = ["CalibrationResult", "Measured", "TableCalibrationResult", "calibrate", "measured"]

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
    targets: Mapping[str, float] | pl.DataFrame | None = None,
    free: Mapping[str, tuple[float, float]] | None = None,
    *,
    data: Any = None,
    params: Mapping[str, tuple[float, float]] | None = None,
    measured: Mapping[str, Measured | str] | None = None,
    holdout: float | None = None,
    seed: int | None = None,
    labels: Sequence[str] = (),
    jacobian: str = "auto",
    threads: int | None = None,
    x0: Mapping[str, float] | None = None,
    scale: Mapping[str, float] | None = None,
    workers: int | None = None,
    max_nfev: int = 100,
    xtol: float | None = None,
    ftol: float | None = None,
    diff_step: float = 1e-4,
    max_wall_ms: float = 600_000.0,
    progress: bool = True,
) -> CalibrationResult | TableCalibrationResult:
    """Least-squares fit of the ``free`` parameters (name -> (low, high)).

    Two forms. ``calibrate(model, targets, free)`` fits one operating point (target metrics or
    a measured trajectory; `CalibrationResult`). ``calibrate(spec, data=table, params={path:
    (low, high)})`` fits a measured table of operating points (`TableCalibrationResult`):

    ``data``: a polars DataFrame (or a pandas DataFrame, or a mapping of columns) whose columns
    are spec paths giving each row's operating point (``actuator.waveform.amplitude_v``,
    ``actuator.waveform.frequency_hz``, ...), measured columns, and the ``labels`` columns to
    carry along. ``measured``: ``{column: ps.measured(metric, peak_to_peak=..., unit=...,
    sigma=...)}`` states each measured column's convention (a bench's peak-to-peak degrees are
    ``ps.measured("left_stroke_amplitude", peak_to_peak=True, unit="deg")``); a plain metric
    name is that metric in its own unit; None takes the columns named after metrics, as they
    are. Any other column must be a spec path (unknown: the nearest names). ``params``: the
    fitted spec paths with bounds inside the spec's ranges; the start is the spec's own value
    when it lies within the bounds (else the middle), or ``x0``. ``holdout``: a fraction in
    (0, 1) of the rows held out of the fit (chosen by ``seed``) and predicted at the end.

    Each residual evaluation is one `paritysim.sweep` of the fitted rows (``threads`` engine
    threads); ``jacobian="auto"`` takes the derivatives from the same sweep's ``gradients=``
    (`paritysim.sensitivity` at every point) when every parameter is differentiable, else
    (``"differences"``) from one sweep of forward differences of ``diff_step`` × the bound
    range. The result reports the fitted values, standard errors and correlations (linearised
    least squares at the optimum, ``s² (JᵀJ)⁻¹`` with the residual variance ``s²``), RMS and
    max errors on the fitted and held-out rows, scipy's convergence status, and plots the
    measured against the predicted values per operating line (:meth:`TableCalibrationResult.plot`).

    Arguments of one form only are refused by the other, never silently unused: ``measured``,
    ``holdout``, ``seed`` (with ``holdout``), ``labels`` and ``threads`` need ``data=``;
    ``scale`` and ``workers`` are the single-point form's. ``jacobian`` there is ``"auto"`` or
    ``"differences"`` (its Jacobian always comes from differences).

    ``model``: a :class:`Simulation` (names are the spec paths of :func:`paritysim.spec_paths`,
    the same language as :func:`paritysim.sweep`; outputs are the simulation metrics) or a callable ``f(**values)``
    returning a mapping of outputs.

    ``xtol``, ``ftol``: scipy's step and cost tolerances (default 1e-10 and 1e-8; with ``data=``
    1e-8 and 1e-6: a relative cost change of 1e-6 moves the parameters by about 1e-3 of their
    standard errors, below what the steady states' own tolerances resolve).

    ``diff_step``: finite-difference step as a fraction of each parameter's bound range.
    Simulation outputs (sampled peaks, steady-state detection) carry small discontinuities,
    so the step must be well above round-off.

    ``targets``: ``{output: value}`` (residual ``(model − target)/scale``, scale defaults to
    ``max(|target|, 1e-12)``), or a DataFrame with ``time_ms`` and columns of the trajectory to
    match (e.g. ``right_phi``; numbers, at least one row, ``time_ms`` increasing), compared on
    the recorded window after aligning time origins (scale per column defaults to its max |value|).

    ``workers`` (default 2): simulations run at once for the single-point Jacobian's columns.

    ``max_wall_ms`` (default 10 min) bounds the whole fit: each simulation gets what is left as
    its ``options.max_wall_ms`` (a callable model is checked between evaluations); when it is
    spent, ``IntegrationError`` naming ``max_wall_ms``.

    ``progress`` (default True): a fit that takes more than a few seconds shows a bar on stderr
    (wall time against ``max_wall_ms``, runs done); ``False`` turns it off.
    """
    if data is not None:
        # The single-point form's own arguments, refused rather than dropped.
        for field_name, point_only, why in (("scale", scale, "the noise scale of a measured column is ps.measured(..., sigma=)"), ("workers", workers, "a table is fitted in sweeps of threads= engine threads")):
            if point_only is not None:
                raise invalid(field_name, repr(point_only)[:60], f"None when data= is given ({why})")
        if seed is not None and holdout is None:
            raise invalid("seed", repr(seed), "None unless holdout= is given (it chooses the held-out rows)")
        if targets is not None:
            raise invalid("targets", type(targets).__name__, "None when data= is given (the measured columns of data are the targets)")
        if free is not None and params is not None:
            raise invalid("free", "given with params", "None when params= is given (one or the other)")
        return calibrate_table(
            model,  # type: ignore[arg-type]
            data,
            params if params is not None else free,
            measured=measured,
            holdout=holdout,
            seed=0 if seed is None else seed,
            labels=labels,
            x0=x0,
            jacobian=jacobian,
            diff_step=diff_step,
            max_nfev=max_nfev,
            xtol=1e-8 if xtol is None else xtol,
            ftol=1e-6 if ftol is None else ftol,
            max_wall_ms=max_wall_ms,
            threads=threads,
            progress=progress,
        )
    for field_name, extra in (("measured", measured), ("holdout", holdout)):
        if extra is not None:
            raise invalid(field_name, type(extra).__name__, "None unless data= is given (a measured table)")
    # The table form's arguments mean nothing for one point: refused, never silently unused.
    for field_name, table_only, why in (("seed", seed, "it chooses the held-out rows of a table"), ("threads", threads, "engine threads of a table's sweeps; one point runs `workers` simulations at once")):
        if table_only is not None:
            raise invalid(field_name, repr(table_only)[:60], f"None unless data= is given ({why})")
    if labels is not None and not (isinstance(labels, Sequence) and not isinstance(labels, str) and len(labels) == 0):
        raise invalid("labels", repr(labels)[:60], "empty unless data= is given (columns of the table carried into the result)")
    check_jacobian(jacobian, ("auto", "differences"), " (the single-point form takes its Jacobian from differences; 'sensitivity' needs data=)")
    if params is not None:
        if free is not None:
            raise invalid("free", "given with params", "None when params= is given (one or the other)")
        free = params
    if targets is None:
        raise invalid("targets", "None", "target metrics {output: value}, a trajectory DataFrame, or data= (a measured table)")
    goal_table: Mapping[str, float] | pl.DataFrame = targets
    if free is None:
        raise invalid("free", "None", "a mapping {name: (low, high)}")
    diff_step = real("diff_step", diff_step)
    if not (math.isfinite(diff_step) and 0 < diff_step < 0.5):
        raise invalid("diff_step", diff_step, "in (0, 0.5)")
    xtol = real("xtol", 1e-10 if xtol is None else xtol)
    if not (math.isfinite(xtol) and 0 < xtol < 1):
        raise invalid("xtol", xtol, "in (0, 1)")
    ftol = real("ftol", 1e-8 if ftol is None else ftol)
    if not (math.isfinite(ftol) and 0 < ftol < 1):
        raise invalid("ftol", ftol, "in (0, 1)")
    max_nfev = whole("max_nfev", max_nfev, 1, 1_000_000)
    workers = whole("workers", 2 if workers is None else workers, 1, 1024)
    deadline = Deadline("max_wall_ms", max_wall_ms)
    if not isinstance(model, Simulation) and not callable(model):
        raise invalid("model", type(model).__name__, "a paritysim.Simulation or a callable f(**values) -> outputs")
    if not isinstance(free, Mapping):
        raise invalid("free", type(free).__name__, "a mapping {name: (low, high)}")
    names = list(free)
    if not names:
        raise invalid("free", "{}", "at least one parameter with (low, high) bounds")
    check_names("x0", x0, names, "parameter", "a name of free")
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
    trajectory_target = isinstance(goal_table, pl.DataFrame)
    if not trajectory_target and not isinstance(goal_table, Mapping):
        raise invalid("targets", type(goal_table).__name__, "a mapping {output: value} or a DataFrame with time_ms and trajectory columns")
    if trajectory_target and not isinstance(model, Simulation):  # a callable returns outputs, no trajectory
        raise invalid("targets", "a DataFrame", "a mapping {output: value} when model is a callable (a trajectory DataFrame needs a paritysim.Simulation)")

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

    output_of: Callable[[int], str]
    if isinstance(goal_table, pl.DataFrame):
        # Checked before any run: polars' ColumnNotFoundError, numpy's IndexError and
        # TypeError (a text column) otherwise.
        if "time_ms" not in goal_table.columns:
            raise invalid("targets", f"a DataFrame of columns {goal_table.columns[:6]}", "a DataFrame with a `time_ms` column (the sample times, ms) and the trajectory columns to match")
        columns = [c for c in goal_table.columns if c != "time_ms"]
        if not columns:
            raise invalid("targets", "a DataFrame of time_ms alone", "time_ms and at least one trajectory column to match (e.g. right_phi)")
        if goal_table.height == 0:
            raise invalid("targets", "an empty DataFrame", "at least one row (a sample time and its measured values)")
        measured_at = {c: _column(goal_table, c, "targets") for c in ["time_ms", *columns]}
        for c, column in measured_at.items():
            bad = np.flatnonzero(~np.isfinite(column))
            if bad.size:
                raise invalid(f"targets.{c}", f"row {int(bad[0])} = {column[bad[0]]}", "a finite number on every row")
        t_measured = measured_at.pop("time_ms")
        back = np.flatnonzero(np.diff(t_measured) < 0)
        if back.size:
            raise invalid("targets.time_ms", f"row {int(back[0]) + 1} = {t_measured[back[0] + 1]}", "increasing times (each row at or after the one before)")
        t_target = t_measured - t_measured[0]
        check_names("scale", scale, columns, "target", "a trajectory column of targets")
        column_scales = {c: real(f"scale.{c}", (scale or {}).get(c, max(float(np.abs(v).max()), 1e-12))) for c, v in measured_at.items()}
        for c, size in column_scales.items():
            if not (math.isfinite(size) and size > 0):
                raise invalid(f"scale.{c}", size, "finite and > 0")

        # The output a residual belongs to (one block of samples per column), to name a non-finite one.
        def output_of(i: int) -> str:
            return columns[i // t_target.size]

        def residual_of(out: dict[str, Any]) -> np.ndarray:
            traj = out["__trajectory__"]
            t = traj["time_ms"].to_numpy() - traj["time_ms"][0]
            if t_target[-1] > t[-1] * (1 + 1e-9):
                # np.interp would hold the window's last value for every later sample: a 3-cycle
                # video against a 1-cycle window fitted both parameters to their bounds.
                cycles = math.ceil(t_target[-1] / t[-1] * model.options.record_cycles - 1e-9)
                raise invalid("targets.time_ms", f"a video of {t_target[-1]:.6g} ms", f"within the model's recorded window ({t[-1]:.6g} ms): record more cycles (options.record_cycles >= {cycles}) or trim the video")
            res = []
            for c in columns:
                if c not in traj.columns:  # polars' ColumnNotFoundError otherwise
                    raise invalid(f"targets.{c}", "<unknown column>", suggest(c, traj.columns, what="a trajectory column"))
                sim = np.interp(t_target, t, traj[c].to_numpy())
                res.append((sim - measured_at[c]) / column_scales[c])
            return np.concatenate(res)
    else:
        keys = list(goal_table)
        if not keys:
            raise invalid("targets", "{}", "at least one output to fit")
        goal = np.array([real(f"targets.{k}", goal_table[k]) for k in keys])
        check_names("scale", scale, keys, "target", "an output of targets")

        def output_of(i: int) -> str:
            return keys[i]

        for k, g in zip(keys, goal, strict=True):
            if g == 0 and k not in (scale or {}):
                # Its residual would be divided by a floor of 1e-12: a metric held at zero by
                # symmetry (round-off, 1e-11) then outweighed every other target, and the fit
                # stayed at its start and said converged.
                raise invalid(f"targets.{k}", 0.0, f"a nonzero target, or a scale for it (scale={{{k!r}: <the size a miss matters at>}}): a residual is divided by its target's size")
        scales = np.array([real(f"scale.{k}", (scale or {}).get(k, abs(g))) for k, g in zip(keys, goal, strict=True)])
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

    start_values = {n: float(v) for n, v in zip(names, start, strict=True)}
    given_bounds = {n: (float(a), float(b)) for n, a, b in zip(names, lo, hi, strict=True)}

    def evaluate(x: np.ndarray) -> np.ndarray:
        values = dict(zip(names, (float(v) for v in x), strict=True))
        r = residual_of(outputs(values))
        bad = np.flatnonzero(~np.isfinite(r))
        if bad.size:
            # Name the point where the outputs broke: the start only if it is the start.
            what = f"`{output_of(int(bad[0]))}` is not finite"
            if np.array_equal(x, start):
                raise invalid("x0", values, f"a start where the model's outputs are finite numbers ({what} there)")
            raise invalid("free", given_bounds, f"bounds inside which the model's outputs are finite numbers ({what} at {values}, reached by the fit from the start {start_values})")
        with lock:
            log.append({**values, "cost": 0.5 * float(r @ r)})
            bar.done()
        return r

    pool = ThreadPoolExecutor(max_workers=max(1, workers))
    bar = LongRun("calibrate", progress, deadline.ms)

    def differences(x: np.ndarray, *_: Any) -> np.ndarray:
        steps = diff_step * (hi - lo)
        # step inwards at the upper bound
        signed = np.where(x + steps > hi, -steps, steps)
        f0 = evaluate(x)
        columns = list(pool.map(lambda i: evaluate(np.where(np.arange(len(x)) == i, x + signed, x)), range(len(x))))
        return np.column_stack([(c - f0) / s for c, s in zip(columns, signed, strict=True)])

    try:
        with bar:
            fit = least_squares(evaluate, start, jac=differences, bounds=(lo, hi), x_scale="jac", max_nfev=max_nfev, xtol=xtol, ftol=ftol)
    except ValueError as exc:
        if isinstance(exc, ParitysimError):
            raise
        # scipy's own checks (evaluate() has refused non-finite outputs already): a typed
        # error naming the bounds and the last point evaluated, not the start (issue 34).
        raise not_finite(exc, "free", given_bounds, log) from exc
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
