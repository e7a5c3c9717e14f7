"""The wheel CI ships: `maturin build` it, install it into a fresh venv, use it there.

Marked slow (a build in the extension's profile plus a venv with the runtime dependencies:
minutes); deselect with ``-m "not slow"``.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

USE = """
import sys
import paritysim as ps
assert ps.__file__.startswith(sys.prefix), ps.__file__   # the installed copy, not the source tree
spec = ps.devices.load("sreetharan2012_3_3_parity_1cut")
r = ps.simulate(spec)
assert r.converged and r.metrics["left_stroke_amplitude"] > r.metrics["right_stroke_amplitude"]
print(len(ps.devices.list()))
"""


@pytest.mark.slow
def test_maturin_wheel_installs_into_a_fresh_venv_and_runs(tmp_path: Path) -> None:
    maturin = shutil.which("maturin") or str(Path(sys.executable).with_name("maturin"))
    dist = tmp_path / "dist"
    # The profile the extension was built with (scripts/_env.sh): its compiled crates are reused.
    profile = os.environ.get("PARITYSIM_PROFILE", "release")
    subprocess.run([maturin, "build", "--profile", profile, "--quiet", "--out", str(dist)], cwd=ROOT, check=True, env={**os.environ})
    wheels = list(dist.glob("paritysim-*.whl"))
    assert len(wheels) == 1, wheels
    names = zipfile.ZipFile(wheels[0]).namelist()
    assert any(n.endswith("devices/sreetharan2012_3_4_parity.toml") for n in names)
    assert any(n.endswith("devices/index.toml") for n in names)
    assert any(n.endswith("LICENSE-APACHE") for n in names) and any(n.endswith("LICENSE-MIT") for n in names)

    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    python = venv / "bin" / "python"
    # uv where the scripts installed it (the same wheel and dependency metadata, ~6x faster than
    # pip here: docs/findings.md §33); pip otherwise, as a user would.
    uv = Path(sys.executable).with_name("uv")
    installer = [str(uv), "pip", "install", "--quiet", "--python", str(python)] if uv.exists() else [str(python), "-m", "pip", "install", "--quiet"]
    subprocess.run([*installer, str(wheels[0])], check=True, cwd=tmp_path)
    out = subprocess.run([str(python), "-c", USE], check=True, capture_output=True, text=True, cwd=tmp_path)
    assert int(out.stdout.strip()) >= 17
    version = subprocess.run([str(python), "-m", "paritysim", "--version"], check=True, capture_output=True, text=True, cwd=tmp_path)
    assert version.stdout.startswith("paritysim ")
