"""Beyond the thesis: the §3.4 device in flight (issue 17).

Every thesis trial holds the body on a torque stand. Here the §3.4 device (Table 3.3 wings,
linear differential, ``section_3_4``'s pinned hinge) is mounted on the default HMF-class
airframe of the spec's ``body`` section (60 mg; box inertia; shoulders 6 mm above the centre of
mass: ``crates/spec/src/body.rs`` gives the sources and assumptions) and released:

1. **Hover trim** (``flight.trim``): actuator amplitude and DC offset for lift = weight and zero
   pitch torque, HMF and Drag PARITY, Uncut wings; for PARITY also with the pivot (arm ratio,
   the q3 of eq. 5.1) as a third knob against the lift-asymmetry (yaw) torque.
2. **1-Cut right wing, open loop**, HMF vs PARITY at their Uncut trim: body roll on a roll
   gimbal and body yaw on a yaw gimbal over ``wingbeats`` wingbeats, plus the free body.
   Single-axis gimbals because the free body (and the ball joint) tumbles within a few dozen
   wingbeats whatever the drivetrain (the open-loop hover is unstable, reported as a claim),
   which would hide the roll/yaw response to the cut that the thesis' torques predict.
3. The same with a **gravity pendulum on the PARITY pivot** (``body.mechanisms``), both signs
   of its moment.
4. **Eq. 5.1 in flight**: the symmetric device (both wings the Table 3.3 left wing), PARITY
   trimmed: a constant q3 (pivot arm ratio ``hL/hR = 1/q3``, §2.4.2), a stroke-synchronous q3
   (``log_q3`` set point, q3 and 1/q3 on the two half-strokes) and a rate controller on the
   synchronous q3's amplitude, on the torque stand and on the roll gimbal.
5. **One drive per wing** (``dual_four_bar``): trims, and a PD on yaw through the side-gain
   difference against the 1-Cut wing on the yaw gimbal.

All numbers are computed here; the thesis has no flight results to compare with, so every claim
is a physical expectation stated before the run, with its computed verdict.
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

from ..claims import Claim
from ._io import results, write_claims, write_trial

DRIVETRAINS = ("HMF", "PARITY")
GIMBALS = ("roll", "yaw")


@dataclass(frozen=True)
class Params:
    """The flight studies (mg-mm-ms-rad-V)."""

    wingbeats: int = 100
    samples_per_cycle: int = 20
    pendulum_moment_mg_mm: float = 1000.0  # m·l of the pivot pendulum: deliberately large (10 mg on 100 mm), to give it authority
    q3: tuple[float, ...] = (0.5, 2.0)  # τL/τR set points of eq. 5.1
    sync_q3: float = 1.2  # the stroke-synchronous q3 (1/q3 on the other half-stroke)
    spring_k2: float = 100.0  # balance spring (mN·mm/rad) of the open-loop synchronous run: without one the strokes slide freely
    target_rates: tuple[float, ...] = (2e-3, -2e-3, 5e-3)  # rad/ms held by the rate controller
    rate_kd: float = 10.0  # ln q3 amplitude per rad/ms of rate error
    control_rate_hz: float = 1000.0
    dual_kp: float = 2.0  # side-gain difference per rad of yaw (sign from the stand)
    dual_kd: float = 20.0  # per rad/ms
    tilt_limit_deg: float = 30.0  # "tumbled": the stroke axis tipped this far
    animation_wingbeats: int = 12
    animation_frames: int = 60


def params(**overrides: Any) -> Params:
    """:class:`Params` with overrides (unknown names raise ``InvalidParameterError``)."""
    names = {f.name for f in dataclasses.fields(Params)}
    unknown = sorted(set(overrides) - names)
    if unknown:
        from .._errors import invalid, suggest

        raise invalid(unknown[0], overrides[unknown[0]], suggest(unknown[0], sorted(names), what="a parameter of this trial"))
    return Params(**overrides)


# ---------------------------------------------------------------- devices


def device_3_4(drivetrain: str, trial: str):  # type: ignore[no-untyped-def]
    """The §3.4 device (``section_3_4.device`` with its pinned hinge)."""
    from . import section_3_4 as s34

    p = s34.params()
    return s34.device(p, drivetrain, trial, hinge=s34.hinge_stiffness(p))


def symmetric_device(drivetrain: str = "PARITY", q3: float = 1.0):  # type: ignore[no-untyped-def]
    """The §3.4 device with both wings the Table 3.3 left wing; whippletree arm ratio
    ``hL/hR = 1/q3`` (so the stand sees ``τL/τR = q3``, eq. 5.1)."""
    spec = device_3_4(drivetrain, "Uncut")
    left = spec.wings[0]
    spec = spec.replace(wings=(left, left), name=f"symmetric §3.4 {drivetrain}, q3 = {q3:g}")
    return spec.with_paths({"drivetrain.arm_ratio": 1.0 / q3}) if drivetrain == "PARITY" else spec


@functools.lru_cache(maxsize=8)
def _trim(drivetrain: str, pivot: bool = False, symmetric: bool = False):  # type: ignore[no-untyped-def]
    from .. import flight
    from ..flight.trim import AMPLITUDE, OFFSET

    spec = symmetric_device(drivetrain) if symmetric else device_3_4(drivetrain, "Uncut")
    if pivot:
        return flight.trim(spec, knobs=(AMPLITUDE, OFFSET, "drivetrain.arm_ratio"))
    return flight.trim(spec)


def _fly(spec, mode: str, wingbeats: int, samples: int, **body: Any):  # type: ignore[no-untyped-def]
    from .. import flight
    from ..simulation import simulate

    return simulate(flight.with_body(spec, mode=mode, **body), record_cycles=wingbeats, samples_per_cycle=samples)


def _trimmed(spec, drivetrain: str):  # type: ignore[no-untyped-def]
    """``spec`` driven with the Uncut device's amplitude/DC trim of ``drivetrain``."""
    return spec.replace(actuator=_trim(drivetrain).spec.actuator)


def _time_to(angle_rad: np.ndarray, t: np.ndarray, limit_deg: float) -> float:
    """Time (ms after release) at which |angle| first exceeds ``limit_deg``; NaN if never."""
    over = np.flatnonzero(np.abs(np.degrees(angle_rad)) > limit_deg)
    return float(t[over[0]] - t[0]) if over.size else math.nan


# ---------------------------------------------------------------- studies


def hover_trim() -> pl.DataFrame:
    """Study 1: one row per trim (HMF, PARITY, PARITY with the pivot as third knob) of the
    Uncut §3.4 device: knob values, residuals (mN, mN·mm), scaled residuals, runs."""
    rows = []
    for label, (d, pivot) in {"HMF": ("HMF", False), "PARITY": ("PARITY", False), "PARITY + pivot": ("PARITY", True)}.items():
        tr = _trim(d, pivot)
        rows.append(
            dict(
                trim=label,
                amplitude_v=tr.knobs["actuator.waveform.amplitude_v"],
                offset_v=tr.knobs["actuator.waveform.offset_v"],
                arm_ratio=tr.knobs.get("drivetrain.arm_ratio", 1.0),
                weight_mn=tr.weight_mn,
                lift_mn=tr.lift_mn,
                **{f"residual_{k}": v for k, v in tr.residuals.items()},
                **{f"scaled_{k}": v for k, v in tr.scaled.items()},
                solved=",".join(tr.solved),
                converged=tr.converged,
                runs=tr.evaluations,
            )
        )
    return pl.DataFrame(rows)


def _attitude_frame(result, study: str, case: str, mode: str) -> pl.DataFrame:  # type: ignore[no-untyped-def]
    from .. import flight

    df = result.trajectory
    t = df["time_ms"].to_numpy()
    return pl.DataFrame(
        {
            "study": study,
            "case": case,
            "mode": mode,
            "wingbeat": (t - t[0]) / result.period_ms,
            "time_ms": t - t[0],
            "roll_deg": np.degrees(flight.twist_angle(df, "roll")),
            "yaw_deg": np.degrees(flight.twist_angle(df, "yaw")),
            "pitch_deg": np.degrees(flight.twist_angle(df, "pitch")),
            "tilt_deg": np.degrees(flight.tilt_angle(df)),
            "omega_roll": df["body_omega_roll"].to_numpy(),
            "q2": df["q2"].to_numpy() if "q2" in df.columns else np.zeros(len(df)),
            "x_mm": df["body_x"].to_numpy(),
            "y_mm": df["body_y"].to_numpy(),
            "z_mm": df["body_z"].to_numpy(),
        }
    )


def cut_wing(**overrides: Any) -> tuple[pl.DataFrame, dict[str, Any]]:
    """Studies 2 and 3: the 1-Cut device at its drivetrain's Uncut trim on the roll and yaw
    gimbals (and free: HMF and PARITY), HMF, PARITY and PARITY with the pivot pendulum
    (±moment). Returns the
    long attitude frame and the free-flight trajectories (for the pictures)."""
    p = params(**overrides)
    n, s = p.wingbeats, p.samples_per_cycle
    frames, free = [], {}
    cases: dict[str, tuple[str, list[dict[str, Any]]]] = {
        "HMF": ("HMF", []),
        "PARITY": ("PARITY", []),
        "PARITY + pendulum (+)": ("PARITY", [{"kind": "gravity_pendulum", "moment_mg_mm": p.pendulum_moment_mg_mm}]),
        "PARITY + pendulum (−)": ("PARITY", [{"kind": "gravity_pendulum", "moment_mg_mm": -p.pendulum_moment_mg_mm}]),
    }
    for case, (d, mechanisms) in cases.items():
        spec = _trimmed(device_3_4(d, "1-Cut"), d)
        study = "pendulum" if mechanisms else "cut"
        for mode in (*GIMBALS, *(() if mechanisms else ("free",))):
            r = _fly(spec, mode, n, s, mechanisms=mechanisms)
            frames.append(_attitude_frame(r, study, case, mode))
            if mode == "free":
                free[case] = r
    return pl.concat(frames), free


def _slide(df: pl.DataFrame, spec) -> tuple[float, float]:  # type: ignore[no-untyped-def]
    """``(turn, slide)`` (rad) over a roll-gimbal run: the body's roll and ``T L Δq2``, the
    strokes' differential shift on the linear differential (``φL − φR = 2 T L q2`` with
    ``L`` the mean arm): equal when the body turns under wings that stay put in the world."""
    from .. import flight

    roll = flight.twist_angle(df, "roll")
    q2 = df["q2"].to_numpy()
    d = spec.drivetrain
    return float(roll[-1] - roll[0]), float(d.transmission_ratio * d.arm_length_mm * (q2[-1] - q2[0]))


def _reversals(stand) -> tuple[float, float]:  # type: ignore[no-untyped-def]
    """Phases (ms into the drive period, from the release) where the right stroke rate turns
    positive and negative on the clamped orbit (linear interpolation between samples)."""
    df = stand.trajectory
    t, w = df["time_ms"].to_numpy(), df["right_phi_dot"].to_numpy()
    out = {}
    for i in np.flatnonzero(np.sign(w[:-1]) != np.sign(w[1:])):
        s = w[i] / (w[i] - w[i + 1])
        out[bool(w[i + 1] > 0)] = float((t[i] + s * (t[i + 1] - t[i]) - t[0]) % stand.period_ms)
    return out[True], out[False]


def stroke_synchronous(u: float, phases: tuple[float, float], period_ms: float, input: str | None = "log_q3") -> dict[str, Any]:
    """A periodic step schedule: ``+u`` while the right stroke angle grows, ``−u`` on its
    return (``ln q3 = ±u``: q3 = e^u on one half-stroke, 1/q3 on the other); without a
    target name (``None``) a controller's ``shape``."""
    up, down = phases
    times, values = ([up, down], [u, -u]) if up < down else ([down, up], [-u, u])
    out: dict[str, Any] = dict(times_ms=times, values=values, interpolation="previous", period_ms=period_ms)
    if input is not None:
        out.update(input=input)
    return out


def _quarters(df: pl.DataFrame) -> list[float]:
    """Mean roll rate (rad/ms) over each quarter of the whole wingbeats."""
    w = df["body_omega_roll"].to_numpy()[:-1]
    n = len(w)
    return [float(w[k * n // 4 : (k + 1) * n // 4].mean()) for k in range(4)]


def eq_5_1(**overrides: Any) -> tuple[pl.DataFrame, pl.DataFrame]:
    """Study 4, one row per case of the symmetric PARITY at its trim (``case`` column):

    * ``constant`` (q3 = 1, and each of ``q3``; the pivot's arm ratio hL/hR = 1/q3, §2.4.2):
      stand cycle-mean and peak roll torques per wing and their peak ratio; on the roll gimbal
      the mean roll rate per quarter of the run, the turn and the whippletree slide T L Δq2;
    * ``synchronous`` (ln q3 = ±ln ``sync_q3`` on the two half-strokes, the centred pivot):
      the stand's cycle-mean roll torque; open loop on the roll gimbal with a balance spring
      ``spring_k2`` (the free whippletree lets the body spin up while the strokes slide);
    * ``rate`` (each of ``target_rates``): a PD at ``control_rate_hz`` on the roll rate setting
      the amplitude of the stroke-synchronous ``ln q3`` (eq. 5.1 as a rate command).

    Returns that table and the roll-gimbal traces (``case``, ``label``)."""
    from .. import flight
    from ..simulation import simulate

    p = params(**overrides)
    actuator = _trim("PARITY", symmetric=True).spec.actuator
    rows, traces = [], []

    def trace(r, case: str, label: str) -> None:  # type: ignore[no-untyped-def]
        traces.append(_attitude_frame(r, "eq5.1", label, "roll").with_columns(pl.lit(case).alias("kind"), pl.lit(label).alias("label")))

    def gimbal(spec, label: str, case: str, **body: Any) -> dict[str, Any]:  # type: ignore[no-untyped-def]
        r = _fly(spec, "roll", p.wingbeats, p.samples_per_cycle, **body)
        df = r.trajectory
        trace(r, case, label)
        turn, slide = _slide(df, spec)
        q = _quarters(df)
        q2 = df["q2"].to_numpy()
        return dict(rate_q1=q[0], rate_q2=q[1], rate_q3=q[2], rate_q4=q[3], turn_rad=turn, slide_rad=slide, q2_travel=float(q2[-1] - q2[0]), q2_max=float(np.abs(q2).max()), q2_last_quarter=float(q2[:-1][3 * (len(q2) - 1) // 4 :].mean()))

    for q3 in (1.0, *p.q3):
        spec = symmetric_device("PARITY", q3).replace(actuator=actuator)
        stand = simulate(flight.with_body(spec, mode="clamped"))
        cyc = stand.cycle[:-1]
        left = (cyc["left_roll_aero"] + cyc["left_roll_inertial"]).to_numpy()
        right = (cyc["right_roll_aero"] + cyc["right_roll_inertial"]).to_numpy()
        rows.append(
            dict(
                case="constant",
                label=f"q3 = {q3:g}",
                q3=q3,
                stand_roll_mean=stand.metrics["body_torque_roll_mean"],
                stand_peak=float(np.abs(cyc["body_torque_roll"].to_numpy()).max()),
                stand_peak_ratio=float(np.abs(left).max() / np.abs(right).max()),
                **gimbal(spec, f"q3 = {q3:g}", "constant"),
            )
        )
    centred = symmetric_device("PARITY").replace(actuator=actuator)
    stand = simulate(flight.with_body(centred, mode="clamped"), samples_per_cycle=200)
    phases, period = _reversals(stand), stand.period_ms
    sprung = centred.with_paths({"drivetrain.balance_spring": p.spring_k2})
    sprung_phases = _reversals(simulate(flight.with_body(sprung, mode="clamped"), samples_per_cycle=200))
    for q3 in (p.sync_q3, 1.0 / p.sync_q3):
        u = math.log(q3)
        s = simulate(flight.with_body(centred, mode="clamped", set_points=[stroke_synchronous(u, phases, period)]), samples_per_cycle=p.samples_per_cycle)
        rows.append(
            dict(
                case="synchronous",
                label=f"q3 = {q3:.3g} / {1 / q3:.3g}, K2 = {p.spring_k2:g}",
                q3=q3,
                stand_roll_mean=s.metrics["body_torque_roll_mean"],
                stand_peak=float(np.abs(s.cycle["body_torque_roll"].to_numpy()).max()),
                **gimbal(sprung, f"synchronous q3 = {q3:.3g}, K2 = {p.spring_k2:g}", "synchronous", set_points=[stroke_synchronous(u, sprung_phases, period)]),
            )
        )
    for target in p.target_rates:
        control = {
            **dict(input="log_q3"),
            "axis": "roll",
            "kp": 0.0,
            "kd": p.rate_kd,
            "target_rate_rad_per_ms": target,
            "rate_hz": p.control_rate_hz,
            "limit": 0.5,
            "shape": stroke_synchronous(1.0, phases, period, input=None),
        }
        rows.append(dict(case="rate", label=f"hold {1e3 * target:+g} rad/s", target_rate=target, **gimbal(centred, f"hold {1e3 * target:+g} rad/s", "rate", control=control)))
    return pl.from_dicts(rows, infer_schema_length=None), pl.concat(traces, how="diagonal")


# ---------------------------------------------------------------- claims


def trim_claims(df: pl.DataFrame, tol: float) -> list[Claim]:
    """Study 1's claims on :func:`hover_trim`'s table."""
    by = {r["trim"]: r for r in df.iter_rows(named=True)}
    out = []
    for label, r in by.items():
        out.append(
            Claim.holds(
                f"trim ({label}): lift = weight and zero {'pitch and yaw' if 'pivot' in label else 'pitch'} torque",
                bool(r["converged"]),
                computed=f"amplitude {r['amplitude_v']:.2f} V, DC {r['offset_v']:+.2g} V"
                + (f", hL/hR {r['arm_ratio']:.4f}" if "pivot" in label else "")
                + f"; lift − weight {r['residual_lift']:+.1e} mN, pitch {r['residual_pitch']:+.1e}, yaw {r['residual_yaw']:+.2g}, roll {r['residual_roll']:+.1e} mN·mm",
                criterion=f"each solved residual / scale < {tol:g} (scale: weight {r['weight_mn']:.3f} mN; × 12 mm for torques)",
                thesis="(beyond the thesis)",
            )
        )
    h, pv = by["HMF"], by["PARITY + pivot"]
    out.append(
        Claim.holds(
            "one actuator cannot trim the lift-asymmetry (yaw) torque of the Uncut wings; the PARITY pivot (q3) can",
            abs(h["scaled_yaw"]) > 100 * tol and abs(pv["scaled_yaw"]) < tol,
            computed=f"yaw at trim: HMF {h['residual_yaw']:+.3f}, PARITY {by['PARITY']['residual_yaw']:+.3f}, PARITY + pivot {pv['residual_yaw']:+.1e} mN·mm",
            criterion=f"|HMF yaw| / scale > {100 * tol:g} and |PARITY + pivot yaw| / scale < {tol:g}",
            thesis="(beyond the thesis)",
        )
    )
    return out


def _summary(df: pl.DataFrame, limit: float) -> dict[tuple[str, str], dict[str, float]]:
    out = {}
    for (case, mode), sub in df.group_by(["case", "mode"]):
        t = sub["time_ms"].to_numpy()
        out[(case, mode)] = {
            "max_roll": float(np.abs(sub["roll_deg"]).max()),
            "final_roll": float(sub["roll_deg"][-1]),
            "max_yaw": float(np.abs(sub["yaw_deg"]).max()),
            "t_yaw": _time_to(np.radians(sub["yaw_deg"].to_numpy()), t, limit),
            "t_tilt": _time_to(np.radians(sub["tilt_deg"].to_numpy()), t, limit),
        }
    return out


def cut_claims(df: pl.DataFrame, p: Params) -> tuple[list[Claim], dict[str, float]]:
    """Studies 2 and 3: claims on :func:`cut_wing`'s attitude frame and the numbers the report
    quotes."""
    s = _summary(df, p.tilt_limit_deg)
    hmf, par = s[("HMF", "roll")], s[("PARITY", "roll")]
    ratio = par["max_roll"] / hmf["max_roll"]
    ty = {c: s[(c, "yaw")]["t_yaw"] for c in ("HMF", "PARITY", "PARITY + pendulum (+)", "PARITY + pendulum (−)")}
    tt = {c: s[(c, "free")]["t_tilt"] for c in DRIVETRAINS}
    lim = f"{p.tilt_limit_deg:g}°"
    fmt = lambda v: "never" if not math.isfinite(v) else f"{v:.0f} ms"  # noqa: E731
    plus, minus = "PARITY + pendulum (+)", "PARITY + pendulum (−)"
    claims = [
        Claim.holds(
            "Drag PARITY holds the roll of a 1-Cut airframe (roll gimbal, open loop)",
            ratio < 0.5,
            computed=f"max |roll| over {p.wingbeats} wingbeats: HMF {hmf['max_roll']:.2f}°, PARITY {par['max_roll']:.2f}° (ratio {ratio:.2f})",
            criterion="PARITY / HMF < 0.5",
            thesis="§3.4: PARITY balances the roll torques (Fig. 3.11)",
        ),
        Claim.holds(
            "Drag PARITY slows the yaw divergence of a 1-Cut airframe (yaw gimbal, open loop)",
            math.isfinite(ty["HMF"]) and (not math.isfinite(ty["PARITY"]) or ty["PARITY"] > 1.2 * ty["HMF"]),
            computed=f"time to |yaw| > {lim}: HMF {fmt(ty['HMF'])}, PARITY {fmt(ty['PARITY'])}",
            criterion="PARITY's time > 1.2 × HMF's",
            thesis="§3.4: mean yaw imbalance reduced 71 % (1-Cut)",
        ),
        Claim.holds(
            "neither drivetrain keeps the free 1-Cut airframe upright open loop",
            all(math.isfinite(tt[c]) for c in ("HMF", "PARITY")),
            computed=f"time to tilt > {lim}: HMF {fmt(tt['HMF'])}, PARITY {fmt(tt['PARITY'])}",
            criterion=f"tilt exceeds {lim} within {p.wingbeats} wingbeats for both",
            thesis="(beyond the thesis: hover is open-loop unstable)",
        ),
        Claim.holds(
            f"a hanging pendulum on the PARITY pivot (m·l = +{p.pendulum_moment_mg_mm:g} mg·mm) delays the yaw divergence",
            math.isfinite(ty["PARITY"]) and (not math.isfinite(ty[plus]) or ty[plus] > 1.2 * ty["PARITY"]),
            computed=f"time to |yaw| > {lim}: without {fmt(ty['PARITY'])}, with {fmt(ty[plus])}",
            criterion="with > 1.2 × without",
            thesis="§5.1: ground-referenced mechanisms (future work)",
            note="its torque grows with the tilt (sin), and a static pivot bias shifts the two strokes' means oppositely, a weak lever on the lift balance",
        ),
        Claim.holds(
            "... and reduces the yaw excursion over the run",
            s[(plus, "yaw")]["max_yaw"] < 0.5 * s[("PARITY", "yaw")]["max_yaw"],
            computed=f"max |yaw| over {p.wingbeats} wingbeats: without {s[('PARITY', 'yaw')]['max_yaw']:.0f}°, with {s[(plus, 'yaw')]['max_yaw']:.0f}°",
            criterion="with < 0.5 × without",
            thesis="§5.1: ground-referenced mechanisms (future work)",
        ),
        Claim.holds(
            "the hanging pendulum keeps roll regulated; an inverted one (m·l < 0, a negative spring on the pivot) does not",
            s[(plus, "roll")]["max_roll"] < 0.5 * hmf["max_roll"] and s[(minus, "roll")]["max_roll"] > hmf["max_roll"],
            computed=f"max |roll|: hanging {s[(plus, 'roll')]['max_roll']:.2f}°, inverted {s[(minus, 'roll')]['max_roll']:.0f}° (HMF {hmf['max_roll']:.2f}°)",
            criterion="hanging < 0.5 × HMF, inverted > HMF",
            thesis="(beyond the thesis; cf. docs/findings.md §3: the pivot needs positive stiffness)",
        ),
    ]
    values = {"roll_ratio": ratio, "hmf_max_roll_deg": hmf["max_roll"], "parity_max_roll_deg": par["max_roll"], **{f"t_yaw_{c}": v for c, v in ty.items()}, **{f"t_tilt_{c}": v for c, v in tt.items()}}
    return claims, values


def eq_5_1_claims(df: pl.DataFrame) -> list[Claim]:
    """Study 4's claims on :func:`eq_5_1`'s table."""
    by = {case: {r["label"]: r for r in df.filter(pl.col("case") == case).iter_rows(named=True)} for case in ("constant", "synchronous", "rate")}
    const = {r["q3"]: r for r in by["constant"].values()}
    base = const[1.0]
    biased = [q for q in const if q != 1.0]
    peak = max(r["stand_peak"] for r in const.values())
    deg = math.degrees
    sync = list(by["synchronous"].values())
    rate = list(by["rate"].values())
    fmt_q = lambda r: "/".join(f"{1e3 * r[f'rate_q{k}']:+.2f}" for k in range(1, 5))  # noqa: E731
    slide_ok = lambda r: abs(r["turn_rad"] - r["slide_rad"]) < 0.25 * abs(r["turn_rad"])  # noqa: E731
    claims = [
        Claim.all_between("the stand sees τL/τR = q3 (peak roll torques, eq. 5.1)", {f"q3 = {q:g}": const[q]["stand_peak_ratio"] / q for q in biased}, 0.95, 1.05, thesis="τL/τR = q3", fmt=".3f",
                          note="shown: measured ratio / q3"),
        Claim.holds(
            "... and no cycle-mean roll torque (§2.4.2: the imbalance gives a zero-averaged roll oscillation)",
            all(abs(const[q]["stand_roll_mean"]) < 1e-2 * peak for q in biased),
            computed=", ".join(f"q3 = {q:g}: {const[q]['stand_roll_mean']:+.1e} mN·mm" for q in biased) + f" (peak {peak:.2f})",
            criterion="|mean| < 1 % of the peak roll torque",
            thesis="“does not lead to an average roll torque”",
        ),
        Claim.holds(
            "in flight (roll gimbal) a constant q3 ≠ 1 turns the body, q3 = 1 does not, q3 ↔ 1/q3 mirrored",
            all(abs(deg(const[q]["turn_rad"])) > 30.0 for q in biased) and abs(deg(base["turn_rad"])) < 1e-6
            and abs(const[biased[0]]["turn_rad"] + const[biased[1]]["turn_rad"]) < 1e-3 * abs(const[biased[0]]["turn_rad"]),
            computed=", ".join(f"q3 = {q:g}: {deg(const[q]['turn_rad']):+.0f}°" for q in biased) + f"; q3 = 1: {deg(base['turn_rad']):+.1e}°",
            criterion="|turn| > 30° for q3 ≠ 1, < 1e-6° for q3 = 1; q3 and 1/q3 opposite within 0.1 %",
            thesis="§5.1: control by biasing the set point",
        ),
        Claim.holds(
            "... but no sustained roll rate (the constant q3's average roll torque is zero)",
            all(abs(const[q]["rate_q4"]) < 0.2 * max(abs(const[q][f"rate_q{k}"]) for k in (1, 2, 3)) for q in biased),
            computed="mean roll rate per quarter of the run (rad/s): " + "; ".join(f"q3 = {q:g}: {fmt_q(const[q])}" for q in biased),
            criterion="|last quarter| < 20 % of the largest earlier quarter",
            thesis="§2.4.2: “a zero-averaged roll oscillation”",
        ),
        Claim.holds(
            "the turn is the whippletree sliding: the body turns under wings that stay put (turn ≈ T L Δq2)",
            all(slide_ok(const[q]) for q in biased),
            computed="; ".join(f"q3 = {q:g}: turn {const[q]['turn_rad']:+.2f} rad, T L Δq2 {const[q]['slide_rad']:+.2f} rad (Δq2 {const[q]['q2_travel']:+.3f} rad)" for q in biased),
            criterion="|turn − T L Δq2| < 25 % of |turn|",
            thesis="(beyond the thesis: the free whippletree is a zero-stiffness roll mode)",
            note="the strokes' differential φL − φR = 2 T L q2 is a body roll relative to the wings; no balance spring holds it",
        ),
        Claim.holds(
            "a stroke-synchronous q3 (q3 on one half-stroke, 1/q3 on the other) has a cycle-mean roll torque, mirrored by q3 ↔ 1/q3",
            all(abs(r["stand_roll_mean"]) > 0.05 * r["stand_peak"] for r in sync) and abs(sync[0]["stand_roll_mean"] + sync[1]["stand_roll_mean"]) < 1e-6 * abs(sync[0]["stand_roll_mean"]),
            computed=", ".join(f"q3 = {r['q3']:.3g}: mean {r['stand_roll_mean']:+.3f} of peak {r['stand_peak']:.2f} mN·mm" for r in sync),
            criterion="|mean| > 5 % of the peak; the two means opposite within 1e-6",
            thesis="§2.4.2: “combination with a split-cycle control strategy”",
        ),
        Claim.holds(
            f"... which with a balance spring turns the body, then settles into a static whippletree deflection (no sustained rate open loop)",
            all(abs(r["rate_q4"]) < 0.1 * abs(r["rate_q1"]) and abs(r["q2_last_quarter"]) > 0.01 for r in sync),
            computed="; ".join(f"q3 = {r['q3']:.3g}: rate per quarter {fmt_q(r)} rad/s, q2 late {r['q2_last_quarter']:+.3f} rad" for r in sync),
            criterion="|last quarter| < 10 % of the first; |late q2| > 0.01 rad",
            thesis="(beyond the thesis)",
            note="the mean torque is internal (airframe against wings): the spring takes it",
        ),
        Claim.holds(
            "a rate controller on the stroke-synchronous q3 holds a commanded roll rate (eq. 5.1 as a rate command)",
            all(all(abs(r[f"rate_q{k}"] - r["target_rate"]) < 0.2 * abs(r["target_rate"]) for k in (2, 3, 4)) for r in rate),
            computed="; ".join(f"{r['label']}: {fmt_q(r)} rad/s" for r in rate),
            criterion="each quarter after the first within 20 % of the target",
            thesis="§5.1: long-timescale control through eq. 5.1",
            note="a proportional loop on the rate: what remains is its droop",
        ),
        Claim.holds(
            "... mirrored, and by sliding the body under the wings: a sustained turn costs whippletree travel",
            all(slide_ok(r) for r in rate)
            and abs(sum(r["rate_q4"] for r in rate if abs(abs(r["target_rate"]) - abs(rate[0]["target_rate"])) < 1e-15)) < 1e-6 * abs(rate[0]["rate_q4"]),
            computed="; ".join(f"{r['label']}: turn {r['turn_rad']:+.2f} rad, T L Δq2 {r['slide_rad']:+.2f} rad (Δq2 {r['q2_travel']:+.3f} rad)" for r in rate),
            criterion="|turn − T L Δq2| < 25 % of |turn|; ±target last quarters opposite within 1e-6",
            thesis="(beyond the thesis)",
            note="so the linkage's q2 range (|q2| < π/2) and the strokes' range bound how far the body can turn this way",
        ),
    ]
    return claims


# ---------------------------------------------------------------- one drive per wing


def dual_device(trial: str, mirrored: bool = False):  # type: ignore[no-untyped-def]
    """The §3.4 wings on a ``dual_four_bar`` (one four-bar and one drive per wing), started at
    30 V (the §3.4 100 V would toggle a rod-crank that drives one wing alone); ``mirrored``
    swaps the wings (the trial's wing on the left)."""
    from ..spec import Drivetrain

    spec = device_3_4("PARITY", trial)
    if mirrored:
        spec = spec.replace(wings=(spec.wings[1], spec.wings[0]))
    return spec.replace(drivetrain=Drivetrain.dual_four_bar(), name=f"§3.4 dual drive {trial}").with_paths({"actuator.waveform.amplitude_v": 30.0})


@functools.lru_cache(maxsize=2)
def _dual_trim():  # type: ignore[no-untyped-def]
    from .. import flight

    return flight.trim(dual_device("Uncut"))


def dual_drive(**overrides: Any) -> tuple[pl.DataFrame, pl.DataFrame, dict[str, Any]]:
    """Study 5 (one drive per wing): the dual-drive trim (amplitude and DC offset, Uncut
    wings), and the 1-Cut right wing at that trim on the yaw gimbal, open loop (and mirrored:
    the cut wing on the left) and with a PD on yaw driving the side-gain difference (its sign
    from the stand's slope). Returns the trim row, the attitude frame and the numbers the
    claims use."""
    from .. import flight
    from ..simulation import simulate

    p = params(**overrides)
    tr = _dual_trim()
    trims = [dict(trim="dual drive", amplitude_v=tr.knobs["actuator.waveform.amplitude_v"], offset_v=tr.knobs["actuator.waveform.offset_v"], converged=tr.converged, **{f"residual_{k}": v for k, v in tr.residuals.items()}, **{f"scaled_{k}": v for k, v in tr.scaled.items()})]
    actuator = tr.spec.actuator
    cut = dual_device("1-Cut").replace(actuator=actuator)

    def stand_yaw(u: float) -> float:
        r = simulate(flight.with_body(cut, mode="clamped", set_points=[dict(input="side_gain_difference", times_ms=[0.0], values=[u])]))
        v = r.metrics["body_torque_yaw_mean"]
        return float("nan") if v is None else float(v)

    slope = (stand_yaw(0.05) - stand_yaw(-0.05)) / 0.1
    sign = math.copysign(1.0, slope)
    control = {**dict(input="side_gain_difference"), "axis": "yaw", "kp": sign * p.dual_kp, "kd": sign * p.dual_kd, "rate_hz": p.control_rate_hz, "limit": 0.3}
    frames = []
    for case, spec, body in (
        ("open loop", cut, {}),
        ("open loop, mirrored", dual_device("1-Cut", mirrored=True).replace(actuator=actuator), {}),
        ("PD on yaw", cut, {"control": control}),
    ):
        r = _fly(spec, "yaw", p.wingbeats, p.samples_per_cycle, **body)
        frames.append(_attitude_frame(r, "dual", case, "yaw"))
    return pl.DataFrame(trims), pl.concat(frames), {"slope": slope}


def dual_claims(trims: pl.DataFrame, df: pl.DataFrame, values: dict[str, Any], p: Params, tol: float) -> list[Claim]:
    """Study 5's claims."""
    by = {r["trim"]: r for r in trims.iter_rows(named=True)}
    yaw = {case: sub.sort("time_ms")["yaw_deg"].to_numpy() for (case,), sub in df.group_by(["case"])}
    t = df.filter(pl.col("case") == "open loop").sort("time_ms")["time_ms"].to_numpy()
    lim = p.tilt_limit_deg
    t_open = _time_to(np.radians(yaw["open loop"]), t, lim)
    held = float(np.abs(yaw["PD on yaw"]).max())
    mirror = float(np.abs(yaw["open loop"] + yaw["open loop, mirrored"]).max())
    d = by["dual drive"]
    return [
        Claim.holds(
            "trim (dual drive): lift = weight and zero pitch torque",
            bool(d["converged"]),
            computed=f"amplitude {d['amplitude_v']:.2f} V, DC {d['offset_v']:+.2g} V; lift − weight {d['residual_lift']:+.1e} mN, pitch {d['residual_pitch']:+.1e}, yaw {d['residual_yaw']:+.2g}, roll {d['residual_roll']:+.1e} mN·mm",
            criterion=f"each solved residual / scale < {tol:g}",
            thesis="(beyond the thesis)",
        ),
        Claim.holds(
            "a PD on yaw through the side-gain difference holds a 1-Cut airframe that yaws away open loop",
            math.isfinite(t_open) and held < 10.0,
            computed=f"open loop |yaw| > {lim:g}° after {t_open:.0f} ms; PD (stand slope {values['slope']:+.2f} mN·mm per unit gain difference): max |yaw| {held:.2f}° over {p.wingbeats} wingbeats",
            criterion=f"open loop exceeds {lim:g}°; PD max |yaw| < 10°",
            thesis="(beyond the thesis: per-side drive control, issue 17)",
        ),
        Claim.holds(
            "the mirrored cut (left wing) yaws the mirrored way",
            mirror < 1e-6 * float(np.abs(yaw["open loop"]).max()),
            computed=f"max |yaw_right-cut + yaw_left-cut| = {mirror:.1e}° of {np.abs(yaw['open loop']).max():.0f}°",
            criterion="< 1e-6 of the excursion",
            thesis="(mirror symmetry)",
        ),
    ]


def _fig_dual(df: pl.DataFrame):  # type: ignore[no-untyped-def]
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 3.8), constrained_layout=True)
    for i, case in enumerate(("open loop", "open loop, mirrored", "PD on yaw")):
        sub = df.filter(pl.col("case") == case).sort("time_ms")
        ax.plot(sub["wingbeat"].to_numpy(), sub["yaw_deg"].to_numpy(), color=f"C{i}", label=case)
    ax.set_yscale("symlog", linthresh=5.0)
    ax.set_xlabel("wingbeats after release")
    ax.set_ylabel("body yaw, yaw gimbal (deg)")
    ax.set_title("one drive per wing: 1-Cut right wing at the Uncut trim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def _cli_dual(out: Path) -> list[Path]:
    p = params()
    trims, df, values = dual_drive()
    tol = _dual_trim().tol
    written = write_trial(df, out, "flight_dual_drive", _fig_dual(df))
    trims.write_csv(out / "flight_dual_drive_trim.csv")
    return [*written, out / "flight_dual_drive_trim.csv", write_claims(out, "flight.dual_drive", dual_claims(trims, df, values, p, tol), {"tol": tol})]


# ---------------------------------------------------------------- figures, CLI, report


def _per_wingbeat(n: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Means of ``v`` over each whole wingbeat (``n`` in wingbeats), at the wingbeats' middles."""
    k = np.floor(n[:-1] + 1e-9).astype(int)  # a sample on a wingbeat boundary opens the next one
    beats = np.unique(k)
    return beats + 0.5, np.array([v[:-1][k == b].mean() for b in beats])


def _fig_cut(df: pl.DataFrame, p: Params):  # type: ignore[no-untyped-def]
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(12, 7), sharex=True, constrained_layout=True)
    for col, study in enumerate(("cut", "pendulum")):
        cases = ["HMF", "PARITY"] if study == "cut" else ["PARITY", "PARITY + pendulum (+)", "PARITY + pendulum (−)"]
        for i, case in enumerate(cases):
            for row, (mode, q) in enumerate((("roll", "roll_deg"), ("yaw", "yaw_deg"))):
                sub = df.filter((pl.col("case") == case) & (pl.col("mode") == mode))
                n, v = sub["wingbeat"].to_numpy(), sub[q].to_numpy()
                axes[row][col].plot(n, v, color=f"C{i}", lw=0.4, alpha=0.35)
                beat, mean = _per_wingbeat(n, v)
                axes[row][col].plot(beat, mean, color=f"C{i}", lw=1.8, label=f"{case} (wingbeat mean)")
        axes[0][col].set_title(("1-Cut right wing, open loop" if study == "cut" else f"PARITY with a pivot pendulum (m·l = ±{p.pendulum_moment_mg_mm:g} mg·mm)"))
        axes[0][col].set_ylabel("body roll, roll gimbal (deg)")
        if study == "pendulum":
            axes[0][col].set_yscale("symlog", linthresh=1.0)
        axes[1][col].set_ylabel("body yaw, yaw gimbal (deg)")
        axes[1][col].set_xlabel("wingbeats after release")
        for row in (0, 1):
            axes[row][col].grid(alpha=0.3)
            axes[row][col].legend(fontsize=8)
    fig.suptitle("Beyond the thesis: §3.4 device on single-axis gimbals, drive trimmed for the Uncut wings")
    return fig


def _fig_eq_5_1(traces: pl.DataFrame, df: pl.DataFrame):  # type: ignore[no-untyped-def]
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2), constrained_layout=True)
    titles = {"constant": "constant q3 (pivot arm ratio 1/q3)", "synchronous": "stroke-synchronous q3, open loop, with a balance spring", "rate": "rate controller on the synchronous q3"}
    th = {r["label"]: r["slide_rad"] / r["q2_travel"] if r["q2_travel"] else math.nan for r in df.iter_rows(named=True)}
    for col, kind in enumerate(("constant", "synchronous", "rate")):
        sub = traces.filter(pl.col("kind") == kind)
        for i, label in enumerate(dict.fromkeys(sub["label"].to_list())):
            tr = sub.filter(pl.col("label") == label)
            n = tr["wingbeat"].to_numpy()
            beat, rate = _per_wingbeat(n, 1e3 * tr["omega_roll"].to_numpy())
            ax[col].plot(beat, rate, color=f"C{i}", label=label)
        ax[col].set_title(titles[kind], fontsize=10)
        ax[col].set_xlabel("wingbeats after release")
        ax[col].grid(alpha=0.3)
        ax[col].legend(fontsize=7)
    ax[0].set_ylabel("roll rate, wingbeat mean (rad/s)")
    # The slide: turn against T L Δq2 for the controlled runs (inset-free: dashed on the right axis).
    twin = ax[2].twinx()
    sub = traces.filter(pl.col("kind") == "rate")
    for i, label in enumerate(dict.fromkeys(sub["label"].to_list())):
        tr = sub.filter(pl.col("label") == label)
        n = tr["wingbeat"].to_numpy()
        twin.plot(n, tr["roll_deg"].to_numpy() - tr["roll_deg"][0], color=f"C{i}", lw=0.8, alpha=0.6)
        twin.plot(n, np.degrees(th[label] * (tr["q2"].to_numpy() - tr["q2"][0])), color=f"C{i}", lw=0.8, ls=":")
    twin.set_ylabel("thin: turn; dotted: T L Δq2 (deg)")
    fig.suptitle("eq. 5.1 in flight: the symmetric PARITY on a roll gimbal")
    return fig


def _fig_trim(df: pl.DataFrame, tol: float):  # type: ignore[no-untyped-def]
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(11, 3.8), constrained_layout=True)
    labels = df["trim"].to_list()
    x = np.arange(len(labels))
    # Every solved knob: the drive amplitude as bars, the DC offset (hundredths of a volt,
    # invisible as a bar) and a solved arm ratio written on each.
    amplitude, offset = df["amplitude_v"].to_numpy(), df["offset_v"].to_numpy()
    bars = ax[0].bar(x, amplitude, 0.5, color="C0")
    arm = df["arm_ratio"].to_numpy()
    notes = [
        f"{a:.2f} V\nDC offset {round(o, 3) + 0.0:+.3f} V" + (f"\narm ratio {r:.4f}" if r != 1.0 else "")
        for a, o, r in zip(amplitude, offset, arm, strict=True)
    ]
    ax[0].bar_label(bars, notes, fontsize=8)
    ax[0].set_ylim(0.0, 1.3 * float(amplitude.max()))
    ax[0].set_xticks(x, labels)
    ax[0].set_ylabel("trim drive amplitude (V)")
    ax[0].set_title(f"hover trim of the §3.4 device (weight {df['weight_mn'][0]:.3f} mN)")
    for k, e in enumerate(("lift", "roll", "yaw", "pitch")):
        ax[1].bar(x + (k - 1.5) * 0.2, np.abs(df[f"scaled_{e}"].to_numpy()) + 1e-16, 0.2, label=e)
    ax[1].axhline(tol, color="k", ls="--", lw=1, label=f"tolerance {tol:g}")
    ax[1].set_yscale("log")
    ax[1].set_xticks(x, labels)
    ax[1].set_ylabel("|residual| / scale")
    ax[1].set_title("residuals at the trim (unsolved ones included)")
    ax[1].legend(fontsize=7, ncol=2)
    return fig


def _cli_trim(out: Path) -> list[Path]:
    df = hover_trim()
    tol = _trim("HMF").tol
    written = write_trial(df, out, "flight_trim", _fig_trim(df, tol))
    return [*written, write_claims(out, "flight.trim", trim_claims(df, tol), {"tol": tol})]


def _cli_cut(out: Path) -> list[Path]:
    from .. import plots
    from ..flight import plots as fplots

    p = params()
    df, free = cut_wing()
    written = write_trial(df, out, "flight_cut_wing", _fig_cut(df, p))
    period = free["HMF"].period_ms
    frames = {c: free[c].trajectory for c in ("HMF", "PARITY")}
    written.append(plots.save(fplots.attitude(frames, period, title="1-Cut right wing, free flight at the Uncut trim: attitude and position"), out / "flight_free_attitude.png"))
    written.append(plots.save(fplots.trajectory_3d(frames, title="1-Cut right wing, free flight: centre of mass; arrows: stroke axis"), out / "flight_free_trajectory.png"))
    # The animation: the first wingbeats of the HMF's free flight, finely sampled.
    spec = _trimmed(device_3_4("HMF", "1-Cut"), "HMF")
    per = max(1, p.animation_frames // p.animation_wingbeats)
    anim = _fly(spec, "free", p.animation_wingbeats, 4 * per)
    # MP4 through ffmpeg (imageio-ffmpeg's binary or a system one), else the GIF it falls back to.
    movie = fplots.animate(anim.trajectory, out / "flight_free_hmf_1cut.mp4", frames=p.animation_frames, title="HMF, 1-Cut, free")
    written.append(movie)
    claims, numbers = cut_claims(df, p)
    values: dict[str, Any] = {**numbers, "animation": movie.name}
    return [*written, write_claims(out, "flight.cut_wing", claims, values)]


def _cli_eq_5_1(out: Path) -> list[Path]:
    df, traces = eq_5_1()
    actuator = _trim("PARITY", symmetric=True).spec.actuator
    written = write_trial(df, out, "flight_eq5_1", _fig_eq_5_1(traces, df))
    return [*written, write_claims(out, "flight.eq5.1", eq_5_1_claims(df), {"amplitude_v": actuator.waveform.amplitude_v})]


CLI_TRIALS = {"flight.trim": _cli_trim, "flight.cut_wing": _cli_cut, "flight.eq5.1": _cli_eq_5_1, "flight.dual_drive": _cli_dual}


def report_section(out: Path) -> str:
    """Markdown: the flight studies (beyond the thesis), from the files the trials wrote."""
    from ..claims import render

    trim_found, tv = results(out, "flight.trim")
    cut_found, cv = results(out, "flight.cut_wing")
    eq_found, ev = results(out, "flight.eq5.1")
    dual_found, _ = results(out, "flight.dual_drive")
    p = params()
    return "\n".join(
        [
            "## Beyond the thesis: the §3.4 device in flight (issue 17)",
            "",
            "**Not in the thesis**: every thesis trial holds the body on a torque stand. Here the §3.4 device flies on the default "
            "HMF-class airframe of the spec's `body` section (60 mg, box inertia, shoulders 6 mm above the centre of mass; "
            "`crates/spec/src/body.rs` states sources and assumptions), with coupled body and wing dynamics (`crates/flight`). "
            "There are no thesis numbers to compare with: each claim is a physical expectation (some sharpened after first runs, "
            "e.g. the inverted pendulum's instability), and every verdict is computed on this run. Axes as the thesis names them: roll about the stroke axis x̂ (the drag-torque axis Drag PARITY "
            "regulates), yaw about the wing normal ŷ (lift asymmetry), pitch about the span ẑ.",
            "",
            "### Hover trim",
            "",
            f"`paritysim.flight.trim`: actuator amplitude and DC offset (acting as a force) solved on the clamped body for "
            f"cycle-mean lift = weight and zero pitch torque; with the PARITY pivot (arm ratio) as a third knob, zero yaw too. "
            f"Tolerance on each solved residual: {tv['tol']:g} of its scale.",
            "",
            render(trim_found),
            "",
            "![trim](flight_trim.png)",
            "",
            f"### A cut wing, open loop, and a pendulum on the pivot",
            "",
            f"The 1-Cut right wing (Table 3.3) at the drive trimmed for the Uncut wings, {p.wingbeats} wingbeats after release from "
            "the clamped steady state. Roll and yaw are each shown on a single-axis gimbal about the centre of mass: the free "
            "body (and the three-axis ball joint) tumbles within a few dozen wingbeats whatever the drivetrain — open-loop "
            "hover is unstable (third claim) — so 100 wingbeats of free flight would show the tumble, not the roll/yaw response "
            "to the cut that the thesis' torques predict. The free flights are drawn below too.",
            "",
            render(cut_found),
            "",
            "![cut wing](flight_cut_wing.png)",
            "",
            "![free attitude](flight_free_attitude.png)",
            "",
            "![free trajectory](flight_free_trajectory.png)",
            "",
            f"Animation of the HMF's first {p.animation_wingbeats} free wingbeats (schematic wings): `{cv.get('animation', 'flight_free_hmf_1cut.gif')}` "
            "(MP4 through ffmpeg when one is found, from the optional `video` extra's imageio-ffmpeg or the system; a GIF otherwise).",
            "",
            "### Eq. 5.1 in flight",
            "",
            f"The symmetric device (both wings the Table 3.3 left wing), PARITY trimmed ({ev['amplitude_v']:.2f} V), on the stand and "
            f"on a roll gimbal for {p.wingbeats} wingbeats. Three ways to command q3: a **constant** q3 by the pivot's arm ratio "
            "hL/hR = 1/q3 (§2.4.2); a **stroke-synchronous** q3 (q3 while the right stroke angle grows, 1/q3 on its return: a "
            "periodic step set point of `log_q3`, the whippletree load that holds τL/τR = q3 on the centred pivot); and a "
            f"**rate controller**, a PD at {p.control_rate_hz:g} Hz on the roll rate setting the amplitude of that synchronous "
            "ln q3 (`[body.control]` with `target_rate_rad_per_ms` and a `shape`). Findings: a constant q3 has no mean roll "
            "torque (the thesis' own remark) and turns the body only while the free whippletree slides; the synchronous q3 has a "
            "mean torque, but it is internal (airframe against wings), so open loop it ends in a whippletree deflection (with a "
            f"balance spring of {p.spring_k2:g} mN·mm/rad) or in sliding strokes (without); closing the loop on the rate holds a "
            "commanded roll rate, the body turning under the wings at a whippletree travel of 1/(T L) per radian.",
            "",
            render(eq_found),
            "",
            "![eq. 5.1](flight_eq5_1.png)",
            "",
            "### One drive per wing",
            "",
            "The §3.4 wings on a `dual_four_bar` drivetrain: each wing its own HMF rod-crank and its own drive (the `[actuator]` "
            "scaled per side by `side_gain`, shifted by `side_offset_v`), the layout of later dual-actuator robots, for comparison "
            f"with the passive drivetrains. Trimmed like the others (amplitude and DC offset), then the 1-Cut right wing at the Uncut trim on the yaw gimbal for {p.wingbeats} wingbeats: open loop, "
            f"mirrored, and with a PD on yaw ({p.control_rate_hz:g} Hz) driving the side-gain difference (+u left, −u right).",
            "",
            render(dual_found),
            "",
            "![dual drive](flight_dual_drive.png)",
            "",
        ]
    )
