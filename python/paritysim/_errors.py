"""Raising the typed errors from Python with the same attributes as the Rust side."""

from __future__ import annotations

from typing import Any

from ._core import InvalidParameterError


def invalid(field: str, value: Any, allowed: str) -> InvalidParameterError:
    """An ``InvalidParameterError`` worded like the Rust one, with ``.field`` and ``.kind`` set."""
    err = InvalidParameterError(f"invalid `{field}` = {value}: must be {allowed}")
    err.field = field  # type: ignore[attr-defined]
    err.kind = "InvalidParameter"  # type: ignore[attr-defined]
    return err
