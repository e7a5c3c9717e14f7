"""Cost of the force and power metrics in a sweep (issue 32, item 1; printed ratio, not a test).

The §3.4 design sweep (hinge stiffness x right-wing cut on the PARITY device, torque stand) with
``yaw_total_mean`` alone and with ``lift_mean`` and ``aero_power_mean`` added (the target:
<= 1.3x per point), and with every force and power metric; runs interleaved, one thread, the
median of ``--repeats``.

Run:  python benchmarks/force_metrics_cost.py [--repeats 5] [--side 4]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

import paritysim as ps

BASE = ["yaw_total_mean"]
ISSUE = [*BASE, "lift_mean", "aero_power_mean"]
ALL = [*ISSUE, "left_lift_mean", "right_lift_mean", "lift_rms", "lift_peak", "aero_force_y_mean", "aero_force_z_mean",
       "aero_force_peak", "actuator_power_mean", "lift_per_power"]  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--side", type=int, default=4, help="grid points per axis")
    args = parser.parse_args()
    spec = ps.devices.load("sreetharan2012_3_4_parity")
    # hinge x cut: both wings' hinge stiffness (mN·mm/rad) x the right wing's Ω1 (38.2: uncut)
    rows = [
        {"wings[0].springs.hinge.stiffness": float(k), "wings[1].springs.hinge.stiffness": float(k), "wings[1].aero.omega1": float(o)}
        for k in np.linspace(1.5, 4.0, args.side)
        for o in np.linspace(20.0, 38.2, args.side)
    ]
    sets = {"base": BASE, "issue": ISSUE, "all": ALL}
    times: dict[str, list[float]] = {k: [] for k in sets}
    ps.sweep(spec, rows[:2], metrics=ALL, threads=1, progress=False)  # warm-up
    for _ in range(args.repeats):
        for name, metrics in sets.items():
            start = time.perf_counter()
            df = ps.sweep(spec, rows, metrics=metrics, threads=1, progress=False)
            times[name].append(time.perf_counter() - start)
            assert (df["status"] == "ok").all(), df["error"].to_list()
    med = {k: statistics.median(v) for k, v in times.items()}
    n = len(rows)
    for k, v in med.items():
        print(f"{k:6s} {len(sets[k]):2d} metrics: median {1e3 * v / n:8.2f} ms/point  "
              f"({', '.join(f'{t:.2f}' for t in times[k])} s)  ratio {v / med['base']:.3f}x")  # fmt: skip


if __name__ == "__main__":
    main()
