"""Bounded work (issue 14): the per-run step and wall-time budgets, cancellation inside the
integrator (Ctrl-C during ``ps.simulate`` and a sweep), work limits of the recording, and the
reproducers of the issue as tests. Latencies are measured in benchmarks/ctrl_c_latency.py; the
bounds here only tell "reacted" from "ignored" (the point would otherwise run for minutes)."""

from __future__ import annotations

import _thread
import threading
import time
from pathlib import Path
from typing import Any

import pytest

import paritysim as ps

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="module")
def hmf() -> ps.Simulation:
    return ps.load_spec(EXAMPLES / "hmf.toml")


def test_a_pathological_point_becomes_an_error_row_naming_the_budget(hmf: ps.Simulation) -> None:
    """Reproducer 4: the §3.4 HMF device at 1e-3 Hz (a period of 1e6 ms) would run for minutes;
    with a 300 ms budget it is an error row and the other point is unaffected."""
    df = ps.sweep(hmf, {"actuator.frequency_hz": [1e-3, 120.0]}, options={"max_wall_ms": 300.0, "max_cycles": 5}, progress=False)
    assert df.height == 2
    slow, normal = df.row(0, named=True), df.row(1, named=True)
    assert slow["status"] == "error" and slow["error_kind"] == "Integration"
    assert "options.max_wall_ms" in slow["error"] and "300 ms" in slow["error"]
    assert normal["status"] == "ok" and normal["left_stroke_amplitude"] > 0.1


def test_simulate_names_the_wall_budget(hmf: ps.Simulation) -> None:
    with pytest.raises(ps.IntegrationError, match=r"options\.max_wall_ms") as info:
        # duration_ms: a slow drive on purpose (without it the frequency is blamed, test_slow_drive.py)
        ps.simulate(hmf.with_paths({"actuator.frequency_hz": 1e-3}), max_wall_ms=100.0, duration_ms=1e7)
    assert 0.0 < info.value.time < 1e6 * 300  # stopped partway through the transient
    assert info.value.field == "options.max_wall_ms"


def test_the_step_budget_names_max_steps(hmf: ps.Simulation) -> None:
    with pytest.raises(ps.IntegrationError, match=r"options\.max_steps") as info:
        ps.simulate(hmf, max_steps=20)
    assert info.value.field == "options.max_steps"


@pytest.mark.parametrize("value", [0.0, -1.0, float("nan"), 1e9])
def test_a_bad_wall_budget_is_a_typed_error(hmf: ps.Simulation, value: float) -> None:
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.simulate(hmf, max_wall_ms=value)
    assert "max_wall_ms" in str(info.value.field)


def test_ctrl_c_interrupts_simulate_inside_the_integration(hmf: ps.Simulation) -> None:
    """SIGINT (``_thread.interrupt_main``) 0.3 s into a run that would take a minute: the
    integrator's cancel flag stops it and ``KeyboardInterrupt`` is raised."""
    # duration_ms: a slow drive on purpose, not refused after simulate's 3 s probe (_slow_drive)
    slow = hmf.with_paths({"actuator.frequency_hz": 1e-3, "options.duration_ms": 1e7})
    timer = threading.Timer(0.3, _thread.interrupt_main)
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            ps.simulate(slow, max_wall_ms=60_000.0)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 30.0  # ignored, it would run to the 60 s budget


def test_simulate_works_again_after_an_interrupt(hmf: ps.Simulation) -> None:
    fast = {"max_cycles": 5, "samples_per_cycle": 40}
    first = ps.simulate(hmf, **fast).metrics
    timer = threading.Timer(0.2, _thread.interrupt_main)
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        ps.simulate(hmf.with_paths({"actuator.frequency_hz": 1e-3, "options.duration_ms": 1e7}))
    timer.cancel()
    assert ps.simulate(hmf, **fast).metrics == first


def test_ctrl_c_stops_running_sweep_points_and_raises_with_the_finished_rows(hmf: ps.Simulation) -> None:
    """Four slow points on two threads: Ctrl-C stops the two running ones inside integration; they
    count as not run, so the interrupt carries no row, and nothing waits for the points."""
    timer = threading.Timer(0.5, _thread.interrupt_main)
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(ps.sweep.SweepInterrupted) as info:
            ps.sweep(hmf, {"actuator.frequency_hz": [1e-3] * 4}, options={"max_wall_ms": 60_000.0}, threads=2, progress=False)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 30.0
    assert info.value.result.height == 0 and info.value.total == 4


def test_reproducer_1_record_cycles_out_of_range_is_an_error_row_not_an_abort(hmf: ps.Simulation) -> None:
    df = ps.sweep(hmf, {"options.record_cycles": [1, 10**15]}, options={"max_cycles": 5, "samples_per_cycle": 40}, progress=False)
    assert df["status"].to_list() == ["ok", "error"]
    assert "options.record_cycles" in df["error"][1] and df["error_kind"][1] == "InvalidParameter"


def test_reproducer_2_a_chunk_where_every_point_fails_keeps_its_rows(hmf: ps.Simulation) -> None:
    with pytest.warns(RuntimeWarning, match="1 of 1 sweep points failed"):
        df = ps.sweep(hmf, {"actuator.frequency_hz": [-1.0]}, keep_cycle=True, progress=False)
    assert df.height == 1 and df["status"][0] == "error"
    assert "frequency_hz" in df["error"][0] and df["cycle_time_ms"][0] is None


def test_reproducer_2_with_several_chunks_all_failing(hmf: ps.Simulation) -> None:
    values = [-1.0, -2.0, 0.0, float("nan"), 1e9]
    with pytest.warns(RuntimeWarning):
        df = ps.sweep(hmf, {"actuator.frequency_hz": values}, keep_cycle=["left_phi"], chunk_size=2, progress=False)
    assert df["point"].to_list() == list(range(len(values)))
    assert (df["status"] == "error").all() and df["error"].str.contains("frequency_hz").all()


def test_reproducer_3_samples_per_cycle_2_pow_63_is_a_typed_error(hmf: ps.Simulation) -> None:
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.simulate(hmf, samples_per_cycle=2**63, record_cycles=2)
    assert "samples_per_cycle" in str(info.value.field)


def test_the_recording_size_is_limited_before_anything_runs(hmf: ps.Simulation) -> None:
    """Each field is in its range, the product is not: 1e6 samples × 1e4 cycles would be 80 GB."""
    start = time.monotonic()
    with pytest.raises(ps.InvalidParameterError, match="recorded samples per run") as info:
        ps.simulate(hmf, samples_per_cycle=10**6, record_cycles=10**4)
    assert info.value.field == "record_cycles"
    assert time.monotonic() - start < 5.0  # rejected up front, not after the transient


def test_cli_sweep_ctrl_c_exits_130_in_one_line_and_keeps_the_finished_rows(tmp_path: Path) -> None:
    """``paritysim sweep`` with two fast points then slow ones: SIGINT once the first chunk is
    checkpointed; exit 130, one line on stderr, the finished rows on disk."""
    import os
    import signal
    import subprocess
    import sys

    study = tmp_path / "study.toml"
    study.write_text(
        f'spec = "{(EXAMPLES / "hmf.toml").as_posix()}"\nmetrics = ["left_stroke_amplitude"]\nchunk_size = 2\n'
        '[options]\nmax_cycles = 5\nsamples_per_cycle = 40\nmax_wall_ms = 600000.0\n'
        '[grid]\n"actuator.frequency_hz" = [100.0, 110.0, 0.001, 0.001]\n'
    )
    out = tmp_path / "runs"
    proc = subprocess.Popen([sys.executable, "-m", "paritysim", "sweep", str(study), "--out", str(out), "--quiet", "--threads", "1"], stderr=subprocess.PIPE, text=True, env={**os.environ})
    parts = out / "study.parquet.parts"
    deadline = time.monotonic() + 60
    while not list(parts.glob("part-*.parquet")):
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.02)
    time.sleep(0.3)  # inside the slow chunk
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert err.strip().splitlines() == ["study: interrupted after 2 of 4 points; re-run the same command to resume"]
    import polars as pl

    saved = pl.concat([pl.read_parquet(p) for p in parts.glob("part-*.parquet")])
    assert sorted(saved["point"].to_list()) == [0, 1] and (saved["status"] == "ok").all()


def _slow_stability_calls() -> dict[str, Any]:
    """Calls of ``ps.stability`` and ``ps.continuation`` that would run for tens of seconds
    (the §3.4 devices at 1e-3 Hz, a 4M-point Hill chart) unless Ctrl-C stops them."""
    import numpy as np

    from paritysim import stability

    hmf = ps.load_spec(EXAMPLES / "hmf.toml").with_paths({"actuator.frequency_hz": 1e-3})
    parity = ps.load_spec(EXAMPLES / "drag_parity.toml").with_paths({"actuator.frequency_hz": 1e-3})
    return {
        "floquet": lambda: stability.floquet(hmf),
        "k2_sweep": lambda: stability.k2_sweep(parity, [1.0, 2.0, 3.0, 4.0]),
        "linearise": lambda: stability.linearise(parity),
        "disturbance_response": lambda: stability.disturbance_response(parity, [10.0, 20.0], 0.1),
        "stability_chart": lambda: stability.stability_chart(np.linspace(0.0, 3.0, 2000), np.linspace(-1.0, 30.0, 2000), brockett=False),
        "continuation": lambda: ps.continuation(hmf, "actuator.waveform.frequency_hz", 2e-3, start=1e-3),
        # Run on the calling thread (no worker thread): polled from the orbit's solve.
        "sensitivity": lambda: ps.sensitivity(hmf, params=["actuator.stiffness"], progress=False),
    }


@pytest.mark.parametrize("name", list(_slow_stability_calls()))
def test_ctrl_c_interrupts_stability_and_continuation(name: str) -> None:
    """SIGINT 0.3 s into each long analysis: the cancel flag installed by the bindings reaches
    every integration (on every pool thread) and ``KeyboardInterrupt`` is raised; ignored, the
    call would run to its 60 s budget or the end of the chart."""
    call = _slow_stability_calls()[name]
    timer = threading.Timer(0.3, _thread.interrupt_main)
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        timer.cancel()
    assert 0.3 <= time.monotonic() - start < 20.0


def test_a_ten_percent_failing_sweep_returns_every_row(hmf: ps.Simulation) -> None:
    """Done-when of issue 14: 40 points, every tenth invalid (each bad kind once): all 40 rows,
    in order, the bad ones error rows naming the field, the others finite."""
    import math

    bad = iter([-1.0, 0.0, math.nan, 1e9])
    values = [next(bad) if i % 10 == 9 else 100.0 + i for i in range(40)]
    df = ps.sweep(hmf, {"actuator.frequency_hz": values}, metrics=["left_stroke_amplitude"], options={"max_cycles": 5, "samples_per_cycle": 40}, progress=False)
    assert df["point"].to_list() == list(range(40))
    failed = df.filter(df["status"] == "error")
    assert failed["point"].to_list() == [9, 19, 29, 39] and failed["error"].str.contains("frequency_hz").all()
    ok = df.filter(df["status"] == "ok")["left_stroke_amplitude"].to_list()
    assert len(ok) == 36 and all(math.isfinite(v) and v > 0 for v in ok)
