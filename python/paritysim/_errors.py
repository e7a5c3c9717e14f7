"""Raising the typed errors from Python with the same attributes as the Rust side."""

from __future__ import annotations

from numbers import Integral, Real
import re
from collections.abc import Iterable
from typing import Any

from ._core import InvalidParameterError


def invalid(field: str, value: Any, allowed: str) -> InvalidParameterError:
    """An ``InvalidParameterError`` worded like the Rust one, with ``.field`` and ``.kind`` set."""
    err = InvalidParameterError(f"invalid `{field}` = {value}: must be {allowed}")
    err.field = field  # type: ignore[attr-defined]
    err.kind = "InvalidParameter"  # type: ignore[attr-defined]
    return err


def real(field: str, value: Any) -> float:
    """``float(value)`` for a public argument, or an ``InvalidParameterError`` naming ``field``
    (the conversion's own error kept as ``__cause__``). Strings and booleans are not numbers."""
    if isinstance(value, (str, bytes, bool)):
        raise invalid(field, repr(value), "a real number")
    try:
        return float(value)
    except (TypeError, ValueError, OverflowError) as exc:
        raise invalid(field, repr(value), "a real number") from exc


def whole(field: str, value: Any, lo: int = 0, hi: int = 2**53) -> int:
    """An integer argument in ``[lo, hi]`` (an integral float such as ``8.0`` is accepted), or an
    ``InvalidParameterError`` naming ``field``."""
    if isinstance(value, Real) and not isinstance(value, (bool, Integral)) and float(value).is_integer():
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise invalid(field, repr(value), f"an integer in [{lo}, {hi}]")
    number = int(value)
    if not lo <= number <= hi:
        raise invalid(field, number, f"an integer in [{lo}, {hi}]")
    return number


def reals(field: str, value: Any) -> Any:
    """``np.asarray(value, float64)`` for a public array argument, or an
    ``InvalidParameterError`` naming ``field`` (strings, dicts and ragged lists are not numbers)."""
    import numpy as np

    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as exc:
        shown = repr(value)
        raise invalid(field, shown if len(shown) <= 60 else shown[:57] + "...", "a real number or an array of real numbers") from exc


def _edit_distance(a: str, b: str) -> int:
    """Levenshtein distance (the Rust core's `schema::nearest` uses the same measure)."""
    if len(a) < len(b):
        a, b = b, a
    previous = list(range(len(b) + 1))
    for i, ca in enumerate(a, 1):
        current = [i]
        for j, cb in enumerate(b, 1):
            current.append(min(previous[j] + 1, current[j - 1] + 1, previous[j - 1] + (ca != cb)))
        previous = current
    return previous[-1]


def _typo(a: str, b: str) -> int | None:
    """The edit distance of ``a`` and ``b`` when it is a plausible typo (the Rust core's rule:
    at most 2, or a third of the longer), else ``None``."""
    if not a or not b:
        return None
    d = _edit_distance(a, b)
    return d if d <= max(2, max(len(a), len(b)) // 3) else None


def close_names(name: str, valid: Iterable[str], limit: int = 5) -> list[str]:
    """At most ``limit`` names of ``valid`` close to ``name``, nearest first: a typo of the whole
    name or of its last path segment (``balance_spring`` in ``drivetrain.balance_spring``), then
    names that contain ``name``'s last segment, then names sharing a word with it."""
    word = str(name).lower()
    tail = word.rsplit(".", 1)[-1]
    words = set(re.split(r"[._\[\]]+", tail)) - {""}
    ranked: list[tuple[int, int, str]] = []
    for order, candidate in enumerate(dict.fromkeys(valid)):
        text = candidate.lower()
        last = text.rsplit(".", 1)[-1]
        scores = [d for d in (_typo(word, text), _typo(tail, last)) if d is not None]
        if scores:
            score = min(scores)
        elif len(tail) >= 3 and tail in text:
            score = 50  # containment ranks after every typo
        elif shared := len(words & set(re.split(r"[._\[\]]+", last)) - {"", "of", "per"}):
            score = 60 - shared  # shares a word of the last segment: `balance` of `balance_stiffness`
        else:
            continue
        ranked.append((score, order, candidate))
    return [c for _, _, c in sorted(ranked)[:limit]]


def suggest(name: str, valid: Iterable[str], limit: int = 5, listed_by: str | None = None) -> str:
    """The ``allowed`` text for an unknown ``name`` among ``valid`` (paths, metrics, knobs,
    settings): the nearest name and at most ``limit`` close ones, never the whole list unless it
    is short. ``listed_by`` tells where the full list is (e.g. ``"ps.spec_paths(spec)"``).

    The one "did you mean" of the Python facade: every argument that takes a name uses it."""
    names = list(dict.fromkeys(valid))
    close = close_names(name, names, limit)
    if len(names) <= limit:
        listing = "one of: " + ", ".join(f"`{n}`" for n in names)
        return f"did you mean `{close[0]}`? ({listing})" if close else listing
    where = f"{listed_by} lists all {len(names)}" if listed_by else f"{len(names)} names, e.g. " + ", ".join(f"`{n}`" for n in names[:3])
    if close:
        others = f"also close: {', '.join(f'`{c}`' for c in close[1:])}; " if len(close) > 1 else ""
        return f"a known name: did you mean `{close[0]}`? ({others}{where})"
    return f"a known name (none close to `{name}`; {where})"
