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


#: The (Ω^L/Ω^R, K2) plane: the asymmetric device's stable orbit ends at a fold (an imperfect
#: pitchfork), followed in the left wing's drag from this ratio.
FOLD_RATIO = 0.9
MAP_RATIOS = np.array([0.85, 0.9, 0.95, 0.99])
MAP_K2 = np.arange(300.0, 575.0, 25.0)
OMEGA_RIGHT = 31.3


def boundary_curve() -> tuple[pl.DataFrame, pl.DataFrame, dict[str, float]]:
    """The fold curve in (Ω^L/Ω^R, K2) by two-parameter continuation, the brute-force map and the
    timings (s)."""
    from .. import continuation
    from ..stability import floquet

    spec = drag_parity_spec(START, omega_left=OMEGA_RIGHT * FOLD_RATIO)
    t0 = time.perf_counter()
    branch = continuation(spec, PATH, start=START, stop=300.0, metrics=False, max_points=40)
    folds = branch.bifurcations.with_row_index("index").filter(pl.col("kind") == "fold")
    curves = []
    for stop in (OMEGA_RIGHT * 0.997, OMEGA_RIGHT * (MAP_RATIOS[0] - 0.01)):
        if folds.height:
            curves.append(branch.follow(int(folds["index"][0]), "wings[0].aero.omega1", stop=stop, start=OMEGA_RIGHT * FOLD_RATIO, max_step=1.0))
    t1 = time.perf_counter()
    curve = (
        pl.concat(curves).with_columns((pl.col("wings[0].aero.omega1") / OMEGA_RIGHT).alias("omega_ratio")).sort("omega_ratio")
        if curves
        else pl.DataFrame(schema={PATH: pl.Float64, "wings[0].aero.omega1": pl.Float64, "spectral_radius": pl.Float64, "stop_reason": pl.String, "omega_ratio": pl.Float64})
    )
    rows = []
    for ratio in MAP_RATIOS:
        for k2 in MAP_K2:
            try:
                f = floquet(drag_parity_spec(float(k2), omega_left=OMEGA_RIGHT * float(ratio)))
                state = "stable" if f.spectral_radius < 1.0 else "unstable"
            except Exception:  # noqa: BLE001 - no periodic orbit found: the whippletree runs away
                state = "no orbit"
            rows.append({"omega_ratio": float(ratio), "k2": float(k2), "state": state})
    t2 = time.perf_counter()
    return curve, pl.DataFrame(rows), {"curve_s": t1 - t0, "map_s": t2 - t1}


def map_agreement(curve: pl.DataFrame, grid: pl.DataFrame) -> tuple[int, int]:
    """Map points at least one grid step from the curve that fall on its predicted side
    (stable above the fold's K2, not stable below), and how many were checked."""
    if curve.height < 2:
        return 0, 0
    ratio, k2_fold = curve["omega_ratio"].to_numpy(), curve[PATH].to_numpy()
    step = float(MAP_K2[1] - MAP_K2[0])
    agree = checked = 0
    for row in grid.iter_rows(named=True):
        if not ratio.min() <= row["omega_ratio"] <= ratio.max():
            continue
        fold = float(np.interp(row["omega_ratio"], ratio, k2_fold))
        if abs(row["k2"] - fold) < step:
            continue
        checked += 1
        agree += (row["state"] == "stable") == (row["k2"] > fold)
    return agree, checked


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


def curve_claims(curve: pl.DataFrame, grid: pl.DataFrame, k_star: float) -> list[Claim]:
    agree, checked = map_agreement(curve, grid)
    near_one = curve.filter(pl.col("omega_ratio") == pl.col("omega_ratio").max())
    end = float(near_one[PATH][0]) if near_one.height else float("nan")
    return [
        Claim.holds(
            "the brute-force map falls on the predicted side of the continued fold curve",
            checked > 0 and agree == checked,
            computed=f"{agree} of {checked} map points (those at least one grid step from the curve)",
            criterion="all: stable above the fold's K2, no stable orbit of this branch below",
            thesis="(beyond the thesis)",
        ),
        Claim.near(
            "as Ω^L/Ω^R → 1 the fold meets the symmetric device's branch point (a cusp)",
            end,
            k_star,
            10.0,
            unit="mN·mm/rad",
            fmt=".5g",
            thesis_text=f"{k_star:.5g} mN·mm/rad (the branch point above)",
            note=f"fold at Ω^L/Ω^R = {float(near_one['omega_ratio'][0]) if near_one.height else float('nan'):.3f}",
        ),
    ]


def _curve_figure(curve: pl.DataFrame, grid: pl.DataFrame, k_star: float):  # type: ignore[no-untyped-def]
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(10, 4.5), constrained_layout=True)
    marks = {"stable": ("o", "C2", "brute force: stable orbit"), "unstable": ("x", "C3", "brute force: unstable orbit"), "no orbit": ("s", "0.5", "brute force: no orbit found")}
    for state, (marker, colour, label) in marks.items():
        sub = grid.filter(pl.col("state") == state)
        if sub.height:
            ax.plot(sub["omega_ratio"], sub["k2"], marker, color=colour, ls="none", mfc="none" if marker != "x" else colour, label=label)
    if curve.height:
        ax.plot(curve["omega_ratio"], curve[PATH], "-", color="C0", lw=2, label="fold curve (two-parameter continuation)")
    ax.plot([1.0], [k_star], "*", color="C0", ms=12, label=f"branch point of the symmetric device, K2 = {k_star:.4g}")
    ax.set_xlabel("Ω^L / Ω^R (left wing cut)")
    ax.set_ylabel("balance spring K2 (mN·mm/rad)")
    ax.set_title("§3.3 linkage: where the continued stable orbit ends")
    ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.01, 0.5))
    ax.grid(alpha=0.3)
    return fig


def _figure(branch: pl.DataFrame, bifurcations: pl.DataFrame, brute: pl.DataFrame):  # type: ignore[no-untyped-def]
    import matplotlib.pyplot as plt

    from ..continuation import _path_label

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
    ax.set_xlabel(_path_label(drag_parity_spec(START), PATH))
    ax.set_ylabel("largest Floquet multiplier |μ|")
    ax.set_title("§3.3 linkage: whippletree stability boundary by continuation")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def _cli(out: Path) -> list[Path]:
    from .. import plots

    branch, bifurcations, brute, timing = boundary()
    written = write_trial(branch.drop("multiplier_modulus", "multiplier_angle"), out, "continuation", _figure(branch, bifurcations, brute))
    bifurcations.write_csv(out / "continuation_bifurcations.csv")
    points = bifurcations.filter(pl.col("kind") == "branch_point")[PATH].to_list()
    k_star = points[0] if points else float("nan")
    curve, grid, curve_timing = boundary_curve()
    curve.write_csv(out / "continuation_fold_curve.csv")
    grid.write_csv(out / "continuation_map.csv")
    png = plots.save(_curve_figure(curve, grid, k_star), out / "continuation_fold_curve.png")
    found = claims(bifurcations, brute) + curve_claims(curve, grid, k_star)
    extra = [out / "continuation_bifurcations.csv", out / "continuation_fold_curve.csv", out / "continuation_map.csv", png]
    return [*written, *extra, write_claims(out, "continuation", found, {**timing, **curve_timing, "map_points": float(grid.height)})]


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
        "(one run; timings are of this machine). With the left wing cut (Ω^L/Ω^R < 1) the "
        "symmetry is broken and the continued stable orbit ends at a fold instead (an imperfect "
        "pitchfork); the fold is followed in Ω^L by two-parameter continuation "
        f"({values['curve_s']:.1f} s) and drawn over a brute-force map of {values['map_points']:.0f} "
        f"Floquet analyses ({values['map_s']:.1f} s).\n\n"
        + render(found)
        + "\n![continuation](continuation.png)\n\n![fold curve](continuation_fold_curve.png)\n"
    )
