"""The CI tier of the whole-surface fuzz (issue 34): a seeded sample of the fast families of
``benchmarks/fuzz_report.py``, each case in a worker process with time and memory limits. Every
outcome must be a finite result or a typed error naming its field: no abort, hang, lost row,
foreign exception, silent non-finite value or unnamed error. The full run (every family,
thousands of cases, the CLI, concurrency and Ctrl-C) is ``python benchmarks/fuzz_report.py``."""

from __future__ import annotations

import argparse
import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _fuzz():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location("fuzz_report", ROOT / "benchmarks" / "fuzz_report.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_seeded_sample_of_the_public_surface_is_clean() -> None:
    fr = _fuzz()
    n, seed = 80, 2034
    args = argparse.Namespace(seed=seed, workers=1, time_limit=60.0, memory_gb=3.0, ctrl_c_s=0.1, families=fr.FAST, verbose=False)
    results = fr.run(args, list(range(n)), n)
    assert len(results) == n
    bad = [(r["i"], r["family"], r["outcome"], r.get("detail", "")) for r in results if r["outcome"] in fr.BAD]
    assert not bad, bad
    # The sample reaches the session 13-14 surface (drives, actuators, wings, table fits, gradients).
    assert {"drive_spec", "device_ctor", "calibrate_table", "gradients"} <= {r["family"] for r in results}
    outcomes = {r["outcome"] for r in results}
    assert fr.TYPED_FIELD in outcomes and fr.FINITE in outcomes  # the sample exercises both


def test_the_outcome_classes_are_told_apart() -> None:
    """The classifier itself: each class from a call built to produce it."""
    import math

    import numpy as np

    import paritysim as ps

    fr = _fuzz()

    def typed_no_field() -> None:
        raise ps.SingularError("x")

    cases = {
        fr.TYPED_FIELD: lambda: ps.kinematics.shoulder_pose("2", 1.0, 0.0, 0.0),
        fr.TYPED_NO_FIELD: typed_no_field,
        fr.FINITE: lambda: {"a": np.ones(3), "b": None},
        fr.NON_FINITE: lambda: {"a": [1.0, math.nan]},
        fr.FOREIGN: lambda: {}["missing"],
        fr.ROWS_LOST: lambda: {"__rows_lost__": 1},
    }
    for expected, call in cases.items():
        assert fr.classify(call, ps, np, 0.1)[0] == expected, expected
