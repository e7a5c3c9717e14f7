"""The report section that reruns §3.4 and the hover trim under Whitney & Wood 2010 (issue 32
item 4): its numbers are the model's (recomputed here independently of the trial), and its
verdicts follow from them."""

from __future__ import annotations

import json
import math

import pytest

import paritysim as ps
from paritysim.trials import aero_models, section_3_4


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("aero_models")
    files = ps.trials.REGISTRY["aero.whitney_wood2010"](out)
    return out, files


def test_the_trial_writes_its_tables_figures_and_computed_verdicts(written):
    out, files = written
    names = {f.name for f in files}
    assert {"aero_whitney_wood2010.png", "aero_whitney_wood2010_1cut.png", "aero_whitney_wood2010_trim.csv"} <= names
    claims = json.loads((out / "aero_whitney_wood2010.claims.json").read_text())
    verdicts = [c["ok"] for c in claims["claims"]]
    assert verdicts and all(v in (True, False) for v in verdicts)  # every verdict computed
    text = aero_models.report_section(out)
    assert text.startswith("## Beyond the thesis") and "| §3.4 statement |" in text


def test_the_whitney_wood_numbers_are_the_models(written):
    """The trial's W&W PARITY Uncut row against a direct run of the same device."""
    out, _ = written
    import polars as pl

    df = pl.read_parquet(out / "aero_whitney_wood2010.parquet")
    p = section_3_4.params(aero="whitney_wood2010")
    k = section_3_4.hinge_stiffness(p)
    run = ps.simulate(section_3_4.device(p, "PARITY", "Uncut", hinge=k), columns=["right_psi"])
    row = df.filter((pl.col("aero") == "whitney_wood2010") & (pl.col("drivetrain") == "PARITY") & (pl.col("trial") == "Uncut")).row(0, named=True)
    assert row["right_stroke_p2p_deg"] == pytest.approx(math.degrees(run.metrics["right_stroke_peak_to_peak"]), rel=1e-12)
    # The pinned hinge makes the right wing rotate the stated 60 degrees under each model.
    assert row["right_rotation_amplitude_deg"] == pytest.approx(60.0, abs=0.01)
    # Every wing of the W&W device carries the added terms at their published values.
    for wing in section_3_4.device(p, "PARITY", "Uncut", hinge=k).wings:
        assert wing.aero.kind == "whitney_wood2010"
        assert wing.aero.rotational_lift == 1.0 and wing.aero.translational_added_mass == 1.0


def test_the_trims_hold_lift_equal_to_weight(written):
    out, _ = written
    import polars as pl

    trims = pl.read_csv(out / "aero_whitney_wood2010_trim.csv")
    assert trims.height == 4 and trims["converged"].all()
    for r in trims.iter_rows(named=True):
        assert r["lift_mn"] == pytest.approx(r["weight_mn"], rel=1e-6)


def test_the_comparison_claim_follows_from_the_per_model_verdicts():
    df, trim = aero_models.table(), aero_models.trims()
    by = aero_models.per_model_claims(df)
    summary = next(c for c in aero_models.claims(df, trim) if c.statement.startswith("every §3.4 statement"))
    expected = all(new.ok for old, new in zip(by["blade_element"], by["whitney_wood2010"], strict=True) if old.ok)
    assert summary.ok == expected
