"""``paritysim sweep study.toml --out runs/``: a parameter sweep described in TOML.

A study file names the device and the grid::

    spec = "hmf.toml"                      # a spec file relative to this file, a named device
                                           #   (`paritysim devices`) or a [spec] table
    metrics = ["left_stroke_amplitude"]    # optional: default all
    gradients = ["actuator.voltage_v"]     # optional: d(metric)/d(path) columns (ps.sweep)
    keep_cycle = false                     # optional: true or a list of trajectory columns
    threads = 2                            # optional: engine threads (--threads wins)
    chunk_size = 256                       # optional: points per chunk (a checkpoint saves each)

    [options]                              # optional overrides of the spec's options
    max_cycles = 60

    [grid]                                 # path = list, or {start, stop, num[, log]} (linspace)
    "actuator.frequency_hz" = { start = 20.0, stop = 200.0, num = 37 }
    "actuator.voltage_v" = [50.0, 100.0]

    [plot]                                 # optional: a PNG of y against x, one line per hue
    x = "actuator.frequency_hz"
    y = "left_stroke_amplitude"
    hue = "actuator.voltage_v"

The results go to ``<out>/<stem>.parquet``, which is also the checkpoint: re-running the command
after an interruption resumes where it stopped.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import polars as pl

from ._errors import invalid, read_study, real, suggest
from .spec import Simulation
from .sweep import MAX_GRID_POINTS

__all__ = ["Study", "add_parser", "load_study", "run_study"]

_KEYS = ("spec", "metrics", "gradients", "keep_cycle", "options", "grid", "plot", "threads", "chunk_size")


@dataclass(frozen=True)
class Study:
    """A parsed study file."""

    spec: Simulation
    grid: dict[str, list[Any]]
    metrics: list[str] | None = None
    gradients: list[str] | None = None
    keep_cycle: bool | list[str] = False
    options: dict[str, Any] = field(default_factory=dict)
    plot: dict[str, Any] | None = None
    threads: int | None = None
    chunk_size: int | None = None


def _axis(name: str, value: Any) -> list[Any]:
    if isinstance(value, list):
        return value
    if isinstance(value, dict):
        unknown = sorted(set(value) - {"start", "stop", "num", "log"})
        if unknown or not {"start", "stop", "num"} <= set(value):
            raise invalid(f"grid.{name}", repr(value), "a list or a table {start, stop, num[, log]}")
        start, stop, num = real(f"grid.{name}.start", value["start"]), real(f"grid.{name}.stop", value["stop"]), value["num"]
        if isinstance(num, bool) or not isinstance(num, int) or not 1 <= num <= MAX_GRID_POINTS:
            raise invalid(f"grid.{name}.num", repr(num), f"an integer in [1, {MAX_GRID_POINTS:.0e}]")
        log = value.get("log", False)
        if not isinstance(log, bool):
            raise invalid(f"grid.{name}.log", repr(log), "true or false")
        if log:
            if start <= 0 or stop <= 0:
                raise invalid(f"grid.{name}", repr(value), "start and stop > 0 for a log axis")
            return np.geomspace(start, stop, num).tolist()
        return np.linspace(start, stop, num).tolist()
    return [value]


def load_study(path: str | Path) -> Study:
    """Parses a study TOML (see the module docstring)."""
    data = read_study(path, "a sweep study", _KEYS)
    path = Path(path)
    raw_spec = data.get("spec")
    if isinstance(raw_spec, dict):
        spec = Simulation.from_dict(raw_spec)
    elif isinstance(raw_spec, str):
        from . import devices

        spec = devices._name_or_file(raw_spec, path.parent)
    else:
        raise invalid("spec", repr(raw_spec), "a named device, a spec file path (relative to the study) or a [spec] table")
    grid = data.get("grid", {})
    if not isinstance(grid, dict):
        raise invalid("grid", repr(grid), "a table of parameter path = values")
    plot = data.get("plot")
    if plot is not None and (not isinstance(plot, dict) or not {"x", "y"} <= set(plot) or set(plot) - {"x", "y", "hue"}):
        raise invalid("plot", repr(plot), "a table with x, y and optionally hue")
    options = data.get("options", {})
    if not isinstance(options, dict):
        raise invalid("options", repr(options)[:60], "a table of the spec's options to override (e.g. max_cycles = 50)")
    return Study(
        spec=spec,
        grid={k: _axis(k, v) for k, v in grid.items()},
        metrics=data.get("metrics"),
        gradients=data.get("gradients"),
        keep_cycle=data.get("keep_cycle", False),
        options=dict(options),
        plot=plot,
        threads=data.get("threads"),
        chunk_size=data.get("chunk_size"),
    )


def run_study(study: Study, out: str | Path, stem: str, threads: int | None = None, progress: bool = True, fresh: bool = False) -> tuple[pl.DataFrame, dict[str, Path]]:
    """Runs a study; writes ``<stem>.parquet`` (and ``<stem>.png`` with a [plot] table).
    Returns the result and the written paths. ``fresh`` discards earlier results first."""
    from .sweep import plot, sweep

    if study.plot is not None:
        _check_plot_columns(study)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    table = out / f"{stem}.parquet"
    if fresh:
        table.unlink(missing_ok=True)
        parts = table.with_name(table.name + ".parts")
        if parts.is_dir():
            shutil.rmtree(parts)
    df = sweep(
        study.spec,
        study.grid,
        metrics=study.metrics,
        gradients=study.gradients,
        keep_cycle=study.keep_cycle,
        threads=threads if threads is not None else study.threads,
        progress=progress,
        checkpoint=table,
        chunk_size=study.chunk_size,
        options=study.options,
    )
    written = {"table": table}
    if study.plot is not None:
        import matplotlib

        matplotlib.use("Agg")
        fig = plot(df, study.plot["x"], study.plot["y"], hue=study.plot.get("hue"), path=out / f"{stem}.png")
        import matplotlib.pyplot as plt

        plt.close(fig)
        written["plot"] = out / f"{stem}.png"
    return df, written


def _check_plot_columns(study: Study) -> None:
    """The [plot] table's columns among those the sweep will write, checked before it runs (a
    misspelt one failed after every point had run)."""
    from . import _core
    from .sweep import STATUS_COLUMNS, _gradient_columns

    assert study.plot is not None
    metrics = list(study.metrics) if isinstance(study.metrics, list) else _core.sweep_metric_names(study.spec.to_json())
    gradients = [study.gradients] if isinstance(study.gradients, str) else list(study.gradients or [])
    columns = ["point", *study.grid, *metrics, *STATUS_COLUMNS, *_gradient_columns(metrics, gradients)]
    ys = study.plot["y"] if isinstance(study.plot["y"], list) else [study.plot["y"]]
    keys = [("plot.x", study.plot["x"]), *((f"plot.y[{i}]" if isinstance(study.plot["y"], list) else "plot.y", y) for i, y in enumerate(ys))]
    if study.plot.get("hue") is not None:
        keys.append(("plot.hue", study.plot["hue"]))
    for key, column in keys:
        if column not in columns:
            raise invalid(key, repr(column), suggest(str(column), columns, what="a column the sweep writes (a grid path, a metric, a status column)"))


def _main(args: argparse.Namespace) -> int:
    study = load_study(args.study)
    stem = Path(args.study).stem
    start = time.perf_counter()
    from .sweep import SweepInterrupted

    try:
        df, written = run_study(study, args.out, stem, threads=args.threads, progress=not args.quiet, fresh=args.fresh)
    except SweepInterrupted as stop:
        print(f"{stem}: interrupted after {stop.result.height} of {stop.total} points; re-run the same command to resume", file=sys.stderr)
        return 130
    n_err = df.filter(pl.col("status") == "error").height
    if df.height and n_err == df.height:
        # Nothing was computed: an error, with the most common reason.
        reason = df["error"].drop_nulls().mode().sort().first() or ""
        print(f"paritysim: error: {stem}: every one of the {df.height} points failed, e.g. {reason}", file=sys.stderr)
        return 1
    if not args.quiet:
        n_unconverged = df.filter(pl.col("status") == "unconverged").height
        print(f"{stem}: {df.height} points ({n_err} failed, {n_unconverged} unconverged) in {time.perf_counter() - start:.2f} s -> " + ", ".join(str(p) for p in written.values()))
    return 0


def add_parser(sub: argparse._SubParsersAction, parents: list[argparse.ArgumentParser] | None = None) -> None:  # type: ignore[type-arg]
    """Adds ``paritysim sweep`` (``parents``: options shared by every subcommand)."""
    p = sub.add_parser("sweep", help="run a parameter sweep described in a study TOML (device + grid)", parents=parents or [], description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("study", help="study file, e.g. examples/sweep_resonance.toml")
    p.add_argument("--out", default="runs", help="output directory (default: runs/)")
    p.add_argument("--threads", type=int, default=None, help="engine threads (default: $PARITYSIM_THREADS or all cores)")
    p.add_argument("--fresh", action="store_true", help="discard earlier results and checkpoints of this study and recompute everything")
    p.add_argument("--quiet", action="store_true", help="no progress bar or summary")
    p.set_defaults(func=_main)
