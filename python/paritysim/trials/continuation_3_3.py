"""Beyond the thesis: the §3.3 linkage's whippletree stability boundary by continuation.

docs/findings.md §3 found by brute force that the rod-crank Drag PARITY of §3.3 has an unstable
whippletree mode below a balance spring K2 ≈ 377 mN·mm/rad. Here the symmetric (Control)
periodic orbit is continued in K2 from 1000 down to 100 mN·mm/rad (`paritysim.continuation`):
the boundary is located where a real Floquet multiplier crosses +1 without the branch turning
(a symmetry-breaking branch point: the whippletree tilts one way or the other). It is checked
against a brute-force Floquet sweep on a 5 mN·mm/rad grid, and both costs are reported.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import polars as pl

from ..claims import Claim
from ._io import results, write_claims, write_trial
from .section_2_6 import drag_parity_spec

PATH = "drivetrain.balance_spring"
#: Continued from START down to STOP; the brute-force grid brackets the finding of findings.md.
START, STOP = 1000.0, 100.0
GRID = np.arange(300.0, 455.0, 5.0)


def boundary() -> tuple[pl.DataFrame, pl.DataFrame, pl.DataFrame, dict[str, float]]:
    """The continued branch, its bifurcations, the brute-force sweep and the timings (s)."""
    from .. import continuation
    from ..stability import k2_sweep

    spec = drag_parity_spec(START)
    t0 = time.perf_counter()
    result = continuation(spec, PATH, start=START, stop=STOP)
    t1 = time.perf_counter()
    brute = k2_sweep(spec, GRID)
    t2 = time.perf_counter()
    return result.branch, result.bifurcations, brute, {"continuation_s": t1 - t0, "brute_force_s": t2 - t1, "map_evaluations": float(result.map_evaluations)}


def claims(bifurcations: pl.DataFrame, brute: pl.DataFrame) -> list[Claim]:
    radius = brute["spectral_radius"].to_numpy()
    k2 = brute["k2"].to_numpy()
    crossing = np.flatnonzero((radius[:-1] > 1.0) & (radius[1:] < 1.0))
    points = bifurcations.filter(pl.col("kind") == "branch_point")[PATH].to_list()
    k_star = points[0] if points else float("nan")
    lo, hi = (float(k2[crossing[0]]), float(k2[crossing[0] + 1])) if crossing.size else (float("nan"), float("nan"))
    return [
        Claim.holds(
            "the symmetric orbit loses stability at a branch point (one real multiplier through +1), nothing else on [100, 1000]",
            list(bifurcations["kind"]) == ["branch_point"],
            computed=", ".join(f"{k} at {v:.4g}" for k, v in zip(bifurcations["kind"], bifurcations[PATH], strict=True)) or "none",
            criterion="exactly one bifurcation, a branch point",
            thesis="(not in the thesis: docs/findings.md §3)",
        ),
        Claim.between(
            "the located boundary lies in the brute-force grid cell where the spectral radius crosses 1",
            k_star,
            lo,
            hi,
            thesis="K2 ≈ 377 mN·mm/rad (docs/findings.md §3, by sweeping)",
            unit="mN·mm/rad",
            fmt=".6g",
        ),
    ]


def _figure(branch: pl.DataFrame, bifurcations: pl.DataFrame, brute: pl.DataFrame):  # type: ignore[no-untyped-def]
    import matplotlib.pyplot as plt

    from ..plots import label_with_unit

    fig, ax = plt.subplots(figsize=(7.5, 4.2), constrained_layout=True)
    stable = branch.filter(pl.col("stability") == "stable")
    unstable = branch.filter(pl.col("stability") != "stable")
    ax.plot(stable[PATH], stable["spectral_radius"], "-", color="C0", lw=2, label="continuation: stable orbit")
    ax.plot(unstable[PATH], unstable["spectral_radius"], "--", color="C0", lw=2, label="continuation: unstable orbit")
    ax.plot(brute["k2"], brute["spectral_radius"], "o", color="C1", ms=4, mfc="none", label=f"brute-force Floquet ({len(brute)} points)")
    for row in bifurcations.iter_rows(named=True):
        ax.axvline(row[PATH], color="C3", lw=0.8)
        ax.annotate(f"{row['kind']}: K2 = {row[PATH]:.5g}", (row[PATH], 1.0), textcoords="offset points", xytext=(6, 8), fontsize=8, color="C3")
    ax.axhline(1.0, color="k", lw=0.6)
    ax.set_xlabel(label_with_unit(PATH) if "(" in label_with_unit(PATH) else f"{PATH} (mN·mm/rad)")
    ax.set_ylabel("largest Floquet multiplier |μ|")
    ax.set_title("§3.3 linkage: whippletree stability boundary by continuation")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def _cli(out: Path) -> list[Path]:
    branch, bifurcations, brute, timing = boundary()
    written = write_trial(branch.drop("multiplier_modulus", "multiplier_angle"), out, "continuation_3_3", _figure(branch, bifurcations, brute))
    bifurcations.write_csv(out / "continuation_3_3_bifurcations.csv")
    return [*written, out / "continuation_3_3_bifurcations.csv", write_claims(out, "continuation", claims(bifurcations, brute), timing)]


CLI_TRIALS = {"continuation": _cli}


def report_section(out: Path) -> str:
    from ..claims import render

    found, values = results(out, "continuation")
    return (
        "## Beyond the thesis: stability boundary by continuation\n\n"
        "The §3.3 rod-crank Drag PARITY (Control, both wings Ω = 31.3) continued in the balance "
        "spring K2 from 1000 to 100 mN·mm/rad (`paritysim.continuation`, pseudo-arclength, "
        "Floquet multipliers from the variational equations), checked against brute-force "
        f"Floquet analysis on a {GRID[1] - GRID[0]:g} mN·mm/rad grid. Continuation took "
        f"{values['continuation_s']:.2f} s for the whole branch ({values['map_evaluations']:.0f} period-map "
        f"evaluations, metrics of every orbit included), the {GRID.size}-point grid {values['brute_force_s']:.2f} s "
        "(one run; timings are of this machine).\n\n"
        + render(found)
        + "\n![continuation](continuation_3_3.png)\n"
    )
