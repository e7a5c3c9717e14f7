"""§3.4: Drag PARITY with rotating wings (Table 3.3, Figs. 3.11-3.13).

Wings of Table 3.3 (full inertia tensors, Ω1..Ω4) on compliant hinges (ψ free), configuration
#3 (Drag PARITY) against #1 (HMF), drive V(t) = 100 V + 100 V sin(2π·110 t) (eq. 3.24).

Not given by the thesis (docs/errata.md#5, #14), each an argument:

* ``hinge_stiffness`` (mN·mm/rad): ``None`` pins it so the Uncut PARITY right wing rotates ±60°,
  the amplitude §3.4 reports (root finding on the model);
* ``dc_offset = "ignore"``: the 100 V DC part biases the piezo without a net force (taken as a
  force it would hold q1 at 120/467 mm, a 45° stroke offset under the §3.3 transmission);
* transmission: eq. 2.15 with "±200 µm → ±35°" as in §3.3; C_rd and the coefficient model:
  the aero crate's cited defaults; the α sign convention: the aero crate's (docs/errata.md#5).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import polars as pl

from .. import aero
from ..claims import Claim, render
from ._io import write_claims, write_trial
from ..simulation import SimulationResult, simulate
from ..spec import Actuator, Aero, Configuration, Drivetrain, Options, Simulation, Spring, Springs, Waveform, Wing

#: Right-wing key of Table 3.3 per trial (the left wing is the same in all trials).
TRIALS = {"Uncut": "right_uncut", "1-Cut": "right_1cut", "2-Cut": "right_2cut"}
DRIVETRAINS = {"HMF": "hmf", "PARITY": "drag_parity"}


#: The §3.3.1 actuator constants, as defined once by the Rust spec's defaults.
_THESIS_ACTUATOR = Actuator()


@dataclass(frozen=True)
class Params:
    """The §3.4 study (mg-mm-ms-rad-V)."""

    hinge_stiffness: float | None = None  # None: pinned to ±60° rotation (Uncut, PARITY)
    target_rotation_deg: float = 60.0
    stroke_deg_per_200um: float = 35.0
    arm_mm: float = 2.5
    balance_stiffness: float = 0.0
    amplitude_v: float = 100.0
    offset_v: float = 100.0
    frequency_hz: float = 110.0
    dc_offset: str = "ignore"
    force_per_volt: float = _THESIS_ACTUATOR.force_per_volt  # from the Rust spec
    actuator_stiffness: float = _THESIS_ACTUATOR.stiffness  # from the Rust spec
    model: str = "dickinson1999"
    aero: str = "blade_element"  # or "whitney_wood2010" (trials.aero_models)
    max_cycles: int = 200
    samples_per_cycle: int = 200

    @property
    def transmission_ratio(self) -> float:
        """T of eq. 2.15 (rad/mm)."""
        return math.radians(self.stroke_deg_per_200um) / 0.2


def whitney_wood_omegas(omega3: float) -> dict[str, float]:
    """Ω5..Ω8 (mg·mm²) for a Table 3.3 wing of ``omega3``: the thesis gives no outline, so
    those of the HMF-like planform, scaled by ``omega3`` over its own (all are ½ρ × mm⁵
    integrals of one shape, so this is the planform scaled uniformly to the wing's Ω3)."""
    from ..planform import Planform

    from .._errors import invalid, real

    w3 = real("omega3", omega3)
    if not (math.isfinite(w3) and w3 > 0):
        raise invalid("omega3", omega3, "finite and > 0 (mg·mm²)")
    shape = Planform.hmf_like()
    scale = w3 / shape.omegas()["omega3"]
    return {k: scale * v for k, v in shape.quasi_steady_omegas().items()}


def _wing(key: str, hinge: float, p: Params) -> Wing:
    w = aero.TABLE_3_3[key]
    springs = Springs(hinge=Spring(stiffness=hinge))  # joint 6 = ψ hinge
    omegas = {k: w[k] for k in ("omega1", "omega2", "omega3", "omega4")}
    if p.aero == "whitney_wood2010":
        law = Aero(kind="whitney_wood2010", **omegas, **whitney_wood_omegas(w["omega3"]), model=p.model)
    else:
        law = Aero(kind="blade_element", **omegas, model=p.model)
    return Wing.from_moments(w["ixx"], w["iyy"], w["izz"], w["ixz"], springs=springs, aero=law)


def device(p: Params, drivetrain: str, trial: str, hinge: float | None = None) -> Simulation:
    """The §3.4 device for ``drivetrain`` in ("HMF", "PARITY") and ``trial`` in TRIALS."""
    from .._errors import invalid, suggest

    for name, value, allowed in (("drivetrain", drivetrain, DRIVETRAINS), ("trial", trial, TRIALS)):
        if value not in allowed:
            raise invalid(name, repr(value), suggest(str(value), list(allowed), what=f"a {name} of §3.4"))
    k = hinge if hinge is not None else hinge_stiffness(p)
    return Simulation(
        name=f"§3.4 {drivetrain} {trial}",
        wings=(_wing("left", k, p), _wing(TRIALS[trial], k, p)),
        configuration=Configuration(DRIVETRAINS[drivetrain]),
        drivetrain=Drivetrain.linear_differential(p.transmission_ratio, p.arm_mm, balance_spring=p.balance_stiffness),
        actuator=Actuator(Waveform(amplitude_v=p.amplitude_v, offset_v=p.offset_v, frequency_hz=p.frequency_hz), p.force_per_volt, p.actuator_stiffness, p.dc_offset),
        options=Options(max_cycles=p.max_cycles, samples_per_cycle=p.samples_per_cycle),
    )


@functools.lru_cache(maxsize=32)
def hinge_stiffness(p: Params) -> float:
    """The hinge stiffness: as given, or pinned so the Uncut PARITY right wing rotates
    ``target_rotation_deg`` (bisection on the model's rotation amplitude, which falls as the
    hinge stiffens)."""
    if p.hinge_stiffness is not None:
        return p.hinge_stiffness
    from scipy.optimize import brentq

    def excess(k: float) -> float:
        r = simulate(device(p, "PARITY", "Uncut", hinge=k))
        return math.degrees(r.metrics["right_rotation_amplitude"]) - p.target_rotation_deg

    # The rotation falls as the hinge stiffens: widen the bracket (×2 each way, a few times)
    # until it holds the target, else name the target with the rotations it spans.
    low, high = 1.5, 6.0
    f_low, f_high = excess(low), excess(high)
    for _ in range(4):
        if f_low >= 0.0 >= f_high:
            return float(brentq(excess, low, high, xtol=1e-4))
        if f_low < 0.0:
            low /= 2.0
            f_low = excess(low)
        if f_high > 0.0:
            high *= 2.0
            f_high = excess(high)
    if f_low >= 0.0 >= f_high:
        return float(brentq(excess, low, high, xtol=1e-4))
    from .._errors import invalid

    span = (p.target_rotation_deg + f_high, p.target_rotation_deg + f_low)
    raise invalid("target_rotation_deg", p.target_rotation_deg, f"a rotation amplitude hinge stiffnesses {low:g}..{high:g} mN·mm/rad reach at these settings: {span[0]:.4g}..{span[1]:.4g} deg")


def params(**overrides: Any) -> Params:
    """:class:`Params` with overrides (unknown names raise ``InvalidParameterError``)."""
    names = {f.name for f in dataclasses.fields(Params)}
    unknown = sorted(set(overrides) - names)
    if unknown:
        from .._errors import invalid, suggest

        raise invalid(unknown[0], overrides[unknown[0]], suggest(unknown[0], sorted(names), what="a parameter of this trial"))
    from .._errors import invalid, suggest
    from ..aero import MODELS
    from ..spec import schema

    # The choices (a typo fell back to the blade element without a word); the model and the
    # DC law as the core lists them, the aero laws this trial builds.
    dc_laws = [v["const"] for v in schema()["$defs"]["DcOffset"]["oneOf"]]
    for name, allowed in (("aero", ("blade_element", "whitney_wood2010")), ("model", MODELS), ("dc_offset", dc_laws)):
        if name in overrides and overrides[name] not in allowed:
            raise invalid(name, repr(overrides[name]), suggest(str(overrides[name]), list(allowed), what=f"a value of {name}"))
    return Params(**overrides)


def _angle_of_attack(cycle: pl.DataFrame, wing: str) -> tuple[float, float]:
    """α (deg) at mid-stroke (max |φ̇|) and at stroke reversal (φ̇ changes sign), averaged over
    both half-strokes, with the aero crate's convention α = 90° + ψ sgn(φ̇)."""
    psi = cycle[f"{wing}_psi"].to_numpy()
    rate = cycle[f"{wing}_phi_dot"].to_numpy()
    alpha = 90.0 + np.degrees(psi) * np.sign(rate)
    mid = [int(np.argmax(rate)), int(np.argmin(rate))]
    flips = np.flatnonzero(np.sign(rate[:-1]) != np.sign(rate[1:]))
    reversal = float(np.mean(90.0 - np.abs(np.degrees(psi[flips])))) if len(flips) else float("nan")
    return float(np.mean(alpha[mid])), reversal


def summarize(result: SimulationResult) -> dict[str, float | None]:
    """The §3.4 quantities of one run (angles in degrees, torques in mN·mm)."""
    if not isinstance(result, SimulationResult):
        from .._errors import invalid

        raise invalid("result", type(result).__name__, "a paritysim.SimulationResult (ps.simulate(device(...)))")
    m, cycle = result.metrics, result.cycle
    out: dict[str, float | None] = {}
    for wing in ("left", "right"):
        out[f"{wing}_stroke_p2p_deg"] = math.degrees(m[f"{wing}_stroke_peak_to_peak"])
        out[f"{wing}_stroke_mean_deg"] = math.degrees(m[f"{wing}_stroke_mean"])
        out[f"{wing}_rotation_amplitude_deg"] = math.degrees(m[f"{wing}_rotation_amplitude"])
        lag = m[f"{wing}_rotation_phase_lag"]  # None when the wing does not rotate
        out[f"{wing}_rotation_lag_deg"] = None if lag is None else math.degrees(lag)
        mid, rev = _angle_of_attack(cycle, wing)
        out[f"{wing}_alpha_midstroke_deg"] = mid
        out[f"{wing}_alpha_reversal_deg"] = rev
    body = cycle[:-1]  # one period (the last sample closes it)
    for axis in ("roll", "yaw"):
        v = body[f"{axis}_total"].to_numpy()
        out[f"{axis}_imbalance_mean"] = float(v.mean())
        out[f"{axis}_imbalance_rms"] = float(np.sqrt(np.mean(v**2)))
        out[f"{axis}_imbalance_peak"] = float(np.abs(v).max())
    return out


def section_3_4(**overrides: Any) -> pl.DataFrame:
    """One row per (trial, drivetrain) with :func:`summarize`'s columns, the hinge stiffness used,
    and (PARITY rows) the reduction of the average yaw imbalance against HMF."""
    p = params(**overrides)
    k = hinge_stiffness(p)
    rows = []
    for trial in TRIALS:
        by = {d: summarize(simulate(device(p, d, trial, hinge=k))) for d in DRIVETRAINS}
        for d, s in by.items():
            reduction = 1.0 - abs(s["yaw_imbalance_mean"]) / abs(by["HMF"]["yaw_imbalance_mean"]) if d == "PARITY" else float("nan")
            rows.append(dict(trial=trial, drivetrain=d, hinge_stiffness=k, **s, yaw_mean_reduction_vs_hmf=reduction))
    return pl.DataFrame(rows)


def trajectories(cycles: int = 3, **overrides: Any) -> pl.DataFrame:
    """Long-format trajectories over ``cycles`` steady cycles for every trial and drivetrain
    (computed once per parameter set: Figs. 3.11-3.13 share them)."""
    return _trajectories(params(**overrides), cycles)


@functools.lru_cache(maxsize=4)
def _trajectories(p: Params, cycles: int) -> pl.DataFrame:
    k = hinge_stiffness(p)
    frames = []
    for trial in TRIALS:
        for d in DRIVETRAINS:
            df = simulate(device(p, d, trial, hinge=k), record_cycles=cycles).trajectory
            t = df["time_ms"].to_numpy()
            frames.append(
                pl.DataFrame(
                    {
                        "trial": trial,
                        "drivetrain": d,
                        "time_ms": t - t[0],
                        "left_phi_deg": np.degrees(df["left_phi"].to_numpy()),
                        "right_phi_deg": np.degrees(df["right_phi"].to_numpy()),
                        "left_psi_deg": np.degrees(df["left_psi"].to_numpy()),
                        "right_psi_deg": np.degrees(df["right_psi"].to_numpy()),
                        "left_roll": (df["left_roll_aero"] + df["left_roll_inertial"]).to_numpy(),
                        "right_roll": (df["right_roll_aero"] + df["right_roll_inertial"]).to_numpy(),
                        "left_yaw": (df["left_yaw_aero"] + df["left_yaw_inertial"]).to_numpy(),
                        "right_yaw": (df["right_yaw_aero"] + df["right_yaw_inertial"]).to_numpy(),
                    }
                )
            )
    return pl.concat(frames)


# ---------------------------------------------------------------- figures, CLI, report


def _fig(df: pl.DataFrame, quantity: str, trials: tuple[str, ...], title: str, ylabel: str):  # type: ignore[no-untyped-def]
    import matplotlib.pyplot as plt

    from ..plots import pair

    fig, axes = plt.subplots(1, len(trials), figsize=(5 * len(trials), 4.6), sharey=True, constrained_layout=True, squeeze=False)
    for ax, trial in zip(axes[0], trials, strict=True):
        for d, colors in (("HMF", ("C0", "C1")), ("PARITY", ("C2", "C3"))):
            sub = df.filter((pl.col("trial") == trial) & (pl.col("drivetrain") == d))
            pair(ax, sub["time_ms"], -sub[f"left_{quantity}"].to_numpy(), sub[f"right_{quantity}"].to_numpy(), (f"{d} left (−)", f"{d} right"), colors)
        ax.set_xlabel("time (ms)")
        if len(trials) > 1:  # each panel's legend says which of its curves coincide
            ax.set_title(trial)
            ax.legend(fontsize=7)
    axes[0][0].set_ylabel(ylabel)
    if len(trials) == 1:  # the title names the trial; the legend goes below, over no peak
        handles, names = axes[0][0].get_legend_handles_labels()
        fig.legend(handles, names, loc="outside lower center", ncol=4, fontsize=7)
    fig.suptitle(title)
    return fig


def _fig3_13(df: pl.DataFrame):  # type: ignore[no-untyped-def]
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(15, 7), sharex=True, sharey=True, constrained_layout=True)
    for col, trial in enumerate(TRIALS):
        sub = df.filter((pl.col("trial") == trial) & (pl.col("drivetrain") == "PARITY"))
        for row, wing in enumerate(("left", "right")):
            ax = axes[row][col]
            ax.plot(sub["time_ms"], sub[f"{wing}_phi_deg"], label="stroke φ")
            ax.plot(sub["time_ms"], sub[f"{wing}_psi_deg"], "--", label="rotation ψ")
            ax.set_title(f"{trial}: {wing} wing")
            if row == 1:
                ax.set_xlabel("time (ms)")
            if col == 0:
                ax.set_ylabel("angle (deg)")
            ax.legend(fontsize=7)
    fig.suptitle("Fig. 3.13: theoretical wing trajectories with Drag PARITY")
    return fig


def section_3_4_claims(df: pl.DataFrame) -> list[Claim]:
    """Each §3.4 statement, evaluated on :func:`section_3_4`'s table ``df``."""
    par = {r["trial"]: r for r in df.filter(pl.col("drivetrain") == "PARITY").iter_rows(named=True)}
    hmf = {r["trial"]: r for r in df.filter(pl.col("drivetrain") == "HMF").iter_rows(named=True)}
    u = par["Uncut"]
    rs = [par[t]["right_stroke_p2p_deg"] for t in TRIALS]
    ls = [par[t]["left_stroke_p2p_deg"] for t in TRIALS]
    rot = [par[t]["right_rotation_amplitude_deg"] for t in TRIALS]
    roll_ratio = [par[t]["roll_imbalance_rms"] / hmf[t]["roll_imbalance_rms"] for t in TRIALS]
    arrow = lambda v: " → ".join(f"{x:.1f}°" for x in v)  # noqa: E731
    reduction = {t: 100 * par[t]["yaw_mean_reduction_vs_hmf"] for t in ("1-Cut", "2-Cut")}
    return [
        Claim.between("stroke ≈ 100° peak-to-peak (Uncut, right wing)", u["right_stroke_p2p_deg"], 70.0, 130.0, thesis="≈ 100°", unit="°", fmt=".1f",
                      note=f"left wing {u['left_stroke_p2p_deg']:.1f}°"),
        Claim.given("rotation ±60°", computed=f"{u['right_rotation_amplitude_deg']:.1f}°", thesis="±60°", note="pins the hinge stiffness (docs/errata.md#14)"),
        Claim.between("rotation lags stroke by ~90°", u["right_rotation_lag_deg"], 60.0, 120.0, thesis="~90°", unit="°", fmt=".1f",
                      note=f"left wing {u['left_rotation_lag_deg']:.1f}°"),
        Claim.near("α ≈ 90° at stroke reversal", u["right_alpha_reversal_deg"], 90.0, 20.0, unit="°", fmt=".1f", note="α convention: docs/errata.md#5"),
        Claim.near("α ≈ 30° mid-stroke", u["right_alpha_midstroke_deg"], 30.0, 15.0, unit="°", fmt=".1f"),
        Claim.holds("right stroke grows as the membrane is cut", rs[0] < rs[1] < rs[2], computed=arrow(rs), criterion="strictly increasing Uncut → 2-Cut"),
        Claim.holds("left stroke shrinks as the membrane is cut", ls[0] > ls[1] > ls[2], computed=arrow(ls), criterion="strictly decreasing Uncut → 2-Cut"),
        Claim.holds("rotation amplitudes decrease as the membrane is cut", rot[0] > rot[1] > rot[2], computed=arrow(rot), criterion="strictly decreasing Uncut → 2-Cut"),
        Claim.holds("PARITY balances roll torques (Fig. 3.11)", all(v < 0.5 for v in roll_ratio[1:]),
                    computed=", ".join(f"{t}: {v:.3f}" for t, v in zip(TRIALS, roll_ratio, strict=True)), criterion="rms net roll PARITY/HMF < 0.5 for the cut wings"),
        Claim.near("average yaw imbalance reduced 71 % (1-Cut)", reduction["1-Cut"], 71.0, 15.0, unit="%", fmt=".0f"),
        Claim.near("average yaw imbalance reduced 72 % (2-Cut)", reduction["2-Cut"], 72.0, 15.0, unit="%", fmt=".0f"),
        Claim.holds("... and not reduced in the Uncut trial", par["Uncut"]["yaw_mean_reduction_vs_hmf"] < 0.3,
                    computed=f"{100 * par['Uncut']['yaw_mean_reduction_vs_hmf']:.0f} %", criterion="reduction < 30 %"),
    ]


def _cli_table(out: Path) -> list[Path]:
    df = section_3_4()
    written = write_trial(df, out, "table3_3", _plot_table(df))
    return [*written, write_claims(out, "table3.3", section_3_4_claims(df), {"hinge_stiffness": float(df["hinge_stiffness"][0])})]


#: What §3.4 states, drawn as markers in table3_3.png (comparison only, never a result).
THESIS_MARKERS = {"stroke_p2p_deg": 100.0, "rotation_amplitude_deg": 60.0, "yaw_reduction_pct": {"Uncut": 0.0, "1-Cut": 71.0, "2-Cut": 72.0}}


def _plot_table(df: pl.DataFrame):  # type: ignore[no-untyped-def]
    import matplotlib.pyplot as plt

    from ..plots import pair

    trials = list(TRIALS)
    x = np.arange(len(trials))
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2), constrained_layout=True)
    thesis = {"marker": "*", "ms": 13, "color": "k", "ls": "none", "mfc": "gold"}
    for (ax, quantity, ylabel, key) in (
        (axes[0], "stroke_p2p_deg", "stroke peak-to-peak (deg)", "stroke_p2p_deg"),
        (axes[1], "rotation_amplitude_deg", "rotation amplitude (deg)", "rotation_amplitude_deg"),
    ):
        for d, colours in (("HMF", ("C0", "C1")), ("PARITY", ("C2", "C3"))):
            sub = df.filter(pl.col("drivetrain") == d)
            pair(ax, x, sub[f"left_{quantity}"].to_numpy(), sub[f"right_{quantity}"].to_numpy(), (f"{d} left", f"{d} right"), colours)
        ax.plot(x, [THESIS_MARKERS[key]] * len(x), **thesis, label=f"thesis ≈ {THESIS_MARKERS[key]:g}° (§3.4)")
        ax.set_xticks(x, trials)
        ax.set_ylabel(ylabel)
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
    axes[0].set_title("stroke amplitude as the right wing is cut")
    axes[1].set_title("wing rotation ψ amplitude")
    par = df.filter(pl.col("drivetrain") == "PARITY")
    axes[2].bar(x, 100 * par["yaw_mean_reduction_vs_hmf"].to_numpy(), 0.5, color="C2", label="paritysim: PARITY vs HMF")
    marks = THESIS_MARKERS["yaw_reduction_pct"]
    axes[2].plot([trials.index(t) for t in marks], list(marks.values()), **thesis, label="thesis: no reduction (Uncut), 71 %, 72 % (§3.4.2)")
    axes[2].set_xticks(x, trials)
    axes[2].set_ylabel("mean yaw imbalance reduction (%)")
    axes[2].set_title("average yaw imbalance, reduction by the PARITY")
    axes[2].legend(fontsize=7)
    axes[2].grid(alpha=0.3, axis="y")
    axes[2].set_ylim(bottom=-8.0)  # keep the thesis star at 0 % (Uncut) off the axis line
    fig.suptitle("Table 3.3 trials (§3.4): paritysim lines and bars, thesis statements as stars")
    return fig


def _cli_fig3_11(out: Path) -> list[Path]:
    df = trajectories()
    return write_trial(df, out, "fig3_11", _fig(df, "roll", tuple(TRIALS), "Fig. 3.11: roll torque imparted by each wing, HMF vs PARITY", "roll torque (mN·mm)"))


def _cli_fig3_12(out: Path) -> list[Path]:
    df = trajectories().filter(pl.col("trial") == "1-Cut")
    return write_trial(df, out, "fig3_12", _fig(df, "yaw", ("1-Cut",), "Fig. 3.12: yaw torque in the 1-Cut trial", "yaw torque (mN·mm)"))


def _cli_fig3_13(out: Path) -> list[Path]:
    df = trajectories()
    return write_trial(df, out, "fig3_13", _fig3_13(df))


CLI_TRIALS = {"table3.3": _cli_table, "fig3.11": _cli_fig3_11, "fig3.12": _cli_fig3_12, "fig3.13": _cli_fig3_13}


def report_section(out: Path) -> str:
    """Markdown: each §3.4 claim (computed by the ``table3.3`` trial) and the figures."""
    from ._io import results

    claims, values = results(out, "table3.3")
    lines = [
        "## §3.4 Drag PARITY with rotating wings (Table 3.3, Figs. 3.11-3.13)",
        "",
        f"Hinge stiffness pinned by the stated ±60° rotation (Uncut, PARITY): k = {values['hinge_stiffness']:.4f} mN·mm/rad. DC part of eq. 3.24: "
        "`ignore` (piezo bias). Transmission as §3.3 (eq. 2.15). Blade-element aero with the Dickinson fits (mirrored past α = 90°, docs/errata.md#P2).",
        "",
        render(claims),
        "",
        "![Fig. 3.11](fig3_11.png)",
        "",
        "![Fig. 3.12](fig3_12.png)",
        "",
        "![Fig. 3.13](fig3_13.png)",
        "",
    ]
    return "\n".join(lines)


# `from paritysim.trials import section_3_4` gives this module; calling it runs the study.
from .._callable_module import make_callable  # noqa: E402

make_callable(__name__, "section_3_4")
