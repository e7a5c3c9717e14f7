"""The bar of one long call (issue 33): ``simulate``, ``calibrate``, ``trim`` and ``continuation`` show wall time
against their budget on stderr once they have run `_progress.DELAY_S`; a short call, and
``progress=False``, and the CLI's ``--quiet`` show nothing."""

from __future__ import annotations

import re
import time
from pathlib import Path

import pytest

import paritysim as ps
from paritysim import _progress

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture
def soon(monkeypatch: pytest.MonkeyPatch) -> None:
    """A bar after 50 ms instead of a few seconds (the tests' runs take about a second)."""
    monkeypatch.setattr(_progress, "DELAY_S", 0.05)
    monkeypatch.setattr(_progress, "REFRESH_S", 0.05)


def _slow_run(**kwargs: object) -> None:
    """The HMF at 1e-3 Hz (a 1e6 ms period, on purpose): stopped by its 1.5 s wall budget."""
    slow = ps.load_spec(EXAMPLES / "hmf.toml").with_paths({"actuator.frequency_hz": 1e-3, "options.duration_ms": 1e7})
    with pytest.raises(ps.IntegrationError, match=r"options\.max_wall_ms"):
        ps.simulate(slow, max_wall_ms=1500.0, **kwargs)  # type: ignore[arg-type]


def test_a_long_simulate_shows_its_wall_time_against_the_budget(soon: None, capsys: pytest.CaptureFixture[str]) -> None:
    _slow_run()
    err = capsys.readouterr().err
    shown = [(int(n), int(total)) for n, total in re.findall(r"simulate: +\d+%\|[^|]*\| (\d+)/(\d+) s of the wall budget", err)]
    assert shown, err
    assert all(total == 2 for _, total in shown)  # 1.5 s, shown to the second
    assert shown[-1][0] >= 1 and [n for n, _ in shown] == sorted(n for n, _ in shown)  # it moved, forwards


def test_no_bar_when_asked_or_quiet_or_short(soon: None, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    _slow_run(progress=False)
    assert capsys.readouterr().err == ""
    with _progress.quiet():
        _slow_run()
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(_progress, "DELAY_S", 30.0)
    ps.simulate(ps.load_spec(EXAMPLES / "hmf.toml"), max_cycles=5, samples_per_cycle=40)
    assert capsys.readouterr().err == ""


def test_a_calibration_counts_its_runs(soon: None, capsys: pytest.CaptureFixture[str]) -> None:
    """A callable model of 20 ms per evaluation: the bar counts the finished runs; the inner
    simulations of a spec model never draw bars of their own (``progress=False`` inside)."""

    def model(x: float) -> dict[str, float]:
        time.sleep(0.02)
        return {"y": (x - 0.3) ** 2 + 1.0}

    start = time.monotonic()
    fit = ps.calibrate(model, {"y": 1.0}, {"x": (0.0, 1.0)}, max_nfev=20, xtol=1e-6)
    took = time.monotonic() - start
    err = capsys.readouterr().err
    counts = [int(n) for n in re.findall(r"(\d+) runs done", err)]
    assert counts and counts == sorted(counts) and counts[-1] <= len(fit.iterations), err
    assert "calibrate:" in err and f"/{600} s of the wall budget" in err
    assert took > 0.1  # long enough to show


@pytest.mark.parametrize("budget", ["3", [1.0], None])
def test_the_bar_never_hides_the_specs_own_error_for_a_bad_budget(budget: object) -> None:
    """Found by the fuzz (seed 34): the bar read ``options.max_wall_ms`` before the spec was
    checked, and ``[1.0]`` or ``"3"`` raised ``TypeError`` from the comparison with 0."""
    hmf = ps.load_spec(EXAMPLES / "hmf.toml")
    if budget is None:  # no budget: the bar shows elapsed time only; the run is fine
        assert ps.simulate(hmf, max_wall_ms=None, max_cycles=5, samples_per_cycle=40).cycles_run >= 1
        return
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.simulate(hmf, max_wall_ms=budget)
    assert info.value.field == "options.max_wall_ms"


def test_short_calls_start_no_thread_each(monkeypatch: pytest.MonkeyPatch) -> None:
    """One watcher serves every call: a thread started per call cost 0.4 ms, 45 % of a short
    simulate (docs/findings.md §30)."""
    hmf = ps.load_spec(EXAMPLES / "hmf.toml")
    ps.simulate(hmf, max_cycles=2, samples_per_cycle=20)  # the watcher exists
    started: list[str] = []
    start = _progress.threading.Thread.start

    def counting(self: _progress.threading.Thread) -> None:
        started.append(self.name)
        start(self)

    monkeypatch.setattr(_progress.threading.Thread, "start", counting)
    for _ in range(10):
        ps.simulate(hmf, max_cycles=2, samples_per_cycle=20)
    assert started == []


def test_a_bar_after_a_short_call_with_a_later_deadline(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """The watcher sleeping towards an earlier call's (long) deadline wakes for a new call due
    sooner."""
    monkeypatch.setattr(_progress, "DELAY_S", 30.0)
    ps.simulate(ps.load_spec(EXAMPLES / "hmf.toml"), max_cycles=2, samples_per_cycle=20)
    monkeypatch.setattr(_progress, "DELAY_S", 0.05)
    monkeypatch.setattr(_progress, "REFRESH_S", 0.05)
    _slow_run()
    assert "of the wall budget" in capsys.readouterr().err


def _child_can_lock() -> bool:
    got = _progress._runs.acquire(timeout=2.0)
    if got:
        _progress._runs.release()
    return got


def test_a_forked_child_does_not_inherit_a_held_watcher_lock() -> None:
    """The watcher holds its lock between waits; a process pool forking then gave its worker a
    lock nobody would release (the worker's first bar would hang)."""
    import multiprocessing

    import threading

    held, done = threading.Event(), threading.Event()

    def hold() -> None:  # the watcher's place: another thread holds the lock at the fork
        with _progress._runs:
            held.set()
            done.wait(30)

    holder = threading.Thread(target=hold)
    holder.start()
    held.wait(30)
    try:
        with multiprocessing.get_context("fork").Pool(1) as pool:
            assert pool.apply(_child_can_lock)
    finally:
        done.set()
        holder.join()


def test_a_long_continuation_shows_its_bar_unless_asked_not_to(soon: None, capsys: pytest.CaptureFixture[str]) -> None:
    linkage = ps.devices.load("sreetharan2012_3_3_parity_linkage")
    run = lambda **kw: ps.continuation(linkage, "drivetrain.balance_spring", 900.0, start=1000.0, metrics=False, **kw)  # noqa: E731
    run(progress=False)
    assert capsys.readouterr().err == ""
    branch = run()
    err = capsys.readouterr().err
    assert re.search(r"continuation: +\d+%\|[^|]*\| \d+/600 s of the wall budget", err), err
    assert branch.branch.height >= 2
