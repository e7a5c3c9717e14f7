"""10,000 generated inputs across the public API and the split of their outcomes (issue 14).

Families: ``ps.simulate`` on specs with mutated fields (spec paths), spec TOML text with a
mutated value, ``ps.Planform``, ``ps.kinematics``, ``ps.laminate.Flexure``, ``ps.stability``
(Hill/LTI functions) and ``ps.sweep`` (100-point sweeps with about 10 % invalid points; each row
counts as one input). Each input ends in one of:

* finite result: every number reachable in the result is finite (None for undefined metrics);
* typed error naming the field: a ``ParitysimError`` with ``.field`` set (also a failure
  found only while running, a rod-crank driven past its reach or the shoulder's joint limit,
  which names the field most responsible and its computed range);
* typed model error: a ``ParitysimError`` without a field (the done-when of issue 14 asks for
  none; seed 14: 6,210 naming the field, 3,790 finite, 0 of these);
* typed error not naming the field: an ``InvalidParameterError`` without ``.field``;
* other exception (not a ``ParitysimError``), non-finite result, or past the time limit.

    python benchmarks/fuzz_report.py [--n 10000] [--seed 14]
"""

from __future__ import annotations

import argparse
import json
import math
import random
import tempfile
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import paritysim as ps
from paritysim import laminate, stability

ROOT = Path(__file__).resolve().parents[1]
SMALL = {"min_cycles": 1, "max_cycles": 4, "samples_per_cycle": 24, "record_cycles": 1, "max_wall_ms": 10_000.0}
TIME_LIMIT_S = 20.0
BAD = [-1.0, 0.0, -0.0, 5e-324, 1e-300, 1e300, -1e300, 1e308, math.nan, math.inf, -math.inf, "3", "x", None, True, [1.0], {"a": 1}, 2**63, -(2**70), 10**15]


def _finite(value: Any) -> bool:
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    if isinstance(value, list | tuple):
        return all(_finite(v) for v in value)
    if isinstance(value, np.ndarray):
        return value.dtype.kind not in "fc" or bool(np.isfinite(value).all())
    if isinstance(value, float | complex):
        return math.isfinite(abs(value))
    if hasattr(value, "to_numpy") and hasattr(value, "columns"):  # a polars DataFrame
        return all(_finite(value[c].to_numpy()) for c in value.columns if value[c].dtype.is_float())
    return True


def classify(call: Callable[[], Any]) -> str:
    start = time.perf_counter()
    try:
        result = call()
        ok = _finite(result)
        outcome = "finite result" if ok else "non-finite result"
    except ps.ParitysimError as exc:
        if getattr(exc, "field", None):
            outcome = "typed error naming the field"
        elif isinstance(exc, ps.InvalidParameterError):
            outcome = "typed error not naming the field"
        else:
            outcome = f"typed model error ({type(exc).__name__})"
    except Exception as exc:  # noqa: BLE001 - what we count
        outcome = f"other exception ({type(exc).__name__}: {str(exc)[:60]})"
    if time.perf_counter() - start > TIME_LIMIT_S:
        outcome = "past the time limit"
    return outcome


def _result_values(r: ps.SimulationResult) -> dict[str, Any]:
    return {"metrics": r.metrics, "columns": r.columns, "residual": r.residual}


def _number(rng: random.Random, typical: float) -> Any:
    """A plausible value most of the time, a hostile one sometimes."""
    return typical * rng.uniform(0.5, 2.0) if rng.random() < 0.7 else rng.choice(BAD)


class Families:
    def __init__(self, rng: random.Random) -> None:
        self.rng = rng
        self.bases = []
        for name in ("hmf.toml", "drag_parity.toml"):
            spec = ps.load_spec(ROOT / "examples" / name).with_paths({f"options.{k}": v for k, v in SMALL.items()})
            paths = [(p, json.loads(v)) for p, _u, _a, v in ps.spec.spec_paths(spec).rows()]
            self.bases.append((spec, paths))
        self.tmp = Path(tempfile.mkdtemp(prefix="fuzz_report_"))
        self.toml_count = 0

    def simulate(self) -> Callable[[], Any]:
        spec, paths = self.rng.choice(self.bases)
        values: dict[str, Any] = {}
        for p, v in paths:
            if isinstance(v, float) and not p.startswith("options.") and self.rng.random() < 0.5:
                values[p] = v * self.rng.uniform(0.7, 1.3)
        for _ in range(self.rng.choice([0, 0, 1, 1, 2])):
            p, _ = self.rng.choice(paths)
            values[p] = self.rng.choice(BAD)

        def run() -> Any:
            return _result_values(ps.simulate(spec.with_paths(values)))

        return run

    def toml(self) -> Callable[[], Any]:
        spec, _ = self.rng.choice(self.bases)
        lines = spec.to_toml().splitlines()
        numeric = [i for i, s in enumerate(lines) if "=" in s and s.split("=", 1)[1].strip()[:1] in "-0123456789"]
        i = self.rng.choice(numeric)
        token = self.rng.choice(["-1.0", "0", "1e300", "nan", "inf", '"x"', "true", "[1.0]", "{}", "18446744073709551616", "", "1.0.0", "'", "[[", "9" * 400, "-0.0"])
        lines[i] = lines[i].split("=", 1)[0] + "= " + token
        if self.rng.random() < 0.1:
            lines.insert(self.rng.randrange(len(lines)), self.rng.choice(["[options", "bogus = 1", "[[wings]]", "=", "\x00"]))
        self.toml_count += 1
        path = self.tmp / f"spec_{self.toml_count}.toml"
        path.write_text("\n".join(lines) + "\n")

        def run() -> Any:
            return _result_values(ps.simulate(ps.load_spec(path)))

        return run

    def planform(self) -> Callable[[], Any]:
        r = self.rng
        kind = r.randrange(3)
        segs = r.choice([4, 16, 128, 512, -1, 0, 2.5, "8", 10**7, 2**64])
        if kind == 0:
            return lambda: (p := ps.Planform.hmf_like(_number(r, 16.6), segments=segs)) and {"area": p.area, "span": p.span, "mean_chord": p.mean_chord}
        if kind == 1:
            return lambda: (p := ps.Planform.rectangle(_number(r, 15.0), _number(r, 5.0), _number(r, 1.0), _number(r, 0.5))) and {"area": p.area, "mean_chord": p.mean_chord}
        return lambda: (p := ps.Planform.semi_ellipse(_number(r, 15.0), _number(r, 5.0), segments=segs)) and {"area": p.area}

    def kinematics(self) -> Callable[[], Any]:
        r = self.rng
        if r.random() < 0.5:
            return lambda: ps.kinematics.shoulder_pose(_number(r, 0.5), _number(r, 0.3), _number(r, 0.4), _number(r, 0.1))
        drive = ps.Drivetrain.linear_differential(3.05, 2.5)
        return lambda: ps.kinematics.drivetrain_map(drive, [_number(r, 0.3)], _number(r, 0.1))

    def laminate(self) -> Callable[[], Any]:
        r = self.rng

        def run() -> Any:
            f = laminate.Flexure(_number(r, 3.0), _number(r, 0.5), _number(r, 7.5))
            return {"stiffness": f.stiffness, "plate": f.plate_stiffness, "limit": f.elastic_limit_angle()}

        return run

    def stability(self) -> Callable[[], Any]:
        r = self.rng
        k = r.randrange(3)
        if k == 0:
            return lambda: stability.hill_floquet(_number(r, 1.0), _number(r, 0.2))
        if k == 1:
            return lambda: stability.lti_transfer(_number(r, 1.0), _number(r, 0.5), [_number(r, 50.0)])
        return lambda: stability.brockett(_number(r, 0.5), _number(r, 6.0), _number(r, 0.1))


def sweep_rows(rng: random.Random, families: Families, n_points: int) -> Counter[str]:
    """One sweep of ``n_points`` with about 10 % invalid values; each row is one input."""
    spec, _ = families.bases[0]
    values = [100.0 * rng.uniform(0.6, 1.4) if rng.random() > 0.1 else rng.choice([-1.0, 0.0, math.nan, 1e9]) for _ in range(n_points)]
    out: Counter[str] = Counter()
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            df = ps.sweep(spec, {"actuator.frequency_hz": values}, metrics=["left_stroke_amplitude"], progress=False)
        except Exception as exc:  # noqa: BLE001
            out[f"other exception ({type(exc).__name__})"] += n_points
            return out
    out["sweep rows lost"] += n_points - df.height
    for row in df.iter_rows(named=True):
        if row["status"] == "ok":
            v = row["left_stroke_amplitude"]
            out["finite result" if v is None or math.isfinite(v) else "non-finite result"] += 1
        elif "`" in (row["error"] or ""):  # the engine names the field in backticks
            out["typed error naming the field"] += 1
        else:
            out[f"typed model error ({row['error_kind']}Error)"] += 1
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10_000)
    parser.add_argument("--seed", type=int, default=14)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    fam = Families(rng)
    weights = {"simulate": 0.2, "toml": 0.15, "planform": 0.15, "kinematics": 0.15, "laminate": 0.15, "stability": 0.1}
    n_sweep = round(args.n * 0.1)
    per_family: dict[str, Counter[str]] = {}
    start = time.perf_counter()
    for name, w in weights.items():
        counter: Counter[str] = Counter()
        for _ in range(round(args.n * w)):
            counter[classify(getattr(fam, name)())] += 1
        per_family[name] = counter
    sweeps: Counter[str] = Counter()
    while sum(sweeps.values()) < n_sweep:
        sweeps += sweep_rows(rng, fam, min(100, n_sweep - sum(sweeps.values())))
    per_family["sweep"] = sweeps
    total: Counter[str] = Counter()
    for c in per_family.values():
        total += c
    n = sum(total.values())
    print(f"{n} inputs in {time.perf_counter() - start:.0f} s (seed {args.seed})\n")
    print(f"{'outcome':60s} {'count':>7s}")
    for outcome, count in total.most_common():
        print(f"{outcome:60s} {count:7d}")
    print("\nper family:")
    for name, c in per_family.items():
        print(f"  {name:10s} " + ", ".join(f"{k}: {v}" for k, v in c.most_common()))


if __name__ == "__main__":
    main()
