"""Every file path named in the map and the engine docs exists.

ARCHITECTURE.md, docs/engine.md, docs/recipes.md and docs/rust.md name files in backticks
(`crates/dynamics/src/device/drive.rs`, `device/form.rs`, `sweep/chain.rs::continued`). A
path there is resolved from the repository root, or inside the engine's source
(`crates/dynamics/src`) or the Python package (`python`, `python/paritysim`); one that resolves
nowhere is a stale map. Needs no extension module.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = ["ARCHITECTURE.md", "docs/engine.md", "docs/recipes.md", "docs/rust.md"]
BASES = [ROOT, ROOT / "crates/dynamics/src", ROOT / "python", ROOT / "python/paritysim"]
# A path: segments of name characters joined by "/", ending in a file name with one of these
# extensions or in "/" (a folder). `rad/mm` (a unit) and `ps.devices.list()/load()` are not.
EXTENSIONS = ("rs", "py", "pyi", "md", "toml", "json", "yml", "yaml", "txt", "sh")
PATH = re.compile(r"^[A-Za-z0-9_.\-<>*]+(?:/[A-Za-z0-9_.\-<>*]+)*(?:/|\.(?:%s))$" % "|".join(EXTENSIONS))


def named_paths(page: str) -> list[str]:
    text = (ROOT / page).read_text(encoding="utf-8")
    found = []
    for token in re.findall(r"`([^`\n]+)`", text):
        token = re.sub(r"(::|:\d).*$", "", token.strip())  # `file.rs::item`, `file.rs:12`
        if "/" in token and "<" not in token and PATH.match(token):
            found.append(token)
    return found


def resolves(path: str) -> bool:
    for base in BASES:
        if "*" in path:
            if any(base.glob(path)):
                return True
        elif (base / path).exists():
            return True
    return False


@pytest.mark.parametrize("page", PAGES)
def test_every_named_path_exists(page: str) -> None:
    paths = named_paths(page)
    assert paths, f"{page} names no file: the scan is broken"
    missing = sorted({p for p in paths if not resolves(p)})
    assert not missing, f"{page} names files that do not exist: {missing}"


def test_the_scan_sees_paths_and_skips_units() -> None:
    assert PATH.match("crates/dynamics/src/device/drive.rs")
    assert PATH.match("device/stroke_plane/")
    assert not PATH.match("rad/mm")
    assert not PATH.match("mN mm/rad")
    assert not resolves("crates/dynamics/src/device/no_such_file.rs")
    assert resolves("device/form.rs") and resolves("paritysim/spec.py")
