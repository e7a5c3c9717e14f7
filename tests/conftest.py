"""Shared pytest configuration and the one end-to-end run of the trials.

``reproduced`` runs ``paritysim reproduce --all`` once per session into a temporary directory;
every test that checks trial outputs or the report reads that directory (and is marked
``slow``). ``pytest -m "not slow"`` skips it. Under pytest-xdist (``-n 2 --dist loadfile``,
as ``scripts/test`` runs) a module's tests stay on one worker, so its module fixtures run once,
and the workers share the one trial run, started in the background as they collect.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
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


def _shared_run(config: pytest.Config) -> Path:
    """Where the workers' one trial run goes: beside their own temporary directories."""
    return config._tmp_path_factory.getbasetemp().parent / "reproduce_all"  # type: ignore[attr-defined]


_CHILD: subprocess.Popen[bytes] | None = None


@pytest.hookimpl(trylast=True)  # after `-m` / `-k` deselected what will not run
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Under pytest-xdist, the first worker to collect a test that reads the trial run starts
    that run in a background process at once: the trials (about 40 s on one core) then overlap
    the other tests instead of one worker waiting for the other to finish them."""
    if "PYTEST_XDIST_WORKER" not in os.environ or fcntl is None:
        return
    if not any("reproduced" in getattr(item, "fixturenames", ()) for item in items):
        return
    shared = _shared_run(config)
    with open(shared.with_name("reproduce_all.lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if shared.with_name("reproduce_all.started").exists():
            return
        shutil.rmtree(shared, ignore_errors=True)
        shared.mkdir()
        cli = f"from paritysim.cli import main; raise SystemExit(main(['reproduce', '--all', '--out', {str(shared)!r}, '--quiet']))"
        # The shell records the exit status whatever ended the run (an exception, a crash of the
        # native module), written whole by a rename.
        record = '"$0" -c "$1"; echo $? > "$2.tmp" && mv "$2.tmp" "$2"'
        done = shared.with_name("reproduce_all.exit")
        log = open(shared.with_name("reproduce_all.log"), "w")  # noqa: SIM115 - the child's
        global _CHILD
        _CHILD = subprocess.Popen(["sh", "-c", record, sys.executable, cli, str(done)], stdout=log, stderr=subprocess.STDOUT)
        shared.with_name("reproduce_all.started").write_text(str(_CHILD.pid))


def pytest_unconfigure(config: pytest.Config) -> None:
    """A trial run still going when its worker ends is not needed (every test that reads it
    waited for it): stopped, not left behind."""
    if _CHILD is not None and _CHILD.poll() is None:
        _CHILD.kill()
        _CHILD.wait()


@pytest.fixture(scope="session")
def reproduced(tmp_path_factory: pytest.TempPathFactory, pytestconfig: pytest.Config) -> Path:
    """The output directory of one ``paritysim reproduce --all`` (CLI entry point).

    Without pytest-xdist it runs here, in process. Under pytest-xdist the workers share one
    run, started in the background when they collect (`pytest_collection_modifyitems`); this
    waits for it and fails with its log if it failed."""
    from paritysim.cli import main

    if "PYTEST_XDIST_WORKER" not in os.environ or fcntl is None:
        out = tmp_path_factory.mktemp("reproduce_all")
        assert main(["reproduce", "--all", "--out", str(out), "--quiet"]) == 0
        return out
    shared = _shared_run(pytestconfig)
    started = shared.with_name("reproduce_all.started")
    done = shared.with_name("reproduce_all.exit")
    pid = int(started.read_text())
    deadline = time.monotonic() + 900.0
    while not done.exists():
        # Ended without its exit file: killed. (The worker that started it reaps it with
        # poll(); for the other, a process that is gone.)
        if _CHILD is not None:
            ended = _CHILD.poll() is not None
        else:
            try:
                os.kill(pid, 0)
                ended = False
            except ProcessLookupError:
                ended = True
        if ended and not done.exists():
            break
        assert time.monotonic() < deadline, "the trial run took more than 15 minutes"
        time.sleep(0.2)
    log = shared.with_name("reproduce_all.log").read_text()
    status = done.read_text().strip() if done.exists() else "killed"
    assert status == "0", f"paritysim reproduce --all failed (exit status {status}):\n{log[-4000:]}"
    return shared
