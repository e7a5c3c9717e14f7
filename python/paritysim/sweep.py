"""Parameter sweeps: thousands of simulations of one design, in parallel, as one DataFrame.

```python
import paritysim as ps
spec = ps.devices.load("sreetharan2012_3_3_parity")   # §3.3 Drag PARITY (eq. 2.15)
df = ps.sweep(spec, {"drivetrain.balance_spring": [0.0, 1.0, 2.0], "wings.left.omega_ratio": [1.0, 0.8, 0.6]},
              metrics=["left_roll_aero_peak", "right_roll_aero_peak"])
```

``paritysim.sweep`` is this module and, called, the `sweep` function (``ps.sweep(...)``).
The rod-crank linkage device (``sreetharan2012_3_3_parity_linkage``, ``examples/drag_parity.toml``)
fails on cut wings: its whippletree mode is unstable at small K2 (docs/findings.md §3).

Each point is the base spec with some fields overridden, run to periodic steady state by the
Rust engine on a local thread pool (GIL released). The result has one row per point in input
order: ``point`` (its index), one column per swept parameter, the metrics, ``converged``,
``cycles_run``, ``orbit_cycles`` (drive periods per period of the steady state: 1, or 2 where
the point's orbit has period-doubled; its metrics then span both cycles), ``status`` (``"ok"``:
converged; ``"unconverged"``: ran, but did not reach its steady state, with a warning naming how
many; ``"error"``: failed), ``error`` and ``error_kind`` (why a point failed or did not converge;
every row is kept).

Parameter paths
---------------
One path language for sweeps, calibration and overrides, owned by the Rust spec crate and
checked before anything runs (an unknown path raises ``InvalidParameterError`` naming the nearest
valid one). `paritysim.spec_paths` lists every path of a spec with its unit and range:

* ``wings[i].inertia[r][c]``, ``wings[i].shoulder.alpha2``,
  ``wings[i].springs.<joint>.stiffness`` (joints ``stroke``, ``passive_s2``, ``passive_s3``,
  ``deviation``, ``wing_deviation``, ``hinge``; fields ``stiffness``, ``cubic``, ``rest_angle``),
  ``wings[i].aero.<field>``, ``wings[i].tunable_hinge.<field>``;
* ``drivetrain.<field>`` (``balance_spring``, ``crank_mm``, ``arm_ratio``, ``kind``...);
* ``actuator.force_per_volt``, ``actuator.stiffness``, ``actuator.waveform.<field>``;
* ``configuration.name``, ``formulation`` and ``options.<field>`` (``max_cycles``, ``rtol``...).

Aliases: ``wings.left`` / ``wings.right`` for ``wings[0]`` / ``wings[1]`` of a two-wing spec;
``wings[*]`` for every wing at once; ``actuator.frequency_hz`` and ``actuator.amplitude_v`` (or
``actuator.voltage_v``) for the waveform fields; ``wings[i].omega_ratio`` multiplies that wing's
``aero.omega1`` by the value (a cut wing of Table 3.2: ``wings.left.omega_ratio = 0.6``).
Deprecated (accepted with a warning): ``drivetrain.k2`` and ``drivetrain.balance_stiffness``
(now ``drivetrain.balance_spring``), ``wings[i].springs[j].<field>`` (now named joints).

Indices are 0-based: ``wings[0]`` is the left wing (eq. 3.21). Springs are named by joint:
``springs.stroke`` is the stroke φ (γ1), ``springs.deviation`` the deviation θ (γ4) and
``springs.hinge`` the wing-rotation (ψ) hinge (γ6, eq. 2.1).

Label columns
-------------
Columns named in ``labels=`` are not parameters: they are carried, unchanged, into the result
(e.g. a ``cut_fraction`` column next to the Ω columns computed from
`paritysim.Planform.cut`), so results need no join.

Threads, progress, checkpoints, clusters
----------------------------------------
``threads=None`` uses ``$PARITYSIM_THREADS`` if set, else every core. ``progress=True`` shows a
tqdm bar (rate, ETA) fed from the engine's atomic counter; Ctrl-C cancels cleanly: running points
stop within milliseconds (they count as not run), the finished rows are checkpointed and
`SweepInterrupted` (a ``KeyboardInterrupt``) is raised carrying them as ``.result``.
``checkpoint="runs/study.parquet"`` flushes finished chunks to ``runs/study.parquet.parts/``
and writes the complete, ordered table to ``runs/study.parquet`` at the end; re-running the
same call skips every point already there (points are matched by their parameter values, so an
extended grid reuses the old points). ``executor=`` takes any ``concurrent.futures.Executor``
(``ProcessPoolExecutor``, ``dask.distributed.Client.get_executor()``): chunks of points are sent
to it and each runs on one engine thread. Ctrl-C there cancels the pending chunks and stops the
running ones inside integration through a stop file the workers poll every 20 ms (workers on
the same machine or a shared filesystem; a remote worker that cannot see it finishes its
chunk): their finished points are kept and checkpointed, and `SweepInterrupted` is raised as
in process.
"""

from __future__ import annotations

import concurrent.futures as cf
import itertools
import logging
import math
import os
import numbers
import warnings
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import polars as pl

from . import _core
from . import _sweep_chunks as runner
from ._core import ParitysimError
from ._errors import invalid, suggest, whole
from ._sweep_checkpoint import _Checkpoint, _fingerprint, _reuse
from .devices import as_simulation
from .spec import Simulation, SpecLike, _dumps

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["THREADS_ENV", "SweepInterrupted", "grid", "plot", "sweep", "valid_paths"]

logger = logging.getLogger(__name__)

#: Environment variable giving the default thread count (a positive integer).
THREADS_ENV: str = _core.SWEEP_THREADS_ENV

#: Result columns besides the parameters and metrics.
STATUS_COLUMNS = ("converged", "cycles_run", "orbit_cycles", "status", "error", "error_kind")

#: Points per thread in a local chunk of a metrics-only sweep (see ``sweep``'s ``chunk_size``).
_LOCAL_CHUNK_PER_THREAD = 1024
#: The most points of such a chunk on a many-core machine (about 160 MB of built devices).
_LOCAL_CHUNK_MAX = 16384

# --------------------------------------------------------------------------- parameter paths


def valid_paths(spec: Simulation, aliases: bool = True) -> list[str]:
    """Every parameter path `sweep` accepts for ``spec`` (canonical, then aliases)."""
    paths = [row[0] for row in _core.spec_paths(spec.to_json())]
    if not aliases:
        return paths
    fields = sorted({p[len("wings[0].") :] for p in paths if p.startswith("wings[0].")})
    if spec.wings[0].aero is not None:
        fields.append("omega_ratio")
    out = paths + [f"wings[*].{f}" for f in fields]
    if len(spec.wings) == 2:
        out += [f"wings.{side}.{f}" for side in ("left", "right") for f in fields]
    if spec.actuator is not None:
        out += ["actuator.frequency_hz", "actuator.amplitude_v", "actuator.voltage_v"]
    out += [f"wings[{i}].omega_ratio" for i, w in enumerate(spec.wings) if w.aero is not None]
    return out


# ------------------------------------------------------------------------------ grids


def grid(axes: Mapping[str, Iterable[Any]]) -> pl.DataFrame:
    """The Cartesian product of ``axes`` as a DataFrame (first axis slowest, like
    ``itertools.product``); pass it, filtered or not, as `sweep`'s ``grid``.

    >>> grid({"drivetrain.balance_spring": [1, 2], "actuator.frequency_hz": [100.0, 110.0, 120.0]}).height
    6
    """
    if not isinstance(axes, Mapping):
        raise invalid("grid", type(axes).__name__, "a mapping from parameter path to values")
    names = list(axes)
    _check_columns(names)
    values = [_axis(name, axes[name]) for name in names]
    if not names:
        return pl.DataFrame()
    points = math.prod(len(v) for v in values)
    if points > MAX_GRID_POINTS:
        sizes = " × ".join(str(len(v)) for v in values)
        raise invalid("grid", f"{sizes} = {points:.3g} points", f"at most {MAX_GRID_POINTS:.0e} points (split the study)")
    columns: list[list[Any]] = [[] for _ in names]
    for combo in itertools.product(*values):
        for k, v in enumerate(combo):
            columns[k].append(v)
    return pl.DataFrame({n: pl.Series(n, c, strict=False) for n, c in zip(names, columns, strict=True)})


#: The most points a grid may hold (1e8 rows of one float are 0.8 GB before any run).
MAX_GRID_POINTS = 10**8


def _axis(name: str, raw: Any) -> list[Any]:
    """One axis' values: a list, a numpy array or one value (a lone number or text is a
    one-point axis, as in a study file). Each is a number, a text, a flag or a list (a path
    such as ``body.set_points[0].values`` takes one), one kind per axis: a ``None`` or a mixed
    axis is an error naming its index (a mixed list became text in every row, so every point
    failed)."""
    if isinstance(raw, np.ndarray):
        vals = raw.ravel().tolist()
    elif isinstance(raw, str | bytes | numbers.Number) or not isinstance(raw, Iterable):
        vals = [raw]
    elif isinstance(raw, range) and len(raw) > MAX_GRID_POINTS:
        raise invalid(f"grid[{name!r}]", f"{len(raw):.3g} values", f"at most {MAX_GRID_POINTS:.0e} values")
    else:
        vals = list(itertools.islice(raw, MAX_GRID_POINTS + 1))
    if not vals:
        raise invalid(f"grid[{name!r}]", "[]", "at least one value")
    if len(vals) > MAX_GRID_POINTS:
        raise invalid(f"grid[{name!r}]", f"more than {MAX_GRID_POINTS:.0e} values", f"at most {MAX_GRID_POINTS:.0e} values")
    first = _kind(vals[0])
    for i, v in enumerate(vals):
        kind = _kind(v)
        if kind is None or kind != first:
            allowed = f"a {first}, as the axis' first value (one kind per axis)" if first and kind else "a number, a text, a flag or a list of numbers (one value per point)"
            raise invalid(f"grid[{name!r}][{i}]", repr(v)[:60], allowed)
    return [v.item() if isinstance(v, np.generic) else v for v in vals]


def _kind(v: Any) -> str | None:
    """What kind of spec value ``v`` is: ``"flag"``, ``"number"``, ``"text"``, or ``None``."""
    if isinstance(v, bool | np.bool_):
        return "flag"
    if isinstance(v, numbers.Real):
        return "number"
    if isinstance(v, str):
        return "text"
    if isinstance(v, list | tuple) and all(_kind(x) == "number" for x in v):
        return "list"
    return None


def _table(spec_grid: Any) -> pl.DataFrame:
    if spec_grid is None:
        return pl.DataFrame()
    if isinstance(spec_grid, pl.DataFrame):
        _check_columns(spec_grid.columns)
        return spec_grid
    if isinstance(spec_grid, Mapping):
        return grid(spec_grid)
    if isinstance(spec_grid, Sequence) and not isinstance(spec_grid, str | bytes) and all(isinstance(r, Mapping) for r in spec_grid):
        for row in spec_grid:
            _check_columns(list(row))
        try:
            return pl.DataFrame(list(spec_grid), strict=False)
        except (TypeError, ValueError, pl.exceptions.PolarsError) as exc:
            raise invalid("grid", f"{len(spec_grid)} rows", f"row dicts of numbers or text ({str(exc)[:80]})") from exc
    raise invalid("grid", type(spec_grid).__name__, "a mapping of axes, a polars DataFrame of rows, or a list of row dicts")


# ------------------------------------------------------------------------------ sweep


def sweep(
    spec: SpecLike,
    grid: Mapping[str, Iterable[Any]] | pl.DataFrame | Sequence[Mapping[str, Any]] | None = None,
    *,
    metrics: Sequence[str] | None = None,
    keep_cycle: bool | Sequence[str] = False,
    threads: int | None = None,
    progress: bool = True,
    checkpoint: str | os.PathLike[str] | None = None,
    executor: cf.Executor | None = None,
    chunk_size: int | None = None,
    options: Mapping[str, Any] | None = None,
    labels: Sequence[str] = (),
    gradients: Sequence[str] | None = (),
) -> pl.DataFrame:
    """Run ``spec`` over a table of parameter overrides; one row per point, in input order.

    Parameters
    ----------
    spec:
        The base design: a `paritysim.Simulation`, its dict, a device's name or a TOML file.
    grid:
        A mapping ``{path: values}`` (Cartesian product, see `grid`; a lone value is a
        one-point axis; each axis holds numbers, texts or flags, one kind, no ``None``), a
        Polars DataFrame whose columns are paths and rows are points, or a list of
        ``{path: value}`` rows. In the last two a null (a path a row leaves out) keeps the
        base design's value at that point. Paths are listed in the module docstring and by
        `valid_paths`. None (or ``{}``, the product of no axes) runs the base design once; an
        empty table or list of rows runs nothing.
    metrics:
        Metric names to keep (default: all that `paritysim.simulate` reports). They are
        streamed by the engine from every sample of the recorded window, including Table 3.2's
        ``delta_tau_peak``, ``tau_l_peak``, ``tau_r_peak``, ``imbalance_instantaneous_pct``,
        ``imbalance_peak_pct`` and the cycle ``_mean`` / ``_rms`` / ``_peak`` of the roll, yaw
        and pitch torques per wing (``left_roll_rms``) and net (``yaw_total_mean``), so
        ``keep_cycle`` is not needed for them.
    keep_cycle:
        True keeps the last recorded cycle of each point as list columns ``cycle_time_ms``,
        ``cycle_<column>`` for every trajectory column; a list of trajectory column names keeps
        only those (plus ``cycle_time_ms``).
    threads:
        Engine threads (default ``$PARITYSIM_THREADS``, else every core). With ``executor``,
        the threads each chunk uses on its worker (default 1).
    progress:
        Show a tqdm progress bar.
    checkpoint:
        A ``.parquet`` path: finished chunks are flushed as they complete and re-running the
        same call skips the points already computed.
    executor:
        Any ``concurrent.futures.Executor`` (e.g. ``dask.distributed.Client.get_executor()``);
        chunks of points are submitted to it.
    chunk_size:
        Points per chunk (default locally: 1024 per thread up to 16384, 256 per thread with
        ``checkpoint`` or ``keep_cycle``; with an executor about 16 chunks per worker, at
        most 256).
    options:
        Overrides of ``spec.options`` for every point, e.g. ``{"max_cycles": 50}``.
    labels:
        Grid columns that are not parameter paths (e.g. ``"cut_fraction"``): passed through
        to the result unchanged, never applied to the spec.
    gradients:
        Continuous spec paths (as `paritysim.sensitivity` takes them): every converged row
        gains ``d(<metric>)/d(<path>)`` columns, the derivatives `paritysim.sensitivity` gives
        at that point (null where the metric, or the orbit in the path, is not differentiable
        there, or the point did not converge; ``gradient_error`` says why a converged point has none). They are taken at
        the orbits a sweep finds (chained from neighbours, as the rows' metrics), so they agree
        with `paritysim.sensitivity`'s, taken at the orbit of a run from rest, to their own
        accuracy (at rtol 1e-8 within about 1e-5 relative; both are that close to rtol-1e-11
        derivatives). Costs about a sensitivity per point (four periods per path), computed in
        this process on the sweep's ``threads`` as each chunk finishes. ``()`` or None: no
        derivatives.

    Returns
    -------
    polars.DataFrame
        ``point``, the parameter columns, the metrics, ``converged``, ``cycles_run``,
        ``orbit_cycles``, ``status`` (``"ok"`` converged, ``"unconverged"``, ``"error"``),
        ``error``, ``error_kind``, and with ``gradients`` the ``d(metric)/d(path)`` columns
        and ``gradient_error``, with ``keep_cycle`` the ``cycle_*`` columns. A ``RuntimeWarning`` names how many points did not
        converge, and, when more than half of the points fail, the most common error (the
        ``"paritysim"`` logger records both).

    Raises
    ------
    InvalidParameterError
        Before any point runs: an unknown parameter path, metric or trajectory column, a bad
        ``threads`` / ``chunk_size`` / ``options``, or a checkpoint from a different sweep.
        Invalid base specs raise the usual typed errors. Failures of individual points do not
        raise: they are rows with ``status = "error"``.
    SweepInterrupted
        On Ctrl-C, after the finished rows were flushed to the checkpoint; ``.result`` holds
        them.
    """
    spec = as_simulation(spec)
    if options is not None and not isinstance(options, Mapping):
        raise invalid("options", type(options).__name__, "a mapping of spec options, e.g. {\"max_cycles\": 50}")
    if options:
        spec = spec.replace(options=spec.options.with_fields("options", **{str(k): v for k, v in options.items()}))
    table = _table(grid)
    # An empty list of rows runs nothing, as an empty table does (None runs the base design).
    no_rows = isinstance(grid, Sequence) and not isinstance(grid, str | bytes) and len(grid) == 0
    _check_values(table)
    label_names = _names("labels", labels)
    if metrics is not None:
        metrics = _names("metrics", metrics)
    if not isinstance(keep_cycle, bool) and keep_cycle is not None:
        keep_cycle = _names("keep_cycle", keep_cycle)
    if threads is not None:
        threads = whole("threads", threads, 1, 4096)
    for name in label_names:
        if name not in table.columns:
            raise invalid("labels", repr(name), suggest(str(name), table.columns, what="a column of the grid"))
    param_table = table.drop(label_names) if label_names else table
    spec_json = spec.to_json()
    _core.validate_spec(spec_json)  # the base design must be valid (typed error naming the field)
    valid_metrics = _core.sweep_metric_names(spec_json)
    metric_names = list(valid_metrics if metrics is None else metrics)
    # Resolves every path (unknown: the nearest valid one), duplicates, metrics: before running.
    probe = _core.SweepRun(spec_json, [str(c) for c in param_table.columns], "[]", metric_names, threads=threads)
    for note in probe.notes:
        warnings.warn(note, DeprecationWarning, stacklevel=2)
    cycle_columns = _cycle_columns(spec_json, keep_cycle)
    gradient_paths = _gradient_paths(spec_json, gradients)
    if executor is None:
        n_threads = _core.sweep_resolve_threads(threads)
    else:
        if not isinstance(executor, cf.Executor):
            raise invalid("executor", type(executor).__name__, "a concurrent.futures.Executor")
        n_threads = _core.sweep_resolve_threads(threads if threads is not None else 1)
    if chunk_size is not None:
        chunk_size = whole("chunk_size", chunk_size, 1, 2**31)  # numpy integers too, as threads

    rows = param_table.rows() if param_table.width else [] if no_rows else [()] * max(table.height, 1)
    n = len(rows)
    fingerprinted = [*metric_names, *_gradient_columns(metric_names, gradient_paths)]
    store = _Checkpoint(checkpoint, _fingerprint(spec_json, table.columns, fingerprinted, cycle_columns), table.columns) if checkpoint is not None else None
    done: list[pl.DataFrame] = []
    todo = list(range(n))
    if store is not None:
        previous = store.load()
        if previous is not None and previous.height:
            done_frame, todo = _reuse(previous, table, table.rows() if table.width else rows)
            done.append(done_frame)

    if chunk_size is None:
        if executor is None:
            if checkpoint is not None or cycle_columns:
                # Checkpoints flush per chunk, and kept cycles are large rows.
                chunk_size = 256 * n_threads
            else:
                # Every chunk ends with lanes idling while its last chains finish, so few, large
                # chunks (docs/findings.md §19); a chunk's points are built as devices before it
                # runs, hence the cap.
                chunk_size = min(_LOCAL_CHUNK_PER_THREAD * n_threads, max(256 * n_threads, _LOCAL_CHUNK_MAX))
        else:
            workers = runner.executor_workers(executor)
            chunk_size = max(1, min(256, math.ceil(len(todo) / (16 * workers)))) if todo else 1
    chunks = [todo[i : i + chunk_size] for i in range(0, len(todo), chunk_size)]

    def make(points: list[int]) -> runner.Chunk:
        return runner.Chunk(spec_json, tuple(param_table.columns), [rows[i] for i in points], points, metric_names, bool(cycle_columns), n_threads)

    def frame(points: list[int], raw: dict[str, Any] | BaseException) -> pl.DataFrame:
        if isinstance(raw, BaseException):
            raw = runner.failed_raw(len(points), len(metric_names), cycle_columns, raw)
        if not table.width:
            params = table
        elif points and points == list(range(points[0], points[0] + len(points))):  # local runs: a slice
            params = table.slice(points[0], len(points))
        else:
            params = table[points]
        df = runner.frame(raw, params, points, metric_names, cycle_columns)
        return _with_gradients(df, spec_json, list(param_table.columns), gradient_paths, metric_names, n_threads) if gradient_paths else df

    from tqdm.auto import tqdm  # type: ignore[import-untyped]

    bar = tqdm(total=n, initial=n - len(todo), unit="pt", desc="sweep", disable=not progress, smoothing=0.05, dynamic_ncols=True)
    new: list[pl.DataFrame] = []

    def finished_chunk(df: pl.DataFrame) -> None:
        new.append(df)
        if store is not None:
            store.flush(df)

    try:
        if executor is None:
            cancelled = runner.run_local(chunks, make, frame, finished_chunk, bar)
        else:
            cancelled = runner.run_executor(executor, chunks, make, frame, finished_chunk, bar)
    finally:
        bar.close()
    result = runner.assemble(done + new, table, metric_names, cycle_columns)
    if gradient_paths and result.height == 0:
        result = result.with_columns([pl.lit(None, pl.Float64).alias(c) for c in _gradient_columns(metric_names, gradient_paths)] + [pl.lit(None, pl.String).alias("gradient_error")])
    if cancelled:
        # The finished rows are flushed (checkpoint) before this; the caller gets them on the
        # exception, never as a silently short table.
        raise SweepInterrupted(result, n, store.parts if store is not None else None)
    if store is not None:
        store.finish(result)
    _report_failures(result)
    return result


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C during `sweep`: raised after the finished rows were saved.

    A ``KeyboardInterrupt`` (code that stops on Ctrl-C keeps stopping); ``.result`` holds the
    rows of the points that finished (sorted by ``point``), ``.total`` the number of points of
    the sweep and ``.checkpoint`` the directory the rows were flushed to (None without
    ``checkpoint=``). Re-running the same call with the same checkpoint resumes.
    """

    def __init__(self, result: pl.DataFrame, total: int, checkpoint: Path | None) -> None:
        where = f"; checkpointed in {checkpoint}" if checkpoint is not None else ""
        super().__init__(f"sweep interrupted after {result.height} of {total} points{where}")
        self.result = result
        self.total = total
        self.checkpoint = checkpoint


def _gradient_paths(spec_json: str, gradients: Sequence[str] | None) -> list[str]:
    """The ``gradients`` paths, checked before any point runs (unknown, discrete or
    wing-dependent paths are the typed errors of `paritysim.sensitivity`); None: none."""
    if gradients is None:
        return []
    if isinstance(gradients, str):
        gradients = [gradients]
    paths = _names("gradients", gradients)
    for p in paths:
        if not p.strip():
            raise invalid("gradients", repr(p), "non-empty spec paths")
    paths = list(dict.fromkeys(paths))  # a path listed twice is one set of columns, as for metrics
    if paths:
        _core.sensitivity_parameters(spec_json, paths)
    return paths


def _gradient_columns(metrics: Sequence[str], paths: Sequence[str]) -> list[str]:
    return [f"d({m})/d({p})" for p in paths for m in metrics]


def _with_gradients(df: pl.DataFrame, spec_json: str, names: list[str], paths: list[str], metrics: list[str], threads: int) -> pl.DataFrame:
    """``df`` with the derivative columns of its converged rows (see `sweep`'s ``gradients``)."""
    columns = _gradient_columns(metrics, paths)
    values: dict[str, list[float | None]] = {c: [None] * df.height for c in columns}
    errors: list[str | None] = [None] * df.height
    status = df["status"].to_list()
    rows = df.select(names).rows() if names else [()] * df.height
    converged = [i for i, state in enumerate(status) if state == "ok"]
    # One native call for the chunk's converged points, on the sweep's own thread count.
    raw = _core.sensitivity_rows(spec_json, [_dumps(dict(zip(names, rows[i], strict=True))) for i in converged], paths, metrics, threads)
    for i, point, kind, error in zip(converged, raw["rows"], raw["error_kind"], raw["error"], strict=True):
        if not isinstance(point, dict):  # the converter hands an all-failed column over as NaN
            errors[i] = f"{kind}Error: {error}"
            continue
        index = {m: k for k, m in enumerate(point["metric"])}
        for j, path in enumerate(paths):
            column = point["jacobian"][j]
            for m in metrics:
                k = index.get(m)
                if k is not None and not point["not_differentiable"][k]:
                    v = float(column[k])
                    values[f"d({m})/d({path})"][i] = v if math.isfinite(v) else None
    return df.with_columns([pl.Series(c, v, dtype=pl.Float64) for c, v in values.items()] + [pl.Series("gradient_error", errors, dtype=pl.String)])


def _report_failures(result: pl.DataFrame) -> None:
    """Logs a summary; warns when more than half of the points failed, naming the most common error."""
    if not result.height or "status" not in result.columns:
        return
    failed = result.filter(pl.col("status") == "error")
    unconverged = int((result["status"] == "unconverged").sum())
    logger.info("sweep: %d points, %d failed, %d unconverged", result.height, failed.height, unconverged)
    if unconverged:
        message = (
            f"{unconverged} of {result.height} sweep points did not converge (status = 'unconverged'; "
            "the 'error' column says why): filter on status == 'ok' for converged rows"
        )
        logger.warning(message)
        warnings.warn(message, RuntimeWarning, stacklevel=_caller_stacklevel())
    if 2 * failed.height <= result.height:
        return
    kinds = Counter(zip(failed["error_kind"].fill_null("?").to_list(), failed["error"].fill_null("").to_list(), strict=True))
    by_kind = Counter(k for k, _ in kinds.elements())
    kind, count = by_kind.most_common(1)[0]
    example = next(msg for (k, msg) in kinds if k == kind)
    message = (
        f"{failed.height} of {result.height} sweep points failed; most common error ({count} points): {kind}: {example}. "
        "Failed rows have status = 'error' (see the 'error' column)"
    )
    logger.warning(message)
    warnings.warn(message, RuntimeWarning, stacklevel=_caller_stacklevel())


def _caller_stacklevel() -> int:
    """The ``stacklevel`` (seen from the caller of this function) of the first frame outside
    the paritysim package, so warnings point at the user's line however sweep was reached."""
    import sys

    package = os.path.dirname(os.path.abspath(__file__))
    frame, level = sys._getframe(1), 1
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(package):
        frame, level = frame.f_back, level + 1  # type: ignore[assignment]
    return level


def _check_columns(names: Sequence[Any]) -> None:
    """Grid columns are parameter paths or labels: non-empty text."""
    for name in names:
        if not isinstance(name, str) or not name.strip():
            raise invalid("grid", repr(name)[:60], "columns named by parameter paths (see paritysim.spec_paths) or labels: non-empty text")


def _check_values(table: pl.DataFrame) -> None:
    """Grid values are plain data (numbers, text, booleans, lists of them): a column of Python
    objects can be neither sent to the engine nor stored in a checkpoint (issue 34)."""
    for column in table.get_columns():
        if column.dtype == pl.Object:
            shown = next((repr(v) for v in column.to_list() if not isinstance(v, int | float | str | bool) and v is not None), "?")
            raise invalid(column.name, shown[:60], "numbers, text or booleans (grid values are plain data)")


def _names(field: str, value: Any) -> list[str]:
    """A name or a sequence of names, or an error naming ``field``."""
    if isinstance(value, str):
        return [value]
    if isinstance(value, Iterable) and not isinstance(value, bytes | Mapping):
        names = list(value)
        for name in names:
            if not isinstance(name, str):
                raise invalid(field, repr(name)[:60], "names (str)")
        return names
    raise invalid(field, repr(value)[:60], "a name or a list of names (str)")


def _cycle_columns(spec_json: str, keep_cycle: bool | Sequence[str]) -> list[str]:
    if keep_cycle is False or keep_cycle is None:
        return []
    available = ["time_ms", *_core.sweep_trajectory_columns(spec_json)]
    if keep_cycle is True:
        return available
    if isinstance(keep_cycle, str):
        keep_cycle = [keep_cycle]
    wanted = ["time_ms", *[c for c in keep_cycle if c != "time_ms"]]
    for c in wanted:
        if c not in available:
            raise invalid("keep_cycle", repr(c), "True or trajectory column names; " + suggest(c, available, what="a trajectory column"))
    return wanted


# ------------------------------------------------------------------------------ plotting


def plot(df: pl.DataFrame, x: str, y: str | Sequence[str], hue: str | None = None, path: str | os.PathLike[str] | None = None, ax: Any = None) -> Figure:
    """Lines of ``y`` against ``x`` (one per value of ``hue``) from the ``ok`` rows of a sweep
    result; saved as PNG when ``path`` is given. Axis and legend labels carry units
    (`paritysim.plots.label_with_unit`)."""
    import matplotlib.pyplot as plt

    from .plots import label_with_unit

    if not isinstance(df, pl.DataFrame):
        raise invalid("df", type(df).__name__, "a sweep result (a polars DataFrame from ps.sweep)")
    ys = [y] if isinstance(y, str) else list(y) if isinstance(y, Sequence) else [y]
    if not ys:
        raise invalid("y", "[]", "a column name or a non-empty list of them")
    named = [("x", x), *((("y" if isinstance(y, str) else f"y[{i}]"), c) for i, c in enumerate(ys)), *([("hue", hue)] if hue else [])]
    for field, c in named:  # the argument (and the study's [plot] key) that names the column
        if c not in df.columns:
            raise invalid(field, repr(c), suggest(str(c), df.columns, what="a column of the sweep result"))
        if df[c].dtype.is_nested():  # a kept cycle is a list per row
            raise invalid(field, repr(c), f"a column of one value per row ({c} holds {df[c].dtype}: a kept cycle is plotted per row, e.g. plt.plot(row['cycle_time_ms'], row['{c}']))")
    if ax is not None and not hasattr(ax, "plot"):
        raise invalid("ax", type(ax).__name__, "a matplotlib Axes (or None for a new figure)")
    ok = df.filter(pl.col("status") == "ok") if "status" in df.columns else df
    if ax is None:
        fig, ax = plt.subplots(figsize=(6, 4), layout="constrained")
    else:
        fig = ax.figure
    groups = ok.partition_by(hue, maintain_order=True) if hue else [ok]
    for g in groups:
        g = g.sort(x)
        for col in ys:
            parts = []
            if hue:
                v = g[hue][0]
                unit = label_with_unit(hue)[len(hue) :].strip(" ()")
                parts.append(f"{hue} = {v:g}{' ' + unit if unit else ''}" if isinstance(v, float | int) and not isinstance(v, bool) else f"{hue} = {v}")
            if len(ys) > 1:
                parts.append(label_with_unit(col))
            ax.plot(g[x].to_numpy(), g[col].to_numpy(), marker="o", ms=3, label=", ".join(parts) or None)
    ax.set_xlabel(label_with_unit(x))
    units = {label_with_unit(c)[len(c) :] for c in ys}
    ax.set_ylabel(label_with_unit(ys[0]) if len(ys) == 1 else "value" + (units.pop() if len(units) == 1 else ""))
    ax.grid(alpha=0.3)
    if hue or len(ys) > 1:
        ax.legend(fontsize=8)
    if path is not None:
        from .plots import save

        save(fig, path, close=False)
    return fig


# `paritysim.sweep` is this module; calling it calls `sweep` (``ps.sweep(spec, grid)``).
from ._callable_module import make_callable  # noqa: E402

make_callable(__name__, "sweep")
