"""How a sweep's points run: chunks of points, each one native run (`_core.SweepRun`) on the
local engine or in an executor worker, and the rows a finished chunk becomes.

`paritysim.sweep` builds the chunks and assembles the table; this module runs them. A chunk is
picklable (`Chunk`), so an executor worker receives it and calls `run_chunk`. `frame` turns a
chunk's raw result into rows: failed points are null metrics with their error, and a point that
ran without converging is ``"unconverged"``, never ``"ok"``. A chunk that fails as a whole
(`failed_raw`) is one error row per point: a sweep never loses rows.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import dataclasses
import json
import os
import shutil
import tempfile
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import polars as pl

from . import _core
from .spec import _dumps

# The `error` of a row with status "unconverged".
UNCONVERGED_REASON = (
    "no periodic steady state within options.steady_tol after {cycles} cycles (raise options.max_cycles "
    "or loosen options.steady_tol); the metrics are those of the last cycles run"
)


@dataclass(frozen=True)
class Chunk:
    """A picklable batch of points (what an executor worker receives)."""

    spec: str  # JSON
    names: tuple[str, ...]
    rows: list[tuple[Any, ...]]
    points: list[int]
    metrics: list[str]
    keep_cycle: bool
    threads: int
    # A file whose appearance asks the worker to stop (Ctrl-C in the submitting process reaches
    # chunks already running in executor workers on the same machine); None: run to the end.
    stop_file: str | None = None


def prepare(chunk: Chunk) -> _core.SweepRun:
    """The run of a chunk (paths resolved in Rust; points are built on the engine's pool)."""
    return _core.SweepRun(chunk.spec, list(chunk.names), rows_json(chunk.rows), chunk.metrics, chunk.keep_cycle, chunk.threads)


def rows_json(rows: Sequence[Sequence[Any]]) -> str:
    """The rows as JSON. Plain Python values (what ``DataFrame.rows()`` gives) take the C
    encoder directly; anything else (numpy scalars, NaN, dataclasses) goes through
    ``spec._dumps``, which names non-finite values for Rust's error message."""
    try:
        return json.dumps(rows, allow_nan=False)
    except (TypeError, ValueError):
        return _dumps(rows)


RESULT_FIELDS = ("finished", "ok", "metrics", "converged", "cycles_run", "orbit_cycles", "error", "error_kind", "cycle")


def raw_fields(result: _core.SweepResult) -> dict[str, Any]:
    """The fields of a native result as a picklable dict."""
    raw = {name: getattr(result, name) for name in RESULT_FIELDS}
    raw["cycle"] = dict(raw["cycle"]) if raw["cycle"] is not None else None
    return raw


def run_chunk(chunk: Chunk) -> dict[str, Any]:
    """Runs a chunk (executor workers call this) until it ends or it is asked to stop: the
    chunk's ``stop_file`` appears (the submitter was interrupted) or this worker gets Ctrl-C.
    A stopped chunk returns its finished points; the running ones count as not run."""
    run = prepare(chunk)
    if chunk.stop_file is None:
        return raw_fields(run.result())
    run.start()
    try:
        while not run.wait(STOP_POLL_S):
            if os.path.exists(chunk.stop_file):
                run.cancel()
    except KeyboardInterrupt:
        run.cancel()
    return raw_fields(run.result())


# How often an executor worker looks for its chunk's stop file (a stat call: negligible).
STOP_POLL_S = 0.02
# How long an interrupted sweep waits for the chunks running in executor workers to stop and
# hand back their finished points (they react within `STOP_POLL_S` plus one budget check).
STOP_WAIT_S = 5.0


def failed_raw(n: int, n_metrics: int, cycle_columns: Sequence[str], exc: BaseException) -> dict[str, Any]:
    """The raw result of a chunk of ``n`` points that failed as a whole (its run could not be
    built, its worker died, ...): one error row per point with the chunk's error, so a sweep
    never loses rows."""
    kind = getattr(exc, "kind", None) or type(exc).__name__.removesuffix("Error") or "Error"
    message = f"the chunk of this point failed: {type(exc).__name__}: {exc}"
    return {
        "finished": np.ones(n, bool),
        "ok": np.zeros(n, bool),
        "metrics": np.full((n, n_metrics), np.nan),
        "converged": np.zeros(n, bool),
        "cycles_run": np.full(n, -1, np.int64),
        "orbit_cycles": np.full(n, -1, np.int64),
        "error": [message] * n,
        "error_kind": [kind] * n,
        "cycle": {c: [None] * n for c in cycle_columns} if cycle_columns else None,
    }


def frame(raw: dict[str, Any], params: pl.DataFrame, points: Sequence[int], metrics: Sequence[str], cycle_columns: Sequence[str]) -> pl.DataFrame:
    """The rows of the finished points of a chunk."""
    finished = np.asarray(raw["finished"], dtype=bool)
    ok = np.asarray(raw["ok"], dtype=bool)
    idx = np.flatnonzero(finished)
    m = np.asarray(raw["metrics"])
    every = idx.size == finished.size  # all finished (no gathers needed)
    cols: dict[str, pl.Series] = {"point": pl.Series("point", np.asarray(points, dtype=np.int64)[idx])}
    taken = (params if every else params[idx.tolist()]) if params.width else None
    if taken is not None:
        for name in taken.columns:
            cols[name] = taken[name]
    ok_f = ok[idx]
    failed = np.flatnonzero(~ok_f)
    for k, name in enumerate(metrics):
        values = m[idx, k].astype(np.float64)
        # failed points have no metrics, and undefined metrics (NaN from the engine, e.g. the
        # phase lag of a wing that does not rotate) are null too: never a silent NaN
        cols[name] = pl.Series(name, values, dtype=pl.Float64, nan_to_null=True).scatter(failed, None)
    # Failed points have no convergence, cycle count or orbit length: null, not a number.
    for name, dtype, np_dtype in (("converged", pl.Boolean, bool), ("cycles_run", pl.Int64, np.int64), ("orbit_cycles", pl.Int64, np.int64)):
        cols[name] = pl.Series(name, np.asarray(raw[name], dtype=np_dtype)[idx], dtype=dtype).scatter(failed, None)
    # "ok" means converged: a point that ran but did not reach its steady state is
    # "unconverged", with the reason in `error` (its metrics are those of the last cycles run).
    converged_f = np.asarray(raw["converged"], dtype=bool)[idx]
    unconverged = ok_f & ~converged_f
    cols["status"] = pl.Series("status", np.where(ok_f, np.where(converged_f, "ok", "unconverged"), "error"), dtype=pl.String)
    errors = list(raw["error"]) if every else [raw["error"][i] for i in idx]
    kinds = list(raw["error_kind"]) if every else [raw["error_kind"][i] for i in idx]
    cycles = np.asarray(raw["cycles_run"], dtype=np.int64)[idx]
    for i in np.flatnonzero(unconverged):
        errors[i] = UNCONVERGED_REASON.format(cycles=int(cycles[i]))
        kinds[i] = "Unconverged"
    cols["error"] = pl.Series("error", errors, dtype=pl.String)
    cols["error_kind"] = pl.Series("error_kind", kinds, dtype=pl.String)
    if cycle_columns:
        cycle = raw["cycle"]
        for name in cycle_columns:
            values = [None if cycle[name][i] is None else list(cycle[name][i]) for i in idx]
            cols[f"cycle_{name}"] = pl.Series(f"cycle_{name}", values, dtype=pl.List(pl.Float64))
    return pl.DataFrame(cols)



def executor_workers(executor: cf.Executor) -> int:
    n = getattr(executor, "_max_workers", None)
    if isinstance(n, int) and n > 0:
        return n
    client = getattr(executor, "_client", None)  # dask.distributed.client.ClientExecutor
    if client is not None:
        with contextlib.suppress(Exception):
            return max(1, sum(client.nthreads().values()))
    return 4


def assemble(frames: list[pl.DataFrame], table: pl.DataFrame, metrics: Sequence[str], cycle: Sequence[str]) -> pl.DataFrame:
    frames = [f for f in frames if f.height]
    if not frames:
        empty = frame(
            {"finished": np.zeros(0, bool), "ok": np.zeros(0, bool), "metrics": np.zeros((0, len(metrics))), "converged": np.zeros(0, bool),
             "cycles_run": np.zeros(0, np.int64), "orbit_cycles": np.zeros(0, np.int64), "error": [], "error_kind": [], "cycle": {c: [] for c in cycle}},
            table.clear() if table.width else table, [], metrics, cycle,
        )  # fmt: skip
        return empty
    return pl.concat(frames, how="vertical_relaxed").sort("point")


def run_local(
    chunks: list[list[int]],
    make: Callable[[list[int]], Chunk],
    frame: Callable[[list[int], dict[str, Any] | BaseException], pl.DataFrame],
    finished_chunk: Callable[[pl.DataFrame], None],
    bar: Any,
) -> bool:
    """Runs the chunks one after the other on the local engine, keeping its threads busy: chunk
    k+1 is parsed while chunk k runs and started as soon as k ends, before k's rows are framed
    and flushed. Returns True when interrupted (Ctrl-C)."""
    pending: Iterator[list[int]] = iter(chunks)
    started: list[tuple[list[int], _core.SweepRun]] = []  # running or finished, not collected

    failed: list[tuple[list[int], Exception]] = []  # chunks whose run could not be built

    def prepared() -> tuple[list[int], _core.SweepRun] | None:
        while (points := next(pending, None)) is not None:
            try:
                return points, prepare(make(points))
            except Exception as exc:  # noqa: BLE001 - a failed chunk becomes its error rows
                failed.append((points, exc))
        return None

    def flush_failed() -> None:
        while failed:
            points, exc = failed.pop(0)
            finished_chunk(frame(points, exc))
            bar.update(len(points))

    def collect(points: list[int], run: _core.SweepRun) -> pl.DataFrame:
        try:
            return frame(points, raw_fields(run.result()))
        except Exception as exc:  # noqa: BLE001 - e.g. the sweep thread failed: error rows
            return frame(points, exc)

    try:
        upcoming = prepared()
        flush_failed()
        if upcoming is None:
            return False
        upcoming[1].start()
        started.append(upcoming)
        upcoming = prepared()
        while started:
            points, run = started[0]
            reported = 0
            while not run.wait(0.02):  # short: Ctrl-C is seen between waits
                reported = advance(bar, run.finished, reported)
            advance(bar, run.finished, reported)
            if upcoming is not None:
                upcoming[1].start()
                started.append(upcoming)
            rows = collect(points, run)
            started.pop(0)
            finished_chunk(rows)
            flush_failed()
            upcoming = prepared()
            if upcoming is None:
                flush_failed()
    except KeyboardInterrupt:
        for _, run in started:
            run.cancel()
        for points, run in started:
            run.wait(None)
            finished_chunk(collect(points, run))
        flush_failed()
        return True
    return False


def advance(bar: Any, finished: int, reported: int) -> int:
    if finished > reported:
        bar.update(finished - reported)
    return max(finished, reported)


def run_executor(
    executor: cf.Executor,
    chunks: list[list[int]],
    make: Callable[[list[int]], Chunk],
    frame: Callable[[list[int], dict[str, Any] | BaseException], pl.DataFrame],
    finished_chunk: Callable[[pl.DataFrame], None],
    bar: Any,
) -> bool:
    """Submits chunks with a bounded number in flight (memory stays bounded); results are
    flushed as they complete. Returns True when interrupted (Ctrl-C)."""
    workers = executor_workers(executor)
    limit = max(2, 2 * workers)
    queue = iter(chunks)
    in_flight: dict[cf.Future[dict[str, Any]], list[int]] = {}
    stop_dir = tempfile.mkdtemp(prefix="paritysim-sweep-")
    stop_file = os.path.join(stop_dir, "stop")
    try:
        while True:
            while len(in_flight) < limit:
                points = next(queue, None)
                if points is None:
                    break
                try:
                    chunk = dataclasses.replace(make(points), stop_file=stop_file)
                    in_flight[executor.submit(run_chunk, chunk)] = points
                except Exception as exc:  # noqa: BLE001 - e.g. a broken pool: error rows
                    finished_chunk(frame(points, exc))
                    bar.update(len(points))
            if not in_flight:
                return False
            done, _ = cf.wait(list(in_flight), timeout=0.02, return_when=cf.FIRST_COMPLETED)  # Ctrl-C is seen between waits
            for fut in done:
                points = in_flight[fut]
                # A chunk whose worker raised or died (BrokenProcessPool...) is error rows.
                error = fut.exception()
                rows = frame(points, error if error is not None else fut.result())
                # Popped only once framed: a Ctrl-C while framing collects it below.
                del in_flight[fut]
                finished_chunk(rows)
                bar.update(len(points))
    except KeyboardInterrupt:
        # Pending chunks are cancelled; running ones see the stop file, stop their points
        # and return the finished ones, which are checkpointed like any finished chunk.
        Path(stop_file).touch()
        running = [fut for fut in in_flight if not fut.cancel()]
        cf.wait(running, timeout=STOP_WAIT_S)
        for fut in running:
            if fut.done() and fut.exception() is None:
                finished_chunk(frame(in_flight[fut], fut.result()))
        return True
    except BaseException:
        Path(stop_file).touch()
        for fut in in_flight:
            fut.cancel()
        raise
    finally:
        # A chunk still running past the wait keeps its stop file (it stops when it looks).
        if all(fut.done() for fut in in_flight):
            shutil.rmtree(stop_dir, ignore_errors=True)
