"""Shared pytest configuration and the one end-to-end run of the trials.

``reproduced`` runs ``paritysim reproduce --all`` once per session into a temporary directory;
every test that checks trial outputs or the report reads that directory (and is marked
``slow``). ``pytest -m "not slow"`` skips it. Under pytest-xdist (``-n 2 --dist loadgroup``,
as ``scripts/test`` runs) those tests share one worker, so the trials still run once.
"""

from __future__ import annotations

import signal
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")

# A shell starts a background job (`cmd &`, nohup) with SIGINT ignored, and Python then leaves
# it ignored: `_thread.interrupt_main()` does nothing and the Ctrl-C tests fail. Python's own
# handler, as in a foreground run. The subprocesses these tests start (the CLI, spawned
# process-pool workers) exec a new interpreter, which resets a handled signal to its default
# and so installs Python's handler again (an ignored one would be inherited as ignored).
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(scope="session")
def reproduced(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The output directory of one ``paritysim reproduce --all`` (CLI entry point, in process)."""
    from paritysim.cli import main

    out = tmp_path_factory.mktemp("reproduce_all")
    assert main(["reproduce", "--all", "--out", str(out), "--quiet"]) == 0
    return out


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Every test that reads ``reproduced`` goes to one xdist worker (``--dist loadgroup``):
    a session fixture runs once per worker, and the trials take about a minute."""
    for item in items:
        if "reproduced" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.xdist_group("reproduced"))
