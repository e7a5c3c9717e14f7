"""Cost of the spec boundary (JSON text -> schema walk -> typed spec -> Device) against one
simulation of the same spec, measured interleaved; prints medians and ratios.

Run:  python benchmarks/spec_boundary.py [--repeats 30]
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import paritysim as ps
from paritysim import _core

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=30)
    args = parser.parse_args()
    spec = ps.load_spec(EXAMPLES / "hmf.toml").replace(options=ps.Options(max_cycles=5, min_cycles=5, record_cycles=1))
    text = spec.to_dict()
    json_text = spec.to_json()
    cases = {
        "python to_dict + json.dumps": lambda: ps.spec._dumps(text),
        "rust validate + build (validate_spec)": lambda: _core.validate_spec(json_text),
        "rust override one path (spec_apply)": lambda: _core.spec_apply(json_text, '{"drivetrain.crank_mm": 0.41}'),
        "simulate (5 cycles)": lambda: _core.simulate(json_text),
    }
    times: dict[str, list[float]] = {k: [] for k in cases}
    for _ in range(args.repeats):  # interleaved: machine noise hits every case alike
        for name, f in cases.items():
            t0 = time.perf_counter()
            f()
            times[name].append(time.perf_counter() - t0)
    sim = statistics.median(times["simulate (5 cycles)"])
    for name, ts in times.items():
        med = statistics.median(ts)
        print(f"{name:40s} {med * 1e6:10.1f} us   ratio to simulate {med / sim:8.4f}")


if __name__ == "__main__":
    main()
