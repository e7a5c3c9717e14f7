"""The CLI and the Fig. 2.9 trial."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import polars as pl
import pytest

import paritysim as ps
from paritysim.cli import main

FIG2_9_COLUMNS = ["alpha2_deg", "alpha3_deg", "phi_deg", "theta_deg", "theta_w_deg", "reachable"]


def test_fig2_9_dataframe() -> None:
    df = ps.trials.fig2_9(step_deg=5.0)
    assert df.columns == FIG2_9_COLUMNS
    configs = df.select("alpha2_deg", "alpha3_deg").unique().sort("alpha2_deg", "alpha3_deg").rows()
    assert configs == [(90.0, 0.0), (90.0, 45.0), (120.0, 60.0)]
    # theta_w is null exactly where unreachable; (90°, 0°) satisfies eq. 2.10 everywhere, and only
    # its corners |phi| = |theta| = 90° (singular: eq. 2.13 has zero determinant) are masked.
    assert df.filter(~pl.col("reachable"))["theta_w_deg"].null_count() == df.filter(~pl.col("reachable")).height
    masked = df.filter((pl.col("alpha3_deg") == 0.0) & ~pl.col("reachable"))
    assert set(zip(masked["phi_deg"].abs(), masked["theta_deg"].abs())) == {(90.0, 90.0)}
    # near the origin the joint is decoupled: theta_w(0, eps) ~ eps (§2.3.3)
    near = df.filter((pl.col("phi_deg") == 0.0) & (pl.col("theta_deg") == 5.0))
    np.testing.assert_allclose(near["theta_w_deg"].to_numpy(), 5.0, atol=1e-9)


def test_fig2_9_rejects_bad_grid() -> None:
    with pytest.raises(ps.InvalidParameterError, match="step_deg"):
        ps.trials.fig2_9(step_deg=0.0)


def test_cli_writes_parquet_csv_and_png(tmp_path: Path) -> None:
    assert main(["reproduce", "fig2.9", "--out", str(tmp_path), "--quiet"]) == 0
    df = pl.read_parquet(tmp_path / "fig2_9.parquet")
    assert df.columns == FIG2_9_COLUMNS and df.height > 1000
    assert pl.read_csv(tmp_path / "fig2_9.csv").columns == FIG2_9_COLUMNS
    png = (tmp_path / "fig2_9.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20_000


def test_cli_unknown_trial_fails_clearly(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["reproduce", "fig9.99", "--out", "unused"]) == 2
    err = capsys.readouterr().err
    assert "unknown trial `fig9.99`" in err and "paritysim reproduce --list` lists all" in err
    assert main(["reproduce", "fig2.99", "--out", "unused"]) == 2
    err = capsys.readouterr().err  # a typo names the trial meant, and a handful at most
    assert "did you mean `fig2.9`?" in err and err.count("`") <= 2 * 6 + 2, err


def test_console_script_runs() -> None:
    """The installed ``paritysim`` entry point (a subprocess); the full ``reproduce --all`` runs
    once per session in the ``reproduced`` fixture (conftest.py)."""
    exe = Path(sys.executable).with_name("paritysim")
    res = subprocess.run([str(exe), "reproduce", "--list"], capture_output=True, text=True, check=False)
    assert res.returncode == 0, res.stderr
    assert set(res.stdout.split()) == set(ps.trials.REGISTRY)


def test_reproduce_laminate_writes_section(tmp_path: Path) -> None:
    assert main(["reproduce", "laminate", "--out", str(tmp_path), "--quiet"]) == 0
    assert "Laminate design layer" in (tmp_path / "laminate.md").read_text()
    claims, _ = ps.claims.load(tmp_path / "laminate.claims.json")
    assert all(c.ok for c in claims), [c.computed for c in claims]


def test_trial_functions_are_exported() -> None:
    for name in ("fig2_9", "table_3_2", "fig3_2", "fig3_3", "fig3_4", "fig2_12", "section_3_4", "lift_dual_parity", "laminate_summary"):
        assert callable(getattr(ps.trials, name)), name
    expected = {"fig2.9", "table3.2", "fig3.2", "fig3.3", "fig3.4", "fig2.12", "calibration3.2", "table3.3", "fig3.11", "fig3.12", "fig3.13", "lift-dual", "laminate", "fig2.13", "sec2.7", "floquet"}
    assert expected <= set(ps.trials.REGISTRY)


def test_run_names_its_outputs_after_the_spec_name(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 33: `paritysim run lift_wide.toml` writes `<spec name>_*`, not `<file stem>_*`."""
    source = Path(__file__).resolve().parents[1] / "examples" / "hmf.toml"
    toml = tmp_path / "lift_wide.toml"
    toml.write_text(source.read_text(encoding="utf-8").replace('name = "hmf"', 'name = "hmf wide/v2"', 1), encoding="utf-8")
    assert main(["run", str(toml), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    written = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert written == ["hmf_wide_v2.png", "hmf_wide_v2_metrics.csv", "hmf_wide_v2_trajectory.parquet"]
    metrics = pl.read_csv(tmp_path / "out" / "hmf_wide_v2_metrics.csv")
    assert metrics["left_stroke_amplitude"][0] > 0.1


def test_run_takes_a_device_name_and_prints_the_headline_numbers_with_units(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "sreetharan2012_3_4_parity", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    metrics = pl.read_csv(tmp_path / "sreetharan2012_3_4_parity_metrics.csv")
    # each printed number is the written metric, with its unit
    for label, key in [("lift_mean (mN)", "lift_mean"), ("actuator_power_mean (mW)", "actuator_power_mean"), ("lift_per_power (mN/mW)", "lift_per_power"), ("left_rotation_amplitude (rad)", "left_rotation_amplitude")]:
        line = next(line for line in out.splitlines() if line.strip().startswith(label))
        assert float(line.split()[-1]) == pytest.approx(metrics[key][0], rel=1e-5)
    assert f"({metrics.width} metrics in sreetharan2012_3_4_parity_metrics.csv)" in out
