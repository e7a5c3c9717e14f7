"""Reproductions of the dissertation's trials, one module per thesis section.

Each function returns Polars DataFrames computed by the model; nothing is copied from the
thesis. A module may define ``CLI_TRIALS: dict[str, Callable[[Path], list[Path]]]`` (name ->
runner writing files into an output directory, including ``<stem>.claims.json``: the thesis
claims with computed verdicts, :mod:`paritysim.claims`) and ``report_section(out_dir) -> str``
(markdown for ``report.md``, built from those files); :data:`REGISTRY` collects the runners for
``paritysim reproduce``.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable
from pathlib import Path

from .laminate_design import laminate_summary
from .section_2_3 import fig2_9
from .section_2_5 import lift_dual_parity
from .section_3_3 import fig2_12, fig3_2, fig3_3, fig3_4, table_3_2
# `section_3_4` is the module (callable as its `section_3_4` study function).
from . import section_3_4

__all__ = [
    "REGISTRY",
    "fig2_9",
    "fig2_12",
    "fig3_2",
    "fig3_3",
    "fig3_4",
    "laminate_summary",
    "lift_dual_parity",
    "section_3_4",
    "table_3_2",
]


def _discover() -> dict[str, Callable[[Path], list[Path]]]:
    registry: dict[str, Callable[[Path], list[Path]]] = {}
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{__name__}.{info.name}")
        registry.update(getattr(module, "CLI_TRIALS", {}))
    return registry


#: CLI trial name -> runner(out_dir) -> written files, from every trial module.
REGISTRY: dict[str, Callable[[Path], list[Path]]] = _discover()


def __dir__() -> list[str]:
    """The public names (`__all__`) and the trial modules, not this file's own imports."""
    modules = [info.name for info in pkgutil.iter_modules(__path__) if not info.name.startswith("_")]
    return sorted({*__all__, *modules})
