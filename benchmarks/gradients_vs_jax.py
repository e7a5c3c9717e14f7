"""Design gradients of the §3.3 Drag PARITY sweep (issue 31): the Jacobian of the five Table 3.2
metrics with respect to 8 parameters at every point of the 32 × 32 grid, paritysim
(``ps.sweep(..., gradients=[...])``: the implicit function theorem at the periodic orbit)
against the script a JAX user would write (``jax.jacfwd`` through a diffrax Dopri5 transient
from rest, ``jit(vmap)`` over the grid), interleaved in one process.

Device: as ``benchmarks/vs_jax.py`` (fixed wings on the linear map eq. 2.15, drag −Ω φ̇|φ̇|,
grid Ω^L/Ω^R ∈ [0.3, 1] × K2 ∈ [0, 100]). Parameters: Ω^L, Ω^R, K2, K1, force per volt, drive
amplitude, drive frequency, transmission ratio. The JAX peer integrates in the drive phase
τ = t/T (so the frequency enters the right-hand side, not the time span) and takes the metrics of
the last of ``--cycles`` cycles from ``--samples`` samples, as paritysim does.

Reference: central differences of whole ``ps.simulate`` runs at rtol 1e-12 (Newton shooting to
1e-12) on ``--check`` points, at relative steps h and h/2; an entry is used only where the two
agree (a sampled peak can move to its neighbouring sample within a step). The error of each
implementation is its worst deviation from the reference relative to the reference's column
scale ``max |∂m/∂p| · |p| / |m|`` (an elasticity), over the checked points.

Run:  python benchmarks/gradients_vs_jax.py [--grid 32] [--cycles 60] [--samples 400] [--repeat 3]
JAX and diffrax are the optional ``bench`` extra; without them only paritysim is timed.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from collections.abc import Callable

import numpy as np

import paritysim as ps

# The §3.3 device, its constants and its spec are vs_jax's (one definition of the benchmark device).
from vs_jax import AMPLITUDE_V, ARM, FORCE_PER_VOLT, FREQUENCY_HZ, INERTIA, K1, METRICS, OMEGA_R, T_RATIO, C
from vs_jax import spec as _device_spec

PARAMS = (
    "wings[0].aero.omega1",
    "wings[1].aero.omega1",
    "drivetrain.balance_spring",
    "actuator.stiffness",
    "actuator.force_per_volt",
    "actuator.waveform.amplitude_v",
    "actuator.waveform.frequency_hz",
    "drivetrain.transmission_ratio",
)


def spec(rtol: float, samples: int) -> ps.Simulation:
    return _device_spec(rtol=rtol, atol=rtol * 1e-2, samples=samples)


def grid_points(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Ω^L and K2 of every point, row-major as ps.sweep's grid (K2 fastest)."""
    ratios, k2s = np.linspace(0.3, 1.0, n), np.linspace(0.0, 100.0, n)
    return np.repeat(ratios * OMEGA_R, n), np.tile(k2s, n)


def theta_of(omega_l: float, k2: float) -> np.ndarray:
    """The 8 parameters (PARAMS' order) at a grid point."""
    return np.array([omega_l, OMEGA_R, k2, K1, FORCE_PER_VOLT, AMPLITUDE_V, FREQUENCY_HZ, T_RATIO])


# ------------------------------------------------------------------------------ paritysim


def ps_jacobians(base: ps.Simulation, grid: int, threads: int) -> np.ndarray:
    """(points, metrics, params) from one ps.sweep with gradients."""
    ratios, k2s = np.linspace(0.3, 1.0, grid), np.linspace(0.0, 100.0, grid)
    df = ps.sweep(
        base,
        {"wings.left.omega_ratio": ratios, "drivetrain.balance_spring": k2s},
        metrics=list(METRICS),
        gradients=list(PARAMS),
        threads=threads,
        progress=False,
    )
    if (df["status"] != "ok").any():
        raise SystemExit(f"paritysim: {int((df['status'] != 'ok').sum())} points not ok")
    columns = [[f"d({m})/d({p})" for p in PARAMS] for m in METRICS]
    out = np.stack([df.select(row).to_numpy() for row in columns], axis=1).astype(float)
    return out  # nulls (a metric not differentiable there) become NaN


def reference(omega_l: float, k2: float, samples: int, rel_step: float) -> tuple[np.ndarray, np.ndarray]:
    """Central differences of whole rtol-1e-12 runs at steps h and h/2: (jacobian at h/2,
    mask where both agree to 1e-6 of the column scale)."""
    base = spec(1e-12, samples).replace(options=ps.Options(rtol=1e-12, atol=1e-14, samples_per_cycle=samples, steady_tol=1e-12))
    base = base.with_paths({"wings.left.omega_ratio": omega_l / OMEGA_R, "drivetrain.balance_spring": k2})
    theta = theta_of(omega_l, k2)

    def metrics(values: dict[str, float]) -> np.ndarray:
        run = ps.simulate(base.with_paths(values), columns=[], metrics=METRICS)
        return np.array([run.metrics[m] for m in METRICS])

    def difference(scale: float) -> np.ndarray:
        cols = []
        for j, path in enumerate(PARAMS):
            h = rel_step * scale * max(abs(theta[j]), 1.0)
            up, down = metrics({path: theta[j] + h}), metrics({path: theta[j] - h})
            cols.append((up - down) / (2 * h))
        return np.stack(cols, axis=1)

    coarse, fine = difference(1.0), difference(0.5)
    scale = np.abs(fine).max(axis=0, keepdims=True) + 1e-300
    return fine, np.abs(coarse - fine) <= 1e-6 * scale


# ------------------------------------------------------------------------------ JAX + diffrax


def jax_jacobians(cycles: int, samples: int, rtol: float) -> Callable[[np.ndarray], np.ndarray] | str:
    """jit(vmap(jacfwd(metrics))) over the grid's parameter rows, or why JAX is skipped."""
    try:
        import diffrax
        import jax
        import jax.numpy as jnp
    except ImportError as e:
        return f"JAX/diffrax not installed ({e.name}); install the `bench` extra"
    jax.config.update("jax_enable_x64", True)
    taus = jnp.linspace(cycles - 1.0, float(cycles), samples + 1)

    def torques(theta, v1, v2):
        omega_l, omega_r, _, _, _, _, _, ratio = (theta[i] for i in range(8))
        pl, pr = -ratio * v1 + ratio * ARM * v2, -ratio * v1 - ratio * ARM * v2
        return -omega_l * C * pl * jnp.abs(pl), -omega_r * C * pr * jnp.abs(pr)

    def rhs(tau, y, theta):
        _, _, k2, k1, fpv, amp, freq, ratio = (theta[i] for i in range(8))
        period = 1e3 / freq  # ms
        q1, q2, v1, v2 = y
        tl, tr = torques(theta, v1, v2)
        g1 = -ratio * (tl + tr) + fpv * amp * jnp.sin(2 * jnp.pi * tau) - k1 * q1
        g2 = ratio * ARM * (tl - tr) - k2 * q2
        return period * jnp.stack([v1, v2, g1 / (2 * INERTIA * ratio**2), g2 / (2 * INERTIA * (ratio * ARM) ** 2)])

    def metrics(theta):
        sol = diffrax.diffeqsolve(
            diffrax.ODETerm(rhs), diffrax.Dopri5(), t0=0.0, t1=float(cycles), dt0=None, y0=jnp.zeros(4), args=theta,
            saveat=diffrax.SaveAt(ts=taus), stepsize_controller=diffrax.PIDController(rtol=rtol, atol=rtol * 1e-2),
            max_steps=400 * cycles, adjoint=diffrax.ForwardMode(),  # jacfwd needs forward-mode through the solve
        )  # fmt: skip
        tl, tr = torques(theta, sol.ys[:, 2], sol.ys[:, 3])
        delta = jnp.abs(tr - tl).max()
        peak_r, peak_l = jnp.abs(tr).max(), jnp.abs(tl).max()
        return jnp.stack([delta, peak_r, peak_l, 100 * delta / peak_r, 100 * (peak_r - peak_l) / peak_r])

    batched = jax.jit(jax.vmap(jax.jacfwd(metrics)))
    return lambda thetas: np.asarray(jax.block_until_ready(batched(jnp.asarray(thetas))))


# ------------------------------------------------------------------------------ comparison


def worst_error(jac: np.ndarray, ref: np.ndarray, ok: np.ndarray, theta: np.ndarray, values: np.ndarray) -> float:
    """Worst |jac − ref| over the trusted entries, as an elasticity error |Δ ∂m/∂p| |p| / |m|."""
    scale = np.abs(theta)[None, :] / np.maximum(np.abs(values)[:, None], 1e-12)
    err = np.abs(jac - ref) * scale
    return float(np.nanmax(np.where(ok, err, np.nan)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--grid", type=int, default=32)
    parser.add_argument("--cycles", type=int, default=60, help="cycles from rest of the JAX peer")
    parser.add_argument("--samples", type=int, default=400, help="samples per cycle (both)")
    parser.add_argument("--rtol", type=float, default=1e-8, help="tolerance of both timed implementations")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--check", type=int, default=3, help="grid points checked against the reference")
    parser.add_argument("--fd-step", type=float, default=1e-5, help="relative step of the reference's differences")
    args = parser.parse_args()
    omega_l, k2 = grid_points(args.grid)
    n = len(k2)
    thetas = np.stack([theta_of(a, b) for a, b in zip(omega_l, k2, strict=True)])
    base = spec(args.rtol, args.samples)
    print(f"§3.3 Drag PARITY, {args.grid}×{args.grid} = {n} points: d(5 Table 3.2 metrics)/d(8 parameters), "
          f"{args.samples} samples per cycle, rtol {args.rtol:g}")  # fmt: skip

    # Checked points: spread over the grid, away from K2 = 0 (a neutral whippletree family there).
    check = [i for i in np.linspace(0, n - 1, args.check + 2).astype(int)[1:-1]]
    t0 = time.perf_counter()
    refs = [reference(omega_l[i], k2[i], args.samples, args.fd_step) for i in check]
    ref_values = [
        np.array(list(ps.simulate(spec(1e-12, args.samples).with_paths({"wings.left.omega_ratio": omega_l[i] / OMEGA_R,
                  "drivetrain.balance_spring": k2[i]}), columns=[], metrics=METRICS).metrics.values()))  # fmt: skip
        for i in check
    ]
    trusted = sum(int(ok.sum()) for _, ok in refs)
    print(f"reference: central differences of rtol-1e-12 runs at points {check} ({time.perf_counter() - t0:.1f} s; "
          f"{trusted} of {len(check) * len(METRICS) * len(PARAMS)} entries agree at h and h/2)")  # fmt: skip

    peers: dict[str, Callable[[], np.ndarray]] = {
        "paritysim ps.sweep(gradients=8 paths)": lambda: ps_jacobians(base, args.grid, args.threads),
    }
    jax_run = jax_jacobians(args.cycles, args.samples, args.rtol)
    if isinstance(jax_run, str):
        print(f"JAX skipped: {jax_run}")
    else:
        t0 = time.perf_counter()
        jax_run(thetas)
        print(f"JAX jit(vmap(jacfwd)): first call (compile + run) {time.perf_counter() - t0:.1f} s")
        peers[f"JAX+diffrax jacfwd, {args.cycles} cycles from rest"] = lambda: jax_run(thetas)

    times: dict[str, list[float]] = {name: [] for name in peers}
    results: dict[str, np.ndarray] = {}
    for _ in range(args.repeat):  # interleaved rounds
        for name, f in peers.items():
            start = time.perf_counter()
            results[name] = f()
            times[name].append(time.perf_counter() - start)
    ms = {name: 1e3 * statistics.median(ts) / n for name, ts in times.items()}
    ours = ms["paritysim ps.sweep(gradients=8 paths)"]
    print(f"\n{'implementation':44s} {'ms/point':>9s} {'vs paritysim':>13s} {'worst elasticity error':>23s} {'missing':>8s}")
    for name in peers:
        jac = results[name]
        err = max(worst_error(jac[i], fine, ok, thetas[i], v) for i, (fine, ok), v in zip(check, refs, ref_values, strict=True))
        missing = int(np.isnan(jac).sum())
        print(f"{name:44s} {ms[name]:9.3f} {ms[name] / ours:12.1f}x {err:23.1e} {missing:8d}")
    jax_names = [k for k in ms if k.startswith("JAX")]
    if jax_names:
        ratio = ours / ms[jax_names[0]]
        print(f"\nparitysim per point = {ratio:.3f} × JAX jacfwd's time (target <= 0.1)")
    print(f"(medians of {args.repeat} interleaved rounds; {args.threads} paritysim threads; 'missing': entries paritysim "
          "flags not differentiable, NaN in its table)")  # fmt: skip


if __name__ == "__main__":
    main()
