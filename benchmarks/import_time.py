"""Median wall time of `import paritysim` in fresh interpreters, next to `import numpy` (peer).

    .venv/bin/python benchmarks/import_time.py [runs]
"""

from __future__ import annotations

import statistics
import subprocess
import sys

CODE = "import time; t = time.perf_counter(); import {m}; print(time.perf_counter() - t)"


def once(module: str) -> float:
    return float(subprocess.run([sys.executable, "-c", CODE.format(m=module)], capture_output=True, text=True, check=True).stdout)


def main() -> None:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 9
    times: dict[str, list[float]] = {"paritysim": [], "numpy": [], "polars": []}
    for _ in range(runs):  # interleaved: the machine is shared and noisy
        for m in times:
            times[m].append(once(m))
    med = {m: statistics.median(v) for m, v in times.items()}
    for m, v in med.items():
        print(f"import {m:10s} median {v * 1e3:8.1f} ms  ({v / med['numpy']:.2f}x numpy)")


if __name__ == "__main__":
    main()
