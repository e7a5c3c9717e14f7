"""Ctrl-C latency of the long calls of the API on pathological inputs (issue 14).

Each trial starts a child Python that runs one long call: ``ps.simulate`` and ``ps.sweep`` (in
process and on a 2-worker ``ProcessPoolExecutor``) of the §3.4 HMF device at
``frequency_hz = 1e-3`` (an integration of minutes), ``ps.stability.floquet`` of it,
``ps.stability.k2_sweep`` of the Drag PARITY device at 1e-3 Hz, a 4M-point Hill chart and
``ps.continuation``. It sends SIGINT once the call is running and reports the time from the
signal to the child's ``except KeyboardInterrupt`` (both sides read CLOCK_MONOTONIC); for the
executor sweep it is the time until the interrupt is raised in the parent, after the chunks
running in the workers have stopped and handed back their finished points. Prints the median
and the worst of the trials per call, interleaved.

    python benchmarks/ctrl_c_latency.py [--trials 7] [--kinds simulate,sweep,...]
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
    import concurrent.futures as cf
    import numpy as np
    import paritysim as ps
    from paritysim import stability
    spec = ps.load_spec(sys.argv[1] + "/hmf.toml")
    parity = ps.load_spec(sys.argv[1] + "/drag_parity.toml").with_paths({"actuator.frequency_hz": 1e-3})
    slow = {"actuator.frequency_hz": [1e-3] * 4}
    slow_spec = spec.with_paths({"actuator.frequency_hz": 1e-3})
    kind = sys.argv[2]
    pool = cf.ProcessPoolExecutor(2) if kind == "sweep_executor" else None
    if pool is not None:
        list(pool.map(abs, [1, 2]))  # workers started before the clock matters
    print("ready", flush=True)
    try:
        if kind == "simulate":
            ps.simulate(slow_spec, max_wall_ms=600000.0)
        elif kind == "sweep":
            ps.sweep(spec, slow, options={"max_wall_ms": 600000.0}, threads=2, progress=False)
        elif kind == "sweep_executor":
            ps.sweep(spec, slow, options={"max_wall_ms": 600000.0}, executor=pool, chunk_size=1, progress=False)
        elif kind == "floquet":
            stability.floquet(slow_spec)
        elif kind == "k2_sweep":
            stability.k2_sweep(parity, [1.0, 2.0, 3.0, 4.0])
        elif kind == "chart":
            stability.stability_chart(np.linspace(0, 3, 2000), np.linspace(-1, 30, 2000), brockett=False)
        elif kind == "continuation":
            ps.continuation(slow_spec, "actuator.waveform.frequency_hz", 2e-3, start=1e-3)
        print("finished", flush=True)
    except KeyboardInterrupt:
        print(f"interrupted {time.monotonic()!r}", flush=True)
    """
)


KINDS = ("simulate", "sweep", "sweep_executor", "floquet", "k2_sweep", "chart", "continuation")


def trial(kind: str) -> float:
    proc = subprocess.Popen([sys.executable, "-c", CHILD, str(ROOT / "examples"), kind], stdout=subprocess.PIPE, text=True)
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
    parser.add_argument("--kinds", default=",".join(KINDS))
    args = parser.parse_args()
    results: dict[str, list[float]] = {k: [] for k in args.kinds.split(",")}
    for _ in range(args.trials):  # interleaved: load changes hit both alike
        for kind in results:
            results[kind].append(trial(kind))
    for kind, lat in results.items():
        print(f"{kind:15s} Ctrl-C latency: median {1e3 * statistics.median(lat):6.1f} ms, worst {1e3 * max(lat):6.1f} ms over {len(lat)} trials")


if __name__ == "__main__":
    main()
