"""Sweep benchmarks (printed ratios; not timed tests).

* ``parallel``: the same 1,000-point sweep with 1 and 2 threads (target speedup >= 1.8 on 2 cores).
* ``baseline``: per-point time against the numpy + scipy model of ``benchmarks/vs_scipy.py``
  looped over the same points, and against a ``multiprocessing.Pool`` of it (target >= 100x).
* ``jax``: JAX + diffrax (jit + vmap, float64, DOP853-class solver) when both are importable;
  skipped otherwise (they are not dependencies).
* ``memory``: a metrics-only sweep of 100,000 points streamed to a Parquet checkpoint; run it
  under ``/usr/bin/time -v`` to read the peak RSS (also printed from ``getrusage``).

Run:  python benchmarks/sweeps.py                  # parallel, baseline, jax
      /usr/bin/time -v python benchmarks/sweeps.py memory --points 100000
"""

from __future__ import annotations

import argparse
import math
import multiprocessing
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import polars as pl

sys.path.insert(0, str(Path(__file__).resolve().parent))
from vs_scipy import run_baseline, spec_for  # noqa: E402

import paritysim as ps  # noqa: E402
from paritysim.sweep import grid, sweep  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
PARAMS = dict(crank=0.4, rod=0.8, arm=2.5, inertia=29.0, omega=31.3, omega_left=31.3, coefficient=3.4609,
              k1=467.0, k2=1.0, force_per_volt=1.2, amplitude_v=100.0, w=2 * math.pi * 0.110)  # fmt: skip
METRICS = ["left_stroke_amplitude", "right_stroke_amplitude", "q2_amplitude"]


def _timed(f):  # type: ignore[no-untyped-def]
    start = time.perf_counter()
    out = f()
    return time.perf_counter() - start, out


def _cpu() -> float:
    """CPU seconds used by this process and its finished children."""
    s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime


def _timed_cpu(f):  # type: ignore[no-untyped-def]
    c0 = _cpu()
    wall, out = _timed(f)
    return wall, _cpu() - c0, out


def parallel(points: int, repeat: int) -> None:
    spec = ps.load_spec(EXAMPLES / "drag_parity.toml")
    n_k2 = 25
    table = grid({"drivetrain.balance_spring": np.linspace(1.0, 20.0, n_k2).tolist(), "actuator.voltage_v": np.linspace(40.0, 100.0, max(1, points // n_k2)).tolist()})
    sweep(spec, table.head(50), threads=2, progress=False)  # warm up
    # best of `repeat`: the machine may be shared. CPU time / wall time says how many cores the
    # run actually got (2.0 = both threads ran all the time).
    t1, c1, one = min((_timed_cpu(lambda: sweep(spec, table, threads=1, progress=False)) for _ in range(repeat)), key=lambda r: r[0])
    t2, c2, two = min((_timed_cpu(lambda: sweep(spec, table, threads=2, progress=False)) for _ in range(repeat)), key=lambda r: r[0])
    same = one.equals(two, null_equal=True)
    ok = int((one["status"] == "ok").sum())
    print(f"[parallel] {table.height} points of examples/drag_parity.toml (steady state, {ok} ok): "
          f"1 thread {t1:.2f} s ({t1 / table.height * 1e3:.2f} ms/pt), 2 threads {t2:.2f} s -> speedup {t1 / t2:.2f}x "
          f"(target >= 1.8; best of {repeat}); cores used {c1 / t1:.2f} and {c2 / t2:.2f}; CPU s 1 vs 2 threads {c1:.2f} vs {c2:.2f}; "
          f"results identical: {same}")  # fmt: skip


def _baseline_point(args: tuple[float, float, int, float]) -> dict:
    k2, volts, cycles, rtol = args
    return run_baseline(PARAMS | {"k2": k2, "amplitude_v": volts}, cycles, rtol, rtol * 1e-2, 0.0)


def baseline(cycles: int, loop_points: int, rtol: float, repeat: int) -> None:
    atol = rtol * 1e-2
    spec = spec_for(PARAMS, cycles, rtol, atol, 0.0)
    k2s, volts = [1.0, 5.0, 20.0, 50.0], np.linspace(60.0, 100.0, 50).tolist()
    table = grid({"drivetrain.balance_spring": k2s, "actuator.waveform.amplitude_v": volts})
    rows = table.rows()
    # Timings are robust to a shared machine: the scipy loop by the median point, the Pool and
    # paritysim by the best of `repeat` runs. The Pool runs first, before this process has
    # started any engine threads (fork safety).
    pool_rows = rows[: 2 * loop_points]
    with multiprocessing.get_context("fork").Pool(2) as pool:
        pool.map(_baseline_point, [(*pool_rows[0], cycles, rtol)])  # warm up the workers
        t_pool = min(_timed(lambda: pool.map(_baseline_point, [(*r, cycles, rtol) for r in pool_rows], chunksize=1))[0] for _ in range(repeat))
    loop = [_timed(lambda r=r: _baseline_point((*r, cycles, rtol))) for r in rows[:loop_points]]
    base = [b for _, b in loop]
    sweep(spec, table.head(20), threads=1, progress=False)  # warm up
    t_s1, ours = min((_timed(lambda: sweep(spec, table, metrics=METRICS, threads=1, progress=False)) for _ in range(repeat)), key=lambda r: r[0])
    t_s2 = min(_timed(lambda: sweep(spec, table, metrics=METRICS, threads=2, progress=False))[0] for _ in range(repeat))
    n = table.height
    per = {"loop": float(np.median([t for t, _ in loop])), "pool": t_pool / len(pool_rows), "ours1": t_s1 / n, "ours2": t_s2 / n}
    worst = max(abs(ours[k][i] - b[k]) / abs(b[k]) for i, b in enumerate(base) for k in ("left_stroke_amplitude", "right_stroke_amplitude"))
    print(f"[baseline] {cycles} wingbeats from rest, rtol {rtol:g}, DOP853 both; paritysim sweep of {n} points vs numpy+scipy:")
    print(f"  numpy+scipy loop        {per['loop'] * 1e3:8.2f} ms/pt ({loop_points} pts, median)  paritysim 1 thread  {per['ours1'] * 1e3:7.3f} ms/pt -> {per['loop'] / per['ours1']:5.0f}x")
    print(f"  multiprocessing.Pool(2) {per['pool'] * 1e3:8.2f} ms/pt ({len(pool_rows)} pts, best of {repeat})  paritysim 2 threads {per['ours2'] * 1e3:7.3f} ms/pt -> {per['pool'] / per['ours2']:5.0f}x")
    print(f"  (target >= 100x per point); stroke amplitudes agree to {worst:.1e} (relative)")


def jax_benchmark(points: int, cycles: int, rtol: float) -> None:
    try:
        import diffrax  # noqa: F401
        import jax  # noqa: F401
    except ImportError:
        print("[jax] skipped: jax and diffrax are not installed (optional; not a paritysim dependency)")
        return
    import diffrax
    import jax
    import jax.numpy as jnp

    jax.config.update("jax_enable_x64", True)
    p = PARAMS
    crank, rod, arm = p["crank"], p["rod"], p["arm"]

    def stroke(q):  # the same linkage as vs_scipy.stroke_map, differentiable
        def side(s):
            x = crank + arm * (jnp.cos(q[1]) - 1)
            y = rod + q[0] + s * arm * jnp.sin(q[1])
            r = jnp.hypot(x, y)
            k = (x * x + y * y + crank * crank - rod * rod) / (2 * crank * r)
            return -(jnp.arctan2(y, x) - jnp.arccos(k))

        return jnp.stack([side(-1.0), side(1.0)])

    def rhs(t, y, args):
        k2, volts = args
        q, qd = y[:2], y[2:]
        jac = jax.jacfwd(stroke)(q)
        jdot_qd = jax.jvp(lambda qq: jax.jacfwd(stroke)(qq) @ qd, (q,), (qd,))[1]
        phi_dot = jac @ qd
        tau = -p["omega"] * p["coefficient"] * jnp.abs(phi_dot) * phi_dot
        force = jnp.array([p["force_per_volt"] * volts * jnp.sin(p["w"] * t) - p["k1"] * q[0], -k2 * q[1]])
        mass = p["inertia"] * jac.T @ jac
        return jnp.concatenate([qd, jnp.linalg.solve(mass, jac.T @ (tau - p["inertia"] * jdot_qd) + force)])

    period = 2 * math.pi / p["w"]
    ts = jnp.linspace((cycles - 1) * period, cycles * period, 201)

    def one(k2, volts):
        sol = diffrax.diffeqsolve(diffrax.ODETerm(rhs), diffrax.Dopri8(), 0.0, cycles * period, period / 50, jnp.zeros(4), args=(k2, volts),
                                  saveat=diffrax.SaveAt(ts=ts), stepsize_controller=diffrax.PIDController(rtol=rtol, atol=rtol * 1e-2), max_steps=1_000_000)  # fmt: skip
        phis = jax.vmap(stroke)(sol.ys[:, :2])
        return 0.5 * (phis[:, 0].max() - phis[:, 0].min())

    batched = jax.jit(jax.vmap(one))
    table = grid({"k2": [1.0, 5.0, 20.0, 50.0], "v": np.linspace(60.0, 100.0, max(1, points // 4)).tolist()})
    k2, v = jnp.asarray(table["k2"].to_numpy()), jnp.asarray(table["v"].to_numpy())
    t_compile, _ = _timed(lambda: batched(k2[:2], v[:2]).block_until_ready())
    t_compile_full, _ = _timed(lambda: batched(k2, v).block_until_ready())
    t_run, amps = _timed(lambda: batched(k2, v).block_until_ready())
    spec = spec_for(PARAMS, cycles, rtol, rtol * 1e-2, 0.0)
    ours_t, ours = _timed(lambda: sweep(spec, {"drivetrain.balance_spring": [1.0, 5.0, 20.0, 50.0], "actuator.waveform.amplitude_v": table["v"].unique(maintain_order=True).to_list()}, metrics=METRICS, progress=False))
    diff = float(np.max(np.abs(np.asarray(amps) - ours["left_stroke_amplitude"].to_numpy())))
    print(f"[jax] {table.height} points: compile {t_compile:.1f} s (+{t_compile_full:.1f} s for the full batch), run {t_run / table.height * 1e3:.3f} ms/pt; "
          f"paritysim {ours_t / table.height * 1e3:.3f} ms/pt -> {t_run / ours_t:.1f}x; max |amplitude diff| {diff:.1e} rad")  # fmt: skip


def memory(points: int, threads: int | None) -> None:
    spec = ps.load_spec(EXAMPLES / "drag_parity.toml")
    cheap = {"min_cycles": 2, "max_cycles": 2, "samples_per_cycle": 16, "record_cycles": 1, "rtol": 1e-6, "atol": 1e-8}
    side = int(math.ceil(math.sqrt(points)))
    table = grid({"drivetrain.balance_spring": np.linspace(1.0, 20.0, side).tolist(), "actuator.voltage_v": np.linspace(40.0, 100.0, side).tolist()}).head(points)
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        df = sweep(spec, table, options=cheap, threads=threads, checkpoint=Path(tmp) / "memory.parquet", progress=sys.stderr.isatty())
        wall = time.perf_counter() - start
        size = (Path(tmp) / "memory.parquet").stat().st_size
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"[memory] {df.height} points ({int((df['status'] == 'ok').sum())} ok, {df.width} columns), metrics-only, checkpointed "
          f"({size / 1e6:.1f} MB parquet): {wall:.1f} s wall, {wall / df.height * 1e6:.0f} us/pt; peak RSS {rss:.0f} MB (target < 500 MB)")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("which", nargs="*", default=["parallel", "baseline", "jax"], choices=["parallel", "baseline", "jax", "memory"])
    parser.add_argument("--points", type=int, default=None, help="points (parallel/jax: 1000, memory: 100000)")
    parser.add_argument("--cycles", type=int, default=20, help="wingbeats per point for baseline/jax")
    parser.add_argument("--loop-points", type=int, default=10, help="points the scipy loop runs (the Pool runs twice as many)")
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--repeat", type=int, default=3, help="best of this many runs (parallel, baseline)")
    parser.add_argument("--threads", type=int, default=None, help="memory benchmark threads")
    args = parser.parse_args()
    pl.Config.set_tbl_rows(20)
    for which in args.which:
        if which == "parallel":
            parallel(args.points or 1000, args.repeat)
        elif which == "baseline":
            baseline(args.cycles, args.loop_points, args.rtol, args.repeat)
        elif which == "jax":
            jax_benchmark(args.points or 1000, args.cycles, args.rtol)
        elif which == "memory":
            memory(args.points or 100_000, args.threads)


if __name__ == "__main__":
    main()
