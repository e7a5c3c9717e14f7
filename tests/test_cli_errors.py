"""The CLI on bad input: one line on stderr naming the problem, exit 1, never a traceback (issue 14)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from paritysim.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _cases(tmp: Path) -> dict[str, tuple[list[str], str]]:
    """name -> (argv, a phrase the one-line message must contain)."""
    (tmp / "empty.toml").write_text("")
    (tmp / "malformed.toml").write_text('name = "x"\n[actuator\n')
    (tmp / "binary.toml").write_bytes(b"\xff\xfe\x00garbage")
    (tmp / "wrong_type.toml").write_text((EXAMPLES / "hmf.toml").read_text().replace("crank_mm = 0.4", 'crank_mm = "wide"'))
    (tmp / "negative.toml").write_text((EXAMPLES / "hmf.toml").read_text().replace("frequency_hz = 110.0", "frequency_hz = -1.0"))
    (tmp / "unknown_key.toml").write_text((EXAMPLES / "hmf.toml").read_text().replace("[options]\n", "[options]\nrecord_cyles = 3\n"))
    (tmp / "study_missing_spec.toml").write_text('spec = "nowhere.toml"\n[grid]\n"actuator.voltage_v" = [1.0]\n')
    (tmp / "study_bad_path.toml").write_text(f'spec = "{EXAMPLES / "hmf.toml"}"\n[grid]\n"actuator.volts" = [1.0]\n')
    (tmp / "study_misspelt_device.toml").write_text('spec = "sreetharan2012_3_3_parit"\n[grid]\n"actuator.voltage_v" = [1.0]\n')
    (tmp / "optimize_misspelt_device.toml").write_text('spec = "sreetharan2012_3_3_parit"\nobjective = "delta_tau_peak"\n[params]\n"actuator.stiffness" = [100.0, 300.0]\n')
    (tmp / "study_mixed_axis.toml").write_text('spec = "sreetharan2012_3_3_parity"\n[grid]\n"actuator.frequency_hz" = [100.0, "x"]\n')
    (tmp / "study_huge_axis.toml").write_text('spec = "sreetharan2012_3_3_parity"\n[grid]\n"actuator.frequency_hz" = {start = 100, stop = 120, num = 100000000000}\n')
    (tmp / "study_all_fail.toml").write_text('spec = "sreetharan2012_3_3_parity"\n[grid]\n"actuator.frequency_hz" = [-1.0, -2.0]\n')
    (tmp / "study_options_not_a_table.toml").write_text('spec = "sreetharan2012_3_3_parity"\noptions = 5\n[grid]\n"actuator.frequency_hz" = [100.0]\n')
    (tmp / "study_log_text.toml").write_text('spec = "sreetharan2012_3_3_parity"\n[grid]\n"actuator.frequency_hz" = {start = 100, stop = 400, num = 3, log = "false"}\n')
    (tmp / "study_plot_typo.toml").write_text('spec = "sreetharan2012_3_3_parity"\nmetrics = ["left_stroke_amplitude"]\n[grid]\n"actuator.frequency_hz" = [100.0]\n[plot]\nx = "actuator.frequency_hz"\ny = "left_stroke_amplitud"\n')
    (tmp / "a_directory.toml").mkdir()
    blocker = tmp / "blocker"
    blocker.write_text("a file where a directory is expected")
    hmf = str(EXAMPLES / "hmf.toml")
    return {
        "missing spec": (["run", str(tmp / "missing.toml")], "missing.toml"),
        "empty spec": (["run", str(tmp / "empty.toml")], ""),
        "malformed spec": (["run", str(tmp / "malformed.toml")], "TOML"),
        "binary spec": (["run", str(tmp / "binary.toml")], "binary.toml"),
        "directory as spec": (["run", str(tmp / "a_directory.toml")], "a_directory.toml"),
        "wrong type": (["run", str(tmp / "wrong_type.toml")], "crank_mm"),
        "negative frequency": (["run", str(tmp / "negative.toml")], "frequency_hz"),
        "unknown option key": (["run", str(tmp / "unknown_key.toml")], "record_cyles"),
        "out is a file": (["run", hmf, "--out", str(blocker / "sub")], "blocker"),
        "reproduce out is a file": (["reproduce", "fig2.9", "--out", str(blocker / "sub"), "--quiet"], "blocker"),
        "missing study": (["sweep", str(tmp / "nope.toml")], "nope.toml"),
        "study with missing spec": (["sweep", str(tmp / "study_missing_spec.toml"), "--out", str(tmp / "o")], "nowhere.toml"),
        "study with unknown path": (["sweep", str(tmp / "study_bad_path.toml"), "--out", str(tmp / "o"), "--quiet"], "actuator.volts"),
        "malformed study": (["sweep", str(tmp / "malformed.toml")], "TOML"),
        # Every file the CLI reads is named with what it should hold (the fuzz, seed 34: a study
        # that was not UTF-8 gave "not a UTF-8 text file" without its path).
        "binary study": (["sweep", str(tmp / "binary.toml")], f"`study` = {tmp / 'binary.toml'}: must be a UTF-8 text file holding a sweep study"),
        "directory as study": (["sweep", str(tmp / "a_directory.toml")], f"`study` = {tmp / 'a_directory.toml'}: must be a readable file holding a sweep study"),
        "malformed study names the file": (["sweep", str(tmp / "malformed.toml")], f"`study` = {tmp / 'malformed.toml'}: must be a sweep study in valid TOML"),
        "binary continuation study": (["continue", str(tmp / "binary.toml")], f"`study` = {tmp / 'binary.toml'}: must be a UTF-8 text file holding a continuation study"),
        "missing continuation study": (["continue", str(tmp / "nope.toml")], f"`study` = {tmp / 'nope.toml'}: must be a readable file holding a continuation study"),
        "malformed continuation study": (["continue", str(tmp / "malformed.toml")], f"`study` = {tmp / 'malformed.toml'}: must be a continuation study in valid TOML"),
        # A misspelt device name: the nearest shipped ones, whichever command reads it.
        "misspelt device": (["run", "sreetharan2012_3_3_parit", "--out", str(tmp / "o")], "did you mean `sreetharan2012_3_3_parity`"),
        "study with a misspelt device": (["sweep", str(tmp / "study_misspelt_device.toml"), "--out", str(tmp / "o")], "did you mean `sreetharan2012_3_3_parity`"),
        "optimize study with a misspelt device": (["optimize", str(tmp / "optimize_misspelt_device.toml"), "--out", str(tmp / "o")], "did you mean `sreetharan2012_3_3_parity`"),
        # A mixed axis made every value text, so every point failed and the command said 0.
        "study with a mixed axis": (["sweep", str(tmp / "study_mixed_axis.toml"), "--out", str(tmp / "o"), "--quiet"], "`grid['actuator.frequency_hz'][1]` = 'x'"),
        "study with a huge axis": (["sweep", str(tmp / "study_huge_axis.toml"), "--out", str(tmp / "o"), "--quiet"], "`grid.actuator.frequency_hz.num`"),
        "study whose options are not a table": (["sweep", str(tmp / "study_options_not_a_table.toml"), "--out", str(tmp / "o"), "--quiet"], "`options` = 5"),
        # "false" was read as true: a log axis.
        "study with a text log flag": (["sweep", str(tmp / "study_log_text.toml"), "--out", str(tmp / "o"), "--quiet"], "`grid.actuator.frequency_hz.log`"),
        # Checked before the run (it failed after every point had run).
        "study with a misspelt plot column": (["sweep", str(tmp / "study_plot_typo.toml"), "--out", str(tmp / "o_typo"), "--quiet"], "did you mean `left_stroke_amplitude`"),
        "study whose every point fails": (["sweep", str(tmp / "study_all_fail.toml"), "--out", str(tmp / "o"), "--quiet"], "every one of the 2 points failed"),
    }


CASE_NAMES = [
    "missing spec",
    "empty spec",
    "malformed spec",
    "binary spec",
    "directory as spec",
    "wrong type",
    "negative frequency",
    "unknown option key",
    "out is a file",
    "reproduce out is a file",
    "missing study",
    "study with missing spec",
    "study with unknown path",
    "malformed study",
    "binary study",
    "directory as study",
    "malformed study names the file",
    "binary continuation study",
    "missing continuation study",
    "malformed continuation study",
    "misspelt device",
    "study with a misspelt device",
    "optimize study with a misspelt device",
    "study with a mixed axis",
    "study with a huge axis",
    "study whose every point fails",
    "study whose options are not a table",
    "study with a text log flag",
    "study with a misspelt plot column",
]


@pytest.mark.parametrize("case", CASE_NAMES)
def test_bad_input_is_one_line_and_exit_1(case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    argv, phrase = _cases(tmp_path)[case]
    assert main(argv) == 1
    err = capsys.readouterr().err.strip()
    lines = err.splitlines()
    assert lines[-1].startswith("paritysim: error: "), err
    # Before the error, only the CLI's own one-line warnings (a sweep's failed points).
    assert all(line.startswith("paritysim: warning: ") for line in lines[:-1]), err
    assert "Traceback" not in err, err
    assert phrase in lines[-1], err


def test_debug_flag_shows_the_traceback(tmp_path: Path) -> None:
    exe = Path(sys.executable).with_name("paritysim")
    missing = str(tmp_path / "missing.toml")
    plain = subprocess.run([str(exe), "run", missing], capture_output=True, text=True, check=False)
    debug = subprocess.run([str(exe), "run", missing, "--debug"], capture_output=True, text=True, check=False)
    assert plain.returncode == 1 and "Traceback" not in plain.stderr
    assert debug.returncode != 0 and "Traceback" in debug.stderr and "FileNotFoundError" in debug.stderr


@pytest.mark.parametrize(
    ("grid", "warning"),
    [
        # Python's default format printed the file, the line and `sys.exit(main())`.
        ('"actuator.frequency_hz" = [-1.0, -2.0, 110.0]', "paritysim: warning: 2 of 3 sweep points failed"),
        # Python hides DeprecationWarnings outside __main__: `drivetrain.k2` ran silently.
        ('"drivetrain.k2" = [0.0]', "paritysim: warning: parameter `drivetrain.k2` is deprecated: use `drivetrain.balance_spring`"),
    ],
)
def test_a_warning_is_one_line_without_python_source(grid: str, warning: str, tmp_path: Path) -> None:
    study = tmp_path / "study.toml"
    study.write_text(f'spec = "sreetharan2012_3_3_parity"\nmetrics = ["left_stroke_amplitude"]\n[grid]\n{grid}\n')
    exe = Path(sys.executable).with_name("paritysim")
    run = subprocess.run([str(exe), "sweep", str(study), "--out", str(tmp_path / "o"), "--quiet"], capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(warning), run.stderr


def test_a_misspelt_plot_column_fails_before_any_point_runs(tmp_path: Path) -> None:
    _cases(tmp_path)
    assert main(["sweep", str(tmp_path / "study_plot_typo.toml"), "--out", str(tmp_path / "o_typo"), "--quiet"]) == 1
    assert not (tmp_path / "o_typo" / "study_plot_typo.parquet").exists()


@pytest.mark.parametrize("flag", ["--all", "--list"])
def test_reproduce_all_or_list_with_trial_names_is_refused(flag: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # `reproduce --all table3.3` ignored the name and ran every trial.
    assert main(["reproduce", flag, "table3.3", "--out", str(tmp_path), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("paritysim: error:") and f"{flag} takes no trial names" in err
    assert not any(tmp_path.iterdir())
