"""The import-time CPU check guards exactly what the build compiles for (python/paritysim/_cpu.py)."""

from __future__ import annotations

import re
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
