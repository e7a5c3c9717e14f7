"""Thesis claims as data: every verdict in ``report.md`` is computed here, never typed.

A trial states each thesis claim as a :class:`Claim`: the statement, the thesis' value (as
printed), the computed value, and the criterion (a tolerance, a range or a qualitative
condition evaluated on computed numbers). :attr:`Claim.verdict` follows from those fields alone;
:func:`render` turns a list of claims into the report's markdown table. Claims round-trip
through JSON (:func:`save`, :func:`load`) so the report reuses what the trials computed.

The verdict words live in :data:`VERDICTS` and nowhere else in the package:
``tests/test_report.py`` checks that no trial module spells one out.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

__all__ = ["VERDICTS", "Claim", "load", "render", "save"]

#: ok -> verdict word. ``None`` (an input the model was pinned to, not a check) -> "input".
VERDICTS = {True: "matches", False: "differs", None: "input"}


def _fmt(v: float, fmt: str) -> str:
    return format(v, fmt) if math.isfinite(v) else str(v)


@dataclass(frozen=True)
class Claim:
    """One thesis statement checked against the model.

    Attributes
    ----------
    statement:
        What the thesis says (with its equation, table or figure number).
    thesis:
        The thesis' value or wording as printed (text; quoted, never used as a result).
    computed:
        The model's value as shown in the report (text).
    criterion:
        The acceptance test in words (e.g. ``|Δ| ≤ 1`` or ``in [0.3, 3] ms``).
    ok:
        Whether the criterion holds (computed by the constructor); ``None`` for an input.
    value:
        The computed number, when there is one (NaN otherwise).
    note:
        Why, or what the check relies on (optional).
    """

    statement: str
    thesis: str
    computed: str
    criterion: str
    ok: bool | None
    value: float = math.nan
    note: str = ""

    @property
    def verdict(self) -> str:
        """The verdict word of :data:`VERDICTS` for :attr:`ok`."""
        return VERDICTS[self.ok]

    # ------------------------------------------------------------------ constructors

    @classmethod
    def near(
        cls, statement: str, value: float, thesis: float, tol: float, *, unit: str = "", fmt: str = ".4g", rel: bool = False, note: str = "", thesis_text: str | None = None
    ) -> Claim:
        """``|value − thesis| ≤ tol`` (``rel=True``: ``≤ tol·|thesis|``). NaN never matches.
        ``thesis_text`` replaces the displayed thesis value (e.g. "exact" for a residual)."""
        bound = tol * abs(thesis) if rel else tol
        ok = bool(math.isfinite(value) and abs(value - thesis) <= bound)
        u = f" {unit}" if unit else ""
        crit = f"|Δ| ≤ {tol:g}·|thesis|" if rel else f"|Δ| ≤ {tol:g}{u}"
        shown = f"{_fmt(value, fmt)}{u} (Δ = {_fmt(value - thesis, '+' + fmt)})" if math.isfinite(value) else str(value)
        return cls(statement, thesis_text if thesis_text is not None else f"{thesis:g}{u}", shown, crit, ok, float(value), note)

    @classmethod
    def between(cls, statement: str, value: float, lo: float, hi: float, *, thesis: str, unit: str = "", fmt: str = ".3g", note: str = "") -> Claim:
        """``lo ≤ value ≤ hi`` (a stated range standing for the thesis' approximate wording)."""
        ok = bool(math.isfinite(value) and lo <= value <= hi)
        u = f" {unit}" if unit else ""
        return cls(statement, thesis, f"{_fmt(value, fmt)}{u}", f"in [{lo:g}, {hi:g}]{u}", ok, float(value), note)

    @classmethod
    def all_between(cls, statement: str, values: dict[str, float], lo: float, hi: float, *, thesis: str, unit: str = "", fmt: str = ".3g", note: str = "") -> Claim:
        """Every value of ``values`` (label -> number) in ``[lo, hi]``."""
        ok = bool(values) and all(math.isfinite(v) and lo <= v <= hi for v in values.values())
        u = f" {unit}" if unit else ""
        shown = ", ".join(f"{k}: {_fmt(v, fmt)}{u}" for k, v in values.items())
        return cls(statement, thesis, shown, f"each in [{lo:g}, {hi:g}]{u}", ok, note=note)

    @classmethod
    def holds(cls, statement: str, ok: bool, *, computed: str, criterion: str, thesis: str = "(qualitative)", note: str = "") -> Claim:
        """A qualitative claim: ``ok`` is a condition the trial evaluated on computed numbers."""
        return cls(statement, thesis, computed, criterion, bool(ok), note=note)

    @classmethod
    def given(cls, statement: str, *, computed: str, note: str, thesis: str = "") -> Claim:
        """A thesis value the model was pinned to (an input, so no verdict is claimed)."""
        return cls(statement, thesis, computed, "used as an input", None, note=note)

    # ------------------------------------------------------------------ (de)serialisation

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (NaN as None)."""
        d = asdict(self)
        d["value"] = None if not math.isfinite(self.value) else self.value
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Claim:
        """Inverse of :meth:`to_dict`."""
        d = dict(d)
        d["value"] = math.nan if d.get("value") is None else float(d["value"])
        return cls(**d)


def render(claims: list[Claim], *, note_column: bool = True) -> str:
    """The markdown table of ``claims`` (statement, thesis, paritysim, criterion, verdict)."""
    head = "| thesis statement | thesis | paritysim | criterion | verdict |"
    lines = [head + (" note |" if note_column else ""), "|---|---|---|---|---|" + ("---|" if note_column else "")]
    for c in claims:
        cells = [c.statement, c.thesis, c.computed, c.criterion, f"**{c.verdict}**"]
        if note_column:
            cells.append(c.note)
        lines.append("| " + " | ".join(s.replace("|", "\\|") for s in cells) + " |")
    return "\n".join(lines)


def save(path: str | Path, claims: list[Claim], values: dict[str, Any] | None = None) -> Path:
    """Writes ``{"claims": [...], "values": {...}}`` (``values``: numbers the report text needs)."""
    from ._errors import invalid

    payload = {"claims": [c.to_dict() for c in claims], "values": values or {}}
    path = Path(path)
    try:
        path.write_text(json.dumps(payload, indent=1, allow_nan=True))
    except OSError as exc:
        raise invalid("path", str(path), f"a writable file path ({exc.strerror or exc})") from exc
    return path


def load(path: str | Path) -> tuple[list[Claim], dict[str, Any]]:
    """Reads what :func:`save` wrote; a file that cannot be read or holds something else is an
    ``InvalidParameterError`` naming ``path``."""
    from ._errors import invalid

    path = Path(path)
    try:
        payload = json.loads(path.read_text())
        return [Claim.from_dict(d) for d in payload["claims"]], payload.get("values", {})
    except OSError as exc:
        raise invalid("path", str(path), f"a readable claims file ({exc.strerror or exc})") from exc
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        raise invalid("path", str(path), f"a claims file as paritysim.claims.save writes it ({type(exc).__name__}: {exc})") from exc
