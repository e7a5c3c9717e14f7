"""Shared pytest configuration and the one end-to-end run of the trials.

``reproduced`` runs ``paritysim reproduce --all`` once per session into a temporary directory;
every test that checks trial outputs or the report reads that directory (and is marked
``slow``). ``pytest -m "not slow"`` skips it.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")


@pytest.fixture(scope="session")
def reproduced(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The output directory of one ``paritysim reproduce --all`` (CLI entry point, in process)."""
    from paritysim.cli import main

    out = tmp_path_factory.mktemp("reproduce_all")
    assert main(["reproduce", "--all", "--out", str(out), "--quiet"]) == 0
    return out
