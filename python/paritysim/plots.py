"""Figures styled like the thesis: labelled axes with units, legends, titles naming the figure."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt  # the backend stays the user's (the CLI picks Agg)
import numpy as np
import polars as pl
from matplotlib.figure import Figure

__all__ = ["fig2_9", "save", "simulation"]


def fig2_9(df: pl.DataFrame) -> Figure:
    """Three contour panels of theta_w over (phi, theta); unreachable poses left blank.

    ``df`` is the output of :func:`paritysim.trials.fig2_9`.
    """
    from .trials.section_2_3 import FIG2_9_BOX_DEG, FIG2_9_CONFIGS_DEG

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8), constrained_layout=True)
    levels = np.arange(-90, 91, 10)
    for ax, (a2, a3), label in zip(axes, FIG2_9_CONFIGS_DEG, "abc", strict=True):
        sub = df.filter((pl.col("alpha2_deg") == a2) & (pl.col("alpha3_deg") == a3))
        phi = np.unique(sub["phi_deg"].to_numpy())
        theta = np.unique(sub["theta_deg"].to_numpy())
        z = sub["theta_w_deg"].fill_null(np.nan).to_numpy().reshape(theta.size, phi.size)
        cs = ax.contourf(phi, theta, z, levels=levels, cmap="coolwarm", extend="both")
        ax.contour(phi, theta, z, levels=levels, colors="k", linewidths=0.4)
        if (a2, a3) == (90.0, 45.0):
            (p0, p1), (t0, t1) = FIG2_9_BOX_DEG["phi"], FIG2_9_BOX_DEG["theta"]
            ax.plot([p0, p1, p1, p0, p0], [t0, t0, t1, t1, t0], color="k", lw=2.0, label="walking box")
            ax.legend(loc="lower right")
        ax.set_title(f"({label}) $\\alpha_2$ = {a2:.0f}°, $\\alpha_3$ = {a3:.0f}°")
        ax.set_xlabel("input stroke $\\phi$ (deg)")
        ax.set_ylabel("input deviation $\\theta$ (deg)")
        ax.set_aspect("equal")
    fig.colorbar(cs, ax=axes, label="wing deviation $\\theta_w$ (deg)")
    fig.suptitle("Fig. 2.9: spherical shoulder transmission map (blank: beyond the joint limit, eq. 2.10)")
    return fig


def simulation(result: object) -> Figure:
    """Stroke, deviation and rotation angles and the body roll torques of a simulation."""
    df = result.trajectory  # type: ignore[attr-defined]
    t = df["time_ms"].to_numpy()
    prefixes = [p for p in ("left", "right", "wing") if f"{p}_phi" in df.columns]
    fig, (ax_a, ax_t) = plt.subplots(2, 1, figsize=(10, 7), sharex=True, constrained_layout=True)
    for p in prefixes:
        ax_a.plot(t, np.degrees(df[f"{p}_phi"].to_numpy()), label=f"{p} stroke $\\phi$")
        if np.ptp(df[f"{p}_psi"].to_numpy()) > 1e-9:
            ax_a.plot(t, np.degrees(df[f"{p}_psi"].to_numpy()), "--", label=f"{p} rotation $\\psi$")
        if np.ptp(df[f"{p}_theta"].to_numpy()) > 1e-9:
            ax_a.plot(t, np.degrees(df[f"{p}_theta"].to_numpy()), ":", label=f"{p} deviation $\\theta$")
        ax_t.plot(t, df[f"{p}_roll_aero"].to_numpy(), label=f"{p} roll, aerodynamic")
        ax_t.plot(t, df[f"{p}_roll_inertial"].to_numpy(), ":", label=f"{p} roll, inertial")
    ax_t.plot(t, df["roll_total"].to_numpy(), "k", lw=1.5, label="net body roll")
    ax_a.set_ylabel("angle (deg)")
    ax_t.set_ylabel("torque (mN·mm)")
    ax_t.set_xlabel("time (ms)")
    ax_a.legend(ncol=2, fontsize=8)
    ax_t.legend(ncol=2, fontsize=8)
    name = getattr(getattr(result, "spec", None), "name", "") or "simulation"
    fig.suptitle(f"{name}: wing angles and body torques over the recorded cycles")
    return fig


def save(fig: Figure, path: str | Path) -> Path:
    """Save a figure (PNG at 150 dpi) and close it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return path
