"""Laminate design layer (issue 9; thesis §3.3.1 ref. [42], §4.2, §4.4.2, §4.5.3).

Everything here is computed by the laminate model; the thesis' statements are listed beside our
numbers for comparison only.
"""

from __future__ import annotations

from pathlib import Path

import polars as pl

from .. import laminate as lam
from ..claims import Claim, render
from ..spec import Actuator

#: What the thesis states (§3.3.1): 467 mN/mm and 120 mN amplitude at 100 V.
THESIS_STATEMENTS = {"stiffness": 467.0, "force_per_volt": 1.2}


def laminate_summary() -> tuple[pl.DataFrame, lam.Bimorph, lam.Layup]:
    """The actuator geometry that yields the thesis' constants, the Mobee stack and its cure curl.

    Returns a DataFrame with columns ``quantity, value, unit, thesis, note``, the designed
    :class:`paritysim.laminate.Bimorph` and the Mobee :class:`paritysim.laminate.Layup`.
    """
    bimorph = lam.Bimorph.design_for(lam.THESIS_ACTUATOR)
    actuator = Actuator.from_laminate(bimorph)
    stack = lam.Layup.mobee()
    kappa = stack.thermal_curvature(lam.CURE_DELTA_T)
    sub = lam.Layup.linkage_sublaminate()
    sub_kappa = sub.thermal_curvature(lam.CURE_DELTA_T)
    rows = [
        ("actuator stiffness", actuator.stiffness, "mN/mm", THESIS_STATEMENTS["stiffness"], "designed bimorph (Mobee actuator layup)"),
        ("actuator force per volt", actuator.force_per_volt, "mN/V", THESIS_STATEMENTS["force_per_volt"], "120 mN at 100 V"),
        ("actuator length", bimorph.length, "mm", None, "solved from the free deflection per volt"),
        ("actuator extension", bimorph.extension, "mm", None, "extension ratio 0.5"),
        ("actuator base width", bimorph.base_width, "mm", None, "solved from the stiffness (tip/base 0.5)"),
        ("actuator active mass", bimorph.active_mass, "mg", None, "heavy: the thesis' constants imply a large actuator"),
        ("Mobee stack layers", float(len(stack)), "-", 18.0, "Fig. 4.27"),
        ("Mobee stack thickness", stack.total_thickness_mm, "mm", None, "sum of layer thicknesses"),
        ("Mobee stack areal mass", stack.areal_mass, "mg/mm^2", None, ""),
        ("Mobee cure curvature kx", float(kappa[0]), "1/mm", None, "cooled from 200 °C (ΔT = -180 K), §4.5.3"),
        ("Mobee cure curvature ky", float(kappa[1]), "1/mm", None, "asymmetric (titanium on one face)"),
        ("linkage sublaminate cure curvature (max)", float(abs(sub_kappa).max()), "1/mm", 0.0, "symmetric layup: no curl"),
    ]
    df = pl.DataFrame(rows, schema=["quantity", "value", "unit", "thesis", "note"], orient="row")
    return df, bimorph, stack


def laminate_claims(df: pl.DataFrame) -> list[Claim]:
    """The thesis' statements the laminate layer reproduces (solved, then re-evaluated)."""
    row = dict(zip(df["quantity"], df["value"], strict=True))
    return [
        Claim.near("§3.3.1: actuator stiffness 467 mN/mm", row["actuator stiffness"], THESIS_STATEMENTS["stiffness"], 1e-6, rel=True, unit="mN/mm", fmt=".6g",
                   note="planform solved for it, then re-evaluated by the laminate model"),
        Claim.near("§3.3.1: 120 mN at 100 V", row["actuator force per volt"], THESIS_STATEMENTS["force_per_volt"], 1e-6, rel=True, unit="mN/V", fmt=".6g"),
        Claim.near("Fig. 4.27: the Mobee stack has 18 layers", row["Mobee stack layers"], 18.0, 0.0, fmt=".0f"),
        Claim.near("§4.5.3: a symmetric sublaminate does not curl on cure", row["linkage sublaminate cure curvature (max)"], 0.0, 1e-12, unit="1/mm", fmt=".1e"),
    ]


def report_markdown(df: pl.DataFrame) -> str:
    """Markdown section for the reproduction report."""
    lines = ["## Laminate design layer (§3.3.1 ref. [42], §4.4.2, §4.5.3)", "", "| quantity | paritysim | unit | thesis | note |", "|---|---|---|---|---|"]
    for q, v, u, t, n in df.iter_rows():
        lines.append(f"| {q} | {v:.6g} | {u} | {'' if t is None else f'{t:g}'} | {n} |")
    lines += ["", render(laminate_claims(df)), "", "The actuator constants are matched by solving for the planform; the result weighs about as much",
              "as the whole robot, so the thesis' constants were likely derived for a different drive definition",
              "(see `paritysim.laminate` docs).", ""]
    return "\n".join(lines)


def _cli_laminate(out: Path) -> list[Path]:
    import matplotlib.pyplot as plt

    from ._io import write_claims, write_trial

    df, _bimorph, stack = laminate_summary()
    fig, ax = plt.subplots(figsize=(8, 7), constrained_layout=True)
    stack.plot(ax=ax, to_scale=True)
    fig.suptitle(f"Fig. 4.27: the Mobee PC-MEMS stack to scale, total {1e3 * stack.total_thickness_mm:.1f} µm")
    written = write_trial(df, out, "laminate", fig)
    (out / "laminate.md").write_text(report_markdown(df))
    return [*written, out / "laminate.md", write_claims(out, "laminate", laminate_claims(df))]


CLI_TRIALS = {"laminate": _cli_laminate}


def report_section(out: Path) -> str:
    """Markdown for the report: the laminate trial's section as it wrote it into ``out``."""
    from ._io import results

    results(out, "laminate")  # runs the trial if it has not run
    return (out / "laminate.md").read_text() + "\n![Fig. 4.27 stack](laminate.png)\n"
