"""§2.3.3: the spherical shoulder's transmission map (Fig. 2.9)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import polars as pl

from ..claims import Claim, render
from ..kinematics import shoulder_map

#: The three (alpha2, alpha3) configurations of Fig. 2.9, in degrees.
FIG2_9_CONFIGS_DEG: tuple[tuple[float, float], ...] = ((90.0, 0.0), (90.0, 45.0), (120.0, 60.0))

#: The walking-trajectory box of §2.3.3 for the (90°, 45°) shoulder: phi_w in ±60°, theta_w in [0°, 45°].
FIG2_9_BOX_DEG = {"phi": (-60.0, 60.0), "theta": (0.0, 45.0)}


def fig2_9(step_deg: float = 1.0, limit_deg: float = 90.0) -> pl.DataFrame:
    """Fig. 2.9: the wing deviation theta_w over (phi, theta) for the three shoulders.

    Parameters
    ----------
    step_deg:
        Grid spacing in degrees (> 0).
    limit_deg:
        The grid spans ``[-limit_deg, limit_deg]`` in phi and theta (in (0, 90]).

    Returns
    -------
    DataFrame with columns ``alpha2_deg, alpha3_deg, phi_deg, theta_deg, theta_w_deg,
    reachable``; ``theta_w_deg`` is null where the pose is outside the joint limit.
    """
    from .._errors import invalid, real

    step_deg, limit_deg = real("step_deg", step_deg), real("limit_deg", limit_deg)
    if not (np.isfinite(step_deg) and step_deg > 0):
        raise invalid("step_deg", step_deg, "finite and > 0")
    if not (np.isfinite(limit_deg) and 0 < limit_deg <= 90):
        raise invalid("limit_deg", limit_deg, "in (0, 90]")
    # Whole steps from -limit within the span (a step that does not divide it stops short),
    # and the limit itself within a step's rounding: arange overshot to 92 deg at step 7.
    count = int(np.floor(2.0 * limit_deg / step_deg + 1e-9))
    axis = np.clip(-limit_deg + step_deg * np.arange(count + 1), -limit_deg, limit_deg)
    phi_deg, theta_deg = np.meshgrid(axis, axis, indexing="xy")
    frames = []
    for a2, a3 in FIG2_9_CONFIGS_DEG:
        out = shoulder_map(np.radians(a2), np.radians(a3), np.radians(phi_deg), np.radians(theta_deg))
        n = phi_deg.size
        frames.append(
            pl.DataFrame(
                {
                    "alpha2_deg": np.full(n, a2),
                    "alpha3_deg": np.full(n, a3),
                    "phi_deg": phi_deg.ravel(),
                    "theta_deg": theta_deg.ravel(),
                    "theta_w_deg": np.degrees(out["theta_w"].ravel()),
                    "reachable": out["reachable"].ravel(),
                }
            ).with_columns(pl.col("theta_w_deg").fill_nan(None))
        )
    return pl.concat(frames)


def fig2_9_claims(df: pl.DataFrame) -> list[Claim]:
    """The §2.3.3 statements about Fig. 2.9, evaluated on the computed maps ``df`` (1° grid)."""
    box = df.filter((pl.col("alpha2_deg") == 90.0) & (pl.col("alpha3_deg") == 45.0) & (pl.col("phi_deg").abs() <= 60.0))
    edges = box.filter(pl.col("theta_deg").is_in([0.0, 45.0]))
    edge_error = float((edges["theta_w_deg"] - edges["theta_deg"]).abs().max())
    a = df.filter((pl.col("alpha2_deg") == 90.0) & (pl.col("alpha3_deg") == 0.0) & pl.col("reachable"))
    # ∂θ_w/∂θ by central differences along θ on the grid (rows of constant φ)
    grid = a.filter((pl.col("phi_deg").abs() <= 30.0) & (pl.col("theta_deg").abs() <= 31.0)).sort("phi_deg", "theta_deg")
    slope_error = 0.0
    for _, rows in grid.group_by("phi_deg"):
        th, tw = rows["theta_deg"].to_numpy(), rows["theta_w_deg"].to_numpy()
        inner = np.abs(th) <= 30.0
        slope_error = max(slope_error, float(np.abs(np.gradient(tw, th)[inner] - 1.0).max()))
    phi, theta = np.radians(a["phi_deg"].to_numpy()), np.radians(a["theta_deg"].to_numpy())
    closed = np.degrees(np.arctan(np.cos(phi) * np.tan(theta)))
    closed_error = float(np.abs(a["theta_w_deg"].to_numpy() - closed).max())
    return [
        Claim.near("(90°, 45°): on the box edges θ ∈ {0°, 45°}, |φ| ≤ 60° the shoulder is perfectly decoupled (θ_w = θ)", edge_error, 0.0, 1e-9, unit="°", fmt=".1e", thesis_text="exact (residual 0)"),
        Claim.holds(
            "(90°, 0°): ∂θ_w/∂θ ≈ 1 over a wide range (Fig. 2.9a)",
            slope_error <= 0.15,
            computed=f"max |∂θ_w/∂θ − 1| = {slope_error:.3f} for |φ|, |θ| ≤ 30°",
            criterion="≤ 0.15 for |φ|, |θ| ≤ 30°",
            note="∂θ_w/∂θ = cos φ at θ = 0: the range ends near |φ| = 30° (docs/errata.md#6)",
        ),
        Claim.near("(90°, 0°): tan θ_w = cos φ tan θ exactly (docs/errata.md#6)", closed_error, 0.0, 1e-9, unit="°", fmt=".1e", thesis_text="exact (residual 0)", note="eqs. 2.11-2.14 as printed"),
    ]


def _cli_fig2_9(out: Path) -> list[Path]:
    from .. import plots
    from ._io import write_claims, write_trial

    df = fig2_9()
    written = write_trial(df, out, "fig2_9", plots.fig2_9(df, FIG2_9_BOX_DEG))
    return [*written, write_claims(out, "fig2.9", fig2_9_claims(df))]


CLI_TRIALS = {"fig2.9": _cli_fig2_9}


def report_section(out: Path) -> str:
    """Markdown for the report: the Fig. 2.9 claims of §2.3.3 as computed by the trial."""
    from ._io import results

    claims, _ = results(out, "fig2.9")
    return "\n".join(["## §2.3.3 Spherical shoulder (Fig. 2.9)", "", render(claims), "", "![Fig. 2.9](fig2_9.png)", ""])
