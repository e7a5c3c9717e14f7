"""Shared pytest configuration and the one end-to-end run of the trials.

``reproduced`` runs ``paritysim reproduce --all`` once per session into a temporary directory;
every test that checks trial outputs or the report reads that directory (and is marked
``slow``). ``pytest -m "not slow"`` skips it. Under pytest-xdist (``-n 2 --dist loadfile``,
as ``scripts/test`` runs) a module's tests stay on one worker, so its module fixtures run once,
and the workers share the one trial run.
"""

from __future__ import annotations

import os
import shutil
import signal
from pathlib import Path

import matplotlib
import pytest

try:
    import fcntl
except ImportError:  # not POSIX: each xdist worker runs the trials itself
    fcntl = None  # type: ignore[assignment]

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
    """The output directory of one ``paritysim reproduce --all`` (CLI entry point, in process).

    Under pytest-xdist the workers share one run: the first that needs it writes it into their
    common temporary directory while the others wait on a lock (a session fixture would
    otherwise run once per worker, and the trials take about a minute)."""
    from paritysim.cli import main

    def run(out: Path) -> Path:
        assert main(["reproduce", "--all", "--out", str(out), "--quiet"]) == 0
        return out

    if "PYTEST_XDIST_WORKER" not in os.environ or fcntl is None:
        return run(tmp_path_factory.mktemp("reproduce_all"))
    shared = tmp_path_factory.getbasetemp().parent / "reproduce_all"
    with open(shared.with_name("reproduce_all.lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        complete = shared.with_name("reproduce_all.complete")
        if not complete.exists():
            shutil.rmtree(shared, ignore_errors=True)
            shared.mkdir()
            run(shared)
            complete.touch()
    return shared
