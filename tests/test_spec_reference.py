"""docs/reference/spec.md lists every field of the Rust core's spec schema and is up to date."""

from __future__ import annotations

import importlib.util
import json
import re
from pathlib import Path

import pytest

import paritysim as ps

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "reference" / "spec.md"
SCHEMA = json.loads((ROOT / "python" / "paritysim" / "spec.schema.json").read_text(encoding="utf-8"))


def _generator():
    spec = importlib.util.spec_from_file_location("generate_spec_reference", ROOT / "scripts" / "generate_spec_reference.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _sections(text: str) -> dict[str, str]:
    """The page's level-2 sections by anchor (`## Actuator {#actuator}` -> its text)."""
    parts = re.split(r"^## .*\{#([\w-]+)\}$", text, flags=re.M)
    return dict(zip(parts[1::2], parts[2::2], strict=True))


def test_the_page_is_generated_from_the_current_schema():
    assert _generator().render() == PAGE.read_text(encoding="utf-8"), "run scripts/generate_spec_reference.py"


def test_every_schema_field_and_choice_has_a_row_in_its_section():
    sections = _sections(PAGE.read_text(encoding="utf-8"))
    expected: list[tuple[str, str]] = [("spec", f"| `{f}` |") for f in SCHEMA["properties"]]
    for name, node in SCHEMA["$defs"].items():
        key = name.lower().replace("_", "-")
        for obj in [node, *node.get("oneOf", [])]:
            expected += [(key, f"| `{f}` |") for f, p in obj.get("properties", {}).items() if not (f == "kind" and "const" in p)]
            if "const" in obj:
                expected.append((key, f'`"{obj["const"]}"`'))
            kind = obj.get("properties", {}).get("kind", {}).get("const")
            if kind:
                expected.append((key, f'`kind = "{kind}"`'))
    assert len(expected) > 150
    missing = [(s, row) for s, row in expected if row not in sections.get(s, "")]
    assert not missing, missing
    # and every numeric field states its unit column, range and meaning (no empty cells)
    for line in PAGE.read_text(encoding="utf-8").splitlines():
        if line.startswith("| `"):
            cells = [c.strip() for c in line.strip("|").split(" | ")]
            assert len(cells) == 5 and cells[2] and cells[3] and cells[4], line


@pytest.mark.parametrize("name", ps.devices.list())
def test_every_parameter_path_of_a_shipped_device_is_documented(name: str):
    text = PAGE.read_text(encoding="utf-8")
    for path in ps.spec_paths(ps.devices.load(name))["path"]:
        leaf = re.sub(r"\[\d+\]", "", path.rsplit(".", 1)[-1])
        if leaf == "kind":
            continue  # the variants are sections (`kind = "..."`), checked above
        assert f"| `{leaf}` |" in text, path


def test_the_page_is_in_the_site_navigation():
    assert "reference/spec.md" in (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
