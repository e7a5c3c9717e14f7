"""Regenerates python/paritysim/devices/*.toml and index.toml from the trial constructors.

Run after changing a trial's device or the spec format:
    .venv/bin/python scripts/generate_devices.py
Each TOML is a plain spec (``ps.load_spec`` reads it); its provenance (what the thesis states,
with section or table, and what we chose and why) is in index.toml and in the file's header.
tests/test_devices.py checks that the shipped files still equal what the trials build.
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path
from typing import Any


ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "python" / "paritysim" / "devices"

S33_STATED = [
    "Right-wing drag parameter Ω^R = 31.3 mg·mm² (§3.3.2, Table 3.2)",
    "Wing inertia about the stroke axis 29.0 mg·mm² (§3.3.2)",
    "Actuator: 120 mN blocked force at 100 V, i.e. 1.2 mN/V, and stiffness 467 mN/mm (§3.3.1)",
    "Drive: 100 V amplitude sine at 110 Hz, no DC part (§3.3.1)",
    "Transmission '±200 µm → ±35°' (§3.3.2) gives T = 35° / 0.2 mm of eq. 2.15",
]
S33_CHOICES = [
    "Drivetrain: eq. 2.15 (linear differential), the model §2.6 proves stable; the rod-crank linkage of Fig. 2.7a is not given (docs/errata.md#14) and its whippletree mode is unstable at small K2 (docs/findings.md §3)",
    "Whippletree arm L = L1 = 2.5 mm (half the 5 mm whippletree): not stated",
    "Balance-beam spring K2 = 0 (docs/errata.md#14: not given; §2.6.3's κ2 = 0 case)",
    "Drag law τ = Ω C_N(90°) φ̇² with C_N from eqs. 3.5-3.6 (docs/errata.md#12; 1.0 would be eq. 2.16)",
    "Izz = 0.05 × Ixx: a fixed wing only uses Ixx; any positive value keeps the tensor valid",
]
S34_STATED = [
    "Wing inertia tensors Ixx, Iyy, Izz, Ixz and Ω1..Ω4 of each wing (Table 3.3)",
    "Drive V(t) = 100 V + 100 V sin(2π·110 Hz·t) (eq. 3.24)",
    "Configuration #3 Drag PARITY / #1 HMF with a free ψ hinge (Table 3.1, §3.4)",
    "Actuator 1.2 mN/V and 467 mN/mm (§3.3.1)",
]
S34_CHOICES = [
    "Hinge stiffness (springs.hinge, joint 6: the ψ hinge) pinned so the Uncut PARITY right wing rotates ±60°, the amplitude §3.4 reports: {hinge:.6g} mN·mm/rad (root finding on the model; not stated, docs/errata.md#14)",
    "dc_offset = 'ignore': the 100 V DC part biases the piezo without a net force (taken as a force it would hold a 45° stroke offset)",
    "Transmission: eq. 2.15 with '±200 µm → ±35°' as in §3.3; whippletree arm 2.5 mm; K2 = 0",
    "Coefficients: Dickinson et al. 1999 fits (eqs. 3.5-3.6); C_rd the aero crate's cited default; α sign convention of the aero crate (docs/errata.md#5)",
]


#: RoboBee-class vehicle: each value and where it comes from (cited only where found; otherwise a
#: representative estimate, said so).
ROBOBEE_STATED = [
    "One piezoelectric bimorph actuator per wing, the 'split actuator' design (Ma, Felton & Wood, IROS 2012: a 70 mg vehicle, peak lift 1.3 mN): drivetrain dual_linear",
    "Flapping frequency 120 Hz (Ma, Chirarattananon, Fuller & Wood, 'Controlled flight of a biologically inspired, insect-scale robot', Science 2013, as reported at its release: an 80 mg vehicle with a 3 cm wingspan flapping 120 times per second): actuator.waveform.frequency_hz",
    "Linear transmission 2.67 rad/mm, a wing of 54 mm² and 0.55 mg, drive 120-200 V at 60-180 Hz (the one-wing RoboBee-class bench sweep described in issue 35; its data carry no licence and are not shipped): drivetrain.transmission_ratio, the outline's area and the wing mass",
]
ROBOBEE_CHOICES = [
    "Wing outline: Planform.hmf_like() scaled to a 15 mm span (half the 3 cm wingspan of Ma et al. 2013, the shoulder offset neglected: representative) and 54 mm²; its inertia tensor, Ω1..Ω4 and the force parameter ½ρ∬z²dA from Wing.from_planform",
    "Wing mass split 0.45 mg membrane + 0.10 mg leading-edge spar (the 0.55 mg total is stated; the split is a representative estimate)",
    "Actuator 150 mN blocked force and 0.5 mm free deflection at 200 V (Actuator.from_blocked_force: 0.75 mN/V, 300 mN/mm): a representative estimate for a RoboBee-class bimorph, no published datasheet value found",
    "Actuator massless and lossless (actuator.mass_mg = damping = 0, the thesis' §3.2.2 assumption): free flight refuses an actuator mass",
    "Stroke flexure 10 mN·mm/rad and ψ hinge 4 mN·mm/rad: representative estimates (the hinge gives a ±53° passive rotation at the nominal drive, in the range of flapping-wing robots)",
    "Drive 100 V amplitude, no DC part: a representative operating point (±32° stroke, ±53° rotation with these estimates), below the one-wing bench's 120-200 V; configuration drag_parity (ψ free, deviation held) with the Dickinson et al. 1999 blade-element coefficients",
]


def robobee_device() -> Any:
    """The RoboBee-class vehicle of ROBOBEE_STATED / ROBOBEE_CHOICES: two wings, a linear drive per wing."""
    import paritysim as ps

    outline = ps.Planform.hmf_like().scaled(span_mm=15.0, area_mm2=54.0)
    wing = ps.Wing.from_planform(outline, mass_mg=0.45, line_masses={"leading_edge": 0.10}, hinge=4.0)
    actuator = ps.Actuator.from_blocked_force(150.0, 0.5, 200.0, waveform=ps.Waveform(amplitude_v=100.0, frequency_hz=120.0))
    return ps.Simulation(
        name="robobee_dual_linear",
        wings=(wing, wing),
        configuration=ps.Configuration("drag_parity"),
        drivetrain=ps.Drivetrain.dual_linear(2.67),
        actuator=actuator,
    ).with_paths({"wings[*].springs.stroke.stiffness": 10.0})


def trial_module(name: str) -> Any:
    return importlib.import_module(f"paritysim.trials.{name}")


def catalogue() -> dict[str, dict[str, Any]]:
    """name -> {spec, title, section, stated, choices, cut_wings}."""
    s33, s34, s25, s26 = (trial_module(n) for n in ("section_3_3", "section_3_4", "section_2_5", "section_2_6"))
    out: dict[str, dict[str, Any]] = {}
    p33 = s33.params()
    for drivetrain in ("PARITY", "HMF"):
        for trial, ratio in s33.TRIALS.items():
            suffix = "" if trial == "Control" else "_" + trial.replace("-", "").lower()
            name = f"sreetharan2012_3_3_{drivetrain.lower()}{suffix}"
            stated = [*S33_STATED, f"Left wing Ω^L = {ratio:g} Ω^R ({trial} trial, §3.3.2; docs/errata.md#11: the ratios define the trials)"]
            out[name] = dict(
                spec=s33.device(p33, drivetrain, ratio * p33.omega_r).replace(name=name),
                title=f"§3.3 {'Drag PARITY' if drivetrain == 'PARITY' else 'HMF'} with fixed wings, {trial} trial (Table 3.2)",
                section="§3.3, Table 3.2",
                stated=stated,
                choices=S33_CHOICES if drivetrain == "PARITY" else [c for c in S33_CHOICES if "K2" not in c and "Drivetrain" not in c] + ["Drivetrain: eq. 2.15 for both wings (the four-bar linearised like the PARITY)"],
                cut_wings=True,
            )
    out["sreetharan2012_3_3_parity_linkage"] = dict(
        spec=s26.drag_parity_spec(k2=1.0).replace(name="sreetharan2012_3_3_parity_linkage"),
        title="§3.3 Drag PARITY on the nonlinear rod-crank linkage (examples/drag_parity.toml)",
        section="§3.3.2, Fig. 2.7a",
        stated=[S33_STATED[0], S33_STATED[1], S33_STATED[2], S33_STATED[3], "Link lengths of §3.3.2: crank 0.4 mm, rod 0.8 mm, whippletree 5 mm"],
        choices=[
            "Linkage topology: a whippletree driving two rod-cranks perpendicular at rest (Fig. 2.7a is not in the text; docs/errata.md#14)",
            "K2 = 1 mN·mm/rad (not given). With this linkage the whippletree mode is UNSTABLE below K2 ≈ 377 mN·mm/rad (Floquet multiplier 1.78 at K2 = 0, docs/findings.md §3): cut-wing points run out of the linkage's domain. Use sreetharan2012_3_3_parity for cut wings",
            "Drag law C_N(90°) φ̇² (docs/errata.md#12); Izz = 1 (unused by fixed wings)",
        ],
        cut_wings=False,
    )
    out["sreetharan2012_3_3_hmf_four_bar"] = dict(
        spec=s26.hmf_spec().replace(name="sreetharan2012_3_3_hmf_four_bar"),
        title="§3.3 HMF on its nonlinear four-bar (examples/hmf.toml)",
        section="§2.3.1, §3.3",
        stated=[S33_STATED[0], S33_STATED[1], S33_STATED[2], S33_STATED[3], "HMF four-bar: 400 µm crank → 60° (§2.3.1)"],
        choices=["Rod 0.8 mm (not stated)", "Drag law C_N(90°) φ̇² (docs/errata.md#12); Izz = 1 (unused by fixed wings)"],
        cut_wings=True,
    )
    p34 = s34.params()
    hinge = s34.hinge_stiffness(p34)
    for drivetrain in ("PARITY", "HMF"):
        for trial in s34.TRIALS:
            suffix = "" if trial == "Uncut" else "_" + trial.replace("-", "").lower()
            name = f"sreetharan2012_3_4_{drivetrain.lower()}{suffix}"
            out[name] = dict(
                spec=s34.device(p34, drivetrain, trial, hinge=hinge).replace(name=name),
                title=f"§3.4 {'Drag PARITY' if drivetrain == 'PARITY' else 'HMF'} with rotating wings, {trial} trial (Table 3.3)",
                section="§3.4, Table 3.3",
                stated=[*S34_STATED, f"Right wing: the {trial} wing of Table 3.3; left wing the same in every trial (§3.4)"],
                choices=[c.format(hinge=hinge) for c in S34_CHOICES],
                cut_wings=True,
            )
    for config in ("lift_parity", "dual_parity"):
        name = f"sreetharan2012_2_5_{config}_1cut"
        out[name] = dict(
            spec=s25.device(config, "1-Cut", hinge_k2=20.0).replace(name=name),
            title=f"§2.5 {'Lift' if config.startswith('lift') else 'Dual'} PARITY exploration on the §3.4 1-Cut wings",
            section="§2.5, Table 3.1 #5/#7",
            stated=["Configuration (Table 3.1) and the §2.5.1 tunable hinge, stiffer with deviation", *S34_STATED[:2]],
            choices=[
                "Tunable hinge V = ½ (k0 + k2 θ²) ψ² with k0 the §3.4 hinge and k2 = 20 mN·mm/rad³ (the law and k2 are ours; §2.5 gives no numbers)",
                "Deviation spring (springs.deviation, joint 4) 10 mN·mm/rad: not stated",
                *[c.format(hinge=hinge) for c in S34_CHOICES[1:]],
            ],
            cut_wings=True,
        )
    out["sreetharan2012_2_6_parity_linear"] = dict(
        spec=s26.drag_parity_spec(k2=1.0, linear=True).replace(name="sreetharan2012_2_6_parity_linear"),
        title="§2.6 Drag PARITY linearised (eq. 2.15, T = L = 2.5), the Floquet-stable reference",
        section="§2.6, eq. 2.15",
        stated=[S33_STATED[0], S33_STATED[1], S33_STATED[2], S33_STATED[3], "Eq. 2.15 (linear differential) of §2.6"],
        choices=["T = 1/L3 = 2.5 rad/mm and L = L0/2 = 2.5 mm: the rest gain of the §3.3.2 linkage (docs/findings.md §2)", "K2 = 1 mN·mm/rad (not given)", "Drag law C_N(90°) φ̇² (docs/errata.md#12)"],
        cut_wings=True,
    )
    out["robobee_dual_linear"] = dict(
        spec=robobee_device(),
        title="RoboBee-class vehicle: two wings, one linear drive per wing",
        section="Ma et al. 2012, 2013; issue 35",
        stated=ROBOBEE_STATED,
        stated_in="the sources",
        choices=ROBOBEE_CHOICES,
        cut_wings=True,
    )
    return out


def header(name: str, entry: dict[str, Any]) -> str:
    lines = [f"# {name}: {entry['title']}", "# Units: mg, mm, ms, rad, V.  Load: ps.devices.load(" + repr(name) + ")", "#", f"# Stated in {entry.get('stated_in', 'the thesis')}:"]
    lines += [f"#   - {s}" for s in entry["stated"]]
    lines += ["# Our choices (not stated, or ambiguous) and why:"]
    lines += [f"#   - {c}" for c in entry["choices"]]
    lines += ["#", "# Generated by scripts/generate_devices.py from paritysim.trials; edit there.", ""]
    return "\n".join(lines) + "\n"


def main() -> int:
    OUT.mkdir(parents=True, exist_ok=True)
    cat = catalogue()
    index: dict[str, Any] = {}
    for name, entry in cat.items():
        (OUT / f"{name}.toml").write_text(header(name, entry) + entry["spec"].to_toml())
        index[name] = {k: entry[k] for k in ("title", "section", "stated", "choices", "cut_wings", "stated_in") if k in entry}
    import tomli_w  # only this script writes plain TOML data (specs are written by the Rust core)

    (OUT / "index.toml").write_text("# Provenance of every shipped device (generated by scripts/generate_devices.py).\n" + tomli_w.dumps(index))
    print(f"wrote {len(cat)} devices to {OUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
