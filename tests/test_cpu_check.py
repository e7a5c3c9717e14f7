"""The import-time CPU check guards exactly what the build compiles for (python/paritysim/_cpu.py)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from paritysim import _core, _cpu

ROOT = Path(__file__).resolve().parents[1]


def _config_features() -> list[str]:
    config = tomllib.loads((ROOT / ".cargo" / "config.toml").read_text())
    flags = config["target"]["cfg(target_arch = \"x86_64\")"]["rustflags"]
    enabled = [flag for flag in flags if flag.startswith("target-feature=")]
    assert len(enabled) == 1, flags
    return re.findall(r"\+([a-z0-9.]+)", enabled[0])


def test_required_list_is_the_cargo_config():
    assert tuple(_config_features()) == _cpu.REQUIRED_X86_64


def test_the_built_extension_needs_nothing_the_check_does_not_test():
    assert set(_core.__target_features__) <= set(_cpu.REQUIRED_X86_64)


def test_fma_stays_off_so_lanes_round_like_the_scalar_path():
    # Fused multiply-adds would round differently from the scalar path (docs/findings.md §18).
    assert "fma" not in _config_features()
    assert "fma" not in _core.__target_features__


def test_a_cpu_without_avx2_is_refused_with_the_remedy(monkeypatch):
    monkeypatch.delenv(_cpu.SKIP_ENV, raising=False)
    monkeypatch.setattr(_cpu, "cpu_features", lambda: {"AVX": True, "AVX2": False})
    monkeypatch.setattr(_cpu.platform, "machine", lambda: "x86_64")
    with pytest.raises(ImportError, match=r"lacks avx2\b.*RUSTFLAGS=\"\".*keep PARITYSIM_SKIP_CPU_CHECK=1 set"):
        _cpu.check()
    monkeypatch.setenv(_cpu.SKIP_ENV, "1")
    _cpu.check()  # skipped on request


def test_other_machines_and_unknown_features_pass():
    assert _cpu.missing_features({"AVX": False, "AVX2": False}, "aarch64") == []
    assert _cpu.missing_features(None, "x86_64") == []
    assert _cpu.missing_features({"AVX": True}, "AMD64") == ["avx2"]


@pytest.mark.skipif(_cpu.platform.machine().lower() not in ("x86_64", "amd64"), reason="x86-64 only")
def test_this_machine_reports_the_features_numpy_sees():
    features = _cpu.cpu_features()
    assert features is not None and "AVX2" in features


# A process whose CPU (as numpy reports it) lacks AVX2, then the command line started in it.
_NO_AVX2 = """
import sys
from numpy._core import _multiarray_umath as umath
umath.__cpu_features__["AVX2"] = False
sys.argv = [{argv0!r}, "--help"]
{start}
"""


@pytest.mark.skipif(_cpu.platform.machine().lower() not in ("x86_64", "amd64"), reason="x86-64 only")
@pytest.mark.parametrize(
    ("argv0", "start", "orig"),
    [
        ("/venv/bin/paritysim", "from paritysim.cli import main; raise SystemExit(main())", []),
        ("-m", "import runpy; runpy.run_module('paritysim', run_name='__main__')", ["-m", "paritysim"]),
    ],
    ids=["console-script", "python-m"],
)
def test_the_command_line_refuses_an_unsupported_cpu_in_one_line(argv0, start, orig):
    env = {k: v for k, v in os.environ.items() if k != _cpu.SKIP_ENV}
    code = _NO_AVX2.format(argv0=argv0, start=start)
    if orig:  # what ``python -m paritysim`` leaves in sys.orig_argv
        code = f"import sys; sys.orig_argv = [sys.executable, *{orig!r}]\n" + code
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert run.returncode == 1, run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in run.stderr, run.stderr
    assert lines[0].startswith("paritysim: error: paritysim's native extension is compiled") and "lacks avx2" in lines[0]


def test_only_the_command_line_counts_as_the_command_line():
    assert _cpu.running_cli(["/x/bin/paritysim", "sweep"], [])
    assert _cpu.running_cli(["-m"], ["/usr/bin/python3", "-m", "paritysim", "trials"])
    assert not _cpu.running_cli(["-c"], ["python", "-c", "import paritysim"])
    assert not _cpu.running_cli(["/x/bin/pytest"], ["python", "-m", "pytest"])
