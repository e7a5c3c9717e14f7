"""Ctrl-C latency of ``ps.simulate`` and ``ps.sweep`` on a pathological point (issue 14).

Each trial starts a child Python that runs the §3.4 HMF device at ``frequency_hz = 1e-3`` (an
integration of minutes), sends it SIGINT once it is integrating, and reports the time from the
signal to the child's ``except KeyboardInterrupt`` (both sides read CLOCK_MONOTONIC). Prints
the median and the worst of the trials.

    python benchmarks/ctrl_c_latency.py [--trials 7]
"""

from __future__ import annotations

import argparse
import signal
import statistics
import subprocess
import sys
import textwrap
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = textwrap.dedent(
    """
    import sys, time
    import paritysim as ps
    spec = ps.load_spec(sys.argv[1])
    slow = {"actuator.frequency_hz": [1e-3] * 4}
    print("ready", flush=True)
    try:
        if sys.argv[2] == "simulate":
            ps.simulate(spec.with_paths({"actuator.frequency_hz": 1e-3}), max_wall_ms=600000.0)
        else:
            ps.sweep(spec, slow, options={"max_wall_ms": 600000.0}, threads=2, progress=False)
        print("finished", flush=True)
    except KeyboardInterrupt:
        print(f"interrupted {time.monotonic()!r}", flush=True)
    """
)


def trial(kind: str) -> float:
    proc = subprocess.Popen([sys.executable, "-c", CHILD, str(ROOT / "examples" / "hmf.toml"), kind], stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None
    assert proc.stdout.readline().strip() == "ready"
    time.sleep(1.0)  # well inside the integration
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=120)
    word, _, stamp = out.strip().partition(" ")
    if word != "interrupted":
        raise SystemExit(f"{kind}: the child did not report an interrupt: {out!r}")
    return float(stamp) - sent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=7)
    args = parser.parse_args()
    results: dict[str, list[float]] = {"simulate": [], "sweep": []}
    for _ in range(args.trials):  # interleaved: load changes hit both alike
        for kind in results:
            results[kind].append(trial(kind))
    for kind, lat in results.items():
        print(f"{kind:9s} Ctrl-C latency: median {1e3 * statistics.median(lat):6.1f} ms, worst {1e3 * max(lat):6.1f} ms over {len(lat)} trials")


if __name__ == "__main__":
    main()
