"""Check the CPU before the native extension loads.

On x86-64 the extension is compiled with AVX and AVX2 (``.cargo/config.toml``: the SIMD lanes
run 4 × f64 in one register, 0.68× the instructions of a baseline build, results bit-identical;
docs/findings.md §18).
A CPU without them would stop the interpreter with an illegal instruction inside the extension;
this check turns that into an ``ImportError`` that says what is missing and how to build for
such a machine. The same check as polars' (``POLARS_SKIP_CPU_CHECK``).
"""

from __future__ import annotations

import os
import platform
import sys
from collections.abc import Mapping, Sequence

#: What the default build requires on x86-64, as ``.cargo/config.toml`` enables it (a test keeps
#: the two equal, and checks that the built extension needs nothing beyond this list).
REQUIRED_X86_64 = ("avx", "avx2")
#: Set to any non-empty value to skip the check (after building with ``RUSTFLAGS=""``).
SKIP_ENV = "PARITYSIM_SKIP_CPU_CHECK"


def cpu_features() -> Mapping[str, bool] | None:
    """The CPU's features as numpy detected them (upper-case names), or None if unknown."""
    try:
        from numpy._core._multiarray_umath import __cpu_features__ as features  # numpy >= 2
    except ImportError:
        try:
            from numpy.core._multiarray_umath import __cpu_features__ as features  # numpy 1.26
        except ImportError:
            return None
    return features


def missing_features(features: Mapping[str, bool] | None, machine: str) -> list[str]:
    """The required features ``features`` lacks on ``machine`` (empty when unknown or not x86-64)."""
    if features is None or machine.lower() not in ("x86_64", "amd64"):
        return []
    return [name for name in REQUIRED_X86_64 if not features.get(name.upper(), False)]


def check() -> None:
    """Raise ``ImportError`` if this CPU lacks a feature the extension was compiled for.

    Raises:
        ImportError: naming the missing features, unless ``PARITYSIM_SKIP_CPU_CHECK`` is set.
    """
    if os.environ.get(SKIP_ENV):
        return
    missing = missing_features(cpu_features(), platform.machine())
    if missing:
        raise ImportError(
            f"paritysim's native extension is compiled for x86-64 with {', '.join(REQUIRED_X86_64)} "
            f"(.cargo/config.toml), and this CPU lacks {', '.join(missing)}. Build it for this "
            f'machine with `RUSTFLAGS="" maturin develop --release` (or `RUSTFLAGS="" '
            f'{SKIP_ENV}=1 scripts/test`) and keep {SKIP_ENV}=1 set when you import it.'
        )


def running_cli(argv: Sequence[str] | None = None, orig_argv: Sequence[str] | None = None) -> bool:
    """Whether this process is the ``paritysim`` command line (the console script, or
    ``python -m paritysim``), whose contract is one line on stderr and never a traceback."""
    argv = sys.argv if argv is None else argv
    orig_argv = getattr(sys, "orig_argv", []) if orig_argv is None else orig_argv
    if argv and os.path.basename(argv[0]) in ("paritysim", "paritysim.exe"):
        return True
    # ``python -m paritysim``: the package is imported while sys.argv[0] is still "-m".
    return any(a == "-m" and b in ("paritysim", "paritysim.cli") for a, b in zip(orig_argv, orig_argv[1:]))


def check_or_exit() -> None:
    """:func:`check`, except that the command line prints the refusal as its one error line and
    exits with status 1 instead of an import traceback.

    Raises:
        ImportError: as :func:`check`, outside the command line.
        SystemExit: status 1, in the command line.
    """
    try:
        check()
    except ImportError as refusal:
        if not running_cli():
            raise
        print(f"paritysim: error: {refusal}", file=sys.stderr)
        raise SystemExit(1) from None
