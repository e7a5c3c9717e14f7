"""The ``paritysim`` command line."""

from __future__ import annotations

import argparse
import re
import sys
import time
import tomllib
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from tqdm import tqdm

from ._core import ParitysimError


def _trials() -> dict[str, Callable[[Path], list[Path]]]:
    from .trials import REGISTRY

    return REGISTRY


def _reproduce(args: argparse.Namespace) -> int:
    if args.names and (args.all or args.list):
        # `--all table3.3` ran every trial (minutes) where one was meant.
        flag = "--all" if args.all else "--list"
        print(f"paritysim: error: {flag} takes no trial names (got {', '.join(args.names)}): name the trials alone, or pass {flag} alone", file=sys.stderr)
        return 2
    if args.list:
        print("\n".join(_trials()))
        return 0
    trials = _trials()
    names = list(trials) if args.all else args.names
    if not names:
        print("nothing to reproduce: name a trial or pass --all; available: " + ", ".join(trials), file=sys.stderr)
        return 2
    unknown = [n for n in names if n not in trials]
    if unknown:
        from ._errors import suggest

        print(f"paritysim: error: unknown trial `{unknown[0]}`: must be " + suggest(unknown[0], trials, listed_by="`paritysim reproduce --list`", what="a trial"), file=sys.stderr)
        return 2
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name in tqdm(names, desc="reproducing", unit="trial", disable=args.quiet):
        start = time.perf_counter()
        written = trials[name](out)
        if not args.quiet:
            tqdm.write(f"{name}: {time.perf_counter() - start:.2f} s -> " + ", ".join(str(p) for p in written))
    if args.all:
        from .report import write_report

        start = time.perf_counter()
        path = write_report(out)
        if not args.quiet:
            print(f"report: {time.perf_counter() - start:.2f} s -> {path}")
    return 0


def _devices(args: argparse.Namespace) -> int:
    from . import devices

    if args.name:
        print(devices.info(args.name))
        print(f"file: {devices.path(args.name)}")
        return 0
    for name in devices.list():
        info = devices.info(name)
        print(f"{name:40s} {info.title}{'' if info.cut_wings else '  [fails on cut wings]'}")
    return 0


def output_stem(name: str, fallback: str) -> str:
    """The file stem of a run's outputs: the spec's ``name`` (what the user called the device),
    made safe as a file name, or ``fallback`` (the TOML file's stem) when the name is empty."""
    safe = re.sub(r"[^\w.-]+", "_", name.strip()).strip("._")
    return safe or fallback


def _run(args: argparse.Namespace) -> int:
    from . import devices, simulate

    spec = devices._name_or_file(args.spec)  # a TOML path, or a named device of the library
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    stem = output_stem(spec.name, Path(args.spec).stem)
    start = time.perf_counter()
    result = simulate(spec)
    result.trajectory.write_parquet(out / f"{stem}_trajectory.parquet")
    result.metrics_frame.write_csv(out / f"{stem}_metrics.csv")
    result.plot(out / f"{stem}.png")
    if not args.quiet:
        state = "converged" if result.converged else "NOT converged"
        if result.orbit_cycles > 1:
            state += f", period-{result.orbit_cycles} orbit"
        print(f"{stem}: {result.cycles_run} cycles ({state}) in {time.perf_counter() - start:.2f} s -> {out}/{stem}.png, {stem}_trajectory.parquet, {stem}_metrics.csv")
        from .plots import label_with_unit  # matplotlib is loaded for the plot already

        for key in _HEADLINE:
            value = result.metrics.get(key)
            if value is not None and (value != 0.0 or not key.endswith("rotation_amplitude")):  # fixed wings: no rotation
                print(f"  {label_with_unit(key):40s} {value: .6g}")
        print(f"  ({len(result.metrics)} metrics in {stem}_metrics.csv)")
    return 0


#: The numbers `paritysim run` prints, where the device has them: the stroke (and rotation) of
#: each wing, the torques, and a designer's lift, power and efficiency.
_HEADLINE = (
    "left_stroke_amplitude",
    "right_stroke_amplitude",
    "left_rotation_amplitude",
    "right_rotation_amplitude",
    "left_roll_aero_peak",
    "right_roll_aero_peak",
    "yaw_total_mean",
    "lift_mean",
    "actuator_power_mean",
    "lift_per_power",
    "work_actuator_per_cycle",
)


def _common() -> argparse.ArgumentParser:
    """Options every subcommand takes (also accepted after the subcommand's name)."""
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help="show the full traceback of an error")
    return common


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (exposed for tests and docs)."""
    parser = argparse.ArgumentParser(prog="paritysim", description="Simulate flapping-wing drivetrains and reproduce the thesis trials.", parents=[_common()])
    parser.add_argument("--version", action="version", version=f"paritysim {__import__('paritysim').__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    rep = sub.add_parser("reproduce", help="reproduce thesis tables and figures", parents=[_common()])
    rep.add_argument("names", nargs="*", help="trials to run (see `paritysim reproduce --list`)")
    rep.add_argument("--list", action="store_true", help="list the available trials and exit")
    rep.add_argument("--all", action="store_true", help="run every implemented trial")
    rep.add_argument("--out", default="results", help="output directory (default: results/)")
    rep.add_argument("--quiet", action="store_true", help="no progress output")
    rep.set_defaults(func=_reproduce)
    run = sub.add_parser("run", help="simulate a device spec (TOML) and write trajectory, metrics and a plot", parents=[_common()])
    run.add_argument("spec", help="device spec (TOML path, e.g. examples/hmf.toml) or a named device (see `paritysim devices`)")
    run.add_argument("--out", default="results", help="output directory (default: results/)")
    run.add_argument("--quiet", action="store_true", help="no summary output")
    run.set_defaults(func=_run)
    dev = sub.add_parser("devices", help="list the named thesis devices (or show one's provenance)", parents=[_common()])
    dev.add_argument("name", nargs="?", help="a device name: print what the thesis states and what we chose")
    dev.set_defaults(func=_devices)
    from .continuation_cli import add_parser as add_continue_parser

    add_continue_parser(sub, parents=[_common()])
    from .optimize_cli import add_parser as add_optimize_parser

    add_optimize_parser(sub, parents=[_common()])
    try:  # `paritysim sweep` lives with the sweep engine (issue 8)
        from .sweep_cli import add_parser as add_sweep_parser
    except ImportError:
        pass
    else:
        add_sweep_parser(sub, parents=[_common()])
    return parser


_STATE = re.compile(r" \(state = \[[^\]]*\]\)")


def describe_error(exc: BaseException) -> str:
    """One line for a user: what failed and on which file or field, without a traceback."""
    if isinstance(exc, ParitysimError):
        # The state vector is for `--debug` (the traceback, `.state`); the responsible field first.
        text = _STATE.sub("", str(exc))
        cause, sep, responsible = text.partition("; most responsible: ")
        if sep:
            text = f"{responsible} (because: {cause})"
        return f"{type(exc).__name__}: {text}"
    if isinstance(exc, FileNotFoundError):
        return f"no such file or directory: {exc.filename}"
    if isinstance(exc, IsADirectoryError):
        return f"expected a file, got a directory: {exc.filename}"
    if isinstance(exc, NotADirectoryError):
        return f"not a directory: {exc.filename}"
    if isinstance(exc, PermissionError):
        return f"permission denied: {exc.filename}"
    if isinstance(exc, OSError) and exc.filename is not None:
        return f"cannot use {exc.filename}: {exc.strerror or exc}"
    if isinstance(exc, tomllib.TOMLDecodeError):
        return f"malformed TOML: {exc}"
    if isinstance(exc, UnicodeDecodeError):
        return f"not a UTF-8 text file: {exc.reason}"
    return f"{type(exc).__name__}: {exc}"


def _one_line_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int, file: Any = None, line: str | None = None) -> None:
    """A warning as the CLI's one line (``paritysim: warning: ...``), not Python's file, line and
    source text."""
    text = " ".join(part.strip() for part in str(message).splitlines() if part.strip())
    # tqdm.write: on a line of its own above a running progress bar, not glued to it.
    tqdm.write(f"paritysim: warning: {text}", file=sys.stderr if file is None else file)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``paritysim`` console script (also ``python -m paritysim``).

    Exit codes: 0 success, 1 an error (one line on stderr; ``--debug`` shows the traceback),
    2 bad command-line usage, 130 interrupted (Ctrl-C; a sweep keeps its finished points)."""
    import matplotlib

    matplotlib.use("Agg")  # the CLI only writes files
    args = build_parser().parse_args(argv)
    debug = bool(getattr(args, "debug", False))
    from contextlib import nullcontext

    from ._progress import quiet

    shown = warnings.showwarning
    if not debug:
        warnings.showwarning = _one_line_warning
    # Python hides DeprecationWarnings outside __main__: the CLI shows paritysim's own (an old
    # spelling in a spec or study file) as the API does.
    filters = warnings.filters[:]
    warnings.filterwarnings("default", category=DeprecationWarning, module=r"paritysim(\.|$)")
    try:
        with quiet() if getattr(args, "quiet", False) else nullcontext():  # no bar of a long run either
            return int(args.func(args))
    except KeyboardInterrupt:
        if debug:
            raise
        print("paritysim: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # noqa: BLE001 - the CLI's contract: one line, never a traceback
        if debug:
            raise
        one_line = " ".join(part.strip() for part in describe_error(exc).splitlines() if part.strip())
        print(f"paritysim: error: {one_line}", file=sys.stderr)
        return 1
    finally:
        warnings.showwarning = shown
        warnings.filters[:] = filters


if __name__ == "__main__":
    raise SystemExit(main())
