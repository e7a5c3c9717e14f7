"""§2.5: Lift PARITY and Dual PARITY (configurations #5-#8 of Table 3.1), an exploration.

The thesis reports no numbers here and says the concept "has not yet reached a successful
conclusion" (§2.5.1), naming a lagging error signal and backdriving as the problems (§2.5.2).
paritysim runs the concept as specified: the §3.4 wings (Table 3.3) with deviation θ free on a
deviation spring, coupled between the wings by C (θL = θR), and the tunable hinge of §2.5.1,
``V = ½ (k0 + k2 θ²) ψ²`` (stiffer with deviation; the law is ours, exposed as parameters).
Baselines: #1 (HMF) and #3 (Drag PARITY) with θ fixed.
"""

from __future__ import annotations

import dataclasses
import importlib
import math
from pathlib import Path
from typing import Any

import numpy as np
import polars as pl

from .. import aero
from ..claims import Claim, render
from ..simulation import simulate
from ..spec import Configuration, Spring, Springs, TunableHinge, Wing
# The package exports the function `section_3_4` under the module's name: load the module itself.
s34 = importlib.import_module("paritysim.trials.section_3_4")

#: (configuration name, Table 3.1 number, wings rotate?)
CONFIGURATIONS = [
    ("hmf", 1, True),
    ("drag_parity", 3, True),
    ("lift_parity", 5, True),
    ("lift_parity_fixed", 6, False),
    ("dual_parity", 7, True),
    ("dual_parity_fixed", 8, False),
]


def _wing(key: str, hinge_k0: float, hinge_k2: float, deviation_stiffness: float) -> Wing:
    w = aero.TABLE_3_3[key]
    springs = Springs(deviation=Spring(stiffness=deviation_stiffness))  # joint 4 = θ
    blade = dataclasses.replace(s34._wing(key, hinge_k0, s34.params()).aero)  # type: ignore[arg-type]
    return Wing.from_moments(w["ixx"], w["iyy"], w["izz"], w["ixz"], springs=springs, aero=blade, tunable_hinge=TunableHinge(hinge_k0, 0.0, hinge_k2))


def device(config: str, trial: str, hinge_k2: float, deviation_stiffness: float = 10.0, **overrides: Any):  # type: ignore[no-untyped-def]
    """A §2.5 device: §3.4's drive and transmission with the §2.5 wings on ``config``."""
    p = s34.params(**overrides)
    k0 = s34.hinge_stiffness(p)
    base = s34.device(p, "PARITY", trial, hinge=k0)
    wings = (_wing("left", k0, hinge_k2, deviation_stiffness), _wing(s34.TRIALS[trial], k0, hinge_k2, deviation_stiffness))
    return base.replace(name=f"§2.5 {config} {trial}", wings=wings, configuration=Configuration(config))


def lift_dual_parity(hinge_k2: float = 20.0, deviation_stiffness: float = 10.0, max_cycles: int = 150, **overrides: Any) -> pl.DataFrame:
    """Yaw (lift-aligned) and roll imbalance for #1, #3 and #5-#8, each trial, without
    (k2 = 0) and with the tunable hinge."""
    rows = []
    for config, number, rotating in CONFIGURATIONS:
        for trial in s34.TRIALS:
            for k2 in (0.0, hinge_k2):
                if not rotating and k2 != 0.0:
                    continue  # ψ is fixed: the hinge has no effect
                spec = device(config, trial, k2, deviation_stiffness, **overrides)
                try:
                    r = simulate(spec, max_cycles=max_cycles)
                except Exception as exc:  # noqa: BLE001 - an exploration records failures as rows
                    rows.append(dict(configuration=config, number=number, rotating=rotating, trial=trial, hinge_k2=k2, status="error", error=str(exc)))
                    continue
                s = s34.summarize(r)
                theta = r.cycle["right_theta"].to_numpy()[:-1]
                rows.append(
                    dict(
                        configuration=config,
                        number=number,
                        rotating=rotating,
                        trial=trial,
                        hinge_k2=k2,
                        status="ok",
                        error="",
                        converged=r.converged,
                        cycles=r.cycles_run,
                        orbit_cycles=r.orbit_cycles,
                        yaw_mean=s["yaw_imbalance_mean"],
                        yaw_rms=s["yaw_imbalance_rms"],
                        roll_rms=s["roll_imbalance_rms"],
                        deviation_mean_deg=math.degrees(float(theta.mean())),
                    )
                )
    return pl.DataFrame(rows, infer_schema_length=None)


def deviation_settling(config: str = "lift_parity", trial: str = "1-Cut", hinge_k2: float = 20.0, cycles: int = 80, **overrides: Any) -> pl.DataFrame:
    """Cycle-mean deviation θ_R from rest over ``cycles`` cycles: the slow error signal of
    §2.5.2 (a lift imbalance is integrated twice into a deviation)."""
    spec = device(config, trial, hinge_k2, **overrides)
    r = simulate(spec, min_cycles=1, max_cycles=1, record_cycles=cycles, samples_per_cycle=40)
    t = r.trajectory["time_ms"].to_numpy()
    theta = r.trajectory["right_theta"].to_numpy()
    period = r.period_ms
    k = np.floor((t - t[0]) / period + 1e-9).astype(int)
    frame = pl.DataFrame({"cycle": k, "theta": theta}).filter(pl.col("cycle") < cycles)
    return frame.group_by("cycle").agg(pl.col("theta").mean().alias("theta_mean_rad")).sort("cycle").with_columns((pl.col("theta_mean_rad") * 180 / math.pi).alias("theta_mean_deg"))


def _plot(df: pl.DataFrame, settle: pl.DataFrame):  # type: ignore[no-untyped-def]
    import matplotlib.pyplot as plt

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(13, 4.5), constrained_layout=True)
    ok = df.filter((pl.col("status") == "ok") & (pl.col("trial") == "1-Cut"))
    # One bar per configuration and hinge k2; a k2 > 0 bar that changes nothing (θ fixed, so
    # the tunable hinge never stiffens; computed, not assumed) is dropped and the label says so.
    labels, values, colours = [], [], []
    for (config, number), g in ok.group_by("configuration", "number", maintain_order=True):
        base = g.filter(pl.col("hinge_k2") == 0.0)["yaw_mean"]
        for r in g.sort("hinge_k2").iter_rows(named=True):
            same = r["hinge_k2"] != 0.0 and len(base) and math.isclose(r["yaw_mean"], base[0], rel_tol=1e-9, abs_tol=1e-12)
            if same:
                labels[-1] += f"\n(= k2 {r['hinge_k2']:g}: no effect)"
                continue
            labels.append(f"#{number} {config}\nk2={r['hinge_k2']:g}")
            values.append(abs(r["yaw_mean"]))
            colours.append("C0" if r["hinge_k2"] == 0.0 else "C1")
    ax.bar(range(len(values)), values, color=colours)
    ax.set_xticks(range(len(values)), labels, rotation=60, fontsize=7)
    from matplotlib.patches import Patch

    ax.legend(handles=[Patch(color="C0", label="hinge k2 = 0"), Patch(color="C1", label="tunable hinge k2 > 0")], fontsize=7)
    ax.set_ylabel("|mean net yaw torque| (mN·mm)")
    ax.set_title("1-Cut: average yaw (lift-aligned) imbalance")
    ax2.plot(settle["cycle"], settle["theta_mean_deg"], "o-", ms=3)
    ax2.set_xlabel("wingbeat")
    ax2.set_ylabel("cycle-mean deviation θ_R (deg)")
    ax2.set_title("Lift PARITY, 1-Cut: the deviation error signal settles slowly (§2.5.2)")
    fig.suptitle("§2.5 Lift PARITY and Dual PARITY: an exploration")
    return fig


def settling_wingbeats(settle: pl.DataFrame, within: float = 0.05) -> int:
    """First wingbeat from which the cycle-mean deviation stays within ``within`` (relative) of
    its final value; -1 if it never settles in the window."""
    final = float(settle["theta_mean_deg"][-1])
    off = ((settle["theta_mean_deg"] - final).abs() > within * max(abs(final), 1e-9)).to_numpy()
    if off[-1]:
        return -1
    last_off = np.flatnonzero(off)
    return int(settle["cycle"][int(last_off[-1]) + 1]) if last_off.size else int(settle["cycle"][0])


def _cli(out: Path) -> list[Path]:
    from ._io import write_claims, write_trial

    df = lift_dual_parity()
    settle = deviation_settling()
    written = write_trial(df, out, "lift_dual", _plot(df, settle))
    settle.write_csv(out / "lift_dual_settling.csv")
    n = settling_wingbeats(settle)
    claim = Claim.holds(
        "§2.5.2: Lift PARITY's error signal lags (a lift imbalance is integrated twice into a deviation)",
        n < 0 or n > 1,
        computed=(f"cycle-mean θ_R (1-Cut) within 5 % of its final value after {n} wingbeats" if n >= 0 else f"not settled within {settle.height} wingbeats"),
        criterion="slower than Drag PARITY's whippletree (< 1 wingbeat, Fig. 3.4)",
    )
    return [*written, out / "lift_dual_settling.csv", write_claims(out, "lift-dual", [claim])]


CLI_TRIALS = {"lift-dual": _cli}


def report_section(out: Path) -> str:
    """Markdown: an account of the exploration (no thesis numbers exist), from the files the
    ``lift-dual`` trial wrote into ``out``."""
    from ._io import results

    claims, _ = results(out, "lift-dual")
    df = pl.read_csv(out / "lift_dual.csv", infer_schema_length=None)
    lines = [
        "## §2.5 Lift PARITY and Dual PARITY (configurations #5-#8): exploration",
        "",
        "No thesis numbers exist. The table lists the cycle-averaged net yaw torque (the lift-aligned imbalance) with and without "
        "the tunable hinge, against the HMF (#1) and Drag PARITY (#3) baselines. *Orbit* is the steady state's period in "
        "wingbeats: 2 where the orbit has period-doubled (the state repeats every second wingbeat; its values are over both).",
        "",
        "| # | configuration | trial | hinge k2 | converged | orbit | mean yaw | rms yaw | rms roll | mean θ_R (deg) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in df.iter_rows(named=True):
        if r["status"] != "ok":
            lines.append(f"| {r['number']} | {r['configuration']} | {r['trial']} | {r['hinge_k2']:g} | error: {str(r['error'])[:60]} | | | | | |")
            continue
        lines.append(
            f"| {r['number']} | {r['configuration']} | {r['trial']} | {r['hinge_k2']:g} | {r['converged']} | {r['orbit_cycles']} | {r['yaw_mean']:.3f} | {r['yaw_rms']:.3f} | {r['roll_rms']:.3f} | {r['deviation_mean_deg']:.1f} |"
        )
    lines += ["", render(claims), "", "![Lift and Dual PARITY](lift_dual.png)", ""]
    return "\n".join(lines)
