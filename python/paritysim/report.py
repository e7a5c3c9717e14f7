"""The reproduction report: ``paritysim reproduce --all --out DIR`` writes ``DIR/report.md``.

Each trial module may define ``report_section(out_dir) -> str``; sections appear in thesis
order. The sections are built from the files the trials wrote into ``out_dir`` (data, figures
and ``*.claims.json``): nothing is recomputed, and every verdict comes from a
:class:`paritysim.claims.Claim` (statement, thesis value, criterion, computed value).
"""

from __future__ import annotations

import importlib
import pkgutil
from collections import Counter
from pathlib import Path

from . import __version__
from . import claims as cl

#: Sections in thesis order; modules not listed follow alphabetically.
ORDER = ["section_2_3", "section_3_3", "section_2_6", "section_3_4", "aero_models", "section_2_5", "laminate_design"]


def _modules() -> list[str]:
    from . import trials

    names = [m.name for m in pkgutil.iter_modules(trials.__path__) if not m.name.startswith("_")]
    return [n for n in ORDER if n in names] + sorted(n for n in names if n not in ORDER)


def summary(out: Path) -> str:
    """A table of verdict counts per trial, from every ``*.claims.json`` in ``out``."""
    lines = ["| trial | " + " | ".join(cl.VERDICTS.values()) + " |", "|---|" + "---|" * len(cl.VERDICTS)]
    total: Counter[str] = Counter()
    for path in sorted(out.glob("*.claims.json")):
        claims, _ = cl.load(path)
        counts = Counter(c.verdict for c in claims)
        total += counts
        lines.append(f"| {path.name.removesuffix('.claims.json')} | " + " | ".join(str(counts[v]) for v in cl.VERDICTS.values()) + " |")
    lines.append("| **all** | " + " | ".join(f"**{total[v]}**" for v in cl.VERDICTS.values()) + " |")
    return "\n".join(lines)


def write_report(out: Path) -> Path:
    """Writes ``out/report.md`` from every trial module's ``report_section`` (a trial that has
    not written its results into ``out`` yet is run first)."""
    sections = []
    for name in _modules():
        module = importlib.import_module(f"paritysim.trials.{name}")
        section = getattr(module, "report_section", None)
        if section is not None:
            sections.append(section(out))
    parts = [
        "# paritysim reproduction report",
        "",
        f"paritysim {__version__}. Every value below is computed by the model; thesis values are quoted for comparison, and each "
        "verdict follows from the stated criterion (`paritysim.claims`). Units: mg, mm, ms, rad, V (torque mN·mm). "
        "Errata and departures from the printed text: docs/errata.md; findings: docs/findings.md.",
        "",
        "## Summary of the claims",
        "",
        summary(out),
        "",
    ]
    for section in sections:
        parts += [section, ""]
    path = out / "report.md"
    path.write_text("\n".join(parts))
    return path
