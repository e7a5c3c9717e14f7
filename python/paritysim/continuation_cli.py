"""``paritysim continue study.toml --out runs/``: a continuation described in TOML.

A study file names the device, the parameter path and its range::

    spec = "drag_parity.toml"        # a spec file relative to this file, or a named device
    path = "drivetrain.balance_spring"
    start = 1000.0                   # optional: default the spec's value
    stop = 100.0

    [settings]                       # optional: keywords of paritysim.continuation
    max_step = 0.5

    [plot]                           # optional: the branch diagram's y column
    y = "spectral_radius"

Writes ``<out>/<stem>.parquet`` (the branch), ``<stem>_bifurcations.csv`` and ``<stem>.png``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

from ._errors import invalid, read_study

__all__ = ["add_parser", "run_study"]

_KEYS = ("spec", "path", "start", "stop", "settings", "plot")


def run_study(study: str | Path, out: str | Path) -> dict[str, Any]:
    """Runs a continuation study file; returns the result and the written paths."""
    from . import devices
    from .continuation import continuation

    data = read_study(study, "a continuation study", _KEYS, ("spec", "path", "stop"), "continue")
    study = Path(study)
    spec = devices._name_or_file(data["spec"], study.parent)
    settings = data.get("settings", {})
    if not isinstance(settings, dict):
        raise invalid("settings", repr(settings), "a table of paritysim.continuation keywords")
    for key in ("spec", "path", "start", "stop"):
        if key in settings:  # a keyword given twice
            raise invalid(f"settings.{key}", repr(settings[key]), f"given as `{key}` at the top of the study, not in [settings]")
    result = continuation(spec, data["path"], data["stop"], start=data.get("start"), **settings)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stem = study.stem
    written = {"branch": out / f"{stem}.parquet", "bifurcations": out / f"{stem}_bifurcations.csv", "plot": out / f"{stem}.png"}
    result.branch.write_parquet(written["branch"])
    result.bifurcations.write_csv(written["bifurcations"])
    plot = data.get("plot", {})
    if not isinstance(plot, dict) or set(plot) - {"y"}:
        raise invalid("plot", repr(plot), "a table with y")
    import matplotlib.pyplot as plt

    plt.close(result.plot(plot.get("y", "spectral_radius"), path=written["plot"]))
    return {"result": result, "written": written}


def _main(args: argparse.Namespace) -> int:
    start = time.perf_counter()
    done = run_study(args.study, args.out)
    result = done["result"]
    if not args.quiet:
        found = ", ".join(f"{k} at {v:.6g}" for k, v in zip(result.bifurcations["kind"], result.bifurcations[result.path], strict=True)) or "no bifurcation"
        print(f"{Path(args.study).stem}: {result.branch.height} orbits ({result.stop_reason}), {found}, {time.perf_counter() - start:.2f} s -> " + ", ".join(str(p) for p in done["written"].values()))
    return 0


def add_parser(sub: argparse._SubParsersAction, parents: list[argparse.ArgumentParser] | None = None) -> None:  # type: ignore[type-arg]
    """Adds ``paritysim continue``."""
    p = sub.add_parser("continue", help="continue a periodic orbit in one parameter (branch, bifurcations, plot)", parents=parents or [], description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("study", help="study file, e.g. examples/continuation_whippletree.toml")
    p.add_argument("--out", default="runs", help="output directory (default: runs/)")
    p.add_argument("--quiet", action="store_true", help="no progress bar or summary")
    p.set_defaults(func=_main)
