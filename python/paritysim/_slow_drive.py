"""Fail fast on a drive frequency typed in the wrong unit (issue 33).

``frequency_hz = 0.12`` (kHz thinking) makes a drive period of 8.3 s on a device whose dynamics
live on the millisecond scale: the integrator still steps at the device's own time scale, so the
run can spend its whole wall budget (a minute) before reaching a steady state. A drive slower
than `SLOW_DRIVE_HZ` is run first under a short wall budget (`PROBE_WALL_MS`): if it finishes,
the result is returned with a warning that it is quasi-static; if not, the run is refused with an
error naming ``actuator.waveform.frequency_hz``, the cost measured so far and the likely value.
Setting ``options.duration_ms`` (a chosen simulated time) runs a slow drive on purpose.
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable
from typing import TypeVar

from ._exceptions import IntegrationError, InvalidParameterError

FIELD = "actuator.waveform.frequency_hz"
#: Below this drive frequency a run is probed first: the shipped devices flap at 100-200 Hz, and a
#: drive period of a second is hundreds of their wingbeats (inertia and drag play no part).
SLOW_DRIVE_HZ = 1.0
#: Wall time a slow drive may take before it is refused (the full budget is `options.max_wall_ms`).
PROBE_WALL_MS = 3000.0

T = TypeVar("T")


def likely_meant(frequency_hz: float) -> float | None:
    """The frequency a unit slip most likely meant: kHz typed as Hz (×1000), when that lands in
    the flapping range (1-1000 Hz)."""
    meant = frequency_hz * 1000.0
    return float(f"{meant:.3g}") if 1.0 <= meant <= 1000.0 else None


def _hint(frequency_hz: float) -> str:
    meant = likely_meant(frequency_hz)
    return f"; did you mean {meant:g} Hz?" if meant is not None else ""


def guarded(spec: object, run: Callable[[object], T]) -> T:
    """``run(spec)``, probed first under `PROBE_WALL_MS` when its sine drive is slower than
    `SLOW_DRIVE_HZ` and no ``options.duration_ms`` is set."""
    actuator = getattr(spec, "actuator", None)
    waveform = getattr(actuator, "waveform", None)
    frequency = getattr(waveform, "frequency_hz", None)
    options = spec.options  # type: ignore[attr-defined]
    if (
        frequency is None
        or getattr(waveform, "kind", "sine") != "sine"
        or not (0.0 < frequency < SLOW_DRIVE_HZ)
        or options.duration_ms is not None
    ):
        return run(spec)
    budget = float(options.max_wall_ms)
    probe = min(budget, PROBE_WALL_MS)
    period_ms = 1000.0 / frequency
    started = time.perf_counter()
    try:
        result = run(spec.replace(options=options.with_fields("options", max_wall_ms=probe)))  # type: ignore[attr-defined]
    except IntegrationError as exc:
        if getattr(exc, "field", None) != "options.max_wall_ms":
            raise
        wall_ms = (time.perf_counter() - started) * 1000.0
        reached = float(getattr(exc, "time", math.nan))
        cycles = max(int(options.min_cycles), 1)
        periods = reached / period_ms
        if periods >= cycles:
            cost = f"{periods:.1f} drive periods without reaching a steady state"
        else:  # the fewest cycles the run needs, at the rate measured so far
            need_s = cycles * period_ms * wall_ms / max(reached, 1e-9) / 1000.0
            cost = f"{periods:.2f} of the at least {cycles} periods the run needs (~{need_s:.0f} s at this rate, more to a steady state)"
        err = InvalidParameterError(
            f"invalid `{FIELD}` = {frequency:g}: must be a flapping drive in Hz{_hint(frequency)} "
            f"A drive period of {period_ms:.0f} ms, while the integrator steps at this device's "
            f"millisecond dynamics: {wall_ms / 1000:.1f} s ran {cost}; to simulate a slow drive "
            f"on purpose, set `options.duration_ms`"
        )
        err.field = FIELD  # type: ignore[attr-defined]
        err.kind = "InvalidParameter"  # type: ignore[attr-defined]
        allowed = f"a flapping drive in Hz{_hint(frequency)}"
        err.problems = [(FIELD, f"{frequency:g}", allowed)]  # type: ignore[attr-defined]
        raise err from exc
    message = (
        f"`{FIELD}` = {frequency:g} Hz: the result is quasi-static (a drive period of "
        f"{period_ms:.0f} ms, far longer than the device's dynamics: inertia and aerodynamic "
        f"drag play no part){_hint(frequency)}"
    )
    warnings.warn(message, UserWarning, stacklevel=3)
    return result
