"""Resonance curve of the HMF: stroke amplitude vs drive frequency and voltage.

§4.4.5 notes Mobee's 30 Hz resonance against the HMF's ~100 Hz. The quadratic wing drag makes
the resonance softer and lower as the voltage (stroke amplitude) rises. The same study runs from
the shell with `paritysim sweep examples/sweep_resonance.toml --out results/`.

Run:  python examples/sweep_resonance.py --out results/
Writes results/sweep_resonance.parquet and results/sweep_resonance.png.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import polars as pl

from paritysim.sweep import plot, sweep
from paritysim.sweep_cli import load_study

EXAMPLES = Path(__file__).resolve().parent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="results", type=Path)
    parser.add_argument("--threads", type=int, default=None)
    args = parser.parse_args()

    study = load_study(EXAMPLES / "sweep_resonance.toml")  # device, grid, metrics, options
    df = sweep(study.spec, study.grid, metrics=study.metrics, options=study.options, threads=args.threads)
    args.out.mkdir(parents=True, exist_ok=True)
    df.write_parquet(args.out / "sweep_resonance.parquet")
    fig = plot(df, "actuator.frequency_hz", "left_stroke_amplitude", hue="actuator.voltage_v", path=args.out / "sweep_resonance.png")
    fig.axes[0].set_ylabel("stroke amplitude (rad)")
    fig.savefig(args.out / "sweep_resonance.png", dpi=150)

    peaks = (
        df.filter(pl.col("status") == "ok")
        .sort("left_stroke_amplitude", descending=True)
        .group_by("actuator.voltage_v", maintain_order=True)
        .first()
        .sort("actuator.voltage_v")
        .select("actuator.voltage_v", pl.col("actuator.frequency_hz").alias("peak_frequency_hz"), pl.col("left_stroke_amplitude").alias("peak_amplitude_rad"))
    )
    print(peaks)
    print(f"wrote {args.out / 'sweep_resonance.parquet'} and {args.out / 'sweep_resonance.png'}")


if __name__ == "__main__":
    main()
