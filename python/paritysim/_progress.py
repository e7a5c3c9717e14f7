"""A progress bar for one long call: ``simulate``, ``calibrate``, ``trim`` and ``continuation`` (issue 33).

A single run has no count of work done that the engine reports while it integrates, so the bar
shows the wall time spent against the call's wall budget (``max_wall_ms``: where it would stop),
and the runs finished so far for the loops (``calibrate``, ``trim``). It appears only once the
call has taken `DELAY_S` (a run of a second shows nothing), on stderr, drawn by tqdm as in
``ps.sweep`` (the same ``progress=True`` argument: ``False`` turns it off). ``paritysim ...
--quiet`` turns every bar off (`quiet`). The bar lives on a daemon thread: the engine releases
the GIL while it runs, so the bar moves while the run does. One watcher thread serves every call
and starts a bar's thread only when the call is due: a short call costs a lock, not a thread.
"""

from __future__ import annotations

import math
import os
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from types import TracebackType
from typing import Any

#: A call shows its bar once it has run this long (s).
DELAY_S = 3.0
#: Refresh period of a shown bar (s).
REFRESH_S = 0.5
_quiet = False


@contextmanager
def quiet() -> Iterator[None]:
    """No bar inside this block (the CLI's ``--quiet``)."""
    global _quiet
    before, _quiet = _quiet, True
    try:
        yield
    finally:
        _quiet = before


def _seconds(budget_ms: Any) -> float | None:
    """The budget in seconds for the bar, or None (no budget, or a value the call itself will
    refuse by name: a bar is drawn before the spec is checked)."""
    try:
        ms = float(budget_ms)
    except (TypeError, ValueError):
        return None
    return ms / 1e3 if math.isfinite(ms) and ms > 0 else None


class LongRun:
    """``with LongRun("simulate", progress, budget_ms) as bar: ...``; ``bar.done()`` counts a
    finished run of a loop."""

    def __init__(self, desc: str, progress: bool, budget_ms: float | None, unit: str = "run") -> None:
        self.desc, self.unit = desc, unit
        self.enabled = bool(progress) and not _quiet
        self.budget_s = _seconds(budget_ms)
        self.runs = 0
        self.shown = False
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def done(self, n: int = 1) -> None:
        self.runs += n

    def __enter__(self) -> LongRun:
        self._start = time.monotonic()
        if self.enabled:
            _watch(self)
        return self

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None, tb: TracebackType | None) -> None:
        with _runs:
            _active.discard(self)
            self._stop.set()
            thread = self._thread
        if thread is not None:
            thread.join()

    def _draw(self) -> None:
        from tqdm.auto import tqdm  # type: ignore[import-untyped]

        elapsed = "{n:.0f}/{total:.0f} s of the wall budget" if self.budget_s else "{n:.0f} s"
        fmt = "{desc}: " + ("{percentage:3.0f}%|{bar}| " if self.budget_s else "") + elapsed + "{postfix}"
        bar: Any = tqdm(total=self.budget_s, desc=self.desc, file=sys.stderr, bar_format=fmt, dynamic_ncols=True, leave=False)
        self.shown = True
        try:
            while True:
                bar.n = time.monotonic() - self._start
                if self.runs:
                    bar.set_postfix_str(f"{self.runs} {self.unit}s done", refresh=False)
                bar.refresh()
                if self._stop.wait(REFRESH_S):
                    break
        finally:
            bar.close()


# One watcher thread for every call (a thread started per call cost 0.4 ms, 45 % of a 0.9 ms
# simulate; docs/findings.md §30): it starts a run's drawing thread once the run is due.
_runs = threading.Condition()
_active: set[LongRun] = set()
_watcher: threading.Thread | None = None
_wakes_at: float | None = None  # the watcher's next wake-up (None: only when notified)


def _watch(run: LongRun) -> None:
    global _watcher
    with _runs:
        _active.add(run)
        if _watcher is None or not _watcher.is_alive():  # first call, or a forked child
            _watcher = threading.Thread(target=_watch_loop, name="paritysim-progress", daemon=True)
            _watcher.start()
        elif _wakes_at is None or run._start + DELAY_S < _wakes_at:  # it would wake too late
            _runs.notify()


def _watch_loop() -> None:
    global _wakes_at
    with _runs:
        while True:
            now = time.monotonic()
            pending = []
            for run in _active:
                if run._thread is not None:
                    continue
                if now - run._start >= DELAY_S:
                    run._thread = threading.Thread(target=run._draw, name=f"paritysim-progress-{run.desc}", daemon=True)
                    run._thread.start()
                else:
                    pending.append(run._start + DELAY_S)
            _wakes_at = min(pending) if pending else None
            _runs.wait(timeout=_wakes_at - now if _wakes_at is not None else None)


def _reset_after_fork() -> None:
    """A forked child (a process pool's worker) starts with no watcher and a fresh lock: the
    parent's lock may have been held by its watcher at the fork, and no thread survives it."""
    global _runs, _watcher, _wakes_at
    _runs = threading.Condition()
    _active.clear()
    _watcher, _wakes_at = None, None


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_reset_after_fork)
