"""Roll-torque ratio vs whippletree pivot bias (§2.4.2, eq. 5.1).

Moving the whippletree pivot off-centre (arm ratio r = hL/hR) biases how Drag PARITY shares the
drive between the wings: the quasi-static balance of the whippletree, T·hL·τL = T·hR·τR (with
K2 = 0), gives a left/right drag-torque ratio τL/τR = hR/hL = 1/r. The sweep measures the peak
roll (drag) torque ratio of the full dynamic model against that line, for a soft and a stiff
balance spring K2. The linear differential of eq. 2.15 is used: with the rod-crank linkage an
off-centre pivot drives one wing past the linkage's reach at 100 V.

Run:  python examples/sweep_pivot_bias.py --out results/
Writes results/sweep_pivot_bias.parquet and results/sweep_pivot_bias.png.
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="results", type=Path)
    parser.add_argument("--points", type=int, default=25, help="arm ratios in [0.5, 2] (log-spaced)")
    parser.add_argument("--threads", type=int, default=None)
    args = parser.parse_args()

    parity = ps.load_spec(EXAMPLES / "drag_parity.toml")
    spec = parity.replace(drivetrain=ps.Drivetrain.linear_differential(2.5, 2.5))  # eq. 2.15
    df = sweep(
        spec,
        {"drivetrain.balance_spring": [0.0, 20.0], "drivetrain.arm_ratio": np.geomspace(0.5, 2.0, args.points).tolist()},
        metrics=["left_roll_aero_peak", "right_roll_aero_peak", "left_stroke_amplitude", "right_stroke_amplitude", "q2_amplitude"],
        threads=args.threads,
        options={"max_cycles": 400},
    ).with_columns(
        roll_torque_ratio=pl.col("left_roll_aero_peak") / pl.col("right_roll_aero_peak"),
        static_prediction=1 / pl.col("drivetrain.arm_ratio"),
    )
    args.out.mkdir(parents=True, exist_ok=True)
    df.write_parquet(args.out / "sweep_pivot_bias.parquet")

    fig, ax = plt.subplots(figsize=(6, 4), layout="constrained")
    plot(df, "drivetrain.arm_ratio", "roll_torque_ratio", hue="drivetrain.balance_spring", ax=ax)
    r = np.geomspace(0.5, 2.0, 100)
    ax.plot(r, 1 / r, "k--", lw=1, label="static balance 1/r")
    ax.set(xscale="log", yscale="log", xlabel="arm ratio r = hL/hR", ylabel="peak roll torque ratio τL/τR")
    ax.legend(fontsize=8)
    fig.savefig(args.out / "sweep_pivot_bias.png", dpi=150)

    ok = df.filter(pl.col("status") == "ok")
    worst = ok.select(((pl.col("roll_torque_ratio") / pl.col("static_prediction")) - 1).abs().max().alias("worst")).item()
    print(f"{ok.height}/{df.height} points ok; largest relative departure from 1/r: {worst:.3f}")
    print(f"wrote {args.out / 'sweep_pivot_bias.parquet'} and {args.out / 'sweep_pivot_bias.png'}")


if __name__ == "__main__":
    main()
