"""§3.3 and §2.4.2 trials: properties the model must compute (never thesis numbers pasted)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import polars as pl
import pytest

import paritysim as ps
from paritysim.cli import main
from paritysim.trials import section_3_3 as s33

FAST = dict(samples_per_cycle=200)


@pytest.mark.parametrize("ratio", [0.85, 0.6, 0.35])
def test_hmf_imbalance_is_one_minus_the_drag_ratio(ratio: float) -> None:
    """A 1-DOF drivetrain moves both wings alike: drag torques stay in the ratio Ω^L/Ω^R."""
    p = s33.params(**FAST)
    m = s33.drag_metrics(ps.simulate(s33.device(p, "HMF", ratio * p.omega_r)))
    assert m["imbalance_peak_pct"] == pytest.approx(100 * (1 - ratio), rel=1e-9)
    assert m["imbalance_instantaneous_pct"] == pytest.approx(100 * (1 - ratio), rel=1e-9)


def test_parity_balances_total_torque_instantly_and_drag_far_better_than_hmf() -> None:
    p = s33.params(balance_stiffness=0.0, **FAST)
    cut = s33.TRIALS["2-Cut"] * p.omega_r
    parity = ps.simulate(s33.device(p, "PARITY", cut))
    cycle = parity.cycle
    total = (cycle["left_roll_aero"] + cycle["left_roll_inertial"] + cycle["right_roll_aero"] + cycle["right_roll_inertial"]).to_numpy()
    scale = np.abs(cycle["right_roll_aero"].to_numpy()).max()
    # massless whippletree with K2 = 0 and equal arms: the wings' total torques cancel at every instant
    assert np.abs(total).max() < 1e-8 * scale
    hmf = s33.drag_metrics(ps.simulate(s33.device(p, "HMF", cut)))
    par = s33.drag_metrics(parity)
    assert par["imbalance_peak_pct"] < 0.25 * hmf["imbalance_peak_pct"]


@pytest.mark.parametrize("arm_ratio", [0.5, 0.75])
def test_biased_whippletree_roll_torque_ratio_follows_the_arm_ratio(arm_ratio: float) -> None:
    _, ratio = s33.fig2_12(arm_ratio=arm_ratio, **FAST)
    assert ratio == pytest.approx(1 / arm_ratio, rel=1e-6)


def test_kick_recovers_within_one_wingstroke() -> None:
    _, recovery = s33.fig3_4(**FAST)
    cut = recovery.filter(pl.col("trial") != "Control")
    assert (cut["time_constant_ms"] < cut["period_ms"]).all()
    assert (cut["deviation_after_one_stroke"] < 0.05).all()


def test_calibration_recovers_known_parameters() -> None:
    truth = {"inertia": 12.0, "drag_multiplier": 1.3}

    def model(inertia: float, drag_multiplier: float) -> dict[str, float]:
        p = s33.params(inertia=inertia, drag_multiplier=drag_multiplier, **FAST)
        hmf = s33.drag_metrics(ps.simulate(s33.device(p, "HMF", p.omega_r)))
        par = s33.drag_metrics(ps.simulate(s33.device(p, "PARITY", 0.599 * p.omega_r)))
        amplitude = ps.simulate(s33.device(p, "HMF", p.omega_r)).metrics["right_stroke_amplitude"]
        return {"tau": hmf["tau_r_peak"], "inst": par["imbalance_instantaneous_pct"], "amplitude": amplitude}

    target = model(**truth)
    fit = ps.calibrate(model, target, {"inertia": (2.0, 40.0), "drag_multiplier": (0.3, 3.0)}, x0={"inertia": 20.0, "drag_multiplier": 1.0})
    assert fit.success
    assert fit.values["inertia"] == pytest.approx(truth["inertia"], rel=1e-4)
    assert fit.values["drag_multiplier"] == pytest.approx(truth["drag_multiplier"], rel=1e-4)
    assert fit.iterations.height > 3 and "cost" in fit.iterations.columns


def test_calibrate_spec_paths_and_errors() -> None:
    spec = ps.load_spec(Path(__file__).resolve().parents[1] / "examples" / "hmf.toml")
    with pytest.raises(ps.InvalidParameterError, match="path"):
        ps.calibrate(spec, {"left_stroke_amplitude": 0.5}, {"actuator.nonsense": (0.0, 1.0)})
    with pytest.raises(ps.InvalidParameterError, match="free"):
        ps.calibrate(spec, {"left_stroke_amplitude": 0.5}, {"actuator.force_per_volt": (2.0, 1.0)})


def test_cli_writes_the_section_3_3_files(tmp_path: Path) -> None:
    assert main(["reproduce", "table3.2", "fig2.12", "--out", str(tmp_path), "--quiet"]) == 0
    table = pl.read_csv(tmp_path / "table3_2.csv")
    assert table.columns == s33.TABLE_COLUMNS and table.height == 6
    assert pl.read_parquet(tmp_path / "fig2_12.parquet").columns == ["drivetrain", "time_ms", "tau_left", "tau_right"]
    assert (tmp_path / "table3_2.png").read_bytes()[:4] == b"\x89PNG"


def test_report_lists_every_table_3_2_cell(tmp_path: Path) -> None:
    assert main(["reproduce", "--all", "--out", str(tmp_path), "--quiet"]) == 0
    report = (tmp_path / "report.md").read_text()
    for drivetrain in ("HMF", "PARITY"):
        for trial in s33.TRIALS:
            for key in ("delta_tau_peak", "tau_r_peak", "tau_l_peak", "imbalance_instantaneous_pct", "imbalance_peak_pct"):
                assert re.search(rf"\| {drivetrain} \| {trial} \| {key} \| [-0-9.]+ \| [-0-9.]+ \| [-+0-9.]+ \| (matches|differs) \|", report), (drivetrain, trial, key)
    for figure in re.findall(r"!\[[^\]]*\]\(([^)]+)\)", report):
        assert (tmp_path / figure).exists(), figure
