"""Baseline a researcher would write: the §3.3 fixed-wing Drag PARITY model in plain numpy +
``scipy.integrate.solve_ivp`` (DOP853), against ``paritysim.simulate`` on the same spec.

The baseline integrates in actuator coordinates q = (q1, q2) (an independent formulation of the
same physics: M_q = Jᵀ I J, the massless linkage, eqs. 2.18-2.19 generalised to the nonlinear
linkage), using only the drivetrain's forward map phi(q) and its derivatives.

Run:  python benchmarks/vs_scipy.py [--cycles 20] [--repeat 3]
Prints both wall times, the ratio, and checks that both give the same metrics.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.integrate import solve_ivp

import paritysim as ps


def rod_crank(delta_x: float, delta_y: float, crank: float, rod: float) -> tuple[float, float, float]:
    """Crank angle beta and its partials w.r.t. the rod-top vertical and horizontal displacement."""
    x, y = crank + delta_x, rod + delta_y
    r = math.hypot(x, y)
    k = (x * x + y * y + crank * crank - rod * rod) / (2 * crank * r)
    beta = math.atan2(y, x) - math.acos(k)
    sb, cb = math.sin(beta), math.cos(beta)
    f_b = 2 * crank * (x * sb - y * cb)
    return beta, -2 * (y - crank * sb) / f_b, -2 * (x - crank * cb) / f_b


def stroke_map(q: np.ndarray, crank: float, rod: float, arm: float) -> tuple[np.ndarray, np.ndarray]:
    """phi = (phi_L, phi_R) and J = dphi/dq for the Drag PARITY linkage (plain Python)."""
    q1, q2 = q
    s2, c2 = math.sin(q2), math.cos(q2)
    phis, jac = [], []
    for side in (-1.0, 1.0):
        beta, b_y, b_x = rod_crank(arm * (c2 - 1), q1 + side * arm * s2, crank, rod)
        phis.append(-beta)
        jac.append([-b_y, -(b_y * side * arm * c2 + b_x * (-arm * s2))])
    return np.array(phis), np.array(jac)


def baseline_rhs(params: dict) -> callable:
    crank, rod, arm = params["crank"], params["rod"], params["arm"]
    inertia, omega, coef = params["inertia"], params["omega"], params["coefficient"]
    k1, k2, fpv, amp, w = params["k1"], params["k2"], params["force_per_volt"], params["amplitude_v"], params["w"]
    h = 1e-6

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        q, qd = y[:2], y[2:]
        _, jac = stroke_map(q, crank, rod, arm)
        # velocity-product term h(q, q_dot) = d/dt(J) q_dot by a directional finite difference
        _, jac_p = stroke_map(q + h * qd, crank, rod, arm)
        _, jac_m = stroke_map(q - h * qd, crank, rod, arm)
        jdot_qd = (jac_p - jac_m) @ qd / (2 * h)
        phi_dot = jac @ qd
        tau_aero = -omega * coef * np.abs(phi_dot) * phi_dot
        force = np.array([fpv * amp * math.sin(w * t) - k1 * q[0], -k2 * q[1]])
        mass = inertia * jac.T @ jac
        rhs_q = jac.T @ (tau_aero - inertia * jdot_qd) + force
        return np.concatenate([qd, np.linalg.solve(mass, rhs_q)])

    return rhs


def run_baseline(params: dict, cycles: int, rtol: float, atol: float, kick: float) -> dict:
    period = 2 * math.pi / params["w"]
    y0 = np.array([0.0, 0.0, 0.0, kick])
    t_eval = np.linspace((cycles - 1) * period, cycles * period, 201)
    sol = solve_ivp(baseline_rhs(params), (0.0, cycles * period), y0, method="DOP853", rtol=rtol, atol=atol, t_eval=t_eval)
    if not sol.success:
        raise RuntimeError(sol.message)
    phis = np.array([stroke_map(sol.y[:2, i], params["crank"], params["rod"], params["arm"])[0] for i in range(sol.y.shape[1])])
    return {
        "left_stroke_amplitude": 0.5 * np.ptp(phis[:, 0]),
        "right_stroke_amplitude": 0.5 * np.ptp(phis[:, 1]),
        "q2_amplitude": 0.5 * np.ptp(sol.y[1]),
        "nfev": sol.nfev,
    }


def spec_for(params: dict, cycles: int, rtol: float, atol: float, kick: float) -> ps.Simulation:
    wing = lambda omega: ps.Wing(  # noqa: E731
        inertia=((params["inertia"], 0, 0), (0, params["inertia"], 0), (0, 0, 1.0)), aero=ps.Aero(omega1=omega, coefficient=params["coefficient"])
    )
    return ps.Simulation(
        wings=(wing(params["omega_left"]), wing(params["omega"])),
        configuration=ps.Configuration("drag_parity_fixed"),
        drivetrain=ps.Drivetrain.linkage_differential(params["crank"], params["rod"], 2 * params["arm"], balance_spring=params["k2"]),
        actuator=ps.Actuator(ps.Waveform(amplitude_v=params["amplitude_v"], frequency_hz=params["w"] / (2 * math.pi) * 1e3), params["force_per_volt"], params["k1"]),
        options=ps.Options(rtol=rtol, atol=atol, min_cycles=cycles - 1, max_cycles=cycles - 1, steady_tol=1e-30, samples_per_cycle=200,
                           initial_p_dot=None if kick == 0 else None),
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--cycles", type=int, default=20)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--omega-left", type=float, default=18.75, help="left wing drag parameter (mg mm^2); 31.3 = Control")
    args = parser.parse_args()
    params = dict(crank=0.4, rod=0.8, arm=2.5, inertia=29.0, omega=31.3, omega_left=args.omega_left, coefficient=3.4609,
                  k1=467.0, k2=1.0, force_per_volt=1.2, amplitude_v=100.0, w=2 * math.pi * 0.110)
    atol = args.rtol * 1e-2
    spec = spec_for(params, args.cycles, args.rtol, atol, 0.0)

    t_rs = min(_timed(lambda: ps.simulate(spec)) for _ in range(args.repeat))
    ours = ps.simulate(spec).metrics
    t_py = min(_timed(lambda: run_baseline(params | {"omega_left": args.omega_left}, args.cycles, args.rtol, atol, 0.0)) for _ in range(max(1, args.repeat // 3)))
    base = run_baseline(params, args.cycles, args.rtol, atol, 0.0)
    print(f"{args.cycles} wingbeats, rtol {args.rtol:g}: paritysim {t_rs * 1e3:.2f} ms, numpy+scipy {t_py * 1e3:.1f} ms, ratio {t_py / t_rs:.0f}x")
    worst = 0.0
    for key in ("left_stroke_amplitude", "right_stroke_amplitude"):
        diff = abs(ours[key] - base[key])
        worst = max(worst, diff / abs(base[key]))
        print(f"  {key:24s} paritysim {ours[key]:.9f}  scipy {base[key]:.9f}  diff {diff:.2e}")
    if worst > 1e-4:
        raise SystemExit(f"MISMATCH: the two models disagree by {worst:.1e} (relative)")
    print(f"  metrics agree to {worst:.1e} (relative)")


def _timed(f: callable) -> float:
    start = time.perf_counter()
    f()
    return time.perf_counter() - start


if __name__ == "__main__":
    main()
