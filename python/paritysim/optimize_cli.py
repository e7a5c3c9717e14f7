"""``paritysim optimize study.toml``: a design optimisation (`paritysim.optimize`) described in TOML.

A study file names the device, the objective, the design variables with their bounds and the
constraints::

    spec = "sreetharan2012_3_4_parity"   # a named device, or a spec file relative to this file
    objective = "actuator_power_mean"
    sense = "min"                          # optional: "min" (default) or "max"
    constraints = ["lift_mean >= 0.5886", "abs(yaw_total_mean) <= 0.05"]   # optional
    stability = 0.98                       # optional: bound on the largest non-neutral |multiplier|
    method = "SLSQP"                       # optional: "SLSQP" (default), "trust-constr" or "ipopt"
    max_iterations = 100                   # optional
    tol = 1e-6                             # optional (relative, see paritysim.optimize)
    out = "runs"                           # optional: output directory, relative to this file

    [set]                                  # optional: spec values set before optimising
    "drivetrain.balance_spring" = 30.0

    [params]                               # path = [low, high]: the design variables
    "wings[*].springs.hinge.stiffness" = [1.0, 5.0]
    "actuator.waveform.amplitude_v" = [20.0, 150.0]

    [x0]                                   # optional: the start (default: the spec's values)
    "actuator.waveform.amplitude_v" = 60.0

    [options]                              # optional: overrides of the spec's options for the runs
    rtol = 1e-10

Writes ``<out>/<stem>_optimum.toml`` (the spec at the returned point; ``paritysim run`` and
``ps.load_spec`` read it), ``<stem>_history.csv`` and ``<stem>_history.parquet`` (one row per
iteration) and ``<stem>_convergence.png``, and prints one line. ``--out`` on the command line
replaces the study's ``out``.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from . import plots
from ._errors import invalid, read_study
from .spec import Simulation

__all__ = ["OptimizeStudy", "add_parser", "load_study", "run_study"]

_KEYS = ("spec", "objective", "sense", "constraints", "stability", "method", "max_iterations", "tol", "out", "set", "params", "x0", "options")


@dataclass(frozen=True)
class OptimizeStudy:
    """A parsed optimisation study file (see the module docstring)."""

    spec: Simulation
    objective: str
    params: dict[str, Any]
    constraints: list[Any] = field(default_factory=list)
    sense: str = "min"
    stability: float | None = None
    method: str = "SLSQP"
    max_iterations: int = 100
    tol: float = 1e-9
    out: Path = Path("runs")
    x0: dict[str, Any] | None = None
    options: dict[str, Any] = field(default_factory=dict)


def _table(data: dict[str, Any], key: str, what: str) -> dict[str, Any] | None:
    value = data.get(key)
    if value is None:
        return None
    if not isinstance(value, dict):
        raise invalid(key, repr(value)[:60], what)
    return value


def load_study(path: str | Path) -> OptimizeStudy:
    """Parses an optimisation study TOML; every problem is an ``InvalidParameterError`` naming
    the key (the values themselves are checked by `paritysim.optimize`, naming its argument)."""
    from . import devices

    data = read_study(path, "an optimisation study", _KEYS, ("spec", "objective", "params"), "optimize")
    path = Path(path)
    spec = devices._name_or_file(data["spec"], path.parent)
    values = _table(data, "set", "a table of spec path = value set before optimising")
    if values:
        spec = spec.with_paths(values)
    params = _table(data, "params", "a table of design variables: path = [low, high]")
    if not params:
        raise invalid("params", "{}", "at least one design variable: path = [low, high]")
    constraints = data.get("constraints", [])
    if not isinstance(constraints, list):
        raise invalid("constraints", repr(constraints)[:60], 'a list of constraint texts, e.g. ["lift_mean >= 0.59"]')
    out = data.get("out", "runs")
    if not isinstance(out, str) or not out.strip():
        raise invalid("out", repr(out)[:60], "an output directory (text, relative to the study file)")
    kwargs = {k: data[k] for k in ("sense", "stability", "method", "max_iterations", "tol") if k in data}
    return OptimizeStudy(
        spec=spec,
        objective=data["objective"],
        params=params,
        constraints=constraints,
        out=path.parent / out,
        x0=_table(data, "x0", "a table of path = start value over the paths of [params]"),
        options=_table(data, "options", "a table of the spec's options to override (e.g. rtol = 1e-10)") or {},
        **kwargs,
    )


def run_study(study: OptimizeStudy, out: str | Path, stem: str, progress: bool = True) -> tuple[Any, dict[str, Path]]:
    """Runs a parsed study; writes the optimum spec, the history and the convergence plot into
    ``out``. Returns the `OptimizationResult` and the written paths."""
    from .optimizer import optimize

    result = optimize(
        study.spec,
        study.objective,
        params=study.params,
        constraints=study.constraints,
        stability=study.stability,
        sense=study.sense,
        method=study.method,
        x0=study.x0,
        max_iterations=study.max_iterations,
        tol=study.tol,
        progress=progress,
        options=study.options,
    )
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = {
        "optimum": out / f"{stem}_optimum.toml",
        "history_csv": out / f"{stem}_history.csv",
        "history_parquet": out / f"{stem}_history.parquet",
        "plot": out / f"{stem}_convergence.png",
    }
    result.save(written["optimum"])
    result.history.write_csv(written["history_csv"])
    result.history.write_parquet(written["history_parquet"])
    fig = result.plot()
    plots.save(fig, written["plot"], dpi=120)
    return result, written


def _main(args: argparse.Namespace) -> int:
    study = load_study(args.study)
    stem = Path(args.study).stem
    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:  # one line each, after the run
        warnings.simplefilter("always", RuntimeWarning)
        result, written = run_study(study, args.out if args.out is not None else study.out, stem, progress=not args.quiet)
    for w in caught:
        print("paritysim: warning: " + " ".join(str(w.message).split()), file=sys.stderr)
    if not args.quiet:
        status = "optimum" if result.success else "FAILED"
        active = ", ".join(result.active) or "none"
        note = "" if result.success else f" ({' '.join(result.message.split())})"
        print(
            f"{stem}: {status} {result.objective_name} = {result.objective:.6g} ({result.sense}) after {result.iterations} iterations, "
            f"{result.sensitivities} sensitivities; active: {active}{note}; {time.perf_counter() - start:.2f} s -> {written['optimum'].parent}/{stem}_*"
        )
    return 0 if result.success else 1


def add_parser(sub: argparse._SubParsersAction, parents: list[argparse.ArgumentParser] | None = None) -> None:  # type: ignore[type-arg]
    """Adds ``paritysim optimize`` (``parents``: options shared by every subcommand)."""
    p = sub.add_parser("optimize", help="optimise a design described in a study TOML (objective, params with bounds, constraints)", parents=parents or [], description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("study", help="study file, e.g. examples/optimize_3_4.toml")
    p.add_argument("--out", default=None, help="output directory (default: the study's `out`, else runs/ next to the study)")
    p.add_argument("--quiet", action="store_true", help="no progress bar or summary")
    p.set_defaults(func=_main)
