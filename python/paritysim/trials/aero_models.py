"""Beyond the thesis (issue 32): what changes in §3.4 when the aerodynamics are today's
RoboBee-standard quasi-steady model.

The thesis' blade element (§3.2.4: translational coefficients and rotational damping, the
``blade_element`` aero with the Dickinson et al. 1999 fits) against Whitney & Wood 2010
(``whitney_wood2010``: the same terms plus rotational lift and translational and rotational
added mass, docs/concepts.md "Aero models"), both on the Table 3.3 wings with the same
coefficient fits, so the difference is the added terms:

1. **The §3.4 trials** (``section_3_4``: Table 3.3, Figs. 3.11-3.13) under each model, each
   with the hinge pinned as §3.4 prescribes (the Uncut PARITY right wing rotating ±60°), and
   each of §3.4's statements evaluated on each model's numbers.
2. **Hover trim** of the Uncut §3.4 device on the default airframe (``flight.trim``: drive
   amplitude and DC offset for lift = weight and zero pitch torque), HMF and Drag PARITY.

The Table 3.3 wings have no outline, so Ω5..Ω8 (the added terms' integrals) are those of the
HMF-like planform scaled to each wing's Ω3 (``section_3_4.whitney_wood_omegas``). No published
measurement of these wings exists to validate either model against; the verdicts are the §3.4
statements and physical expectations, computed for both.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import polars as pl

from ..claims import VERDICTS, Claim
from ._io import results, write_claims, write_trial

#: The two aero models compared: (label, ``section_3_4.Params.aero``).
MODELS = {"thesis (blade element)": "blade_element", "Whitney & Wood 2010": "whitney_wood2010"}
SHORT = {"blade_element": "thesis' model", "whitney_wood2010": "W&W 2010"}


@functools.lru_cache(maxsize=1)
def table() -> pl.DataFrame:
    """``section_3_4``'s table under each model (column ``aero``)."""
    from . import section_3_4 as s34

    return pl.concat([s34.section_3_4(aero=aero).with_columns(pl.lit(aero).alias("aero")) for aero in MODELS.values()])


@functools.lru_cache(maxsize=1)
def trims() -> pl.DataFrame:
    """Hover trim of the Uncut §3.4 HMF and Drag PARITY under each model: drive amplitude and
    DC offset (V), lift and weight (mN), the remaining yaw torque (mN·mm), convergence."""
    from .. import flight
    from . import section_3_4 as s34

    rows = []
    for aero in MODELS.values():
        p = s34.params(aero=aero)
        for drivetrain in s34.DRIVETRAINS:
            t = flight.trim(s34.device(p, drivetrain, "Uncut", hinge=s34.hinge_stiffness(p)), progress=False)
            rows.append(
                {
                    "aero": aero,
                    "drivetrain": drivetrain,
                    "amplitude_v": t.knobs["actuator.waveform.amplitude_v"],
                    "offset_v": t.knobs["actuator.waveform.offset_v"],
                    "lift_mn": t.lift_mn,
                    "weight_mn": t.weight_mn,
                    "yaw_residual": t.residuals["yaw"],
                    "converged": t.converged,
                }
            )
    return pl.DataFrame(rows)


def trajectories() -> pl.DataFrame:
    """``section_3_4.trajectories`` under each model (column ``aero``)."""
    from . import section_3_4 as s34

    return pl.concat([s34.trajectories(aero=aero).with_columns(pl.lit(aero).alias("aero")) for aero in MODELS.values()])


def per_model_claims(df: pl.DataFrame) -> dict[str, list[Claim]]:
    """§3.4's statements (``section_3_4_claims``) evaluated on each model's rows of ``df``."""
    from . import section_3_4 as s34

    return {aero: s34.section_3_4_claims(df.filter(pl.col("aero") == aero).drop("aero")) for aero in MODELS.values()}


def claims(df: pl.DataFrame, trim: pl.DataFrame) -> list[Claim]:
    """What holds under Whitney & Wood 2010: each §3.4 statement on its numbers (the thesis'
    model's verdict in the note), whether the conclusions that hold under the thesis' model
    still hold, and the hover trim."""
    by = per_model_claims(df)
    thesis, ww = by["blade_element"], by["whitney_wood2010"]
    out = []
    for old, new in zip(thesis, ww, strict=True):
        if new.ok is None:  # an input (the pinned rotation): no verdict under either model
            continue
        out.append(
            Claim(f"W&W 2010: {new.statement}", new.thesis, new.computed, new.criterion, new.ok, new.value,
                  note=f"thesis' model: {old.computed} ({old.verdict})")  # fmt: skip
        )
    held = [(o, n) for o, n in zip(thesis, ww, strict=True) if o.ok]
    kept = [o.statement for o, n in held if n.ok]
    lost = [o.statement for o, n in held if not n.ok]
    out.append(
        Claim.holds(
            "every §3.4 statement that holds under the thesis' model also holds under W&W 2010",
            not lost,
            computed=f"{len(kept)} of {len(held)} kept" + (f"; not kept: {'; '.join(lost)}" if lost else ""),
            criterion="each statement true under the thesis' model is true under W&W",
            thesis="(model comparison)",
        )
    )
    ww_rows = trim.filter(pl.col("aero") == "whitney_wood2010")
    amp = {(r["aero"], r["drivetrain"]): r["amplitude_v"] for r in trim.iter_rows(named=True)}
    out.append(
        Claim.holds(
            "the §3.4 device hovers under W&W 2010 (trim to lift = weight, zero pitch torque)",
            bool(ww_rows["converged"].all()),
            computed=", ".join(f"{r['drivetrain']}: {r['amplitude_v']:.1f} V, lift {r['lift_mn']:.4f} of {r['weight_mn']:.4f} mN" for r in ww_rows.iter_rows(named=True)),
            criterion="the trim converges for HMF and PARITY",
            thesis="(flight, beyond the thesis)",
        )
    )
    ratio = {d: amp[("whitney_wood2010", d)] / amp[("blade_element", d)] for d in ("HMF", "PARITY")}
    out.append(
        Claim.holds(
            "hover needs a larger drive under W&W 2010 (its added mass takes stroke amplitude at a given drive)",
            all(v > 1.0 for v in ratio.values()),
            computed=", ".join(f"{d}: {v:.3f}× the thesis' model's amplitude" for d, v in ratio.items()),
            criterion="trim amplitude ratio W&W / thesis > 1 for both drivetrains",
            thesis="(physical expectation)",
        )
    )
    return out


# ---------------------------------------------------------------- figures, CLI, report


def _fig_table(df: pl.DataFrame):  # type: ignore[no-untyped-def]
    import matplotlib.pyplot as plt

    from . import section_3_4 as s34

    trials = list(s34.TRIALS)
    x = np.arange(len(trials))
    width = 0.38
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2), constrained_layout=True)
    for k, (label, aero) in enumerate(MODELS.items()):
        par = df.filter((pl.col("aero") == aero) & (pl.col("drivetrain") == "PARITY"))
        shift = (k - 0.5) * width
        axes[0].bar(x + shift, par["right_stroke_p2p_deg"], width, color=f"C{2 * k}", label=f"{label}: right")
        axes[0].plot(x + shift, par["left_stroke_p2p_deg"], "o", color=f"C{2 * k + 1}", label=f"{label}: left")
        axes[1].bar(x + shift, par["right_rotation_amplitude_deg"], width, color=f"C{2 * k}", label=f"{label}: right")
        axes[1].plot(x + shift, par["left_rotation_amplitude_deg"], "o", color=f"C{2 * k + 1}", label=f"{label}: left")
        axes[2].bar(x + shift, 100 * par["yaw_mean_reduction_vs_hmf"], width, color=f"C{2 * k}", label=label)
    for ax, ylabel, title in (
        (axes[0], "stroke peak-to-peak (deg)", "PARITY strokes as the right wing is cut"),
        (axes[1], "rotation amplitude (deg)", "PARITY wing rotation ψ"),
        (axes[2], "mean yaw imbalance reduction vs HMF (%)", "average yaw imbalance, reduction by the PARITY"),
    ):
        ax.set_xticks(x, trials)
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.grid(alpha=0.3, axis="y")
        ax.legend(fontsize=7)
    fig.suptitle("Table 3.3 trials (§3.4) under the thesis' blade element and Whitney & Wood 2010")
    return fig


def _fig_trajectories(df: pl.DataFrame):  # type: ignore[no-untyped-def]
    """Figs. 3.11-3.13 for the 1-Cut trial, one row per model."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(15, 7.5), sharex=True, constrained_layout=True)
    for row, aero in enumerate(MODELS.values()):
        sub = df.filter((pl.col("aero") == aero) & (pl.col("trial") == "1-Cut"))
        for col, quantity in enumerate(("roll", "yaw")):
            ax = axes[row][col]
            for d, color in (("HMF", "C0"), ("PARITY", "C2")):
                s = sub.filter(pl.col("drivetrain") == d)
                ax.plot(s["time_ms"], (s[f"left_{quantity}"] + s[f"right_{quantity}"]).to_numpy(), color=color, label=f"{d}: net")
            ax.set_title(f"{SHORT[aero]}: net {quantity}, 1-Cut (Fig. 3.1{1 + col})", fontsize=10)
            ax.set_ylabel(f"{quantity} torque (mN·mm)")
            ax.legend(fontsize=7)
            ax.grid(alpha=0.3)
        ax = axes[row][2]
        s = sub.filter(pl.col("drivetrain") == "PARITY")
        for wing, color in (("left", "C0"), ("right", "C3")):
            ax.plot(s["time_ms"], s[f"{wing}_phi_deg"], color=color, label=f"{wing} stroke φ")
            ax.plot(s["time_ms"], s[f"{wing}_psi_deg"], "--", color=color, label=f"{wing} rotation ψ")
        ax.set_title(f"{SHORT[aero]}: PARITY angles, 1-Cut (Fig. 3.13)", fontsize=10)
        ax.set_ylabel("angle (deg)")
        ax.legend(fontsize=7, ncol=2)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time (ms)")
    return fig


def _cli(out: Path) -> list[Path]:
    df, trim = table(), trims()
    traj = trajectories()
    written = write_trial(df, out, "aero_whitney_wood2010", _fig_table(df))
    written += write_trial(traj, out, "aero_whitney_wood2010_1cut", _fig_trajectories(traj))
    written += [out / "aero_whitney_wood2010_trim.parquet", out / "aero_whitney_wood2010_trim.csv"]
    trim.write_parquet(written[-2])
    trim.write_csv(written[-1])
    by = per_model_claims(df)
    values = {
        "hinge_stiffness": {aero: float(df.filter(pl.col("aero") == aero)["hinge_stiffness"][0]) for aero in MODELS.values()},
        "thesis_model": [{"statement": c.statement, "computed": c.computed, "ok": c.ok} for c in by["blade_element"]],
        "whitney_wood": [{"statement": c.statement, "computed": c.computed, "ok": c.ok} for c in by["whitney_wood2010"]],
        "trims": trim.to_dicts(),
    }
    return [*written, write_claims(out, "aero.whitney_wood2010", claims(df, trim), values)]


CLI_TRIALS = {"aero.whitney_wood2010": _cli}


def report_section(out: Path) -> str:
    """Markdown: §3.4's statements under both models side by side, the trims, the verdicts."""
    from ..claims import render

    found, values = results(out, "aero.whitney_wood2010")
    rows = ["| §3.4 statement | thesis' blade element | Whitney & Wood 2010 |", "|---|---|---|"]
    for old, new in zip(values["thesis_model"], values["whitney_wood"], strict=True):
        rows.append(f"| {old['statement']} | {old['computed']} ({VERDICTS[old['ok']]}) | {new['computed']} ({VERDICTS[new['ok']]}) |")
    trim_rows = ["| aero | drivetrain | amplitude (V) | DC offset (V) | lift / weight (mN) | yaw torque left (mN·mm) |", "|---|---|---|---|---|---|"]
    for r in values["trims"]:
        trim_rows.append(
            f"| {r['aero']} | {r['drivetrain']} | {r['amplitude_v']:.2f} | {r['offset_v']:.3f} | {r['lift_mn']:.4f} / {r['weight_mn']:.4f} | {r['yaw_residual']:.3f} |"
        )
    k = values["hinge_stiffness"]
    lines = [
        "## Beyond the thesis: §3.4 under Whitney & Wood 2010 aerodynamics",
        "",
        "The §3.4 trials rerun with the RoboBee-standard quasi-steady model (rotational lift, translational and rotational "
        "added mass added to the thesis' terms; docs/concepts.md, Aero models), side by side with the thesis' model. Each "
        f"model pins its own hinge to the stated ±60° rotation: k = {k['blade_element']:.4f} (thesis' model) and "
        f"{k['whitney_wood2010']:.4f} mN·mm/rad (W&W). Ω5..Ω8 of the Table 3.3 wings: the HMF-like planform's, scaled to "
        "each wing's Ω3 (the thesis gives no outline). No published measurement of these wings exists to validate either.",
        "",
        *rows,
        "",
        "Hover trim of the Uncut device on the default 60 mg airframe:",
        "",
        *trim_rows,
        "",
        render(found),
        "",
        "![Table 3.3 under both models](aero_whitney_wood2010.png)",
        "",
        "![Figs. 3.11-3.13, 1-Cut, under both models](aero_whitney_wood2010_1cut.png)",
        "",
    ]
    return "\n".join(lines)
