"""Roll imbalance vs the left wing's drag (Ω ratio) for HMF and Drag PARITY: Table 3.2 as a curve.

A damaged (cut) left wing has a smaller drag parameter Ω1 = ratio × 31.3 mg·mm². The HMF's
single-DOF four-bar forces equal strokes, so the peak drag torques differ by the drag ratio:
imbalance = 1 − τL/τR = 1 − ratio. Drag PARITY's whippletree lets the lighter wing stroke further
until the torques (nearly) balance. PARITY uses the linear differential of eq. 2.15 here: with the
nonlinear rod-crank linkage a cut wing strokes past the linkage's reach at 100 V (those points
come back as `status = "error"` rows; see docs/findings.md §3 for the linkage's whippletree mode).

Run:  python examples/sweep_imbalance.py --out results/
Writes results/sweep_imbalance.parquet and results/sweep_imbalance.png.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import polars as pl

import paritysim as ps
from paritysim.sweep import plot, sweep

EXAMPLES = Path(__file__).resolve().parent
METRICS = ["left_roll_aero_peak", "right_roll_aero_peak", "left_stroke_amplitude", "right_stroke_amplitude", "q2_amplitude"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="results", type=Path)
    parser.add_argument("--points", type=int, default=25, help="Ω ratios in [0.3, 1]")
    parser.add_argument("--threads", type=int, default=None)
    args = parser.parse_args()

    ratios = np.linspace(0.3, 1.0, args.points).tolist()
    hmf = ps.load_spec(EXAMPLES / "hmf.toml")
    parity = ps.load_spec(EXAMPLES / "drag_parity.toml")
    parity_linear = parity.replace(drivetrain=ps.Drivetrain.linear_differential(2.5, 2.5))  # eq. 2.15, T = 1/L3
    options = {"max_cycles": 400}  # soft whippletree springs settle slowly
    frames = [
        sweep(hmf, {"wings.left.omega_ratio": ratios}, metrics=METRICS, threads=args.threads, options=options)
        .with_columns(design=pl.lit("HMF"), **{"drivetrain.balance_spring": pl.lit(None, dtype=pl.Float64)}),
    ]
    for k2 in (2.0, 20.0, 100.0):
        df = sweep(parity_linear, {"wings.left.omega_ratio": ratios, "drivetrain.balance_spring": [k2]}, metrics=METRICS, threads=args.threads, options=options)
        frames.append(df.with_columns(design=pl.lit(f"PARITY eq. 2.15, K2 = {k2:g}")))
    linkage = sweep(parity, {"wings.left.omega_ratio": ratios, "drivetrain.balance_spring": [500.0]}, metrics=METRICS, threads=args.threads, options=options)
    frames.append(linkage.with_columns(design=pl.lit("PARITY linkage, K2 = 500")))
    cols = ["design", "wings.left.omega_ratio", "drivetrain.balance_spring", *METRICS, "converged", "status", "error"]
    df = pl.concat([f.select(cols) for f in frames]).with_columns(
        roll_imbalance=1 - pl.col("left_roll_aero_peak") / pl.col("right_roll_aero_peak"),
    )
    args.out.mkdir(parents=True, exist_ok=True)
    df.write_parquet(args.out / "sweep_imbalance.parquet")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
    plot(df, "wings.left.omega_ratio", "roll_imbalance", hue="design", ax=ax1)
    ax1.set_ylabel("roll imbalance 1 − τL/τR (peak drag torques)")
    plot(df, "wings.left.omega_ratio", "left_stroke_amplitude", hue="design", ax=ax2)
    ax2.set_ylabel("left stroke amplitude (rad)")
    ps.plots.save(fig, args.out / "sweep_imbalance.png")

    summary = df.group_by("design", maintain_order=True).agg(
        ok=(pl.col("status") == "ok").sum(),
        failed=(pl.col("status") == "error").sum(),
        # At the smallest ratio that ran (the linkage fails below about 0.85): say which.
        smallest_ok_ratio=pl.col("wings.left.omega_ratio").filter(pl.col("status") == "ok").min(),
        imbalance_there=pl.col("roll_imbalance").filter(pl.col("status") == "ok").sort_by(pl.col("wings.left.omega_ratio").filter(pl.col("status") == "ok")).first(),
    )
    print(summary)
    print(f"wrote {args.out / 'sweep_imbalance.parquet'} and {args.out / 'sweep_imbalance.png'}")


if __name__ == "__main__":
    main()
