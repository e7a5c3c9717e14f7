"""Every Python block of README.md and docs/ runs: the README quick start verbatim, in a clean
working directory, against the installed package (issue 33).

Blocks marked ``exec="on"`` in docs/ run in the mkdocs build (`scripts/test`, `scripts/docs`);
this file runs every other ```python block, and checks that nothing falls between the two.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FENCE = re.compile(r"^(?P<indent>[ \t]*)```(?P<info>[^\n`]*)\n(?P<body>.*?)^(?P=indent)```[ \t]*$", re.M | re.S)


@dataclass(frozen=True)
class Block:
    file: Path
    line: int
    info: str
    code: str

    @property
    def id(self) -> str:
        return f"{self.file.relative_to(ROOT)}:{self.line}"

    @property
    def built_by_mkdocs(self) -> bool:
        # mkdocs builds every page under docs/ (docs_dir) and markdown-exec runs `exec="on"`.
        return 'exec="on"' in self.info and (ROOT / "docs") in self.file.parents


def python_blocks() -> list[Block]:
    files = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    blocks = []
    for file in files:
        if "_ext" in file.parts:
            continue
        text = file.read_text(encoding="utf-8")
        for m in FENCE.finditer(text):
            info = m["info"].strip()
            if info.split(" ", 1)[0] not in {"python", "py", "pycon"}:
                continue
            code = "\n".join(line[len(m["indent"]) :] for line in m["body"].splitlines())
            blocks.append(Block(file, text.count("\n", 0, m.start()) + 1, info, code))
    return blocks


BLOCKS = python_blocks()
RUN_HERE = [b for b in BLOCKS if not b.built_by_mkdocs]

# Checks appended to a block (same process): what the README promises, as numbers.
AFTER = {
    "README.md": """
import math, pathlib
assert result.converged and result.metrics["left_stroke_amplitude"] > 0.1
assert df.height > 1000  # the last `df` is Fig. 2.9's map
assert abs(fit.model_outputs["left_stroke_amplitude"] - 0.6) < 1e-3, fit
assert 0.5 < fit.values["actuator.force_per_volt"] < 2.0
for png in ("drag_parity.png", "fig2_9.png"):
    assert pathlib.Path(png).stat().st_size > 10_000, png
print("README checks passed")
""",
}


def test_the_readme_quick_start_and_every_docs_block_are_covered():
    ids = [b.id for b in BLOCKS]
    assert any(i.startswith("README.md:") for i in ids), "the README quick start was not found"
    assert len(BLOCKS) >= 40, ids  # the tutorials' executed blocks are found too
    assert all(b.built_by_mkdocs for b in BLOCKS if b not in RUN_HERE)
    assert len(RUN_HERE) >= 2


@pytest.mark.parametrize("block", RUN_HERE, ids=[b.id for b in RUN_HERE])
def test_block_runs_verbatim_in_a_clean_directory(block: Block, tmp_path: Path):
    script = block.code + "\n" + AFTER.get(str(block.file.relative_to(ROOT)), "")
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
    env.update(MPLBACKEND="Agg", PYTHONSAFEPATH="1")  # the clean directory only, not the checkout
    run = subprocess.run(
        [sys.executable, "-c", script], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0, f"{block.id} failed:\n{run.stderr[-3000:]}"
    assert "Traceback" not in run.stderr
    if block.id.startswith("README.md"):
        assert "README checks passed" in run.stdout
