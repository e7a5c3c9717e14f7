"""The reproduction report: ``paritysim reproduce --all --out DIR`` writes ``DIR/report.md``.

Each trial module may define ``report_section(out_dir) -> str``;
sections appear in thesis order. Every number the thesis states is listed with ours, the
difference and a verdict; figures written by the trials are embedded.
"""

from __future__ import annotations

import importlib
import pkgutil
from pathlib import Path

from . import __version__

#: Sections in thesis order; modules not listed follow alphabetically.
ORDER = ["section_2_3", "section_3_3", "section_2_6", "section_3_4", "section_2_5", "laminate_design"]


def _modules() -> list[str]:
    from . import trials

    names = [m.name for m in pkgutil.iter_modules(trials.__path__)]
    return [n for n in ORDER if n in names] + sorted(n for n in names if n not in ORDER)


def write_report(out: Path) -> Path:
    """Writes ``out/report.md`` from every trial module's ``report_section``."""
    parts = [
        "# paritysim reproduction report",
        "",
        f"paritysim {__version__}. Every value below is computed by the model; thesis values are quoted for comparison. "
        "Units: mg, mm, ms, rad, V (torque mN·mm). See docs/findings.md for what we found along the way.",
        "",
    ]
    for name in _modules():
        module = importlib.import_module(f"paritysim.trials.{name}")
        section = getattr(module, "report_section", None)
        if section is None:
            continue
        parts.append(section(out))
        parts.append("")
    path = out / "report.md"
    path.write_text("\n".join(parts))
    return path
