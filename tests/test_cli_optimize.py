"""`paritysim optimize study.toml`: a tiny study end to end, and bad study files as one-line
typed errors (exit 1, no traceback)."""

from __future__ import annotations

from pathlib import Path

import polars as pl
import pytest
from scipy.optimize import brentq

import paritysim as ps
from paritysim.cli import main

DEVICE = "sreetharan2012_3_4_parity"
WEIGHT = 60 * 9.81e-3  # mN: a 60 mg airframe (mg-mm-ms units)
AMPLITUDE = "actuator.waveform.amplitude_v"

TINY = f"""
spec = "{DEVICE}"
objective = "actuator_power_mean"
constraints = ["lift_mean >= {WEIGHT}"]
tol = 1e-10
out = "from_study"

[set]
"drivetrain.balance_spring" = 30.0

[params]
"{AMPLITUDE}" = [20.0, 150.0]
"""


def _write(tmp: Path, text: str, name: str = "study.toml") -> Path:
    path = tmp / name
    path.write_text(text)
    return path


def test_tiny_study_writes_the_optimum_history_and_plot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    study = _write(tmp_path, TINY)
    assert main(["optimize", str(study), "--quiet"]) == 0
    out = tmp_path / "from_study"  # the study's `out`, relative to the study file
    written = sorted(p.name for p in out.iterdir())
    assert written == ["study_convergence.png", "study_history.csv", "study_history.parquet", "study_optimum.toml"]
    assert capsys.readouterr().out == ""  # --quiet
    # Power grows with the amplitude, so the optimum is the amplitude at which lift = weight:
    # an independent root of whole ps.simulate runs.
    spec = ps.devices.load(DEVICE).with_paths({"drivetrain.balance_spring": 30.0})
    root = brentq(lambda v: ps.simulate(spec.with_paths({AMPLITUDE: v})).metrics["lift_mean"] - WEIGHT, 20.0, 150.0, xtol=1e-12)
    optimum = ps.load_spec(out / "study_optimum.toml")
    assert optimum.actuator.waveform.amplitude_v == pytest.approx(root, rel=1e-6)
    assert optimum.drivetrain.balance_spring == 30.0  # [set] carried into the saved spec
    history = pl.read_csv(out / "study_history.csv")
    assert history.columns == ["iteration", "objective", "max_violation", AMPLITUDE]
    assert history.equals(pl.read_parquet(out / "study_history.parquet"))
    assert history["iteration"][0] == 0 and history[AMPLITUDE][0] == 100.0  # starts at the device's value


def test_summary_line_and_out_flag(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    study = _write(tmp_path, TINY)
    assert main(["optimize", str(study), "--out", str(tmp_path / "flag")]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("study: optimum actuator_power_mean = ") and "active: lift_mean >= " in lines[0]
    assert (tmp_path / "flag" / "study_optimum.toml").is_file() and not (tmp_path / "from_study").exists()


def test_infeasible_study_exits_1_and_says_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    study = _write(tmp_path, TINY.replace(f"lift_mean >= {WEIGHT}", "lift_mean >= 1000.0").replace("tol = 1e-10", "tol = 1e-6\nmax_iterations = 20"))
    assert main(["optimize", str(study), "--out", str(tmp_path / "o")]) == 1
    out = capsys.readouterr().out
    assert "FAILED" in out and "infeasible" in out and "lift_mean >= 1000" in out
    assert (tmp_path / "o" / "study_optimum.toml").is_file()  # the returned point is still written


@pytest.mark.parametrize(
    ("edit", "phrase"),
    [
        (lambda t: t.replace('objective = "actuator_power_mean"', 'objective = "actuator_power_mean"\nobjectve = 1'), "`objectve`"),
        (lambda t: t.replace('objective = "actuator_power_mean"\n', ""), "`objective` = <missing>"),
        (lambda t: t.replace(f'spec = "{DEVICE}"', 'spec = "nowhere.toml"'), "nowhere.toml"),
        (lambda t: t.replace('"actuator_power_mean"', '"actuator_powr_mean"'), "`objective`"),
        (lambda t: t.replace(f'"{AMPLITUDE}" = [20.0, 150.0]', '"actuator.waveform.kind" = [0.0, 1.0]'), "`params`"),
        (lambda t: t.replace(f'"{AMPLITUDE}" = [20.0, 150.0]', f'"{AMPLITUDE}" = [150.0, 20.0]'), "low < high"),
        (lambda t: t.replace(f'"lift_mean >= {WEIGHT}"', '"lift_mean >> 1"'), "`constraints[0]`"),
        (lambda t: "params = 3\n" + t[: t.index("[params]")], "`params`"),
        (lambda t: t.replace('"drivetrain.balance_spring" = 30.0', '"drivetrain.balance_sprin" = 30.0'), "drivetrain.balance_sprin"),
        (lambda t: t + "[x0]\n\"actuator.waveform.amplitude_v\" = 500.0\n", "x0"),
        (lambda t: t.replace("[set]", 'method = "newton"\n[set]'), "`method`"),
        (lambda t: t + "[set\n", "valid TOML"),
    ],
    ids=["unknown key", "missing objective", "missing spec file", "unknown metric", "discrete path", "bounds order", "malformed constraint", "params not a table", "unknown set path", "x0 out of bounds", "method", "malformed TOML"],
)
def test_bad_study_is_one_typed_line(tmp_path: Path, capsys: pytest.CaptureFixture[str], edit, phrase: str) -> None:  # type: ignore[no-untyped-def]
    study = _write(tmp_path, edit(TINY))
    assert main(["optimize", str(study), "--out", str(tmp_path / "o"), "--quiet"]) == 1
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("paritysim: error: InvalidParameterError: "), lines[0]
    assert phrase in lines[0], lines[0]
    assert "Traceback" not in err
