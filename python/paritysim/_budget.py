"""A wall-clock budget for Python-level loops of engine calls (``trim``, ``calibrate``): the
remaining time is handed to every simulation as its ``options.max_wall_ms``, so the engine's
one budget mechanism (``integrate::budget``: deadline and Ctrl-C, checked inside the
integrator) stops the run in progress, and the loop stops between runs (issue 34)."""

from __future__ import annotations

import math
import time
from typing import Any

from . import _core
from ._errors import invalid, real


def exceeded(field: str, ms: float) -> _core.IntegrationError:
    err = _core.IntegrationError(f"exceeded the wall-time budget `{field}` = {ms:g} ms (raise it, or ask for less work)")
    err.field = field  # type: ignore[attr-defined]
    err.kind = "Integration"  # type: ignore[attr-defined]
    err.time = math.nan  # type: ignore[attr-defined]
    err.state = []  # type: ignore[attr-defined]
    err.problems = [(field, f"{ms:g}", "a larger budget (ms), or less work")]  # type: ignore[attr-defined]
    return err


class Deadline:
    """``max_wall_ms`` from now, for the argument ``field``."""

    def __init__(self, field: str, max_wall_ms: Any) -> None:
        ms = real(field, max_wall_ms)
        if not (math.isfinite(ms) and 0.0 < ms <= 1e9):
            raise invalid(field, max_wall_ms, "a wall-time budget in (0, 1e9] ms")
        self.field, self.ms = field, ms
        self.end = time.monotonic() + ms / 1e3

    def remaining_ms(self) -> float:
        """What is left (ms), or the budget's error once it is spent."""
        left = (self.end - time.monotonic()) * 1e3
        if left <= 0.0:
            raise exceeded(self.field, self.ms)
        return left

    def run(self, simulate: Any, spec: Any, **overrides: Any) -> Any:
        """``simulate(spec, **overrides)`` within the time left; the run's own budget error
        becomes this budget's when this one is what ran out."""
        left = self.remaining_ms()
        own = spec.options.max_wall_ms
        try:
            return simulate(spec, **overrides, max_wall_ms=left if own is None else min(own, left))
        except _core.IntegrationError as exc:
            if getattr(exc, "field", None) == "options.max_wall_ms" and time.monotonic() >= self.end - 1e-3:
                raise exceeded(self.field, self.ms) from exc
            raise
