"""Raising the typed errors from Python with the same attributes as the Rust side."""

from __future__ import annotations

from numbers import Integral, Real
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
