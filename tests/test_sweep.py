"""Parameter sweeps: order and bit-identity across threads, error rows, validation before any
work, checkpoints that survive a kill, cancellation, executors (Dask, process pools), CLI."""

from __future__ import annotations

import _thread
import concurrent.futures as cf
import dataclasses
import json
import importlib
import math
import re
import multiprocessing
import os
import pickle
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path
from typing import Any

import numpy as np
import polars as pl
import pytest

import paritysim as ps
from paritysim import _core
from paritysim.cli import main
from paritysim.sweep import grid, plot, sweep, valid_paths

# The module (``paritysim.sweep`` may be re-exported as the function of the same name).
sweep_module = importlib.import_module("paritysim.sweep")
# How its chunks run (the functions these tests replace to inject failures and count work).
chunks_module = importlib.import_module("paritysim._sweep_chunks")

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
FAST = {"max_cycles": 5, "samples_per_cycle": 40, "record_cycles": 1}


@pytest.fixture(scope="module")
def parity() -> ps.Simulation:
    spec = ps.load_spec(EXAMPLES / "drag_parity.toml")
    return spec.replace(options=dataclasses.replace(spec.options, **FAST))


@pytest.fixture(scope="module")
def hmf() -> ps.Simulation:
    spec = ps.load_spec(EXAMPLES / "hmf.toml")
    return spec.replace(options=dataclasses.replace(spec.options, **FAST))


def _bits(df: pl.DataFrame) -> dict[str, Any]:
    """Columns as comparable values; floats by their bit patterns (NaN-safe, exact)."""
    out: dict[str, Any] = {}
    for name in df.columns:
        s = df[name]
        if s.dtype == pl.Float64:
            out[name] = (s.is_null().to_list(), s.fill_null(0.0).to_numpy().view(np.uint64).tolist())
        else:
            out[name] = s.to_list()
    return out


def assert_same(a: pl.DataFrame, b: pl.DataFrame) -> None:
    assert a.columns == b.columns
    assert a.schema == b.schema
    assert _bits(a) == _bits(b)


def assert_equivalent(a: pl.DataFrame, b: pl.DataFrame, rel: float = 1e-5) -> None:
    """The same points computed along other continuation chains (another chunking, a resume,
    an executor, a direct `simulate`): the same periodic orbits, so float columns agree to the
    orbit's accuracy (relative to each column's scale: stroke means near zero carry the
    amplitude's ~1e-7 rad, up to 4e-6 of their own scale) and everything else exactly, except
    ``cycles_run`` (how many periods the chain needed)."""
    assert a.columns == b.columns
    assert a.schema == b.schema
    exact = [c for c in a.columns if a[c].dtype != pl.Float64 and c != "cycles_run"]
    assert a.select(exact).equals(b.select(exact))
    for name in (c for c in a.columns if a[c].dtype == pl.Float64):
        x, y = a[name].to_numpy(), b[name].to_numpy()
        assert (np.isnan(x) == np.isnan(y)).all(), name
        finite = ~np.isnan(x)
        scale = max(float(np.abs(x[finite]).max(initial=0.0)), 1e-300)
        # no absolute allowance for what vanishes by symmetry (q2, net roll torque, imbalance
        # %): examples/drag_parity.toml's symmetric orbit is unstable (whippletree multiplier
        # 1.4-2.0), so its points fall back to the transient and run cold, exactly symmetric,
        # in every chain (chained, its round-off grew to an imbalance of 1.2e-5 %: findings §9)
        assert (np.abs(x[finite] - y[finite]) <= rel * scale + 1e-12).all(), (name, x, y)


GRID = {"drivetrain.balance_spring": [1.0, 5.0], "wings[*].aero.omega1": [25.0, 31.3], "actuator.frequency_hz": [100.0, 110.0, 120.0]}


# ----------------------------------------------------------------------------- grid and paths


def test_grid_is_a_cartesian_product_first_axis_slowest() -> None:
    g = grid({"a": [1, 2], "b": np.array([10.0, 20.0, 30.0])})
    assert g.columns == ["a", "b"] and g.height == 6
    assert g.row(0) == (1, 10.0) and g.row(2) == (1, 30.0) and g.row(3) == (2, 10.0)
    with pytest.raises(ps.InvalidParameterError, match="at least one value"):
        grid({"a": []})


def test_results_are_in_input_order_and_bit_identical_for_1_and_2_threads(parity: ps.Simulation) -> None:
    one = sweep(parity, GRID, threads=1, progress=False, chunk_size=5)
    two = sweep(parity, GRID, threads=2, progress=False, chunk_size=5)
    assert_same(one, two)
    assert_same(two, sweep(parity, GRID, threads=2, progress=False, chunk_size=5))  # repeatable
    # other chunk boundaries start other continuation chains: the same orbits, not the same bits
    assert_equivalent(one, sweep(parity, GRID, threads=2, progress=False))
    assert one["point"].to_list() == list(range(12))
    assert one.select(list(GRID)).rows() == grid(GRID).rows()
    assert (one["status"] == "ok").all()
    # each row is `simulate` of that point (the same orbit, to its accuracy)
    for i in (0, 7, 11):
        k2, omega, f = grid(GRID).row(i)
        spec = parity.replace(
            drivetrain=dataclasses.replace(parity.drivetrain, balance_spring=k2),
            wings=tuple(dataclasses.replace(w, aero=dataclasses.replace(w.aero, omega1=omega)) for w in parity.wings),
            actuator=dataclasses.replace(parity.actuator, waveform=dataclasses.replace(parity.actuator.waveform, frequency_hz=f)),
        )
        direct = ps.simulate(spec).metrics
        for name, value in direct.items():
            got = one[name][i]
            if value is None or np.isnan(value):
                assert got is None or np.isnan(got), (name, i)
                continue
            scale = float(np.nanmax(np.abs(one[name].to_numpy(allow_copy=True))))
            assert abs(got - value) <= 1e-6 * scale, (name, i, got, value)


def test_aliases_mean_their_canonical_fields(parity: ps.Simulation) -> None:
    a = sweep(parity, {"wings.left.omega_ratio": [0.8], "drivetrain.balance_spring": [5.0], "actuator.voltage_v": [80.0]}, progress=False)
    b = sweep(parity, {"wings[0].aero.omega1": [0.8 * 31.3], "drivetrain.balance_stiffness": [5.0], "actuator.waveform.amplitude_v": [80.0]}, progress=False)
    metrics = [c for c in a.columns if c.endswith(("_amplitude", "_peak"))]
    assert_same(a.select(metrics), b.select(metrics))
    both = sweep(parity, {"wings[*].aero.omega1": [20.0]}, metrics=["left_stroke_amplitude", "right_stroke_amplitude"], progress=False)
    assert both["left_stroke_amplitude"][0] == both["right_stroke_amplitude"][0]
    paths = valid_paths(parity)
    for p in ("wings[1].springs.hinge.cubic", "wings[0].inertia[2][2]", "options.max_cycles", "drivetrain.balance_spring", "wings.left.omega_ratio"):
        assert p in paths


def test_unknown_paths_and_names_are_rejected_before_any_work(parity: ps.Simulation, monkeypatch: pytest.MonkeyPatch) -> None:
    def no_work(*_: Any, **__: Any) -> None:
        raise AssertionError("a point was prepared before validation finished")

    monkeypatch.setattr(chunks_module, "prepare", no_work)
    with pytest.raises(ps.InvalidParameterError, match=r"drivetrain\.k3.*did you mean `drivetrain\.") as info:
        sweep(parity, {"drivetrain.balance_spring": [1.0], "drivetrain.k3": [1.0]}, progress=False)
    assert info.value.field == "drivetrain.k3"
    with pytest.raises(ps.InvalidParameterError, match=r"wings\[2\]"):
        sweep(parity, {"wings[2].aero.omega1": [1.0]}, progress=False)
    hmf_one_wing = parity.replace(wings=parity.wings[:1], drivetrain=None, actuator=None, configuration=ps.Configuration(name=None))
    with pytest.raises(ps.InvalidParameterError, match="wings.left"):
        sweep(hmf_one_wing, {"wings.left.omega_ratio": [1.0]}, progress=False)
    with pytest.raises(ps.InvalidParameterError, match="same field"):
        sweep(parity, {"drivetrain.balance_spring": [1.0], "drivetrain.balance_stiffness": [2.0]}, progress=False)
    with pytest.raises(ps.InvalidParameterError, match="metrics.*left_stroke_amplitude"):
        sweep(parity, GRID, metrics=["left_stroke_amplitud"], progress=False)
    with pytest.raises(ps.InvalidParameterError, match="keep_cycle"):
        sweep(parity, GRID, keep_cycle=["left_phee"], progress=False)
    with pytest.raises(ps.InvalidParameterError, match="threads"):
        sweep(parity, GRID, threads=0, progress=False)
    with pytest.raises(ps.InvalidParameterError, match="options"):
        sweep(parity, GRID, options={"max_cycle": 3}, progress=False)
    with pytest.raises(ps.InvalidParameterError, match="options.method"):
        sweep(parity, GRID, options={"method": "euler"}, progress=False)
    with pytest.raises(ps.InvalidParameterError, match="chunk_size"):
        sweep(parity, GRID, chunk_size=0, progress=False)
    with pytest.raises(ps.InvalidParameterError, match=r"wings\[0\]\.inertia"):  # an invalid base spec
        bad = dataclasses.replace(parity.wings[0], inertia=((1.0, 0, 0), (0, -1.0, 0), (0, 0, 1.0)))
        sweep(parity.replace(wings=(bad, parity.wings[1])), GRID, progress=False)


def test_failing_points_become_error_rows_and_the_rest_is_kept(parity: ps.Simulation) -> None:
    rows = pl.DataFrame(
        {
            "drivetrain.balance_spring": [1.0, -1.0, 1.0, 5.0, None],
            "actuator.voltage_v": [100.0, 100.0, 5000.0, 80.0, 90.0],
            "options.max_cycles": [5, 5, 5, 0, 5],
        }
    )
    df = sweep(parity, rows, metrics=["left_stroke_amplitude"], progress=False)
    assert df["status"].to_list() == ["ok", "error", "error", "error", "ok"]
    assert df["error_kind"].to_list() == [None, "InvalidParameter", "Integration", "InvalidParameter", None]
    assert "drivetrain.balance_spring" in df["error"][1] and "in [0, 10000] mN mm/rad" in df["error"][1]
    assert "integration failed" in df["error"][2]
    assert "max_cycles" in df["error"][3]
    assert df["left_stroke_amplitude"].null_count() == 3 and df["cycles_run"].null_count() == 3
    # a null keeps the base value (K2 = 1); the last row equals the base design at 90 V
    base = ps.simulate(parity.replace(actuator=dataclasses.replace(parity.actuator, waveform=dataclasses.replace(parity.actuator.waveform, amplitude_v=90.0))))
    assert df["left_stroke_amplitude"][4] == base.metrics["left_stroke_amplitude"]


def test_a_non_finite_value_is_an_error_row_naming_its_path(parity: ps.Simulation) -> None:
    # Plain rows take json's C encoder; a NaN makes it refuse and the rows go through
    # spec._dumps, which hands the value to Rust as text so the error names the field.
    df = sweep(parity, {"drivetrain.balance_spring": [1.0, float("nan"), 2.0]}, metrics=["left_stroke_amplitude"], progress=False)
    assert df["status"].to_list() == ["ok", "error", "ok"]
    assert df["error_kind"][1] == "InvalidParameter" and "drivetrain.balance_spring" in df["error"][1]
    plain = sweep(parity, {"drivetrain.balance_spring": [1.0, 2.0]}, metrics=["left_stroke_amplitude"], progress=False)
    assert df["left_stroke_amplitude"].to_list()[::2] == plain["left_stroke_amplitude"].to_list()
    assert json.loads(chunks_module.rows_json([(np.float64(0.5), 3)])) == [[0.5, 3]]


def test_option_paths_run_per_point(parity: ps.Simulation) -> None:
    df = sweep(parity, {"options.max_cycles": [1, 2], "options.min_cycles": [1]}, options={"steady_tol": 1e-30}, progress=False)
    assert df["cycles_run"].to_list() == [1, 2]
    assert df["converged"].to_list() == [False, False]


def test_no_grid_runs_the_base_design_and_an_empty_table_runs_nothing(parity: ps.Simulation) -> None:
    df = sweep(parity, progress=False, metrics=["q2_amplitude"])
    assert df.height == 1 and df["q2_amplitude"][0] == ps.simulate(parity).metrics["q2_amplitude"]
    empty = sweep(parity, pl.DataFrame({"drivetrain.balance_spring": []}, schema={"drivetrain.balance_spring": pl.Float64}), metrics=["q2_amplitude"], progress=False)
    assert empty.height == 0
    assert empty.columns == ["point", "drivetrain.balance_spring", "q2_amplitude", "converged", "cycles_run", "orbit_cycles", "status", "error", "error_kind"]
    # An empty list of rows is an empty table too (it ran the base design once).
    assert sweep(parity, [], metrics=["q2_amplitude"], progress=False).height == 0


def test_keep_cycle_returns_the_last_cycle_as_list_columns(hmf: ps.Simulation) -> None:
    df = sweep(hmf, {"actuator.frequency_hz": [90.0, 120.0]}, keep_cycle=["left_phi"], options={"record_cycles": 2}, progress=False)
    assert [c for c in df.columns if c.startswith("cycle_")] == ["cycle_time_ms", "cycle_left_phi"]
    spec = hmf.replace(
        actuator=dataclasses.replace(hmf.actuator, waveform=dataclasses.replace(hmf.actuator.waveform, frequency_hz=120.0)),
        options=dataclasses.replace(hmf.options, record_cycles=2),
    )
    cycle = ps.simulate(spec).cycle
    assert df["cycle_left_phi"][1].to_list() == cycle["left_phi"].to_list()
    assert df["cycle_time_ms"][1].to_list() == cycle["time_ms"].to_list()
    everything = sweep(hmf, None, keep_cycle=True, progress=False)
    assert len([c for c in everything.columns if c.startswith("cycle_")]) == 1 + len(_core.sweep_trajectory_columns(hmf.to_json()))


# ----------------------------------------------------------------------------- progress and cancel


def test_run_handle_reports_progress_and_cancel_keeps_finished_points(parity: ps.Simulation) -> None:
    run = _core.SweepRun(parity.to_json(), ["actuator.voltage_v"], json.dumps([[100.0]] * 400), ["left_stroke_amplitude"], False, 2)
    assert (run.total, run.finished, run.threads) == (400, 0, 2)
    run.start()
    while run.finished < 10:
        time.sleep(0.001)
    run.cancel()
    assert run.wait(None)
    res = run.result()
    done = int(res.finished.sum())
    assert run.cancelled and 10 <= done < 400 and done == run.finished
    assert res.ok[res.finished].all() and not res.ok[~res.finished].any()
    values = res.metrics[res.finished, 0]
    # the same device everywhere: one orbit (chained points reach it from their neighbour)
    assert np.allclose(values, values[0], rtol=1e-7, atol=0.0)
    starts = res.metrics[np.flatnonzero(res.finished)[np.flatnonzero(res.finished) % 16 == 0], 0]
    assert np.all(starts == values[0])  # each chain's first point starts from the spec's start
    assert np.isnan(res.metrics[~res.finished, 0]).all()
    with pytest.raises(ps.ParitysimError, match="already started"):
        run.start()


def test_ctrl_c_checkpoints_the_finished_rows_then_raises(parity: ps.Simulation, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """Ctrl-C (SIGINT via ``_thread.interrupt_main``) once 128 points have finished: a count, not
    a timer, so the outcome does not depend on the machine's load. The finished rows are in the
    checkpoint and on the raised `SweepInterrupted` (a KeyboardInterrupt), bit-identical to a
    fresh run of the same points."""
    table = grid({"drivetrain.balance_spring": np.linspace(1.0, 2.0, 10_000).tolist()})
    after = 128
    advance = chunks_module.advance
    done = [0]  # points finished so far, over all chunks (`finished` counts within a chunk)
    fired = []

    def advance_then_interrupt(bar: Any, finished: int, reported: int) -> int:
        done[0] += max(finished - reported, 0)
        if done[0] >= after and not fired:
            fired.append(done[0])
            _thread.interrupt_main()
        return advance(bar, finished, reported)

    monkeypatch.setattr(chunks_module, "advance", advance_then_interrupt)
    checkpoint = tmp_path / "study.parquet"
    metrics = ["q2_amplitude", "left_stroke_amplitude"]
    with pytest.raises(KeyboardInterrupt) as stopped:
        sweep(parity, table, metrics=metrics, threads=2, chunk_size=64, progress=False, checkpoint=checkpoint)
    assert isinstance(stopped.value, sweep_module.SweepInterrupted)
    partial = stopped.value.result
    assert fired and after <= partial.height < table.height and stopped.value.total == table.height
    assert partial["point"].is_sorted() and (partial["status"] == "ok").all()
    saved = pl.concat([pl.read_parquet(f) for f in sorted(checkpoint.with_name("study.parquet.parts").glob("part-*.parquet"))]).sort("point")
    assert_same(saved, partial)
    again = sweep(parity, table[partial["point"].to_list()], metrics=metrics, progress=False)
    assert_equivalent(partial.drop("point"), again.drop("point"))


def test_thread_count_comes_from_the_environment() -> None:
    code = "import paritysim._core as c; print(c.sweep_resolve_threads())"
    env = {**os.environ, _core.SWEEP_THREADS_ENV: "3"}
    assert subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout.strip() == "3"
    env[_core.SWEEP_THREADS_ENV] = "zero"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.returncode != 0 and "PARITYSIM_THREADS" in out.stderr and "InvalidParameterError" in out.stderr


# ----------------------------------------------------------------------------- checkpoints

KILL_SCRIPT = textwrap.dedent(
    """
    import importlib, sys, time
    sw = importlib.import_module("paritysim.sweep")
    from test_sweep_inputs import spec, table

    real_flush = sw._Checkpoint.flush
    def slow_flush(self, df):
        real_flush(self, df)
        time.sleep(0.3)      # leave time to kill us between chunks
    sw._Checkpoint.flush = slow_flush
    sw.sweep(spec(), table(), threads=1, chunk_size=4, checkpoint=sys.argv[1], progress=False)
    print("finished")
    """
)

INPUTS = textwrap.dedent(
    f"""
    import dataclasses
    import paritysim as ps
    from paritysim.sweep import grid

    def spec():
        s = ps.load_spec({str(EXAMPLES / "drag_parity.toml")!r})
        return s.replace(options=dataclasses.replace(s.options, **{FAST!r}))

    def table():
        return grid({{"drivetrain.balance_spring": [1.0, 2.0, 3.0, 4.0, 5.0], "actuator.voltage_v": [60.0, 80.0, 100.0, 5000.0]}})
    """
)


def test_checkpoint_resumes_a_killed_sweep_and_matches_an_uninterrupted_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "test_sweep_inputs.py").write_text(INPUTS)
    (tmp_path / "kill_me.py").write_text(KILL_SCRIPT)
    checkpoint = tmp_path / "runs" / "study.parquet"
    parts = checkpoint.with_name("study.parquet.parts")
    proc = subprocess.Popen([sys.executable, str(tmp_path / "kill_me.py"), str(checkpoint)], cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(tmp_path)})
    try:
        deadline = time.monotonic() + 60
        while len(list(parts.glob("part-*.parquet"))) < 2:
            assert proc.poll() is None, "the sweep ended before it could be killed"
            assert time.monotonic() < deadline, "no chunk was flushed"
            time.sleep(0.02)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.wait()
    assert not checkpoint.exists()
    flushed = pl.concat([pl.read_parquet(p) for p in parts.glob("part-*.parquet")])
    assert 8 <= flushed.height < 20

    sys.path.insert(0, str(tmp_path))
    try:
        from test_sweep_inputs import spec, table  # type: ignore[import-not-found]
    finally:
        sys.path.remove(str(tmp_path))
    ran: list[int] = []
    real = chunks_module.prepare

    def counting(chunk: Any) -> Any:
        ran.extend(chunk.points)
        return real(chunk)

    monkeypatch.setattr(chunks_module, "prepare", counting)
    resumed = sweep(spec(), table(), threads=2, chunk_size=4, checkpoint=checkpoint, progress=False)
    assert sorted(ran) == sorted(set(range(20)) - set(flushed["point"].to_list())), "only unfinished points run"
    assert checkpoint.exists() and not parts.exists()
    monkeypatch.setattr(chunks_module, "prepare", real)
    fresh = sweep(spec(), table(), threads=2, progress=False)
    assert_equivalent(resumed, fresh)
    assert (fresh["status"] == "error").sum() == 5  # 5 kV rows are kept as errors, and resumed as such
    assert_equivalent(pl.read_parquet(checkpoint), fresh)

    # a complete checkpoint answers a re-run without running anything; a longer grid reuses it
    ran.clear()
    monkeypatch.setattr(chunks_module, "prepare", counting)
    assert_same(sweep(spec(), table(), checkpoint=checkpoint, progress=False), resumed)
    assert ran == []
    longer = grid({"drivetrain.balance_spring": [1.0, 2.0, 3.0, 4.0, 5.0, 6.0], "actuator.voltage_v": [60.0, 80.0, 100.0, 5000.0]})
    extended = sweep(spec(), longer, checkpoint=checkpoint, progress=False)
    assert sorted(ran) == [20, 21, 22, 23] and extended.height == 24
    assert_same(extended.head(20), resumed)


def test_a_checkpoint_from_another_sweep_is_refused(parity: ps.Simulation, tmp_path: Path) -> None:
    path = tmp_path / "study.parquet"
    sweep(parity, {"drivetrain.balance_spring": [1.0]}, checkpoint=path, progress=False)
    other = parity.replace(actuator=dataclasses.replace(parity.actuator, stiffness=400.0))
    with pytest.raises(ps.InvalidParameterError, match="checkpoint"):
        sweep(other, {"drivetrain.balance_spring": [1.0]}, checkpoint=path, progress=False)


# ----------------------------------------------------------------------------- executors


def test_specs_and_chunks_pickle(parity: ps.Simulation) -> None:
    parity.to_json()  # with its cached JSON
    assert pickle.loads(pickle.dumps(parity)) == parity
    for name in ("hmf", "drag_parity"):
        spec = ps.load_spec(EXAMPLES / f"{name}.toml")
        assert pickle.loads(pickle.dumps(spec)) == spec


def test_process_pool_executor_matches_local(parity: ps.Simulation) -> None:
    local = sweep(parity, GRID, progress=False)
    with cf.ProcessPoolExecutor(max_workers=2, mp_context=multiprocessing.get_context("spawn")) as pool:
        remote = sweep(parity, GRID, executor=pool, chunk_size=5, progress=False)
    assert_equivalent(local, remote)


def test_dask_local_cluster_matches_local(parity: ps.Simulation) -> None:
    distributed = pytest.importorskip("distributed")
    local = sweep(parity, GRID, progress=False)
    with distributed.LocalCluster(processes=True, n_workers=2, threads_per_worker=1, dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        remote = sweep(parity, GRID, executor=client.get_executor(), chunk_size=3, progress=False)
    assert_equivalent(local, remote)


def test_ctrl_c_reaches_the_chunks_running_in_process_pool_workers(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """Two fast points then four that would integrate for minutes, one point per chunk on two
    worker processes. Ctrl-C once the two fast rows are framed (a count, not a timer): pending
    chunks are cancelled, the running ones see the stop file and stop inside integration, the
    fast rows are checkpointed and `SweepInterrupted` is raised as in process; the workers are
    free again at once (they did not run the slow points to the end)."""
    hmf = ps.load_spec(EXAMPLES / "hmf.toml")
    real = chunks_module.frame
    framed: list[int] = []

    def frame_then_interrupt(raw: Any, *args: Any) -> Any:
        out = real(raw, *args)
        framed.append(out.height)
        if sum(framed) == 2 and len(framed) == 2:
            _thread.interrupt_main()
        return out

    monkeypatch.setattr(chunks_module, "frame", frame_then_interrupt)
    checkpoint = tmp_path / "study.parquet"
    values = [100.0, 110.0] + [1e-3] * 4
    with cf.ProcessPoolExecutor(max_workers=2, mp_context=multiprocessing.get_context("spawn")) as pool:
        with pytest.raises(sweep_module.SweepInterrupted) as stopped:
            sweep(hmf, {"actuator.frequency_hz": values}, options={**FAST, "max_wall_ms": 600_000.0}, metrics=["left_stroke_amplitude"], executor=pool, chunk_size=1, checkpoint=checkpoint, progress=False)
        interrupted = time.monotonic()
        assert pool.submit(abs, -3).result(timeout=20) == 3
        assert time.monotonic() - interrupted < 20.0  # the slow points would run for minutes
    partial = stopped.value.result
    assert partial["point"].to_list() == [0, 1] and (partial["status"] == "ok").all()
    assert stopped.value.total == len(values)
    saved = pl.concat([pl.read_parquet(f) for f in checkpoint.with_name("study.parquet.parts").glob("part-*.parquet")]).sort("point")
    assert_same(saved, partial)
    assert not list(Path(tempfile.gettempdir()).glob("paritysim-sweep-*/stop"))


# ----------------------------------------------------------------------------- CLI


def test_cli_runs_a_study_file(tmp_path: Path) -> None:
    study = tmp_path / "study.toml"
    study.write_text(
        textwrap.dedent(
            f"""
            spec = {str(EXAMPLES / "hmf.toml")!r}
            metrics = ["left_stroke_amplitude"]
            [options]
            max_cycles = 5
            samples_per_cycle = 40
            [grid]
            "actuator.frequency_hz" = {{ start = 80.0, stop = 140.0, num = 4 }}
            "actuator.voltage_v" = [50.0, 100.0]
            [plot]
            x = "actuator.frequency_hz"
            y = "left_stroke_amplitude"
            hue = "actuator.voltage_v"
            """
        )
    )
    assert main(["sweep", str(study), "--out", str(tmp_path / "runs"), "--threads", "2", "--quiet"]) == 0
    df = pl.read_parquet(tmp_path / "runs" / "study.parquet")
    assert df.height == 8 and (df["status"] == "ok").all()
    assert df["actuator.frequency_hz"].to_list()[:4] == [80.0, 80.0, 100.0, 100.0]
    assert (tmp_path / "runs" / "study.png").stat().st_size > 1000
    bad = tmp_path / "bad.toml"
    bad.write_text(study.read_text().replace("actuator.voltage_v", "actuator.voltage"))
    assert main(["sweep", str(bad), "--out", str(tmp_path / "runs"), "--quiet"]) == 1


def test_a_study_names_a_shipped_device_and_asks_gradients(tmp_path: Path) -> None:
    """`spec` takes a device name as `paritysim run`, `optimize` and `continue` do, and
    `gradients` gives the columns `ps.sweep(..., gradients=...)` gives."""
    study = tmp_path / "named.toml"
    study.write_text(
        textwrap.dedent(
            """
            spec = "sreetharan2012_3_3_parity"
            metrics = ["left_stroke_amplitude"]
            gradients = ["actuator.voltage_v"]
            [grid]
            "drivetrain.balance_spring" = [5.0, 10.0]
            """
        )
    )
    assert main(["sweep", str(study), "--out", str(tmp_path / "runs"), "--threads", "1", "--quiet"]) == 0
    df = pl.read_parquet(tmp_path / "runs" / "named.parquet")
    spec = ps.devices.load("sreetharan2012_3_3_parity")
    for row in df.iter_rows(named=True):
        point = spec.with_paths({"drivetrain.balance_spring": row["drivetrain.balance_spring"]})
        s = ps.sensitivity(point, ["actuator.voltage_v"], metrics=["left_stroke_amplitude"], progress=False)
        # the sweep's chained orbit and a run from rest: the derivatives' own accuracy (rtol 1e-8)
        assert row["d(left_stroke_amplitude)/d(actuator.voltage_v)"] == pytest.approx(s.derivative("left_stroke_amplitude", "actuator.voltage_v"), rel=2e-5)


def test_plot_draws_one_line_per_hue(hmf: ps.Simulation) -> None:
    df = sweep(hmf, {"actuator.voltage_v": [50.0, 100.0], "actuator.frequency_hz": [90.0, 110.0, 130.0]}, progress=False)
    fig = sweep_module.plot(df, "actuator.frequency_hz", "left_stroke_amplitude", hue="actuator.voltage_v")
    assert len(fig.axes[0].lines) == 2
    assert math.isfinite(fig.axes[0].lines[0].get_ydata()[0])
    # A column that is not in the result is named by the argument that asked for it.
    for kwargs, field in [({"x": "voltage"}, "x"), ({"y": "amplitude"}, "y"), ({"y": ["left_stroke_amplitude", "amplitude"]}, "y[1]"), ({"hue": "volts"}, "hue")]:
        args = {"x": "actuator.frequency_hz", "y": "left_stroke_amplitude", "hue": None, **kwargs}
        with pytest.raises(ps.InvalidParameterError, match=re.escape(f"invalid `{field}` =")):
            sweep_module.plot(df, **args)


# ----------------------------------------------------------------------------- chunk failures


def test_a_chunk_whose_run_cannot_be_built_becomes_error_rows(parity: ps.Simulation, monkeypatch: pytest.MonkeyPatch) -> None:
    """Any failure of a whole chunk (here its native run raising when built) gives one error row
    per point of that chunk; the other chunks are unaffected."""
    real = chunks_module.prepare

    def prepare(chunk: Any) -> Any:
        if 2 in chunk.points:
            raise MemoryError("simulated failure of the chunk")
        return real(chunk)

    monkeypatch.setattr(chunks_module, "prepare", prepare)
    df = sweep(parity, {"actuator.voltage_v": [60.0, 70.0, 80.0, 90.0, 100.0]}, metrics=["left_stroke_amplitude"], chunk_size=2, threads=1, progress=False)
    assert df["point"].to_list() == [0, 1, 2, 3, 4]
    assert df["status"].to_list() == ["ok", "ok", "error", "error", "ok"]
    assert df["error_kind"][2] == "Memory" and "simulated failure" in df["error"][3]
    assert df["left_stroke_amplitude"][2] is None and df["left_stroke_amplitude"][4] > 0


def test_a_chunk_whose_executor_worker_raises_becomes_error_rows(parity: ps.Simulation, monkeypatch: pytest.MonkeyPatch) -> None:
    real = chunks_module.run_chunk

    def run_chunk(chunk: Any) -> Any:
        if 0 in chunk.points:
            raise RuntimeError("worker lost")
        return real(chunk)

    monkeypatch.setattr(chunks_module, "run_chunk", run_chunk)
    with cf.ThreadPoolExecutor(2) as pool:
        df = sweep(parity, {"actuator.voltage_v": [60.0, 70.0, 80.0, 90.0]}, metrics=["left_stroke_amplitude"], executor=pool, chunk_size=2, keep_cycle=["left_phi"], progress=False)
    assert df["status"].to_list() == ["error", "error", "ok", "ok"]
    assert df["error"].str.contains("worker lost").to_list() == [True, True, None, None]
    assert df["cycle_left_phi"][0] is None and len(df["cycle_left_phi"][2]) > 8


@pytest.mark.parametrize(
    ("axes", "field"),
    [
        ({"actuator.force_per_volt": [1.0, None]}, "grid['actuator.force_per_volt'][1]"),
        ({"actuator.frequency_hz": [100.0, "x"]}, "grid['actuator.frequency_hz'][1]"),
        ({"actuator.frequency_hz": [100.0, [110.0]]}, "grid['actuator.frequency_hz'][1]"),
        ({"actuator.frequency_hz": [[100.0, "x"]]}, "grid['actuator.frequency_hz'][0]"),
        ({"actuator.frequency_hz": range(10**11)}, "grid['actuator.frequency_hz']"),
        ({"actuator.frequency_hz": range(10**5), "actuator.force_per_volt": range(10**4)}, "grid"),
    ],
)
def test_a_bad_axis_is_an_error_naming_its_value(axes: dict[str, object], field: str) -> None:
    # A None ran at the spec's own value as an "ok" row; a mixed list made every value text
    # (every point failed); a huge range raised MemoryError.
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.grid(axes)
    assert info.value.field == field


def test_a_lone_value_is_a_one_point_axis(parity: ps.Simulation) -> None:
    # As in a study file (it raised TypeError: 'float' object is not iterable).
    df = sweep(parity, {"actuator.force_per_volt": 1.3, "actuator.frequency_hz": np.float64(105.0)}, metrics=["left_stroke_amplitude"], progress=False)
    assert df.height == 1 and df["actuator.force_per_volt"][0] == 1.3 and df["status"][0] == "ok"


def test_with_paths_refuses_none() -> None:
    # The core reads a null as "keep the value": with_paths({path: None}) changed nothing.
    spec = ps.devices.load("sreetharan2012_3_3_parity")
    with pytest.raises(ps.InvalidParameterError) as info:
        spec.with_paths({"actuator.force_per_volt": None})
    assert info.value.field == "values['actuator.force_per_volt']"


def test_a_path_a_row_leaves_out_keeps_the_base_value(parity: ps.Simulation) -> None:
    # Rows of different paths (null where a row leaves one out), as the docstring says.
    rows = [{"actuator.force_per_volt": 1.3}, {"actuator.frequency_hz": 105.0}]
    df = sweep(parity, rows, metrics=["left_stroke_amplitude"], progress=False)
    assert df["actuator.force_per_volt"].null_count() == 1 and df["actuator.frequency_hz"].null_count() == 1
    for row, values in zip(df.iter_rows(named=True), rows, strict=True):
        alone = ps.simulate(parity.with_paths(values), metrics=["left_stroke_amplitude"], progress=False)
        assert row["left_stroke_amplitude"] == pytest.approx(alone.metrics["left_stroke_amplitude"], rel=1e-6)


def test_plot_names_what_it_cannot_draw(parity: ps.Simulation) -> None:
    df = sweep(parity, {"actuator.frequency_hz": [100.0, 110.0]}, metrics=["left_stroke_amplitude"], keep_cycle=["left_phi"], progress=False)
    x = "actuator.frequency_hz"
    for kwargs, field in (({"y": "cycle_left_phi"}, "y"), ({"y": "left_stroke_amplitude", "ax": 5}, "ax"), ({"y": []}, "y")):
        with pytest.raises(ps.InvalidParameterError) as info:
            plot(df, x, **kwargs)
        assert info.value.field == field
    with pytest.raises(ps.InvalidParameterError) as info:
        plot({"a": [1]}, "a", "a")  # type: ignore[arg-type]
    assert info.value.field == "df"
    fig = plot(df, x, "left_stroke_amplitude", hue="converged")
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()] == ["converged = True"]  # was "= 1"
    assert sweep(parity, {x: [100.0]}, metrics=["left_stroke_amplitude"], chunk_size=np.int64(1), progress=False).height == 1
