"""§2.6-2.7: stability of Drag PARITY (Fig. 2.13), disturbance rejection (eq. 2.59), and the
Floquet analysis of the full nonlinear model that the thesis could not do.

Every number here is computed by the model; the thesis' values are quoted only for comparison.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import polars as pl

from .. import stability as st
from ..claims import Claim, render
from ._io import write_claims
from ..spec import Actuator, Aero, Configuration, Drivetrain, Simulation, Waveform, Wing

#: C_N(90°) of eqs. 3.5-3.6, as in examples/drag_parity.toml (docs/errata.md#12).
CN90 = 3.4609
#: Fixed §3.3 wing: stroke inertia 29.0 mg·mm² (§3.3.2).
INERTIA = ((29.0, 0.0, 0.0), (0.0, 29.0, 0.0), (0.0, 0.0, 1.0))
#: Disturbance frequencies (Hz): multiples of 10 Hz fit an integer number of periods into 11
#: cycles at 110 Hz, so the Fourier projection is exact.
DISTURBANCE_HZ = (20.0, 30.0, 60.0, 100.0, 150.0, 300.0)
#: The thesis' |H(300 Hz)| (§2.7), quoted for comparison only.
THESIS_H300 = 0.003


def _wings(omega_left: float, coefficient: float) -> tuple[Wing, Wing]:
    return (
        Wing(inertia=INERTIA, aero=Aero(kind="stroke_drag", omega1=omega_left, coefficient=coefficient)),
        Wing(inertia=INERTIA, aero=Aero(kind="stroke_drag", omega1=31.3, coefficient=coefficient)),
    )


def drag_parity_spec(k2: float = 1.0, *, linear: bool = False, omega_left: float = 31.3, coefficient: float = CN90, volts: float = 100.0) -> Simulation:
    """The §3.3 Drag PARITY device of ``examples/drag_parity.toml`` (Control trial, K2 = 1).

    ``linear=True`` swaps the linkage for its linearisation, eq. 2.15 with T = 2.5 rad/mm,
    L = 2.5 mm (docs/findings.md item 2).
    """
    drivetrain = (
        Drivetrain.linear_differential(2.5, 2.5, balance_spring=k2) if linear else Drivetrain.linkage_differential(balance_spring=k2)
    )
    return Simulation(
        wings=_wings(omega_left, coefficient),
        configuration=Configuration(name="drag_parity_fixed"),
        drivetrain=drivetrain,
        actuator=Actuator(waveform=Waveform(amplitude_v=volts, frequency_hz=110.0)),
        name="drag_parity_linear" if linear else "drag_parity",
    )


def hmf_spec() -> Simulation:
    """The §3.3 HMF device of ``examples/hmf.toml``."""
    return Simulation(
        wings=_wings(31.3, CN90),
        configuration=Configuration(name="hmf_fixed"),
        drivetrain=Drivetrain.hmf_four_bar(),
        actuator=Actuator(waveform=Waveform(amplitude_v=100.0, frequency_hz=110.0)),
        name="hmf",
    )


# ------------------------------------------------------------------ Fig. 2.13


def fig2_13(n: int = 200, beta0: tuple[float, float] = (-1.0, 6.0), kappa: tuple[float, float] = (-1.0, 4.0)) -> pl.DataFrame:
    """The Fig. 2.13 stability chart of eq. 2.25 on an ``n × n`` (β0, κ) grid extended to
    negative damping and stiffness (see :func:`paritysim.stability.stability_chart`)."""
    return st.stability_chart(np.linspace(*beta0, n), np.linspace(*kappa, n))


def device_points() -> pl.DataFrame:
    """The §3.3 device placed on Fig. 2.13: (β0, κ2) of its whippletree mode from its orbit,
    and (a, b) of eq. 2.25 there, for K2 = 1 (the example) and 500 mN·mm/rad."""
    rows = []
    for k2 in (1.0, 500.0):
        lin = st.linearise(drag_parity_spec(k2))
        h = lin["hill"]
        f = st.hill_floquet(h["beta0"], h["kappa2"])
        rows.append({"k2": k2, "beta0": h["beta0"], "kappa2": h["kappa2"], "a": f["a"], "b": f["b"], "region": f["region"]})
    return pl.DataFrame(rows)


def _cli_fig2_13(out: Path) -> list[Path]:
    from .. import plots

    chart = fig2_13()
    pts = device_points()
    written = [out / "fig2_13.parquet", out / "fig2_13.csv"]
    chart.write_parquet(written[0])
    chart.write_csv(written[1])
    ab = {f"§3.3, K2 = {r['k2']:g}": (r["a"], r["b"]) for r in pts.iter_rows(named=True)}
    bk = {f"§3.3, K2 = {r['k2']:g}": (r["beta0"], r["kappa2"]) for r in pts.iter_rows(named=True)}
    written.append(plots.save(st.plot_fig2_13(chart.filter(pl.col("beta0") >= 0.0).gather_every(7), ab), out / "fig2_13.png"))
    written.append(plots.save(st.plot_chart_map(chart, bk), out / "fig2_13_map.png"))
    written.append(write_claims(out, "fig2.13", linearised_claims(chart), {"devices": pts.to_dicts()}))
    return written


def linearised_claims(chart: pl.DataFrame) -> list[Claim]:
    """The §2.6 closed forms (with docs/errata.md#7 to #10) checked on the eq. 2.25 solver,
    and Fig. 2.13's statements checked on ``chart``."""
    from scipy.special import i0

    rng = np.random.default_rng(0)
    worst_det = 0.0
    for beta0, kappa in zip(rng.uniform(-1, 5, 50), rng.uniform(-1, 8, 50), strict=True):
        m = st.hill_monodromy(beta0, kappa, rng.uniform(-3, 3))
        scale = max(math.exp(-2 * beta0), abs(m[0, 0] * m[1, 1]) + abs(m[0, 1] * m[1, 0]))
        worst_det = max(worst_det, abs(np.linalg.det(m) - math.exp(-2 * beta0)) / scale)
    beta0 = 0.9
    m = st.hill_monodromy(beta0, 0.0)
    err_250 = abs(m[0, 1] / (math.pi * math.exp(-beta0) * i0(beta0)) - 1)
    far = st.hill_solution(beta0, 0.0, [-math.pi / 2 + 40 * math.pi])[0]
    limit = math.pi * i0(beta0) * math.exp(-beta0) / (1 - math.exp(-2 * beta0))
    err_254 = abs(far[0, 1] / limit - 1)
    printed_254 = abs(far[0, 1] / (limit / math.pi) - 1)
    w = st.hill_floquet(1.0, 0.05)
    undamped = st.stability_chart([0.0], np.linspace(0.05, 4.0, 51), brockett=False)
    n_marginal = int((undamped["region_name"] == "marginal").sum())
    guaranteed = chart.filter(pl.col("brockett_bounded"))
    brockett_ok = bool((guaranteed["spectral_radius"] <= 1 + guaranteed["multiplier_error"] + 1e-12).all())
    weak = chart.filter((pl.col("kappa") > 0) & (pl.col("kappa") <= 0.1) & (pl.col("beta0") != 0))
    unstable_positive = chart.filter((pl.col("beta0") > 0) & (pl.col("kappa") > 0) & (pl.col("spectral_radius") > 1 + pl.col("multiplier_error"))).height
    return [
        Claim.near("eq. 2.45: det M = e^(-2β0), 50 random (β0, κ, t0)", worst_det, 0.0, 1e-9, fmt=".1e", thesis_text="exact (residual 0)", note="error relative to the products of entries"),
        Claim.near("eq. 2.50: κ = 0 monodromy entry π e^(-β0) I0(β0), β0 = 0.9", err_250, 0.0, 1e-9, fmt=".1e", thesis_text="exact (residual 0)", note="relative error"),
        Claim.near("eq. 2.54 with the factor π restored (docs/errata.md#10)", err_254, 0.0, 1e-9, fmt=".1e", thesis_text="exact (residual 0)",
                   note=f"relative error; the printed form (without π) is off by {printed_254:.3g}"),
        Claim.holds(
            "Fig. 2.13: Region I is b ≤ 1, |a| ≤ (1+b)/2 (docs/errata.md#9)",
            w["region"] == 1 and w["spectral_radius"] < 1 and w["a"] > (w["b"] - 1) / 2,
            computed=f"β0 = 1, κ = 0.05: a = {w['a']:.3f}, b = {w['b']:.3f}, max|ρ| = {w['spectral_radius']:.3f}, Region {st.REGIONS[w['region']]}",
            criterion="stable point that the printed bound a > (b−1)/2 calls Region III",
            thesis="a > (b − 1)/2 bounds Region III",
        ),
        Claim.holds(
            "undamped (β0 = 0): multipliers on the unit circle, neither stable nor unstable",
            n_marginal == undamped.height,
            computed=f"{n_marginal} of {undamped.height} points marginal",
            criterion="every point labelled marginal (|ρ| = 1 within the multipliers' error)",
        ),
        Claim.holds(
            "eq. 2.51: for a weak spring (κ ≪ 1) the system is stable exactly when β0 ≥ 0",
            bool(weak.filter(pl.col("beta0") > 0)["stable"].all()) and not bool(weak.filter(pl.col("beta0") < 0)["stable"].any()),
            computed=f"{weak.filter(pl.col('beta0') > 0)['stable'].sum()} of {weak.filter(pl.col('beta0') > 0).height} chart points with β0 > 0, "
            f"0 < κ ≤ 0.1 asymptotically stable; {weak.filter(pl.col('beta0') < 0)['stable'].sum()} with β0 < 0",
            criterion="all with β0 > 0 stable, none with β0 < 0",
            note=f"{unstable_positive} chart points with β0, κ > 0 (κ up to {float(chart['kappa'].max()):g}) have max|ρ| > 1 beyond its error",
        ),
        Claim.holds(
            "eqs. 2.57-2.58: where Brockett's criterion guarantees boundedness, the Floquet multipliers agree",
            brockett_ok,
            computed=f"{guaranteed.height} guaranteed points",
            criterion="max|ρ| ≤ 1 + its error at each",
        ),
    ]


# ------------------------------------------------------------------ §2.7


def h_300(k2: float = 1.0) -> dict[str, float]:
    """Eq. 2.59 for the §3.3 device at 300 Hz: |H| of ``lti`` (as §2.7 builds it from the
    simulated orbit) and of ``lti_averaged`` (with the linkage's geometric stiffness), and the
    K2 at which the ``lti`` model would give the thesis' 0.003."""
    lin = st.linearise(drag_parity_spec(k2))
    lti, avg = lin["lti"], lin["lti_averaged"]
    f = np.array([300.0])
    gain = float(np.abs(st.lti_transfer(lti["beta_star"], lti["kappa0"], f))[0])
    gain_avg = float(np.abs(st.lti_transfer(avg["beta_star"], avg["kappa0"], f))[0]) if avg["kappa0"] > 0 else math.nan
    # |H| = κ0/|κ0 − ω² + iβ*ω| = 0.003, solved for κ0 (κ0 ∝ K2 at fixed orbit).
    w = 2 * math.pi * 0.3
    h = THESIS_H300
    # (1 − h²) κ0² + 2h²ω² κ0 − h²(ω⁴ + β*²ω²) = 0
    qa, qb, qc = 1 - h * h, 2 * h * h * w * w, -h * h * (w**4 + (lti["beta_star"] * w) ** 2)
    kappa0 = (-qb + math.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)
    k2_for_thesis = k2 * kappa0 / lti["kappa0"] if lti["kappa0"] > 0 else math.nan
    return {
        "k2": k2,
        "beta_star": lti["beta_star"],
        "kappa0": lti["kappa0"],
        "h300": gain,
        "h300_averaged": gain_avg,
        "k2_for_thesis_h300": k2_for_thesis,
        "geometric_stiffness": lin["geometric_stiffness"],
    }


def _sec2_7_cases() -> dict[str, Simulation]:
    return {
        "linkage, C_N, K2 = 500": drag_parity_spec(500.0),
        "eq. 2.15, C_N, K2 = 500": drag_parity_spec(500.0, linear=True),
        "eq. 2.15, eq. 2.16 (C = 1), 50 V, K2 = 200": drag_parity_spec(200.0, linear=True, coefficient=1.0, volts=50.0),
    }


def sec2_7() -> pl.DataFrame:
    """Eq. 2.59 against the nonlinear disturbance response (amplitude 0.1 mN·mm) for three
    devices: the §3.3 linkage at K2 = 500 (its K2 = 1 orbit is unstable, so nothing settles),
    the linear map of eq. 2.15 with the same drag, and eq. 2.15 with eq. 2.16 drag (C = 1)."""
    frames = []
    for label, spec in _sec2_7_cases().items():
        df = st.disturbance_response(spec, DISTURBANCE_HZ, amplitude=0.1)
        frames.append(df.with_columns(pl.lit(label).alias("device")).select("device", *df.columns))
    return pl.concat(frames)


def _cli_sec2_7(out: Path) -> list[Path]:
    from .. import plots

    df = sec2_7()
    written = [out / "sec2_7.parquet", out / "sec2_7.csv"]
    df.write_parquet(written[0])
    df.write_csv(written[1])
    f = np.logspace(0, math.log10(2000), 300)
    lin = st.linearise(drag_parity_spec(1.0))
    curves = {"§3.3 device, K2 = 1 (its orbit is unstable)": (f, st.lti_transfer(lin["lti"]["beta_star"], lin["lti"]["kappa0"], f))}
    for label, spec in _sec2_7_cases().items():
        lin = st.linearise(spec)
        curves[label] = (f, st.lti_transfer(lin["lti"]["beta_star"], lin["lti"]["kappa0"], f))
        if label.startswith("linkage"):
            avg = lin["lti_averaged"]
            curves[f"{label}, with geometric stiffness"] = (f, st.lti_transfer(avg["beta_star"], avg["kappa0"], f))
    measured = {d: df.filter(pl.col("device") == d) for d in df["device"].unique(maintain_order=True)}
    written.append(plots.save(st.plot_bode(curves, measured), out / "sec2_7.png"))
    h1, h500 = h_300(1.0), h_300(500.0)
    claim = Claim.near("§2.7: |H(300 Hz)| = 0.003 (eq. 2.59, §3.3 device, K2 = 1 as in examples/drag_parity.toml)", h1["h300"], THESIS_H300, 0.5, rel=True,
                       fmt=".2g", note=f"K2 is not given (docs/errata.md#14); the thesis' value needs K2 ≈ {h1['k2_for_thesis_h300']:.0f} mN·mm/rad")
    return [*written, write_claims(out, "sec2.7", [claim], {"h300": {"1": h1, "500": h500}})]


# ------------------------------------------------------------------ the nonlinear model


def critical_k2(spec_for: object = None, lo: float = 100.0, hi: float = 1000.0, tol: float = 1e-3) -> float:
    """The K2 at which the §3.3 device's whippletree multiplier crosses 1 (bisection on
    log K2; the mode is unstable below it)."""
    make = spec_for if callable(spec_for) else drag_parity_spec
    radius = lambda k2: st.floquet(make(k2)).spectral_radius  # noqa: E731
    if not (radius(lo) > 1.0 > radius(hi)):
        return math.nan
    while hi / lo > 1 + tol:
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if radius(mid) > 1.0 else (lo, mid)
    return math.sqrt(lo * hi)


def floquet_devices() -> pl.DataFrame:
    """Floquet multipliers of the §3.3 devices (examples/hmf.toml, examples/drag_parity.toml at
    K2 = 1 and 500, also with the 1-Cut wing of Table 3.2 (docs/errata.md#11's ratio), the linear map of
    eq. 2.15 at K2 = 0 and 1) and of the §3.4 rotating-wing
    devices (Table 3.3 wings, hinge pinned to ±60° rotation, K2 = 0; see trials.section_3_4)."""
    import importlib

    # the package attribute `section_3_4` is the function; load the module itself
    s34 = importlib.import_module("paritysim.trials.section_3_4")

    p34 = s34.params()
    cases = {
        "hmf (§3.3)": hmf_spec(),
        "drag_parity (§3.3), K2 = 1": drag_parity_spec(1.0),
        "drag_parity (§3.3), K2 = 500": drag_parity_spec(500.0),
        "drag_parity (§3.3), 1-Cut (Ω ratio 0.599), K2 = 1": drag_parity_spec(1.0, omega_left=0.599 * 31.3),
        "drag_parity (§3.3), 1-Cut (Ω ratio 0.599), K2 = 500": drag_parity_spec(500.0, omega_left=0.599 * 31.3),
        "eq. 2.15 (§3.3 drag), K2 = 0": drag_parity_spec(0.0, linear=True),
        "eq. 2.15 (§3.3 drag), K2 = 1": drag_parity_spec(1.0, linear=True),
        "§3.4 HMF, Uncut": s34.device(p34, "HMF", "Uncut"),
        "§3.4 PARITY, Uncut": s34.device(p34, "PARITY", "Uncut"),
        "§3.4 PARITY, 1-Cut": s34.device(p34, "PARITY", "1-Cut"),
    }
    rows = []
    for label, spec in cases.items():
        f = st.floquet(spec)
        w = f.whippletree_multipliers
        rows.append(
            {
                "device": label,
                "multipliers": [str(complex(np.round(z, 10))) for z in f.multipliers],
                "spectral_radius": f.spectral_radius,
                "whippletree_radius": float(np.abs(w).max()) if w is not None else None,
                "stability": f.stability,
                "slowest_decay_ms": f.slowest_decay_ms,
                "growth_time_ms": f.growth_time_ms,
                "period_ms": f.period_ms,
                "monodromy_uncertainty": f.monodromy_uncertainty,
                "method": f.method,
            }
        )
    return pl.DataFrame(rows)


def floquet_k2(k2: np.ndarray | None = None) -> pl.DataFrame:
    """The whippletree multiplier vs K2 for the §3.3 linkage and its eq. 2.15 linearisation."""
    k2 = np.concatenate([[0.0], np.logspace(-1, 4, 41)]) if k2 is None else np.asarray(k2, dtype=float)
    frames = []
    for label, linear in (("linkage (§3.3)", False), ("eq. 2.15", True)):
        df = st.k2_sweep(drag_parity_spec(1.0, linear=linear), k2)
        frames.append(df.with_columns(pl.lit(label).alias("drivetrain")).select("drivetrain", *df.columns))
    return pl.concat(frames)


def _cli_floquet(out: Path) -> list[Path]:
    from .. import plots

    sweep = floquet_k2()
    devices = floquet_devices()
    written = [out / "floquet.parquet", out / "floquet.csv", out / "floquet_devices.parquet", out / "floquet_devices.csv"]
    sweep.drop("moduli").write_parquet(written[0])
    sweep.drop("moduli").write_csv(written[1])
    devices.write_parquet(written[2])
    devices.with_columns(pl.col("multipliers").list.join(" ")).write_csv(written[3])
    frames = {d: sweep.filter((pl.col("drivetrain") == d) & (pl.col("k2") > 0)) for d in sweep["drivetrain"].unique(maintain_order=True)}
    written.append(plots.save(st.plot_k2_sweep(frames), out / "floquet.png"))
    stability = dict(zip(devices["device"], devices["stability"], strict=True))
    linear = sweep.filter((pl.col("drivetrain") == "eq. 2.15") & (pl.col("k2") > 0))["stability"].to_list()
    k_crit = critical_k2()
    claims = [
        Claim.holds("§2.6.3: Drag PARITY on eq. 2.15 is stable for every K2 > 0", set(linear) == {"asymptotic"},
                    computed=f"{linear.count('asymptotic')} of {len(linear)} K2 values in (0, 10⁴] asymptotically stable", criterion="all asymptotic"),
        Claim.holds("§2.6.3: κ = 0 (K2 = 0) is the marginal case", stability["eq. 2.15 (§3.3 drag), K2 = 0"] == "marginal",
                    computed=stability["eq. 2.15 (§3.3 drag), K2 = 0"], criterion="a multiplier 1 within its error"),
        Claim.holds("§2.6.3: \"all implementations will be stable\": the §3.3 device (rod-crank linkage of examples/drag_parity.toml, K2 = 1)",
                    stability["drag_parity (§3.3), K2 = 1"] == "asymptotic", computed=stability["drag_parity (§3.3), K2 = 1"],
                    criterion="all multipliers inside the unit circle", note=f"unstable below K2 ≈ {k_crit:.0f} mN·mm/rad (docs/findings.md item 3)"),
    ]
    written.append(write_claims(out, "floquet", claims, {"devices": devices.drop("multipliers").to_dicts(), "critical_k2": k_crit}))
    return written


CLI_TRIALS = {"fig2.13": _cli_fig2_13, "sec2.7": _cli_sec2_7, "floquet": _cli_floquet}


# ------------------------------------------------------------------ report


def report_section(out: Path) -> str:
    """Markdown for report.md from the claims the ``fig2.13``, ``sec2.7`` and ``floquet`` trials
    wrote into ``out``."""
    from ._io import results

    linearised, _ = results(out, "fig2.13")
    rejection, sec27 = results(out, "sec2.7")
    nonlinear, flo = results(out, "floquet")
    h1, h500 = sec27["h300"]["1"], sec27["h300"]["500"]

    def fmt(v: float | None) -> str:
        return "-" if v is None else f"{v:.4g}"

    rows = "\n".join(
        f"| {r['device']} | {fmt(r['spectral_radius'])} | {fmt(r['whippletree_radius'])} | {r['stability']} "
        f"| {fmt(r['slowest_decay_ms'])} | {fmt(r['growth_time_ms'])} |"
        for r in flo["devices"]
    )
    return f"""## §2.6-2.7: stability and disturbance rejection

Linearised model (eq. 2.25, `paritysim.stability`), computed with a Taylor-series integrator.
Also verified in tests: eq. 2.52 is `M = exp(π Q)` and eq. 2.53 is `M^(n+1)` (docs/errata.md#10),
eq. 2.27's coefficient is `-¼β0² cos² t` (docs/errata.md#8), the drag forces of eqs. 2.17-2.19
carry `T³`, so `β0 = 2ΩΦ/I` (docs/errata.md#7).

{render(linearised)}

![Fig. 2.13](fig2_13.png)

Disturbance rejection (eq. 2.59), §3.3 device (examples/drag_parity.toml), β* from the
cycle-averaged aerodynamic damping of its simulated orbit: K2 = 1 gives β* = {h1['beta_star']:.3f} /ms,
κ0 = {h1['kappa0']:.3g} /ms²; K2 = 500 gives |H(300 Hz)| = {h500['h300']:.3g}. The rod-crank linkage adds a
geometric stiffness of {h500['geometric_stiffness']:.0f} mN·mm/rad to the whippletree mode, which eq. 2.59
ignores (see `sec2_7.csv` for the nonlinear response against the LTI estimate).

{render(rejection)}

![§2.7 transfer functions](sec2_7.png)

Full nonlinear model (shooting + finite-difference monodromy, multipliers per drive period
T = 9.09 ms; multipliers below ~1e-6 are at the resolution of the finite differences):

| device | max abs(ρ) | whippletree abs(ρ) | stability | slowest decay (ms) | growth time (ms) |
|---|---|---|---|---|---|
{rows}

{render(nonlinear)}

![Floquet multipliers vs K2](floquet.png)

The §3.4 rotating-wing PARITY (eq. 2.15, K2 = 0) has the same cyclic q2 direction as the K2 = 0
linear map (a multiplier 1); see the table above for the computed labels.
"""
