"""§3.4 design study: mean yaw imbalance vs wing-hinge stiffness and right-membrane cut fraction.

The rotating-wing Drag PARITY device of §3.4 (Table 3.3 wings, ``sreetharan2012_3_4_parity``)
against the HMF baseline (``sreetharan2012_3_4_hmf``). The right membrane is cut at the tip
(``Planform.cut``) on a stand-in outline (``Planform.hmf_like``); the measured Uncut Ω1..Ω4 of
Table 3.3 are scaled by the exact cut/uncut ratio of the stand-in's integrals. The docs
tutorial "§3.4 design study" walks through the same steps.

Run:  python examples/design_study_3_4.py --out results/
Writes results/design_study_3_4.parquet and results/design_study_3_4.png.
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

HINGE = "wings[*].springs.hinge.stiffness"  # the ψ hinge of both wings


def grid(cut_fractions: list[float], hinges: list[float], right: ps.Aero) -> pl.DataFrame:
    """Rows of (cut_fraction label, hinge stiffness, right-wing Ω1..Ω4)."""
    outline = ps.Planform.hmf_like()
    uncut = outline.omegas()
    rows = []
    for f in cut_fractions:
        cut = outline.cut(f, where="tip").omegas()
        omegas = {f"wings.right.aero.omega{k}": getattr(right, f"omega{k}") * cut[f"omega{k}"] / uncut[f"omega{k}"] for k in range(1, 5)}
        rows += [{"cut_fraction": f, HINGE: k, **omegas} for k in hinges]
    return pl.DataFrame(rows)


def study(spec: ps.Simulation, points: pl.DataFrame, drivetrain: str) -> pl.DataFrame:
    df = ps.sweep(spec, points, labels=["cut_fraction"], keep_cycle=["yaw_total"], metrics=["right_rotation_amplitude"], progress=False)
    one_period = pl.col("cycle_yaw_total").list.head(pl.col("cycle_yaw_total").list.len() - 1)
    return df.with_columns(yaw_mean=one_period.list.mean(), drivetrain=pl.lit(drivetrain)).drop("cycle_time_ms", "cycle_yaw_total")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="results", help="output directory")
    parser.add_argument("--cuts", type=int, default=11, help="cut fractions from 0 to 0.3")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    parity, hmf = ps.devices.load("sreetharan2012_3_4_parity"), ps.devices.load("sreetharan2012_3_4_hmf")
    points = grid(np.round(np.linspace(0.0, 0.3, args.cuts), 4).tolist(), [1.5, 2.0, 2.5, 3.0, 4.0], parity.wings[1].aero)  # type: ignore[arg-type]
    df = pl.concat([study(parity, points, "PARITY"), study(hmf, points, "HMF")])
    df.write_parquet(out / "design_study_3_4.parquet")

    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True, layout="constrained")
    for ax, drivetrain in zip(axes, ("PARITY", "HMF"), strict=True):
        for (k,), g in df.filter(pl.col("drivetrain") == drivetrain).group_by(HINGE, maintain_order=True):
            ax.plot(g["cut_fraction"], g["yaw_mean"], marker="o", ms=3, label=f"hinge {k:g} mN·mm/rad")
        ax.set_title(f"§3.4 {drivetrain}: mean yaw imbalance")
        ax.set_xlabel("right membrane cut (fraction of span)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("mean net yaw torque (mN·mm)")
    axes[1].legend(fontsize=7)
    fig.savefig(out / "design_study_3_4.png", dpi=150)
    failed = int((df["status"] == "error").sum())
    print(f"{df.height} points ({failed} failed) -> {out / 'design_study_3_4.parquet'}, {out / 'design_study_3_4.png'}")


if __name__ == "__main__":
    main()
