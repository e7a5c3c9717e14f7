"""Figures styled like the thesis: labelled axes with units, legends, titles naming the figure."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless by default; a user's interactive backend still works via pyplot
import matplotlib.pyplot as plt
import numpy as np
import polars as pl
from matplotlib.figure import Figure

__all__ = ["fig2_9", "save"]


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


def save(fig: Figure, path: str | Path) -> Path:
    """Save a figure (PNG at 150 dpi) and close it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return path
