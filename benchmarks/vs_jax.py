"""A §3.3 Drag PARITY design sweep, side by side: paritysim against the scripts a researcher
would write (scipy ``solve_ivp`` DOP853 in a loop; JAX + diffrax Dopri5 with ``jit(vmap)`` and
with ``shard_map`` over 2 host devices), in one process, interleaved.

Device (issue 12): fixed wings on the linear map eq. 2.15 (T = 2.5 rad/mm, L = 2.5 mm),
I = 29 mg·mm², drag −Ω φ̇|φ̇| with C = 1, Ω^R = 31.3, K1 = 467 mN/mm, 120 mN at 110 Hz; a
grid over Ω^L/Ω^R ∈ [0.3, 1] × K2 ∈ [0, 100]; Table 3.2 metrics (Δτ peak, τR and τL peaks,
instantaneous and peak imbalance %) of the last cycle from ``--samples`` samples.

Also timed in the same rounds: one §3.4 rotating trial (the shipped
``sreetharan2012_3_4_parity_1cut`` device at its default options: blade-element wings on the
stroke plane), against the same run at rtol 1e-12; and a §3.4 design sweep (issue 30) against
its JAX + diffrax peer (``benchmarks/_jax_3_4.py``: the same blade-element model with passive
rotation, written from the equations, smooth through stroke reversal, no event location): the
``sreetharan2012_3_4_parity`` device with a K2 = 100 mN·mm/rad balance spring (K2 = 0 leaves the
whippletree's offset a family of orbits, docs/findings.md §26-27: a script's run from rest and
paritysim's shooting land on members 1e-5 rad apart), hinge stiffness × right membrane cut
(``--grid-3-4`` per axis), mean yaw torque, stroke amplitudes and means, rotation amplitudes of
the last cycle; ``ps.sweep`` at the device's default options against the peer's
``--cycles-3-4`` cycles from rest, both checked against an rtol 1e-12 ``ps.sweep`` (itself checked
against the peer at rtol 1e-12 on three points).

Every peer's metrics are compared with an rtol 1e-12 reference (paritysim, Newton shooting to a
residual of 1e-11 at rtol 1e-12; checked against a 1e-12 long transient on a few points).
The script peers run a fixed number of cycles from rest (``--cycles``), as a script would.

Run:  python benchmarks/vs_jax.py [--grid 32] [--cycles 60] [--scipy-points 4] [--repeat 3]
                                   [--grid-3-4 8] [--cycles-3-4 60]   # --grid-3-4 0: no §3.4 sweep
      python benchmarks/vs_jax.py --scale 100000   # peak RSS of 100,000 Table 3.2 points, and
                                                   # the 1- vs 2-thread speedup (same results?)
JAX and diffrax are the optional ``bench`` extra (``pip install -e .[bench]``); without them
the JAX rows are skipped and the script says so.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time
import warnings
from collections.abc import Callable

# Two host devices for shard_map (must be set before JAX is imported).
os.environ.setdefault("XLA_FLAGS", "--xla_force_host_platform_device_count=2")

import _jax_3_4 as peer_3_4
import numpy as np
from scipy.integrate import solve_ivp

import paritysim as ps

T_RATIO, ARM, INERTIA, C, OMEGA_R = 2.5, 2.5, 29.0, 1.0, 31.3
ROTATING_DEVICE = "sreetharan2012_3_4_parity_1cut"
ROTATING_PEER = "paritysim simulate, §3.4 rotating 1-Cut trial"
SWEEP_3_4_DEVICE, K2_3_4 = "sreetharan2012_3_4_parity", 100.0  # mN·mm/rad: the §3.3 grid's stiffest
K1, FORCE_PER_VOLT, AMPLITUDE_V, FREQUENCY_HZ = 467.0, 1.2, 100.0, 110.0
W = 2 * math.pi * FREQUENCY_HZ * 1e-3  # rad/ms
PERIOD = 2 * math.pi / W
METRICS = ("delta_tau_peak", "tau_r_peak", "tau_l_peak", "imbalance_instantaneous_pct", "imbalance_peak_pct")


def spec(rtol: float = 1e-8, atol: float = 1e-10, samples: int = 4000, steady_state: str = "shooting") -> ps.Simulation:
    def wing(omega: float) -> ps.Wing:
        return ps.Wing(inertia=((INERTIA, 0, 0), (0, INERTIA, 0), (0, 0, 1.0)), aero=ps.Aero(omega1=omega, coefficient=C))

    return ps.Simulation(
        wings=(wing(OMEGA_R), wing(OMEGA_R)),
        configuration=ps.Configuration("drag_parity_fixed"),
        drivetrain=ps.Drivetrain.linear_differential(T_RATIO, ARM, balance_spring=0.0),
        actuator=ps.Actuator(ps.Waveform(amplitude_v=AMPLITUDE_V, frequency_hz=FREQUENCY_HZ), FORCE_PER_VOLT, K1),
        options=ps.Options(rtol=rtol, atol=atol, samples_per_cycle=samples, steady_state=steady_state),
    )


def table_metrics(tl: np.ndarray, tr: np.ndarray) -> dict[str, float]:
    """Table 3.2 from the stroke-axis drag torques of one cycle (the left wing's body roll is
    mirrored: Δτ = τL_roll + τR_roll = τR − τL in stroke-axis terms)."""
    delta = float(np.abs(tr - tl).max())
    peak_r, peak_l = float(np.abs(tr).max()), float(np.abs(tl).max())
    return dict(
        delta_tau_peak=delta,
        tau_r_peak=peak_r,
        tau_l_peak=peak_l,
        imbalance_instantaneous_pct=100 * delta / peak_r,
        imbalance_peak_pct=100 * (peak_r - peak_l) / peak_r,
    )


# ------------------------------------------------------------------------------ scipy loop


def scipy_point(omega_l: float, k2: float, cycles: int, samples: int, rtol: float, atol: float) -> dict[str, float]:
    """What a researcher writes first: numpy RHS in drivetrain coordinates, DOP853, t_eval."""

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        q1, q2, v1, v2 = y
        pl, pr = -T_RATIO * v1 + T_RATIO * ARM * v2, -T_RATIO * v1 - T_RATIO * ARM * v2
        tl, tr = -omega_l * C * pl * abs(pl), -OMEGA_R * C * pr * abs(pr)
        g1 = -T_RATIO * (tl + tr) + FORCE_PER_VOLT * AMPLITUDE_V * math.sin(W * t) - K1 * q1
        g2 = T_RATIO * ARM * (tl - tr) - k2 * q2
        return np.array([v1, v2, g1 / (2 * INERTIA * T_RATIO**2), g2 / (2 * INERTIA * (T_RATIO * ARM) ** 2)])

    ts = np.linspace((cycles - 1) * PERIOD, cycles * PERIOD, samples + 1)
    sol = solve_ivp(rhs, (0.0, cycles * PERIOD), np.zeros(4), method="DOP853", rtol=rtol, atol=atol, t_eval=ts)
    v1, v2 = sol.y[2], sol.y[3]
    pl, pr = -T_RATIO * v1 + T_RATIO * ARM * v2, -T_RATIO * v1 - T_RATIO * ARM * v2
    return table_metrics(-omega_l * C * pl * np.abs(pl), -OMEGA_R * C * pr * np.abs(pr))


# ------------------------------------------------------------------------------ JAX + diffrax


def jax_runners(cycles: int, samples: int, rtol: float, atol: float) -> tuple[Callable, Callable | None] | str:
    """(jit(vmap), shard_map over 2 devices or None), or the reason JAX is skipped."""
    try:
        import diffrax
        import jax
        import jax.numpy as jnp
    except ImportError as e:  # the optional `bench` extra
        return f"JAX/diffrax not installed ({e.name}); install the `bench` extra"
    jax.config.update("jax_enable_x64", True)
    ts = jnp.linspace((cycles - 1) * PERIOD, cycles * PERIOD, samples + 1)

    def rhs(t, y, args):
        omega_l, k2 = args
        q1, q2, v1, v2 = y
        pl, pr = -T_RATIO * v1 + T_RATIO * ARM * v2, -T_RATIO * v1 - T_RATIO * ARM * v2
        tl, tr = -omega_l * C * pl * jnp.abs(pl), -OMEGA_R * C * pr * jnp.abs(pr)
        g1 = -T_RATIO * (tl + tr) + FORCE_PER_VOLT * AMPLITUDE_V * jnp.sin(W * t) - K1 * q1
        g2 = T_RATIO * ARM * (tl - tr) - k2 * q2
        return jnp.stack([v1, v2, g1 / (2 * INERTIA * T_RATIO**2), g2 / (2 * INERTIA * (T_RATIO * ARM) ** 2)])

    def one(omega_l, k2):
        sol = diffrax.diffeqsolve(
            diffrax.ODETerm(rhs), diffrax.Dopri5(), t0=0.0, t1=cycles * PERIOD, dt0=None, y0=jnp.zeros(4), args=(omega_l, k2),
            saveat=diffrax.SaveAt(ts=ts), stepsize_controller=diffrax.PIDController(rtol=rtol, atol=atol), max_steps=400 * cycles,
        )
        v1, v2 = sol.ys[:, 2], sol.ys[:, 3]
        pl, pr = -T_RATIO * v1 + T_RATIO * ARM * v2, -T_RATIO * v1 - T_RATIO * ARM * v2
        tl, tr = -omega_l * C * pl * jnp.abs(pl), -OMEGA_R * C * pr * jnp.abs(pr)
        delta = jnp.abs(tr - tl).max()
        peak_r, peak_l = jnp.abs(tr).max(), jnp.abs(tl).max()
        return jnp.stack([delta, peak_r, peak_l, 100 * delta / peak_r, 100 * (peak_r - peak_l) / peak_r])

    vmapped = jax.jit(jax.vmap(one))
    sharded = None
    if len(jax.devices()) >= 2:
        from jax.sharding import Mesh
        from jax.sharding import PartitionSpec as P

        try:
            from jax import shard_map  # JAX >= 0.6
        except ImportError:
            from jax.experimental.shard_map import shard_map
        mesh = Mesh(np.array(jax.devices()[:2]), ("points",))
        try:
            mapped = shard_map(jax.vmap(one), mesh=mesh, in_specs=(P("points"), P("points")), out_specs=P("points"), check_vma=False)
        except TypeError:
            mapped = shard_map(jax.vmap(one), mesh=mesh, in_specs=(P("points"), P("points")), out_specs=P("points"), check_rep=False)
        sharded = jax.jit(mapped)

    def wrap(f):
        def run(omega_l: np.ndarray, k2: np.ndarray) -> np.ndarray:
            return np.asarray(jax.block_until_ready(f(jnp.asarray(omega_l), jnp.asarray(k2))))

        return run

    return wrap(vmapped), (wrap(sharded) if sharded is not None else None)


# ------------------------------------------------------------------------------ paritysim


UNCONVERGED: dict[str, int] = {}  # rows a peer's sweep ran without converging (kept: metrics of its last cycles)


def ps_sweep(ratios: np.ndarray, k2s: np.ndarray, base: ps.Simulation, threads: int, unconverged_as: str | None = None) -> np.ndarray:
    """Table 3.2 metrics of the grid; every row must be "ok", except "unconverged" rows of a
    peer that names itself (``unconverged_as``): the transient steady state from rest at
    default options leaves the K2 = 3.2 row (a slow whippletree mode) short of steady_tol after
    max_cycles; such rows keep the metrics of their last cycles and are counted."""
    with warnings.catch_warnings():
        if unconverged_as:
            warnings.simplefilter("ignore")
        df = ps.sweep(
            base, {"wings.left.omega_ratio": ratios, "drivetrain.balance_spring": k2s}, metrics=list(METRICS), threads=threads, progress=False
        )
    allowed = ["ok", "unconverged"] if unconverged_as else ["ok"]
    if (~df["status"].is_in(allowed)).any():
        bad = df.filter(~df["status"].is_in(allowed))
        raise SystemExit(f"paritysim: {len(bad)} points not {' or '.join(allowed)}: {bad['error'][0]}")
    if unconverged_as:
        UNCONVERGED[unconverged_as] = int((df["status"] == "unconverged").sum())
    return df.select(METRICS).to_numpy()


def errors(values: np.ndarray, reference: np.ndarray) -> tuple[float, float]:
    """Worst error of the torques relative to τR's peak (Δτ vanishes at Ω^L = Ω^R), worst
    absolute error (points) of the percentages."""
    rel = np.abs(values[:, :3] - reference[:, :3]) / np.abs(reference[:, 1:2])
    pct = np.abs(values[:, 3:] - reference[:, 3:])
    return float(rel.max()), float(pct.max())


def ps_sweep_3_4(base: ps.Simulation, rows: object, threads: int) -> np.ndarray:
    df = ps.sweep(base, rows, metrics=list(peer_3_4.METRICS), threads=threads, progress=False)
    if (df["status"] != "ok").any():
        raise SystemExit(f"paritysim §3.4: {int((df['status'] != 'ok').sum())} points not ok: {df.filter(df['status'] != 'ok')['error'][0]}")
    return df.select(peer_3_4.METRICS).to_numpy()


def errors_3_4(values: np.ndarray, reference: np.ndarray) -> tuple[float, float, float]:
    """Worst error of the mean yaw torque (mN·mm, and relative to the grid's largest |mean yaw|)
    and of the stroke and rotation angles (rad)."""
    yaw = float(np.abs(values[:, 0] - reference[:, 0]).max())
    return yaw, yaw / float(np.abs(reference[:, 0]).max()), float(np.abs(values[:, 1:] - reference[:, 1:]).max())


def timed(f: Callable[[], np.ndarray]) -> tuple[float, np.ndarray]:
    start = time.perf_counter()
    out = f()
    return time.perf_counter() - start, out


def scale(points: int, threads: int) -> None:
    """Peak memory of a large metrics-only sweep, then 1 vs 2 threads on the 32 × 32 grid."""
    import resource

    side = int(math.ceil(math.sqrt(points)))
    ratios, k2s = np.linspace(0.3, 1.0, side), np.linspace(0.0, 100.0, side)
    start = time.perf_counter()
    out = ps_sweep(ratios, k2s, spec(), threads)
    wall = time.perf_counter() - start
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"[scale] {len(out)} points, Table 3.2 metrics (shooting, 4000 samples): {wall:.1f} s wall "
          f"({wall / len(out) * 1e3:.3f} ms/pt, {threads} threads); peak RSS {rss:.0f} MB (target < 300 MB)")  # fmt: skip
    ratios, k2s = np.linspace(0.3, 1.0, 32), np.linspace(0.0, 100.0, 32)
    def cpu() -> float:
        r = resource.getrusage(resource.RUSAGE_SELF)
        return r.ru_utime + r.ru_stime

    def run(n: int) -> tuple[float, float, np.ndarray]:
        c0 = cpu()
        wall, out = timed(lambda: ps_sweep(ratios, k2s, spec(), n))
        return wall, cpu() - c0, out

    rounds = [(run(1), run(2)) for _ in range(3)]
    t1 = statistics.median(r[0][0] for r in rounds)
    t2 = statistics.median(r[1][0] for r in rounds)
    cores = statistics.median(r[1][1] / r[1][0] for r in rounds)
    same = all(np.array_equal(a[2], b[2]) for a, b in rounds)
    print(f"[threads] 1024 points: 1 thread {t1:.2f} s, 2 threads {t2:.2f} s -> speedup {t1 / t2:.2f}x (target >= 1.8; "
          f"medians of 3 interleaved rounds; the 2-thread runs got {cores:.2f} cores); bit-identical: {same}")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--grid", type=int, default=32, help="points per axis")
    parser.add_argument("--cycles", type=int, default=60, help="fixed cycles of the script peers")
    parser.add_argument("--samples", type=int, default=4000)
    parser.add_argument("--scipy-points", type=int, default=4)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--grid-3-4", type=int, default=8, help="points per axis of the §3.4 sweep (0: none)")
    parser.add_argument("--cycles-3-4", type=int, default=60, help="fixed cycles of the §3.4 JAX peer")
    parser.add_argument("--scale", type=int, default=0, help="run only the memory / thread-scaling check with this many points")
    args = parser.parse_args()
    if args.scale:
        scale(args.scale, args.threads)
        return
    atol = args.rtol * 1e-2
    ratios = np.linspace(0.3, 1.0, args.grid)
    k2s = np.linspace(0.0, 100.0, args.grid)
    # Row-major like ps.sweep's grid: the last axis (K2) varies fastest.
    omega_l = np.repeat(ratios * OMEGA_R, args.grid)
    k2 = np.tile(k2s, args.grid)
    n = len(k2)

    print(f"§3.3 linear-map Drag PARITY, {args.grid}×{args.grid} = {n} points, {args.samples} samples per cycle, rtol {args.rtol:g}")
    t_ref, reference = timed(lambda: ps_sweep(ratios, k2s, spec(1e-12, 1e-14, args.samples), args.threads))
    print(f"reference: paritysim shooting at rtol 1e-12 ({t_ref:.1f} s)")
    # An independent check of the reference on a few points: a long transient at rtol 1e-12.
    check = [0, n // 3, n - 1]
    long = spec(1e-12, 1e-14, args.samples, steady_state="transient").replace(
        options=ps.Options(rtol=1e-12, atol=1e-14, samples_per_cycle=args.samples, steady_tol=1e-12, max_cycles=20000)
    )
    for i in check:
        r = ps.sweep(long, [{"wings.left.omega_ratio": omega_l[i] / OMEGA_R, "drivetrain.balance_spring": k2[i]}], metrics=list(METRICS), progress=False)
        rel, pct = errors(r.select(METRICS).to_numpy(), reference[i : i + 1])
        print(f"  point {i}: long transient vs reference: torques {rel:.1e} rel, percentages {pct:.1e} points")

    jax_run = jax_runners(args.cycles, args.samples, args.rtol, atol)
    peers: dict[str, Callable[[], np.ndarray]] = {
        "paritysim sweep, shooting (metrics only)": lambda: ps_sweep(ratios, k2s, spec(args.rtol, atol, args.samples), args.threads),
        "paritysim sweep, transient": lambda: ps_sweep(
            ratios, k2s, spec(args.rtol, atol, args.samples, "transient"), args.threads, unconverged_as="paritysim sweep, transient"
        ),
    }
    sizes = {name: n for name in peers}
    if isinstance(jax_run, str):
        print(f"JAX skipped: {jax_run}")
    else:
        vmapped, sharded = jax_run
        for name, f in [("JAX+diffrax Dopri5 jit(vmap)", vmapped), ("JAX+diffrax Dopri5 shard_map x2", sharded)]:
            if f is None:
                print(f"{name} skipped: fewer than 2 host devices")
                continue
            t_compile, _ = timed(lambda f=f: f(omega_l, k2))
            print(f"{name}: first call (compile + run) {t_compile:.1f} s")
            peers[name] = lambda f=f: f(omega_l, k2)
            sizes[name] = n
    pick = np.linspace(0, n - 1, args.scipy_points).astype(int)
    peers[f"scipy solve_ivp DOP853 loop ({args.scipy_points} points)"] = lambda: np.array(
        [list(scipy_point(omega_l[i], k2[i], args.cycles, args.samples, args.rtol, atol).values()) for i in pick]
    )
    sizes[f"scipy solve_ivp DOP853 loop ({args.scipy_points} points)"] = len(pick)
    # One cold trial (issue 12: <= 0.7 ms, >= 300x scipy): ps.simulate per point at the
    # default steady state from the spec's own start, one thread, specs built beforehand,
    # the Table 3.2 metrics only (no trajectory column).
    base = spec(args.rtol, atol, args.samples)
    trial_specs = [base.with_paths({"wings.left.omega_ratio": omega_l[i] / OMEGA_R, "drivetrain.balance_spring": k2[i]}) for i in pick]
    peers["paritysim simulate, one cold trial per point"] = lambda: np.array(
        [list(ps.simulate(s, columns=[], metrics=METRICS).metrics.values()) for s in trial_specs]
    )
    sizes["paritysim simulate, one cold trial per point"] = len(pick)
    # The §3.4 rotating trial (issue 12: <= 3 ms): the shipped 1-Cut Drag PARITY device
    # (blade-element wings, stroke plane, hinge spring) at its default options, the same five
    # metrics, against the same run at rtol 1e-12.
    rotating = ps.devices.load(ROTATING_DEVICE)
    rotating_reference = np.array([list(ps.simulate(rotating, columns=[], metrics=METRICS, rtol=1e-12, atol=1e-14).metrics.values())])
    peers[ROTATING_PEER] = lambda: np.array([list(ps.simulate(rotating, columns=[], metrics=METRICS).metrics.values())])
    sizes[ROTATING_PEER] = 1

    # The §3.4 design sweep and its JAX peer.
    peers_3_4: dict[str, Callable[[], np.ndarray]] = {}
    if args.grid_3_4:
        base_3_4 = ps.devices.load(SWEEP_3_4_DEVICE).with_paths({"drivetrain.balance_spring": K2_3_4})
        rows, hinge, omegas_right = peer_3_4.grid(base_3_4, args.grid_3_4)
        n_3_4 = len(hinge)
        samples_3_4 = base_3_4.options.samples_per_cycle
        print(f"\n§3.4 {SWEEP_3_4_DEVICE} with K2 = {K2_3_4:g} mN·mm/rad, hinge stiffness × right membrane cut, "
              f"{args.grid_3_4}×{args.grid_3_4} = {n_3_4} points, {samples_3_4} samples per cycle")  # fmt: skip
        tight = base_3_4.with_paths({"options.rtol": 1e-12, "options.atol": 1e-14, "options.steady_tol": 1e-12})
        t_ref, reference_3_4 = timed(lambda: ps_sweep_3_4(tight, rows, args.threads))
        print(f"reference: paritysim ps.sweep at rtol 1e-12, steady_tol 1e-12 ({t_ref:.1f} s)")
        jax_3_4 = peer_3_4.runners(base_3_4, args.cycles_3_4, samples_3_4, args.rtol, atol)
        peers_3_4["paritysim ps.sweep (device defaults)"] = lambda: ps_sweep_3_4(base_3_4, rows, args.threads)
        if isinstance(jax_3_4, str):
            print(f"JAX skipped: {jax_3_4}")
        else:
            # The peer's equations against paritysim's: both at rtol 1e-12 on three points.
            check = [0, n_3_4 // 2 - 1, n_3_4 - 1]
            tight_peer = peer_3_4.runners(base_3_4, 100, samples_3_4, 1e-12, 1e-14)
            assert not isinstance(tight_peer, str)
            out = tight_peer[0](hinge[check], omegas_right[check])
            yaw, yaw_rel, angles = errors_3_4(out, reference_3_4[check])
            print(f"  points {check}: JAX peer at rtol 1e-12 (100 cycles) vs reference: mean yaw {yaw:.1e} mN·mm, angles {angles:.1e} rad")
            for name, f in [("JAX+diffrax Dopri5 jit(vmap)", jax_3_4[0]), ("JAX+diffrax Dopri5 shard_map x2", jax_3_4[1])]:
                if f is None:
                    print(f"{name} skipped: fewer than 2 host devices")
                    continue
                t_compile, _ = timed(lambda f=f: f(hinge, omegas_right))
                print(f"{name}: first call (compile + run) {t_compile:.1f} s")
                peers_3_4[name] = lambda f=f: f(hinge, omegas_right)

    times: dict[str, list[float]] = {name: [] for name in [*peers, *(f"3.4 {k}" for k in peers_3_4)]}
    results: dict[str, np.ndarray] = {}
    for _ in range(args.repeat):  # interleaved rounds, both sections
        for name, f in [*peers.items(), *((f"3.4 {k}", g) for k, g in peers_3_4.items())]:
            dt, out = timed(f)
            times[name].append(dt)
            results[name] = out
    for name in peers_3_4:
        sizes[f"3.4 {name}"] = n_3_4
    ms = {name: 1e3 * statistics.median(ts) / sizes[name] for name, ts in times.items()}
    ours = ms["paritysim sweep, shooting (metrics only)"]
    jax_best = min((v for k, v in ms.items() if k.startswith("JAX")), default=float("nan"))
    print(f"\n{'implementation':48s} {'ms/point':>10s} {'vs paritysim':>13s} {'torque err':>11s} {'pct err':>9s}")
    for name in peers:
        ref = reference[pick] if name.startswith(("scipy", "paritysim simulate")) else reference
        ref = rotating_reference if name == ROTATING_PEER else ref
        rel, pct = errors(results[name], ref)
        print(f"{name:48s} {ms[name]:10.3f} {ms[name] / ours:12.1f}x {rel:11.1e} {pct:9.1e}")
    for name, count in UNCONVERGED.items():
        if count:
            print(f"{name}: {count} of {n} rows unconverged after max_cycles (their last cycles' metrics are in its errors)")
    ours_on_scipy_points = errors(results["paritysim sweep, shooting (metrics only)"][pick], reference[pick])
    print(f"paritysim on the scipy points: torque err {ours_on_scipy_points[0]:.1e}, pct err {ours_on_scipy_points[1]:.1e}")
    if math.isfinite(jax_best):
        print(f"\nparitysim per point = {ours / jax_best:.3f} × the best JAX set-up's time")
    ratio_3_3 = ours / jax_best if math.isfinite(jax_best) else float("nan")
    if peers_3_4:
        ours_3_4 = ms["3.4 paritysim ps.sweep (device defaults)"]
        print(f"\n{'§3.4 implementation':48s} {'ms/point':>10s} {'vs paritysim':>13s} {'yaw err':>9s} {'yaw rel':>9s} {'angle err':>10s}")
        for name in peers_3_4:
            yaw, yaw_rel, angles = errors_3_4(results[f"3.4 {name}"], reference_3_4)
            print(f"{name:48s} {ms[f'3.4 {name}']:10.3f} {ms[f'3.4 {name}'] / ours_3_4:12.1f}x {yaw:9.1e} {yaw_rel:9.1e} {angles:10.1e}")
        print("(yaw err: worst |Δ mean yaw torque|, mN·mm; yaw rel: over the grid's largest |mean yaw|; angle err: strokes and rotations, rad)")
        best_3_4 = min((v for k, v in ms.items() if k.startswith("3.4 JAX")), default=float("nan"))
        if math.isfinite(best_3_4):
            print(f"\nparitysim per point = {ratio_3_3:.3f} × the best JAX set-up's time (§3.3), "
                  f"{ours_3_4 / best_3_4:.3f} × (§3.4)")  # fmt: skip
    print(f"(medians of {args.repeat} interleaved rounds; {args.threads} paritysim threads; script peers run {args.cycles} cycles "
          f"(§3.4: {args.cycles_3_4}) from rest)")  # fmt: skip


if __name__ == "__main__":
    main()
