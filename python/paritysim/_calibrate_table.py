"""``ps.calibrate(spec, data=table, params=...)``: fit a model to a measured table of operating
points (issue 35, item 5).

The table has spec-path columns (the operating points: drive voltage, frequency, ...) and
measured columns. Every residual evaluation is one `paritysim.sweep` over the fitted rows, with
the parameters as further columns of its grid; the Jacobian comes from the same sweep's
``gradients=`` (`paritysim.sensitivity` at every point) when the parameters are differentiable,
else from one more sweep of forward differences. The standard errors are those of linearised
least squares at the optimum: ``cov = s² (JᵀJ)⁻¹`` with ``s² = Σr² / (m − p)``.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import polars as pl
from scipy.optimize import least_squares

from . import _core
from ._budget import Deadline
from ._errors import invalid, real, suggest, whole
from ._exceptions import ParitysimError
from ._progress import LongRun
from .spec import Simulation

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["Measured", "TableCalibrationResult", "measured"]

#: Metrics that are angles (rad): a bench may report them in degrees.
_ANGLE = re.compile(r"(^|_)(stroke|rotation|deviation|q2)_(amplitude|peak_to_peak|mean)$|_phase_lag$|^q2_amplitude$")
_UNITS = ("rad", "deg")


@dataclass(frozen=True)
class Measured:
    """How a measured column relates to a model metric (see `measured`)."""

    metric: str
    peak_to_peak: bool = False
    unit: str | None = None
    sigma: float = 1.0

    @property
    def factor(self) -> float:
        """measured value = ``factor`` × metric."""
        return (2.0 if self.peak_to_peak else 1.0) * (180.0 / math.pi if self.unit == "deg" else 1.0)

    @property
    def unit_label(self) -> str:
        """The unit of the measured column (``""`` for a metric given in its own unit)."""
        return self.unit or ""

    def __repr__(self) -> str:
        extra = "".join([", peak_to_peak=True" if self.peak_to_peak else "", f", unit={self.unit!r}" if self.unit else "", f", sigma={self.sigma:g}" if self.sigma != 1.0 else ""])
        return f"measured({self.metric!r}{extra})"


def measured(metric: str, *, peak_to_peak: bool = False, unit: str | None = None, sigma: float = 1.0) -> Measured:
    """The convention of a measured column, stated, never guessed.

    ``metric``: the model metric it measures (a name of ``ps.simulate(spec).metrics``).
    ``peak_to_peak``: the bench reports the peak-to-peak swing and ``metric`` is an
    ``*_amplitude`` (half the peak-to-peak): measured = 2 × metric.
    ``unit``: ``"deg"`` or ``"rad"`` for an angle metric (the model's are in rad), None: the
    metric's own unit.
    ``sigma``: the measurement's noise scale in the column's units (> 0): residuals are divided
    by it, so columns of different units weigh by their noise. The reported standard errors
    use the residual variance of the fit (they do not trust ``sigma``'s absolute size).

    ``measured("left_stroke_amplitude", peak_to_peak=True, unit="deg")`` is a column of
    peak-to-peak stroke in degrees.
    """
    if not isinstance(metric, str) or not metric:
        raise invalid("metric", repr(metric), "a metric name (text)")
    if not isinstance(peak_to_peak, bool):
        raise invalid("peak_to_peak", repr(peak_to_peak), "True or False")
    if peak_to_peak and not metric.endswith("_amplitude"):
        raise invalid("peak_to_peak", True, f"False for `{metric}`: peak_to_peak=True doubles an `*_amplitude` metric (half the peak-to-peak)")
    if unit is not None and unit not in _UNITS:
        raise invalid("unit", repr(unit), "None (the metric's own unit), 'rad' or 'deg'")
    if unit is not None and not _ANGLE.search(metric):
        raise invalid("unit", repr(unit), f"None for `{metric}`: only angle metrics (rad) convert to degrees")
    s = real("sigma", sigma)
    if not (math.isfinite(s) and s > 0):
        raise invalid("sigma", sigma, "finite and > 0 (the column's noise scale, in its units)")
    return Measured(metric, peak_to_peak, unit, s)


@dataclass(frozen=True, repr=False)
class TableCalibrationResult:
    """A fit of a spec to a measured table (``ps.calibrate(spec, data=..., params=...)``).

    ``values``: the fitted parameters; ``stderr``: their standard errors and ``correlation``
    (rows and columns in the order of ``names``) from the Jacobian at the optimum and the
    residual variance; ``success``/``status``/``message``: scipy's convergence report;
    ``errors``: per measured column, the RMS and max |measured − predicted| on the fitted and
    the held-out rows (in the column's units); ``table``: the data with ``split`` (``"fit"`` /
    ``"holdout"``), ``predicted_<column>`` and the row's sweep ``status`` at the fit;
    ``spec``: the spec with the fitted values; ``iterations``: every evaluation's values and
    cost; ``sweeps``: how many sweeps the fit ran; ``jacobian``: ``"sensitivity"`` or
    ``"differences"``. ``repr`` is the summary table; :meth:`plot` the measured against the
    predicted values per operating line.
    """

    names: list[str]
    values: dict[str, float]
    stderr: dict[str, float]
    correlation: np.ndarray
    covariance: np.ndarray
    bounds: dict[str, tuple[float, float]]
    success: bool
    status: int
    message: str
    cost: float
    dof: int
    residual_std: float
    errors: pl.DataFrame
    table: pl.DataFrame
    spec: Simulation
    iterations: pl.DataFrame
    sweeps: int
    jacobian: str
    measured: dict[str, Measured]
    operating: list[str]
    failed_points: int = 0
    notes: list[str] = field(default_factory=list)

    def _error(self, column: str, what: str) -> float:
        row = self.errors.filter(pl.col("column") == column)
        return float(row[what][0]) if row.height else math.nan

    @property
    def holdout_rms(self) -> dict[str, float]:
        """RMS |measured − predicted| on the held-out rows, per measured column (NaN: none held out)."""
        return {c: self._error(c, "holdout_rms") for c in self.measured}

    @property
    def holdout_max(self) -> dict[str, float]:
        """Largest |measured − predicted| on the held-out rows, per measured column."""
        return {c: self._error(c, "holdout_max") for c in self.measured}

    @property
    def fit_rms(self) -> dict[str, float]:
        """RMS |measured − predicted| on the fitted rows, per measured column."""
        return {c: self._error(c, "fit_rms") for c in self.measured}

    def summary(self) -> str:
        """The fitted values with standard errors and bounds, the correlations, the errors per
        column on the fitted and held-out rows, and the optimiser's verdict."""
        state = "converged" if self.success else "NOT converged"
        n_fit = int((self.table["split"] == "fit").sum())
        n_hold = self.table.height - n_fit
        lines = [f"TableCalibrationResult: {state} ({self.message}); {n_fit} fitted rows, {n_hold} held out; {self.sweeps} sweeps, Jacobian by {self.jacobian}"]
        width = max(len(n) for n in self.names) + 4
        lines.append(f"  {'parameter':<{width}}  {'value':>12}  {'std. error':>11}  {'rel.':>7}  bounds")
        for i, n in enumerate(self.names):
            v, se = self.values[n], self.stderr[n]
            rel = abs(se / v) if v else math.inf
            lo, hi = self.bounds[n]
            at = "  (at a bound)" if min(v - lo, hi - v) <= 1e-9 * max(1.0, hi - lo) else ""
            lines.append(f"  {'[' + str(i + 1) + '] ' + n:<{width}}  {v:>12.6g}  {se:>11.3g}  {rel:>7.1%}  [{lo:g}, {hi:g}]{at}")
        if len(self.names) > 1:
            lines.append(f"  {'correlations':<{width}}  " + " ".join(f"{'[' + str(i + 1) + ']':>6}" for i in range(len(self.names))))
            for i in range(len(self.names)):
                lines.append(f"  {'[' + str(i + 1) + ']':<{width}}  " + " ".join(f"{self.correlation[i, j]:>+6.2f}" for j in range(len(self.names))))
        lines.append(f"  {'column':<{width}}  {'fit RMS':>12}  {'fit max':>11}  {'held-out RMS':>12}  {'held-out max':>12}")
        for r in self.errors.iter_rows(named=True):
            unit = f" {r['unit']}" if r["unit"] else ""
            lines.append(f"  {r['column'] + unit:<{width}}  {r['fit_rms']:>12.4g}  {r['fit_max']:>11.4g}  {r['holdout_rms']:>12.4g}  {r['holdout_max']:>12.4g}")
        lines.append(f"  residual std. (weighted): {self.residual_std:.4g} with {self.dof} degrees of freedom")
        if self.failed_points:
            lines.append(f"  {self.failed_points} point evaluations failed during the fit (penalised)")
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)

    def __repr__(self) -> str:
        return self.summary()

    def plot(self, x: str | None = None, line: str | None = None, path: Any = None) -> Figure:
        """Measured (filled: fitted rows, open: held out) and predicted values against the
        operating column ``x`` (default: the one with the most distinct values), one colour per
        operating line ``line`` (default: the other columns); one panel per measured column.
        See `paritysim.plots.calibration_table`."""
        from .plots import calibration_table

        return calibration_table(self, x=x, line=line, path=path)


# ---------------------------------------------------------------------------- the fit


#: Rows per sweep of a table's residual evaluation; the fit's budget is checked between blocks.
_BLOCK_ROWS = 512


def _frame(data: Any) -> pl.DataFrame:
    if isinstance(data, pl.DataFrame):
        return data
    if hasattr(data, "to_dict") and type(data).__module__.startswith("pandas"):
        try:
            return pl.from_pandas(data)
        except Exception as exc:  # noqa: BLE001 - pandas/pyarrow conversion errors of every kind
            raise invalid("data", type(data).__name__, f"a table polars can read ({str(exc)[:80]})") from exc
    if isinstance(data, Mapping):
        try:
            return pl.DataFrame(dict(data), strict=False)
        except (TypeError, ValueError, pl.exceptions.PolarsError) as exc:
            raise invalid("data", f"{len(data)} columns", f"columns of equal length ({str(exc)[:80]})") from exc
    raise invalid("data", type(data).__name__, "a polars DataFrame, a pandas DataFrame or a mapping {column: values}")


def _column(table: pl.DataFrame, name: str, field: str = "data") -> np.ndarray:
    try:
        return table[name].cast(pl.Float64, strict=True).fill_null(np.nan).to_numpy()
    except (pl.exceptions.PolarsError, TypeError, ValueError) as exc:
        raise invalid(f"{field}.{name}", f"a column of {table[name].dtype}", "numbers") from exc


#: The ``jacobian=`` of a table fit.
JACOBIANS = ("auto", "sensitivity", "differences")


def check_jacobian(jacobian: Any, allowed: Sequence[str] = JACOBIANS, why: str = "") -> str:
    """``jacobian`` if it is one of ``allowed``, else an ``InvalidParameterError`` naming it
    (``why``: what the other values need). Both forms of `paritysim.calibrate` check here."""
    if not isinstance(jacobian, str) or jacobian not in allowed:
        shown = (", ".join(repr(a) for a in allowed[:-1]) + " or ") if len(allowed) > 1 else ""
        raise invalid("jacobian", repr(jacobian), f"{shown}{allowed[-1]!r}{why}")
    return jacobian


def check_names(field: str, given: Any, names: Sequence[str], kind: str, what: str) -> None:
    """``given`` (``x0``, ``scale``) is None or a mapping whose every key is one of ``names``:
    an unknown key (a typo) is an ``InvalidParameterError`` naming ``field.key`` and the
    nearest names, never silently unused. Both forms of `paritysim.calibrate` check here."""
    if given is None:
        return
    if not isinstance(given, Mapping):
        raise invalid(field, type(given).__name__, f"a mapping {{{kind}: value}}")
    for k in given:
        if k not in names:
            raise invalid(f"{field}.{k}", f"<not a {kind}>", suggest(str(k), names, what=what))


def not_finite(exc: ValueError, field: str, bounds: Mapping[str, tuple[float, float]], log: list[dict[str, float]]) -> _core.InvalidParameterError:
    """scipy's own refusal of a fit (a residual or Jacobian that is not finite) as an error
    naming the bounds and the last point evaluated: the fit may have moved far from its start."""
    last = {n: v for n, v in log[-1].items() if n in bounds} if log else None
    return invalid(field, dict(bounds), f"bounds inside which the model's outputs are finite numbers (scipy: {exc}; last evaluated at {last})")


def _alias(path: str) -> str:
    for a, b in (("wings[*].", "wings[0]."), ("wings.left.", "wings[0]."), ("wings.right.", "wings[1]."), ("actuator.frequency_hz", "actuator.waveform.frequency_hz"), ("actuator.amplitude_v", "actuator.waveform.amplitude_v"), ("actuator.voltage_v", "actuator.waveform.amplitude_v")):
        if path.startswith(a):
            return b + path[len(a) :]
    return path


def _current(paths: pl.DataFrame, path: str) -> float | None:
    row = paths.filter(pl.col("path") == _alias(path))
    if not row.height:
        return None
    try:
        v = float(row["value"][0])
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _check_bounds(spec: Simulation, name: str, lo: float, hi: float) -> None:
    """The bounds inside the range the spec accepts for ``name`` (unknown paths: did-you-mean)."""
    for v in (lo, hi):
        try:
            spec.with_paths({name: v})
        except _core.InvalidParameterError as exc:
            text = str(exc)
            allowed = text.split(": must be ", 1)[1] if ": must be " in text else text
            if "unknown parameter path" in text:
                raise invalid(f"params.{name}", "<unknown parameter path>", allowed) from exc
            raise invalid(f"params.{name}", (lo, hi), f"bounds inside the spec's range for `{name}`: {allowed}") from exc


def calibrate_table(
    spec: Simulation,
    data: Any,
    params: Any,
    *,
    measured: Mapping[str, Measured | str] | None = None,
    holdout: float | None = None,
    seed: int = 0,
    labels: Sequence[str] = (),
    x0: Mapping[str, float] | None = None,
    jacobian: str = "auto",
    diff_step: float = 1e-4,
    max_nfev: int = 100,
    xtol: float = 1e-8,
    ftol: float = 1e-6,
    max_wall_ms: float = 600_000.0,
    threads: int | None = None,
    progress: bool = True,
) -> TableCalibrationResult:
    """See `paritysim.calibrate` (``data=`` form)."""
    from .sweep import sweep, valid_paths

    if not isinstance(spec, Simulation):
        raise invalid("model", type(spec).__name__, "a paritysim.Simulation when data= is given (a table is fitted by sweeps of a spec)")
    table = _frame(data)
    if table.height == 0:
        raise invalid("data", "an empty table", "at least one row")
    diff_step = real("diff_step", diff_step)
    if not (math.isfinite(diff_step) and 0 < diff_step < 0.5):
        raise invalid("diff_step", diff_step, "in (0, 0.5)")
    xtol = real("xtol", xtol)
    if not (math.isfinite(xtol) and 0 < xtol < 1):
        raise invalid("xtol", xtol, "in (0, 1)")
    ftol = real("ftol", ftol)
    if not (math.isfinite(ftol) and 0 < ftol < 1):
        raise invalid("ftol", ftol, "in (0, 1)")
    max_nfev = whole("max_nfev", max_nfev, 1, 1_000_000)
    seed = whole("seed", seed, 0, 2**63 - 1)
    jacobian = check_jacobian(jacobian)
    deadline = Deadline("max_wall_ms", max_wall_ms)

    # --- the parameters and their bounds
    if not isinstance(params, Mapping) or not params:
        raise invalid("params", type(params).__name__ if not isinstance(params, Mapping) else "{}", "a mapping {spec path: (low, high)} with at least one parameter")
    names = [str(n) for n in params]
    bounds: dict[str, tuple[float, float]] = {}
    for n in names:
        pair = params[n]
        if isinstance(pair, str | bytes) or not isinstance(pair, Sequence | np.ndarray) or len(pair) != 2:
            raise invalid(f"params.{n}", repr(pair)[:60], "a (low, high) pair of finite bounds")
        low, high = real(f"params.{n}", pair[0]), real(f"params.{n}", pair[1])
        if not (math.isfinite(low) and math.isfinite(high) and low < high):
            raise invalid(f"params.{n}", (low, high), "finite bounds with low < high")
        _check_bounds(spec, n, low, high)
        bounds[n] = (low, high)
    check_names("x0", x0, names, "parameter", "a path of params")
    paths_table = _core_paths(spec)
    start = []
    for n in names:
        low, high = bounds[n]
        if x0 is not None and n in x0:
            v = real(f"x0.{n}", x0[n])
            if not (math.isfinite(v) and low <= v <= high):
                raise invalid(f"x0.{n}", v, f"within the bounds [{low:g}, {high:g}]")
        else:
            cur = _current(paths_table, n)
            v = cur if cur is not None and low <= cur <= high else 0.5 * (low + high)
        start.append(v)

    # --- the columns: operating points, measured, labels
    metric_names = list(_core.sweep_metric_names(spec.to_json()))
    if isinstance(labels, str):
        labels = [labels]
    labels = [str(c) for c in labels]
    for c in labels:
        if c not in table.columns:
            raise invalid(f"labels.{c}", "<not a column of data>", suggest(c, table.columns, what="a column of data"))
    if measured is None:
        taken = {c: measured_of(c, c) for c in table.columns if c in metric_names}
    else:
        if not isinstance(measured, Mapping) or not measured:
            raise invalid("measured", type(measured).__name__, "a mapping {column: ps.measured(metric, ...) or metric name}")
        taken = {}
        for c, m in measured.items():
            if c not in table.columns:
                raise invalid(f"measured.{c}", "<not a column of data>", suggest(str(c), table.columns, what="a column of data"))
            taken[str(c)] = measured_of(str(c), m)
    column_units = dict(_core.trajectory_column_units(spec.to_json()))
    for c, m in taken.items():
        if m.metric not in metric_names:
            raise invalid(f"measured.{c}", repr(m.metric), suggest(m.metric, metric_names, listed_by="simulate(spec).metrics", what="a metric of this device"))
        if m.unit is not None and m.metric.startswith("q2_") and column_units.get("q2") != "rad":
            # A dual drivetrain's q2 is the right actuator's displacement (mm): degrees of it
            # were taken as 57.3 × mm, and the fit ran to a bound.
            raise invalid(f"measured.{c}", f"{m.metric} in {m.unit}", f"no unit for `{m.metric}` on this device: its q2 is in {column_units.get('q2')}, not an angle")
    paths = set(valid_paths(spec))
    for c in labels:
        if c in paths:
            # Every row then ran at the spec's own value (frequency in labels: fitted 0.597 and
            # 421 where the truth was 0.55 and 260, success=True).
            raise invalid(f"labels.{c}", "<a spec path>", "a column that is not a spec path: a label is carried along, never applied, so each row's value would be ignored; leave it out of labels to run each row at its value, or rename the column")
    operating = [c for c in table.columns if c not in taken and c not in labels]
    for c in operating:
        if c not in paths:
            raise invalid(f"data.{c}", "<unknown column>", suggest(c, [*paths, *metric_names], listed_by="ps.spec_paths(spec)", what="a spec path (an operating point), a metric (a measured column; or name it in measured= or labels=)"))
        if c in bounds or _alias(c) in {_alias(n) for n in names}:
            raise invalid(f"params.{c}", "<also a column of data>", "a parameter that is not an operating-point column")
    if not taken:
        raise invalid("measured", "None", f"measured columns: data has no column named after a metric ({', '.join(table.columns[:6])}); map each to its metric with measured={{column: ps.measured(metric, peak_to_peak=..., unit=...)}}")
    if not operating:
        raise invalid("data", "no operating-point columns", "spec-path columns giving each row's operating point (e.g. actuator.waveform.amplitude_v)")
    op = {c: _column(table, c) for c in operating}
    for c, column in op.items():
        bad = np.flatnonzero(~np.isfinite(column))
        if bad.size:
            raise invalid(f"data.{c}", f"row {int(bad[0])} = {column[bad[0]]}", "a finite number on every row")
    y = {c: _column(table, c) for c in taken}
    for c, column in y.items():
        if not np.isfinite(column).any():
            raise invalid(f"data.{c}", "no finite value", "at least one measured number")

    # --- the split
    n_rows = table.height
    split = np.zeros(n_rows, dtype=bool)  # True: held out
    if holdout is not None:
        fraction = real("holdout", holdout)
        if not (0.0 < fraction < 1.0):
            raise invalid("holdout", holdout, "a fraction in (0, 1) of the rows to hold out")
        n_held = int(round(fraction * n_rows))
        if n_held == 0:  # 0.02 of 15 rows held out none, and the held-out errors were NaN
            raise invalid("holdout", holdout, f"a fraction that holds out at least one of the {n_rows} rows (>= {0.5 / n_rows:.3g}), or None")
        split[np.random.default_rng(seed).choice(n_rows, size=n_held, replace=False)] = True
    fit_rows = np.flatnonzero(~split)
    n_obs = sum(int(np.isfinite(y[c][fit_rows]).sum()) for c in taken)
    if n_obs < len(names):
        raise invalid("holdout" if holdout is not None else "data", holdout if holdout is not None else f"{n_rows} rows", f"at least {len(names)} measured values on the fitted rows (one per parameter); got {n_obs}")

    metrics = sorted({m.metric for m in taken.values()})
    mode = jacobian
    if mode in ("auto", "sensitivity"):
        try:
            _core.sensitivity_parameters(spec.to_json(), names)
            mode = "sensitivity"
        except ParitysimError:
            if jacobian == "sensitivity":
                raise
            mode = "differences"

    grid_fit = table[fit_rows.tolist()].select(operating)
    weights = {c: 1.0 / m.sigma for c, m in taken.items()}
    masks = {c: np.isfinite(y[c][fit_rows]) for c in taken}
    state: dict[str, Any] = {"sweeps": 0, "failed": 0, "penalty": None, "gradient_failures": 0}
    log: list[dict[str, float]] = []
    cache: dict[str, Any] = {}

    def run(grid: pl.DataFrame, gradients: bool) -> pl.DataFrame:
        own = spec.options.max_wall_ms  # type: ignore[attr-defined]
        parts = []
        # The budget bounds the whole sweep, not only each point: a long table runs in blocks
        # with the deadline checked between them (a 1e5-row table ran far past max_wall_ms).
        for start in range(0, max(grid.height, 1), _BLOCK_ROWS):
            left = deadline.remaining_ms()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                parts.append(sweep(spec, grid.slice(start, _BLOCK_ROWS), metrics=metrics, threads=threads, progress=False, options={"max_wall_ms": left if own is None else min(own, left)}, gradients=names if gradients else ()))
        df = parts[0] if len(parts) == 1 else pl.concat(parts, how="vertical_relaxed")
        state["sweeps"] += 1
        bar.done()
        deadline.remaining_ms()
        return df

    def with_params(grid: pl.DataFrame, values: np.ndarray) -> pl.DataFrame:
        return grid.with_columns([pl.lit(float(v)).alias(nm) for nm, v in zip(names, values, strict=True)])

    def residuals_of(df: pl.DataFrame, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Weighted residuals of the fitted rows and a mask of the failed entries."""
        res, failed = [], []
        for c, m in taken.items():
            pred = m.factor * df[m.metric].cast(pl.Float64).fill_null(np.nan).to_numpy()
            r = (pred - y[c][rows]) * weights[c]
            res.append(r[masks[c]])
            failed.append(~np.isfinite(r[masks[c]]))
        return np.concatenate(res), np.concatenate(failed)

    def gradient_of(df: pl.DataFrame) -> np.ndarray | None:
        blocks = []
        if any(f"d({m.metric})/d({nm})" not in df.columns for m in taken.values() for nm in names):
            return None  # a sweep run without gradients (a sensitivity failed)
        for c, m in taken.items():
            cols = [df[f"d({m.metric})/d({nm})"].cast(pl.Float64).fill_null(np.nan).to_numpy() for nm in names]
            blocks.append((m.factor * weights[c] * np.column_stack(cols))[masks[c]])
        J = np.vstack(blocks)
        return J if np.isfinite(J).all() else None

    def evaluate(x: np.ndarray) -> np.ndarray:
        df = run(with_params(grid_fit, x), gradients=mode == "sensitivity")
        r, failed = residuals_of(df, fit_rows)
        if failed.any() and mode == "sensitivity":
            # A point whose sensitivity failed (not its run): its metrics without derivatives;
            # the Jacobian of this evaluation then comes from differences.
            state["gradient_failures"] += 1
            df = run(with_params(grid_fit, x), gradients=False)
            r, failed = residuals_of(df, fit_rows)
        if failed.any():
            if state["penalty"] is None:
                raise invalid("x0", {nm: float(v) for nm, v in zip(names, x, strict=True)}, f"a start where every fitted point runs ({int(failed.sum())} failed: {df.filter(pl.col('status') == 'error')['error'].head(1).to_list()})")
            state["failed"] += int(failed.sum())
            r = np.where(failed, state["penalty"], r)
        if state["penalty"] is None:
            state["penalty"] = 10.0 * (float(np.abs(r).max()) + 1.0)
        J = gradient_of(df) if mode == "sensitivity" and not failed.any() else None
        cache.update(x=x.copy(), J=J, r=r)
        log.append({**{nm: float(v) for nm, v in zip(names, x, strict=True)}, "cost": 0.5 * float(r @ r)})
        return r

    lower = np.array([bounds[nm][0] for nm in names])
    upper = np.array([bounds[nm][1] for nm in names])

    def differences(x: np.ndarray) -> np.ndarray:
        f0 = evaluate(x) if cache.get("x") is None or not np.array_equal(cache["x"], x) else cache["r"]
        steps = diff_step * (upper - lower)
        signed = np.where(x + steps > upper, -steps, steps)
        shifted = [np.where(np.arange(len(x)) == i, x + signed, x) for i in range(len(x))]
        grid = pl.concat([with_params(grid_fit, s) for s in shifted])
        df = run(grid, gradients=False)
        m = grid_fit.height
        cols = []
        for i, s in enumerate(signed):
            r, failed = residuals_of(df[i * m : (i + 1) * m], fit_rows)
            r = np.where(failed, f0, r)
            cols.append((r - f0) / s)
        return np.column_stack(cols)

    def jac(x: np.ndarray, *_: Any) -> np.ndarray:
        if cache.get("x") is not None and np.array_equal(cache["x"], x) and cache.get("J") is not None:
            return np.asarray(cache["J"])
        return differences(x)

    bar = LongRun("calibrate", progress, deadline.ms, unit="sweep")
    with bar:
        try:
            fit = least_squares(evaluate, np.array(start), jac=jac, bounds=(lower, upper), x_scale="jac", max_nfev=max_nfev, xtol=xtol, ftol=ftol)
        except ValueError as exc:
            if isinstance(exc, ParitysimError):
                raise
            # Not the start's fault: evaluate() refused a failing start already (issue 34).
            raise not_finite(exc, "params", bounds, log) from exc
        x = np.asarray(fit.x, dtype=float)
        J = np.asarray(fit.jac, dtype=float)
        # The prediction of every row at the fit (fitted and held out): one sweep.
        final = run(with_params(table.select(operating), x), gradients=False)

    m_obs, p = J.shape
    dof = m_obs - p
    ssr = float(fit.fun @ fit.fun)
    s2 = ssr / dof if dof > 0 else math.nan
    notes = []
    try:
        inv = np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        inv = np.linalg.pinv(J.T @ J)
        notes.append("the Jacobian at the fit is singular: some parameters are not identified by these data (pseudo-inverse)")
    cov = s2 * inv
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    # A parameter the data cannot see (a column of J that others span, or zero) has no finite
    # error: the pseudo-inverse gave it 0, "perfectly determined" (a wing's force parameter
    # fitted to stroke amplitudes read 0.0 %).
    _, singular, vt = np.linalg.svd(J, full_matrices=True)
    rank = int(np.sum(singular > 1e-10 * singular.max())) if singular.size and singular.max() > 0 else 0
    unseen = np.any(np.abs(vt[rank:]) > 1e-6, axis=0) if rank < p else np.zeros(p, dtype=bool)
    se = np.where(unseen, math.inf, se)
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    if dof <= 0:
        notes.append(f"no degrees of freedom left ({m_obs} measured values for {p} parameters): no standard errors")
    if state["gradient_failures"]:
        notes.append(f"{state['gradient_failures']} evaluation(s) took the Jacobian from differences: the sensitivity of some point failed")
    unconverged = int((final["status"] == "unconverged").sum())
    if unconverged:
        notes.append(f"{unconverged} rows did not reach a steady state at the fit (their metrics are those of the last cycles run)")

    out = table.with_columns(pl.Series("split", np.where(split, "holdout", "fit")))
    rows = []
    for c, m in taken.items():
        pred = m.factor * final[m.metric].cast(pl.Float64).fill_null(np.nan).to_numpy()
        out = out.with_columns(pl.Series(f"predicted_{c}", pred))
        err = pred - y[c]
        stats: dict[str, Any] = {"column": c, "metric": m.metric, "unit": m.unit_label}
        for part, sel in (("fit", ~split), ("holdout", split)):
            e = err[sel & np.isfinite(y[c])]
            stats[f"n_{part}"] = int(e.size)
            stats[f"{part}_rms"] = float(np.sqrt(np.mean(e**2))) if e.size else math.nan
            stats[f"{part}_max"] = float(np.max(np.abs(e))) if e.size else math.nan
        rows.append(stats)
    out = out.with_columns(final["status"].alias("status"))
    values = {nm: float(v) for nm, v in zip(names, x, strict=True)}
    return TableCalibrationResult(
        names=names,
        values=values,
        stderr={nm: float(s) if dof > 0 else math.nan for nm, s in zip(names, se, strict=True)},
        correlation=corr,
        covariance=cov,
        bounds=bounds,
        success=bool(fit.success),
        status=int(fit.status),
        message=str(fit.message),
        cost=float(fit.cost),
        dof=dof,
        residual_std=math.sqrt(s2) if dof > 0 else math.nan,
        errors=pl.DataFrame(rows, schema_overrides={"unit": pl.String}),
        table=out,
        spec=spec.with_paths(values),
        iterations=pl.DataFrame(log),
        sweeps=state["sweeps"],
        jacobian=mode,
        measured=taken,
        operating=operating,
        failed_points=state["failed"],
        notes=notes,
    )


def _core_paths(spec: Simulation) -> pl.DataFrame:
    from .spec import spec_paths

    return spec_paths(spec)


def measured_of(column: str, given: Any) -> Measured:
    """A `Measured` from a ``measured=`` value (a metric name is that metric in its own unit)."""
    if isinstance(given, Measured):
        return given
    if isinstance(given, str):
        return Measured(given)
    raise invalid(f"measured.{column}", repr(given)[:60], "ps.measured(metric, peak_to_peak=..., unit=...) or a metric name")
