"""Package surface: lazy imports, callable modules, logging, the sweep failure warning, labels."""

from __future__ import annotations

import logging
from pathlib import Path
import subprocess
import sys
import warnings

import pytest

import paritysim as ps

PROBE = """
import sys
import paritysim
heavy = [m for m in ("matplotlib", "polars", "scipy", "paritysim.trials") if m in sys.modules]
print(",".join(heavy) or "none")
"""
BACKEND = """
import matplotlib
matplotlib.use("svg")
import paritysim, paritysim.plots, paritysim.trials
print(matplotlib.get_backend())
"""


def test_import_is_lazy_and_keeps_the_matplotlib_backend() -> None:
    # What the import loads is the stable measure (the time is reported by benchmarks/import_time.py):
    # without matplotlib loaded, the backend cannot change.
    loaded = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, check=True).stdout.strip()
    assert loaded == "none", f"import paritysim loaded {loaded}"
    backend = subprocess.run([sys.executable, "-c", BACKEND], capture_output=True, text=True, check=True).stdout.strip()
    assert backend == "svg"  # even the plotting modules leave the user's choice alone


def test_dir_lists_the_public_names_and_each_resolves() -> None:
    names = dir(ps)
    for own_import in ("importlib", "logging", "Any", "TYPE_CHECKING", "annotations", "_cpu"):
        assert own_import not in names
    public = [n for n in names if not n.startswith("_")]
    assert {"simulate", "sweep", "sensitivity", "optimize", "Simulation", "flight"} <= set(public)
    for name in public:  # tab completion offers nothing that fails
        getattr(ps, name)


def test_sweep_and_section_3_4_are_modules_and_callable() -> None:
    import importlib

    sweep_module = importlib.import_module("paritysim.sweep")
    assert ps.sweep is sweep_module and callable(ps.sweep)
    assert "Parameter paths" in (ps.sweep.__doc__ or "")
    from paritysim.trials import section_3_4

    assert section_3_4 is importlib.import_module("paritysim.trials.section_3_4")
    assert callable(section_3_4) and hasattr(section_3_4, "params")


def test_label_columns_pass_through_and_are_not_parameters() -> None:
    spec = ps.devices.load("sreetharan2012_3_3_parity")
    rows = [{"cut": c, "wings.left.omega_ratio": 1.0 - c} for c in (0.0, 0.4)]
    df = ps.sweep(spec, rows, labels=["cut"], progress=False, metrics=["left_stroke_amplitude"], options={"max_cycles": 60})
    assert df["cut"].to_list() == [0.0, 0.4]
    # the cut wing (less drag) flaps wider under the PARITY: the labels sit on the right rows
    amp = df["left_stroke_amplitude"].to_list()
    assert amp[1] > amp[0]
    with pytest.raises(ps.InvalidParameterError, match="labels"):
        ps.sweep(spec, rows, labels=["missing"], progress=False)
    with pytest.raises(ps.InvalidParameterError, match="cut"):
        ps.sweep(spec, rows, progress=False)  # without labels= it is an unknown path


def test_mostly_failing_sweep_warns_with_the_most_common_error(caplog: pytest.LogCaptureFixture) -> None:
    spec = ps.devices.load("sreetharan2012_3_3_parity_linkage")
    with caplog.at_level(logging.WARNING, logger="paritysim"), pytest.warns(RuntimeWarning, match=r"of 2 sweep points failed; most common error \(\d points\): Integration") as record:
        df = ps.sweep(spec, {"wings.left.omega_ratio": [0.6, 0.42]}, progress=False)
    assert (df["status"] == "error").sum() > 1
    assert record[0].filename == __file__  # points at the caller, not at paritysim
    assert any("sweep points failed" in r.message for r in caplog.records)


def test_healthy_sweep_does_not_warn() -> None:
    spec = ps.devices.load("sreetharan2012_3_3_parity")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ps.sweep(spec, {"wings.left.omega_ratio": [1.0, 0.6]}, progress=False, options={"max_cycles": 60})


def test_python_dash_m_runs_the_cli() -> None:
    out = subprocess.run([sys.executable, "-m", "paritysim", "--version"], capture_output=True, text=True, check=True)
    assert out.stdout.startswith("paritysim ")


def test_cli_lists_devices_and_runs_one_by_name(tmp_path: Path) -> None:
    listing = subprocess.run([sys.executable, "-m", "paritysim", "devices"], capture_output=True, text=True, check=True).stdout
    assert "sreetharan2012_3_4_parity_1cut" in listing
    assert "sreetharan2012_3_3_parity_linkage" in listing and "[fails on cut wings]" in listing
    out = subprocess.run([sys.executable, "-m", "paritysim", "run", "sreetharan2012_3_3_parity", "--out", str(tmp_path)], capture_output=True, text=True, check=True)
    assert "converged" in out.stdout
    assert (tmp_path / "sreetharan2012_3_3_parity_metrics.csv").exists()
    bad = subprocess.run([sys.executable, "-m", "paritysim", "devices", "nope"], capture_output=True, text=True)
    assert bad.returncode == 1 and "InvalidParameterError" in bad.stderr and "Traceback" not in bad.stderr


def test_design_study_example_runs(tmp_path: Path) -> None:
    root = Path(__file__).resolve().parents[1]
    out = subprocess.run([sys.executable, str(root / "examples" / "design_study_3_4.py"), "--out", str(tmp_path), "--cuts", "3"], capture_output=True, text=True, check=True)
    assert "(0 failed)" in out.stdout
    import polars as pl

    df = pl.read_parquet(tmp_path / "design_study_3_4.parquet")
    assert df.height == 2 * 3 * 5 and set(df["cut_fraction"]) == {0.0, 0.15, 0.3}
