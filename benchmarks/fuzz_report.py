"""Generated inputs over the whole public surface and the split of their outcomes (issues 14, 34).

Every public function of ``paritysim`` (specs and files, simulate with and without a Python
controller, sweeps with checkpoints and executors, calibrate, flight, continuation, stability,
aero, kinematics, planform, laminate, devices; the session 13-14 surface: one-wing and per-wing
linear drives, polynomial transmissions, the drive's losses, Whitney & Wood aerodynamics,
datasheet and laminate actuators, planform wings and scaling, ``calibrate(data=...)`` and
``measured``, sensitivity, optimize with SLSQP/trust-constr/IPOPT, ``floquet(orbit_cycles=)``,
``paritysim optimize``/``reproduce``), every CLI command, file and concurrency faults
(two sweeps sharing a checkpoint, a process-pool executor) and Ctrl-C during the long calls.
Each case runs in a worker process with a memory limit (``RLIMIT_AS``: what the worker maps
after importing plus ``--memory-gb``) and a time limit (``--time-limit``): a worker that dies
is an *abort*, one past the limit a *hang*; either is replaced and the run goes on. Cases are
generated from ``(seed, index)`` alone, so any case can be replayed (``--replay N``).

Outcomes (the classes of issue 34's table):

* typed error naming the field: a ``ParitysimError`` with ``.field`` (a CLI error: exit status
  1 or 2 with one line naming the argument or field, no traceback);
* typed error naming no field;
* finite result: every number reachable in the result is finite (None for undefined values),
  a Ctrl-C honoured within ``--ctrl-c-s`` (0.1 s), a shared checkpoint with no row lost;
* non-finite result;
* foreign exception: anything not a ``ParitysimError`` (counted by type);
* abort, hang, rows lost (a sweep or shared checkpoint that lost a row or a table).

    python benchmarks/fuzz_report.py [--n 2000] [--seed 34] [--workers 2] [--families a,b]

``tests/test_fuzz_surface.py`` runs a seeded sample of the fast families in CI.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import select
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

TYPED_FIELD = "typed error naming the field"
TYPED_NO_FIELD = "typed error naming no field"
FINITE = "finite result"
NON_FINITE = "non-finite result"
FOREIGN = "foreign exception"
ABORT = "abort"
HANG = "hang"
ROWS_LOST = "rows lost"
CLASSES = (TYPED_FIELD, TYPED_NO_FIELD, FINITE, NON_FINITE, FOREIGN, ABORT, HANG, ROWS_LOST)
BAD = (ABORT, HANG, ROWS_LOST, FOREIGN, NON_FINITE, TYPED_NO_FIELD)

# ------------------------------------------------------------------ generated values

NAN, INF = math.nan, math.inf
BAD_NUMBERS: list[Any] = [-1.0, 0.0, -0.0, 5e-324, 1e-300, 1e300, -1e300, 1e308, NAN, INF, -INF, "3", "x", None, True, [1.0], {"a": 1}, 2**63, -(2**70), 10**15, 1j]
BAD_INTS: list[Any] = [-1, 0, 1, 2.5, "8", None, True, 2**63, 10**15, 10**9, NAN, [3]]
BAD_NAMES: list[Any] = ["", "bogus", "max_cycle", None, 3, b"x", ["a"], "wings[9].aero.omega1", "actuator.frequency"]


def bad_arrays(np: Any) -> list[Any]:
    return [[], [NAN], [1e308, -1e308], "abc", [[1.0, 2.0], [3.0]], np.zeros((2, 2, 2)), None, [None, 1.0], np.array([1, 2], dtype=object), {"a": 1}, np.full(3, INF), np.zeros(10**6), np.zeros(10**7), [1j]]


class Gen:
    """Values for one case: plausible most of the time, hostile sometimes (at least once)."""

    def __init__(self, rng: random.Random, np: Any) -> None:
        self.rng, self.np = rng, np
        self.hostile = rng.random() < 0.8
        self.used = False

    def _bad(self, p: float = 0.3) -> bool:
        hit = self.hostile and (self.rng.random() < p or not self.used)
        self.used |= hit
        return hit

    def num(self, typical: float) -> Any:
        return self.rng.choice(BAD_NUMBERS) if self._bad() else typical * self.rng.uniform(0.5, 2.0)

    def int(self, typical: int, lo: int = 1) -> Any:
        return self.rng.choice(BAD_INTS) if self._bad() else max(lo, int(typical * self.rng.uniform(0.5, 2.0)))

    def name(self, valid: list[str]) -> Any:
        return self.rng.choice(BAD_NAMES) if self._bad() else self.rng.choice(valid)

    def array(self, lo: float, hi: float, n: int = 8) -> Any:
        if self._bad():
            return self.rng.choice(bad_arrays(self.np))
        return self.np.linspace(lo, hi, self.rng.randint(1, n))


# ------------------------------------------------------------------ the cases

#: The spec paths of the session 13-14 surface, each with a typical value (a list: valid names).
NEW_PATHS: list[tuple[str, Any]] = [
    ("drivetrain.higher_odd_ratios", None), ("drivetrain.transmission_ratio", 2.67), ("drivetrain.cubic_ratio", 5.0),
    ("drivetrain.balance_damping", 0.3), ("drivetrain.balance_cubic", 10.0), ("actuator.mass_mg", 30.0), ("actuator.damping", 2.0),
    ("actuator.cubic_stiffness", 1e3), ("wings[*].springs.hinge_damping", 0.2), ("wings[0].springs.hinge_damping", 0.2),
    ("wings[*].aero.omega5", -3.0), ("wings[*].aero.omega6", 0.6), ("wings[*].aero.omega7", 2.9), ("wings[*].aero.omega8", -1.0),
    ("wings[*].aero.rotational_lift", 1.0), ("wings[*].aero.translational_added_mass", 1.0), ("wings[*].aero.rotational_added_mass", 1.0),
    ("wings[*].aero.kind", ["whitney_wood2010", "blade_element", "stroke_drag"]), ("wings[*].aero.model", ["whitney_wood2010", "dickinson1999"]),
    ("drivetrain.kind", ["single_linear", "dual_linear"]), ("actuator.waveform.amplitude_v", 80.0),
]  # fmt: skip

SMALL = {"min_cycles": 1, "max_cycles": 4, "samples_per_cycle": 24, "record_cycles": 1, "max_wall_ms": 10_000.0}


def _specs(ps: Any) -> dict[str, Any]:
    def small(name: str) -> Any:
        return ps.load_spec(EXAMPLES / name).with_paths({f"options.{k}": v for k, v in SMALL.items()})

    specs = {"hmf": small("hmf.toml"), "parity": small("drag_parity.toml"), "flight": small("free_flight.toml")}
    opts = {f"options.{k}": v for k, v in SMALL.items()}
    # The one-wing device (issue 35): a stroke-only wing on one linear drive, cubic transmission.
    one = ps.devices.load("sreetharan2012_3_3_parity").to_dict()
    wing = one["wings"][0]
    wing["aero"] = {"kind": "stroke_drag", "omega1": 10.0, "coefficient": 3.46}
    one.update(wings=[wing], configuration={"name": "single_wing_fixed"}, drivetrain={"kind": "single_linear", "transmission_ratio": 2.67, "cubic_ratio": 5.0})
    one["actuator"].update(mass_mg=20.0, damping=1.0, cubic_stiffness=500.0)
    specs["one_wing"] = ps.Simulation.from_dict(one).with_paths(opts)
    # One linear drive per wing, with an odd polynomial transmission.
    dual = specs["hmf"].to_dict()
    dual["drivetrain"] = {"kind": "dual_linear", "transmission_ratio": 2.67, "cubic_ratio": 5.0, "higher_odd_ratios": [1.0]}
    specs["dual"] = ps.Simulation.from_dict(dual)
    # Whitney & Wood 2010 aerodynamics from a planform, and the drive's losses.
    ww = ps.Wing.from_planform(ps.Planform.hmf_like(), mass_mg=0.5, aero_model=ps.Aero(kind="whitney_wood2010"), hinge=2.0).aero  # type: ignore[call-arg]
    parity = specs["parity"]
    specs["ww"] = parity.replace(wings=tuple(w.replace(aero=ww) for w in parity.wings))
    specs["lossy"] = parity.with_paths({"actuator.mass_mg": 30.0, "actuator.damping": 2.0, "actuator.cubic_stiffness": 1e3, "drivetrain.balance_damping": 0.3, "drivetrain.balance_cubic": 10.0, "wings[*].springs.hinge_damping": 0.2})
    return specs


class Cases:
    """Each family returns a zero-argument callable (run in the worker) from ``Gen`` values."""

    def __init__(self, ps: Any, np: Any, tmp: Path) -> None:
        self.ps, self.np, self.tmp = ps, np, tmp
        self.specs = _specs(ps)
        self.paths = {k: [(p, json.loads(v)) for p, _u, _a, v in ps.spec.spec_paths(s).rows()] for k, s in self.specs.items()}
        self.files = self._files()

    def _files(self) -> dict[str, Path]:
        t = self.tmp
        (t / "latin.toml").write_bytes("name = 'caf\xe9'\n".encode("latin-1"))
        (t / "broken.toml").write_text('name = "x"\n[actuator\n')
        (t / "empty.toml").write_text("")
        (t / "a_dir").mkdir(exist_ok=True)
        (t / "garbage.parquet").write_text("not parquet")
        (t / "a_file").write_text("x")
        good = t / "good.toml"
        good.write_text(self.specs["hmf"].to_toml())
        return {"latin": t / "latin.toml", "broken": t / "broken.toml", "empty": t / "empty.toml", "dir": t / "a_dir", "missing": t / "nope.toml", "good": good, "garbage": t / "garbage.parquet", "under_file": t / "a_file" / "x.parquet"}

    # -- specs and files
    def spec_mutation(self, g: Gen) -> Callable[[], Any]:
        key = g.rng.choice(["hmf", "parity", "flight"])
        spec, paths = self.specs[key], self.paths[key]
        values: dict[str, Any] = {}
        for p, v in paths:
            if isinstance(v, float) and not p.startswith("options.") and g.rng.random() < 0.3:
                values[p] = v * g.rng.uniform(0.7, 1.3)
        for _ in range(g.rng.choice([1, 1, 2])):
            p, _v = g.rng.choice(paths)
            values[p] = g.rng.choice([*BAD_NUMBERS, object(), {1, 2}, b"x", "nan"])
        return lambda: self.ps.simulate(spec.with_paths(values))

    def spec_file(self, g: Gen) -> Callable[[], Any]:
        target = g.rng.choice([*self.files.values(), 42, None, b"x"])
        if g.rng.random() < 0.5:
            lines = self.specs["hmf"].to_toml().splitlines()
            numeric = [i for i, s in enumerate(lines) if "=" in s and s.split("=", 1)[1].strip()[:1] in "-0123456789"]
            i = g.rng.choice(numeric)
            lines[i] = lines[i].split("=", 1)[0] + "= " + g.rng.choice(["-1.0", "nan", "inf", '"x"', "true", "[1.0]", "{}", "18446744073709551616", "", "'", "[[", "9" * 400])
            target = self.tmp / f"mutated_{g.rng.randrange(10**9)}.toml"
            target.write_text("\n".join(lines) + "\n")
        return lambda: self.ps.simulate(self.ps.load_spec(target))

    def spec_dict(self, g: Gen) -> Callable[[], Any]:
        d = self.specs["hmf"].to_dict()
        kind = g.rng.randrange(5)
        if kind == 0:
            node = d
            for _ in range(g.rng.choice([50, 500, 5000])):
                node["x"] = {}
                node = node["x"]
        elif kind == 1:
            d["actuator"] = g.rng.choice([None, 3, [1], "x", {"bogus": 1}])
        elif kind == 2:
            d = g.rng.choice([[], 3, "x", None, {"name": None}])
        elif kind == 3:
            return lambda: self.ps.Simulation.from_json(g.rng.choice(["{", "[]", "null", 3, json.dumps(self.specs["hmf"].to_dict())[:-5]]))
        else:
            d["options"] = {"max_cycles": g.rng.choice(BAD_INTS)}
        return lambda: self.ps.Simulation.from_dict(d)

    def spec_misc(self, g: Gen) -> Callable[[], Any]:
        s = self.specs["hmf"]
        k = g.rng.randrange(4)
        if k == 0:
            key = g.name(["actuator.frequency_hz"])
            return lambda: s.with_paths(g.rng.choice([[1], None, {key if isinstance(key, str | int | bytes) or key is None else repr(key): g.num(120.0)}]))
        if k == 1:
            return lambda: s.save(g.rng.choice([self.files["dir"], self.files["under_file"], 3, self.tmp / "saved.toml"]))
        if k == 2:
            return lambda: self.ps.devices.load(g.name(self.ps.devices.list()))
        return lambda: self.ps.devices.info(g.name(self.ps.devices.list()))

    # -- simulate
    def simulate(self, g: Gen) -> Callable[[], Any]:
        key = g.rng.choice(["hmf", "parity"])
        spec = self.specs[key]
        kwargs: dict[str, Any] = {}
        for opt, typical in (("record_cycles", 1), ("samples_per_cycle", 24), ("max_cycles", 4)):
            if g.rng.random() < 0.3:
                kwargs[opt] = g.int(typical)
        if g.rng.random() < 0.3:
            kwargs["columns"] = g.rng.choice([[], ["left_phi"], ["bogus"], 3, "left_phi"])
        if g.rng.random() < 0.3:
            kwargs["metrics"] = g.rng.choice([[], ["left_stroke_amplitude"], ["bogus"], [None]])
        if g.rng.random() < 0.2:
            kwargs["max_wall_ms"] = g.num(5000.0)
        return lambda: self.ps.simulate(spec, **kwargs)

    def controller(self, g: Gen) -> Callable[[], Any]:
        spec = self.specs["flight"]
        outs = [{}, {"q2_bias": 0.01}, {"bogus": 1.0}, {"q2_bias": NAN}, None, 3, {"q2_bias": "x"}]
        out = g.rng.choice(outs) if g._bad() else {}
        rate = g.num(500.0)
        return lambda: self.ps.simulate(spec, controller=lambda t, b: out, control_rate_hz=rate)

    # -- sweep
    def sweep(self, g: Gen) -> Callable[[], Any]:
        spec = self.specs["hmf"]
        n = g.rng.randint(1, 6)
        values = [100.0 * g.rng.uniform(0.8, 1.3) if g.rng.random() > 0.2 else g.rng.choice(BAD_NUMBERS + [object()]) for _ in range(n)]
        kwargs: dict[str, Any] = {"progress": False, "metrics": ["left_stroke_amplitude"]}
        for name, make in (
            ("threads", lambda: g.int(2)),
            ("chunk_size", lambda: g.int(2)),
            ("options", lambda: g.rng.choice([{"max_cycles": g.int(4)}, [1], {"bogus": 1}, {"max_wall_ms": g.num(5000.0)}])),
            ("keep_cycle", lambda: g.rng.choice([True, ["left_phi"], ["bogus"], 5, "left_phi"])),
            ("labels", lambda: g.rng.choice([5, ["nope"], []])),
            ("checkpoint", lambda: g.rng.choice([*self.files.values(), self.tmp / f"ck_{g.rng.randrange(10**9)}.parquet", 3])),
            ("metrics", lambda: g.rng.choice([[1], ["bogus"], "left_stroke_amplitude", None])),
        ):
            if g.rng.random() < 0.2:
                kwargs[name] = make()
        key = g.name(["actuator.frequency_hz"]) if g.rng.random() < 0.2 else "actuator.frequency_hz"
        grid = {key if isinstance(key, str | int | bytes) or key is None else repr(key): values}  # a dict key must hash

        def run() -> Any:
            import warnings

            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                df = self.ps.sweep(spec, grid, **kwargs)
            if df.height != n:
                return {"__rows_lost__": n - df.height}
            return df.drop(list(grid))  # the grid's own values come back as given (NaN too)

        return run

    def sweep_executor(self, g: Gen) -> Callable[[], Any]:
        def run() -> Any:
            import concurrent.futures as cf
            import warnings

            values = [100.0, g.num(110.0), 120.0]
            with cf.ProcessPoolExecutor(2) as pool, warnings.catch_warnings():
                warnings.simplefilter("ignore")
                df = self.ps.sweep(self.specs["hmf"], {"actuator.frequency_hz": values}, executor=pool, chunk_size=1, progress=False, metrics=["left_stroke_amplitude"])
            return {"__rows_lost__": 3 - df.height} if df.height != 3 else df.drop("actuator.frequency_hz")

        return run

    def shared_checkpoint(self, g: Gen) -> Callable[[], Any]:
        """Two sweeps (threads, or a child process and this one) on one checkpoint."""

        def run() -> Any:
            import threading

            import polars as pl

            path = self.tmp / f"shared_{g.rng.randrange(10**9)}.parquet"
            grids = [[100.0 + 5 * i for i in range(4)], [102.5 + 5 * i for i in range(4)]]
            out: dict[int, Any] = {}

            def one(i: int) -> None:
                try:
                    out[i] = self.ps.sweep(self.specs["hmf"], {"actuator.frequency_hz": grids[i]}, chunk_size=1, threads=1, checkpoint=path, progress=False, metrics=["left_stroke_amplitude"])
                except BaseException as exc:  # noqa: BLE001 - a lost table
                    out[i] = exc

            if g.rng.random() < 0.5:
                ts = [threading.Thread(target=one, args=(i,)) for i in range(2)]
                for t in ts:
                    t.start()
                for t in ts:
                    t.join()
            else:
                code = f"import paritysim as ps; spec = ps.load_spec({str(EXAMPLES / 'hmf.toml')!r}).with_paths({ {f'options.{k}': v for k, v in SMALL.items()}!r}); ps.sweep(spec, {{'actuator.frequency_hz': {grids[1]!r}}}, chunk_size=1, threads=1, checkpoint={str(path)!r}, progress=False, metrics=['left_stroke_amplitude'])"
                child = subprocess.Popen([sys.executable, "-c", code], stderr=subprocess.PIPE, text=True)
                one(0)
                _, err = child.communicate(timeout=120)
                out[1] = pl.DataFrame({"actuator.frequency_hz": grids[1]}) if child.returncode == 0 else RuntimeError(err[-300:])
            lost = sum(1 for v in out.values() if not isinstance(v, pl.DataFrame))
            saved = pl.read_parquet(path)["actuator.frequency_hz"].to_list() if path.exists() else []
            lost += len(set(grids[0] + grids[1]) - set(saved))
            return {"__rows_lost__": lost} if lost else {"rows": len(saved)}

        return run

    # -- calibrate, flight, continuation
    def calibrate(self, g: Gen) -> Callable[[], Any]:
        spec = self.specs["hmf"]
        targets = g.rng.choice([{"left_stroke_amplitude": g.num(0.6)}, {"bogus": 1.0}, {}, 3, {"left_stroke_amplitude": None}])
        free = g.rng.choice([{"actuator.force_per_volt": (g.num(0.5), g.num(2.0))}, {"actuator.force_per_volt": 5}, {"bogus": (0, 1)}, {}, [1]])
        kwargs = g.rng.choice([{}, {"max_nfev": g.int(2)}, {"x0": {"actuator.force_per_volt": g.num(1.0)}}, {"diff_step": g.num(1e-4)}, {"workers": g.int(2)}, {"xtol": g.num(1e-10)}])
        kwargs = {"max_nfev": 3, **kwargs}
        return lambda: self.ps.calibrate(spec, targets, free, **kwargs)

    def gradients(self, g: Gen) -> Callable[[], Any]:
        key = g.rng.choice(["hmf", "hmf", "one_wing", "lossy", "ww"])
        spec = self.specs[key]
        valid = ["actuator.waveform.amplitude_v", "actuator.frequency_hz", "actuator.stiffness", "actuator.mass_mg", "actuator.damping", "actuator.cubic_stiffness"]
        valid += {"hmf": ["wings[*].aero.omega1"], "one_wing": ["drivetrain.cubic_ratio", "drivetrain.transmission_ratio"], "lossy": ["drivetrain.balance_damping", "drivetrain.balance_cubic", "wings[*].springs.hinge_damping"], "ww": ["wings[*].aero.rotational_lift", "wings[*].aero.omega5"]}[key]
        params = g.rng.choice([[g.name(valid)], [g.name(valid), g.name(valid)], "actuator.stiffness", [], 3, [None], ["drivetrain.kind"], ["options.samples_per_cycle"]])
        metrics = g.rng.choice([None, ["left_stroke_amplitude"], ["bogus"], "lift_mean", 3, []])
        kwargs = g.rng.choice([{}, {"rtol": g.num(1e-9)}, {"max_wall_ms": g.num(5000.0)}, {"samples_per_cycle": g.int(100)}, {"progress": g.rng.choice([True, "no", None])}])
        k = g.rng.randrange(4)
        if k == 1:
            bounds = g.rng.choice([{"actuator.waveform.amplitude_v": (g.num(60.0), g.num(120.0))}, {"actuator.stiffness": (1, 0)}, {"bogus": (0, 1)}, {}, 3])
            constraints = g.rng.choice([[], ["left_stroke_amplitude >= 0.5"], ["bogus <= 1"], ["left_stroke_amplitude >="], "abs(yaw_total_mean) <= 0.1", [3], ["__import__('os') <= 1"]])
            objective = g.rng.choice(["actuator_power_mean", "bogus", 3, None, "left_stroke_amplitude"])
            method = g.name(["SLSQP", "trust-constr", "ipopt", "ipopt"])
            extra = g.rng.choice([{}, {}, {"x0": {"actuator.waveform.amplitude_v": g.num(90.0)}}, {"stability": g.num(0.98)}, {"sense": g.name(["min", "max"])}, {"tol": g.num(1e-6)}, {"rtol": g.num(1e-9)}])
            return lambda: self.ps.optimize(spec, objective=objective, params=bounds, constraints=constraints, method=method, max_iterations=g.int(3), progress=False, **extra)
        if k == 2:
            metric = "wing_stroke_amplitude" if key == "one_wing" else "left_stroke_amplitude"
            return lambda: self.ps.sweep(spec, {"actuator.waveform.amplitude_v": [80.0, 100.0]}, metrics=[metric], gradients=params, progress=False)
        if k == 3:
            return lambda: self.ps.stability.floquet(spec, orbit_cycles=g.int(1), max_newton=g.int(5))
        return lambda: self.ps.sensitivity(spec, params, metrics=metrics, **{"progress": False, **kwargs})

    def flight(self, g: Gen) -> Callable[[], Any]:
        spec = self.specs["flight"]
        k = g.rng.randrange(3)
        if k == 0:
            kwargs = g.rng.choice([{"tol": g.num(1e-4)}, {"max_evaluations": g.int(3)}, {"knobs": g.rng.choice([["bogus"], 3, [None]])}, {"initial": g.array(0, 100, 3)}, {"equations": ["bogus"]}])
            return lambda: self.ps.flight.trim(spec, **{"max_evaluations": 2, **kwargs})
        if k == 1:
            return lambda: self.ps.flight.with_body(self.specs["hmf"], mode=g.name(["roll", "yaw", "free", "clamped"]), initial_attitude_rad=(g.num(0.1), 0.0, 0.0))
        return lambda: self.ps.flight.body_of(g.rng.choice([spec, self.specs["hmf"], None, 3]))

    def continuation(self, g: Gen) -> Callable[[], Any]:
        spec = self.specs["parity"]
        path = g.name(["drivetrain.balance_spring", "actuator.waveform.amplitude_v"])
        settings = g.rng.choice([{}, {"max_points": g.int(3)}, {"method": g.name(["natural", "arclength"])}, {"bogus": 1}, {"initial_step": g.num(0.1)}])
        settings = {"max_points": 3, **settings}
        return lambda: self.ps.continuation(spec, path, g.num(50.0), start=g.num(100.0) if g.rng.random() < 0.5 else None, max_wall_ms=10_000.0, **settings)

    # -- stability
    def stability(self, g: Gen) -> Callable[[], Any]:
        st = self.ps.stability
        k = g.rng.randrange(11)
        if k == 0:
            return lambda: st.hill_monodromy(g.num(1.0), g.num(0.2), g.num(-1.5))
        if k == 1:
            return lambda: st.hill_solution(g.num(1.0), g.num(0.2), g.array(0.0, 50.0), max_wall_ms=10_000.0)
        if k == 2:
            return lambda: st.hill_floquet(g.num(1.0), g.num(0.2))
        if k == 3:
            return lambda: st.region(g.array(-1, 1), g.array(0, 1))
        if k == 4:
            return lambda: st.stability_chart(g.array(0, 3, 20), g.array(-1, 30, 20), brockett=g.rng.random() < 0.5, max_wall_ms=20_000.0)
        if k == 5:
            return lambda: st.brockett(g.num(0.5), g.num(6.0), g.num(0.1))
        if k == 6:
            return lambda: st.hill_parameters(inertia=g.num(50.0), drag=g.num(40.0), transmission_ratio=g.num(3.0), arm_length_mm=g.num(2.5), k1=g.num(300.0), k2=g.num(5.0), stroke_amplitude=g.num(1.0), frequency_hz=g.num(100.0))
        if k == 7:
            return lambda: st.lti_transfer(g.num(1.0), g.num(0.5), g.array(1, 300))
        if k == 8:
            return lambda: st.linearise(self.specs["parity"], samples=g.int(500, 8))
        if k == 9:
            opts = g.rng.choice([{}, {"samples_per_cycle": g.int(64, 16)}, {"max_window_cycles": g.int(2)}, {"settle_cycles": g.int(2, 0)}])
            return lambda: st.disturbance_response(self.specs["parity"], g.array(20, 200, 2), g.num(0.1), **{"settle_cycles": 2, "max_window_cycles": 2, "samples_per_cycle": 32, **opts})
        opts = g.rng.choice([{}, {"max_newton": g.int(5)}, {"tol": g.num(1e-8)}, {"bogus": 1}, {"fd_step": g.num(1e-5)}])
        return lambda: st.floquet(self.specs["parity"], **opts)

    # -- aero, kinematics, planform, laminate, dynamics
    def aero(self, g: Gen) -> Callable[[], Any]:
        a = self.ps.aero
        k = g.rng.randrange(3)
        if k == 0:
            return lambda: a.center_of_pressure(g.rng.choice([None, NAN, 1e308, "x", 0.5, [0.1, 0.2]]) if g._bad() else g.array(0, 3))
        if k == 1:
            return lambda: a.coefficients(g.array(0, 3), model=g.name(list(a.MODELS)))
        omegas = g.rng.choice([a.TABLE_3_3["left"], {**a.TABLE_3_3["left"], "force": g.num(1.0)}, [g.num(40.0), 0.5, 17.0, 0.7], {"omega1": 1.0}, "abcd", 3, [1, 2]])
        kwargs = {name: g.array(-1, 1) if g.rng.random() < 0.5 else g.num(0.5) for name in ("phi", "theta", "psi", "phi_dot", "theta_dot", "psi_dot") if g.rng.random() < 0.5}
        if g.rng.random() < 0.2:
            kwargs["rotational_damping"] = g.num(5.0)
        if g.rng.random() < 0.2:
            kwargs["normal_force_law"] = g.name(["coefficient", "unit"])
        return lambda: a.moments(omegas, **kwargs)

    def kinematics(self, g: Gen) -> Callable[[], Any]:
        kin, D = self.ps.kinematics, self.ps.Drivetrain
        k = g.rng.randrange(5)
        if k == 0:
            return lambda: kin.shoulder_pose(g.num(2.0), g.num(1.0), g.num(0.3), g.num(0.1), g.num(0.0))
        if k == 1:
            return lambda: kin.shoulder_partials(g.num(2.0), g.num(1.0), g.num(0.3), g.num(0.1))
        if k == 2:

            def shoulder_map() -> Any:  # NaN marks unreachable poses (documented, with `reachable`)
                out = kin.shoulder_map(g.num(2.094), g.num(1.047), g.array(-0.5, 0.5), g.array(-0.1, 0.1))
                return {k: v[out["reachable"]] for k, v in out.items()}

            return shoulder_map
        if k == 3:
            return lambda: kin.drivetrain_map(g.rng.choice([D.linkage_differential(), D.linear_differential(3.05, 2.5), D.hmf_four_bar(), None, 3]), g.array(-0.05, 0.05), g.array(-0.1, 0.1))
        return lambda: D.linear_differential(g.num(3.05), g.num(2.5))

    def planform(self, g: Gen) -> Callable[[], Any]:
        P = self.ps.Planform
        k = g.rng.randrange(8)
        if k == 0:
            return lambda: P.hmf_like(g.num(16.6), segments=g.int(32, 4))
        if k == 1:
            return lambda: P.rectangle(g.num(15.0), g.num(5.0), g.num(1.0), g.num(0.5))
        if k == 2:
            return lambda: P.semi_ellipse(g.num(15.0), g.num(5.0), segments=g.int(32, 4))
        if k == 3:
            pts = g.rng.choice([[[0, 0], [1], [1, 1]], [[0, 0]], "x", [[1e308, 0], [1, 1], [0, 1]], [[1.0, 0.0], [10.0, 0.0], [10.0, -3.0], [1.0, -3.0]], None])
            return lambda: P.from_points(pts)
        p = P.hmf_like()
        if k == 4:
            return lambda: p.scaled(g.num(1.2)).area
        if k == 5:
            return lambda: p.cut(g.num(0.2), where=g.name(["tip", "trailing"]), measure=g.name(["span", "area"])).area
        if k == 6:
            return lambda: p.inertia(g.num(0.01), point_masses=g.rng.choice([[], [[1.0, 0.0, 0.1]], [[1e200, 1e200, 1e200]], "x", [[1.0, 2.0]]]))
        return lambda: (p.omegas(g.num(1.2e-3)), p.chord(g.array(0, 16)), p.translated(g.num(0.1), g.num(0.1)).area)

    def laminate(self, g: Gen) -> Callable[[], Any]:
        lam = self.ps.laminate
        k = g.rng.randrange(3)
        if k == 0:

            def flex() -> Any:
                f = lam.Flexure(g.num(3.0), g.num(0.5), g.num(7.5))
                return {"stiffness": f.stiffness, "plate": f.plate_stiffness, "limit": f.elastic_limit_angle()}

            return flex
        if k == 1:

            def bimorph() -> Any:
                b = lam.Bimorph(lam.Layup.bimorph_mobee(), g.num(10.0), extension=g.num(2.0), base_width=g.num(1.0), width_ratio=g.num(0.5))
                return {"stiffness": b.stiffness, "force_per_volt": b.force_per_volt, "active_mass": b.active_mass, "tip_width": b.tip_width}

            return bimorph

        def design() -> Any:
            b = lam.Bimorph.design_for(width_ratio=g.num(0.5), extension_ratio=g.num(0.5))
            return {"stiffness": b.stiffness, "length": b.length}

        return design

    def dynamics(self, g: Gen) -> Callable[[], Any]:
        spec = g.rng.choice([self.specs["hmf"], self.specs["parity"], None, 3])
        index = g.rng.choice([0, 1, -1, 2, "a", None, 2.0]) if g._bad() else 0
        return lambda: self.ps.dynamics.wing_terms(spec, g.array(0, 0.3, 3) if g._bad() else [0.2, 0.05, 0.1], [g.num(1.0), 0.0, g.num(0.5)], index=index)

    # -- the surface of sessions 13-14: per-wing drives, polynomial transmissions, drive
    # losses, Whitney & Wood aerodynamics, datasheet/laminate actuators, planform wings,
    # table calibration
    def drive_spec(self, g: Gen) -> Callable[[], Any]:
        """The new spec fields, mutated by path (or as a drivetrain table), then run."""
        key = g.rng.choice(["one_wing", "dual", "ww", "lossy"])
        spec = self.specs[key]
        values: dict[str, Any] = {}
        for _ in range(g.rng.choice([1, 1, 2, 3])):
            path, typical = g.rng.choice(NEW_PATHS)
            if path == "drivetrain.higher_odd_ratios":
                values[path] = g.rng.choice([[NAN], "x", [1e308], [], [0.1] * 50, [[1.0]], None, [1.0, -2.0], {"a": 1}, [INF]]) if g._bad() else [g.num(1.0)]
            elif isinstance(typical, list):
                values[path] = g.name(typical)
            else:
                values[path] = g.num(typical)
        k = g.rng.randrange(6)
        if k == 0:
            d = spec.to_dict()
            table = g.rng.choice([
                {"kind": g.name(["single_linear", "dual_linear"])},
                {"kind": "single_linear", "transmission_ratio": g.num(2.67), "cubic_ratios": 1.0},
                {"kind": "dual_linear", "transmission_ratio": g.num(2.67), "higher_odd_ratios": g.rng.choice([[g.num(1.0)], "x", 3, [None]])},
                {"kind": "single_linear", "transmission_ratio": g.num(2.67), "cubic_ratio": g.num(5.0), "balance_damping": g.num(0.3)},
                None, 3, [],
            ])  # fmt: skip
            d["drivetrain"] = table
            return lambda: self.ps.simulate(self.ps.Simulation.from_dict(d))
        if k == 1:
            return lambda: self.ps.stability.floquet(spec.with_paths(values), orbit_cycles=g.int(1), max_newton=5)
        if k == 2:
            return lambda: self.ps.sweep(spec, {path: [typical, typical * 1.1] if not isinstance(typical, list) else typical[:2] for path, typical in [g.rng.choice(NEW_PATHS[1:])]}, progress=False, metrics=None)
        return lambda: self.ps.simulate(spec.with_paths(values))

    def device_ctor(self, g: Gen) -> Callable[[], Any]:
        """Drivetrain / Actuator / Wing / Planform constructors of the new surface, each checked
        by a spec that holds it (``validate``) and sometimes run."""
        ps = self.ps
        k = g.rng.randrange(9)
        one, dual = self.specs["one_wing"], self.specs["dual"]
        odd = lambda: g.rng.choice([None, [g.num(1.0)], "x", [NAN], [[1.0]], 3, [1.0] * 40])  # noqa: E731
        if k == 0:
            return lambda: one.replace(drivetrain=ps.Drivetrain.single_linear(g.num(2.67), cubic_ratio=g.num(5.0) if g.rng.random() < 0.6 else None, higher_odd_ratios=odd())).validate().to_dict()["drivetrain"]
        if k == 1:
            return lambda: ps.simulate(dual.replace(drivetrain=ps.Drivetrain.dual_linear(g.num(2.67), cubic_ratio=g.num(5.0), higher_odd_ratios=odd()))).metrics
        if k == 2:
            fields = g.rng.choice([{}, {"mass_mg": g.num(30.0)}, {"damping": g.num(2.0)}, {"cubic_stiffness": g.num(1e3)}, {"bogus": 1.0}, {"dc_offset": g.name(["as_force", "ignore"])}, {"stiffness": 3.0}])
            waveform = g.rng.choice([None, None, ps.Waveform(), 3, "x"])
            return lambda: one.replace(actuator=ps.Actuator.from_blocked_force(g.num(120.0), g.num(0.257), g.num(100.0), waveform=waveform, **fields)).validate().actuator.stiffness
        if k == 3:
            from types import SimpleNamespace

            lam = ps.laminate
            bimorph = g.rng.choice([lam.Bimorph.design_for(), None, 3, "x", SimpleNamespace(stiffness=NAN, force_per_volt=1.0, effective_mass=1.0), SimpleNamespace(stiffness=300.0, force_per_volt="x", effective_mass=-1.0), SimpleNamespace(stiffness_mn_per_mm=300.0, force_per_volt_mn_per_v=1.0)]) if g._bad() else lam.Bimorph.design_for()
            mass = g.rng.choice([True, False, "yes", None, 1]) if g._bad() else g.rng.choice([True, False])
            fields = g.rng.choice([{}, {"damping": g.num(2.0)}, {"mass_mg": g.num(5.0)}, {"bogus": 1}])
            return lambda: one.replace(actuator=ps.Actuator.from_laminate(bimorph, mass=mass, **fields)).validate().actuator.mass_mg
        if k == 4:

            def effective() -> Any:
                b = ps.laminate.Bimorph(ps.laminate.Layup.bimorph_mobee(), g.num(10.0), extension=g.num(2.0), base_width=g.num(1.0), width_ratio=g.num(0.5))
                return {"effective_mass": b.effective_mass, "active_mass": b.active_mass}

            return effective
        if k == 5:
            P = ps.Planform
            planform = g.rng.choice([P.hmf_like(), P.rectangle(15.0, 5.0, 1.0, 0.5), None, 3]) if g._bad() else P.hmf_like()
            lines = g.rng.choice([(), [("leading_edge", g.num(0.1))], {"leading_edge": g.num(0.1)}, [[0.0, 0.0, 10.0, 0.0, g.num(0.1)]], "x", [[1.0, 2.0]], [("bogus", 1.0)], [[NAN, 0, 1, 0, 1]], self.np.zeros((0, 5))])
            points = g.rng.choice([(), [[5.0, 0.0, g.num(0.05)]], "x", [[1.0, 2.0]], [[NAN, 0.0, 1.0]], [[1e300, 1e300, 1e300]]])
            hinge = g.rng.choice([None, g.num(2.0), ps.Spring(stiffness=2.0), ps.TunableHinge(stiffness_at_zero=2.0), "x", -1.0])  # type: ignore[call-arg]
            model = g.rng.choice([*ps.aero.MODELS, "stroke_drag", ps.Aero(kind="whitney_wood2010"), None, "bogus", 3])  # type: ignore[call-arg]
            fields = g.rng.choice([{}, {}, {"inertia": 1}, {"bogus": 1}, {"shoulder": 3}, {"aero": None}])

            def wing() -> Any:
                w = ps.Wing.from_planform(planform, mass_mg=g.num(0.5), line_masses=lines, point_masses=points, hinge=hinge, aero_model=model, air_density_mg_per_mm3=g.num(1.2e-3), **fields)
                spec = self.specs["parity"]
                return ps.simulate(spec.replace(wings=(w, w))).metrics if g.rng.random() < 0.3 else w.to_dict()

            return wing
        if k == 6:
            p = ps.Planform.hmf_like()
            kwargs = g.rng.choice([{"factor": g.num(1.2)}, {"span_mm": g.num(16.6)}, {"area_mm2": g.num(40.0)}, {"span_mm": g.num(16.6), "area_mm2": g.num(40.0)}, {"factor": g.num(1.2), "span_mm": 10.0}, {}])

            def scaled() -> Any:
                q = p.scaled(**kwargs)
                return {"area": q.area, "span": q.span, **q.omegas(g.num(1.2e-3)), **q.quasi_steady_omegas(g.num(1.2e-3))}

            return scaled
        if k == 7:
            fields = {name: g.num(typical) for name, typical in (("omega5", -3.0), ("omega6", 0.6), ("omega7", 2.9), ("omega8", -1.0), ("rotational_lift", 1.0), ("translational_added_mass", 1.0), ("rotational_added_mass", 1.0), ("rotational_damping", 5.0)) if g.rng.random() < 0.4}
            spec = self.specs["ww"]

            def ww() -> Any:
                aero = spec.wings[0].aero.replace(**fields)
                return ps.simulate(spec.replace(wings=(spec.wings[0].replace(aero=aero), spec.wings[1]))).metrics

            return ww
        return lambda: self.ps.aero.coefficients(g.array(0, 3), model=g.name(["whitney_wood2010", *self.ps.aero.MODELS]))

    def calibrate_table(self, g: Gen) -> Callable[[], Any]:
        """``ps.calibrate(spec, data=table, params=...)`` and ``ps.measured``."""
        ps = self.ps
        if g.rng.random() < 0.2:
            return lambda: ps.measured(g.name(["left_stroke_amplitude", "lift_mean", "left_rotation_amplitude"]), peak_to_peak=g.rng.choice([True, False, "yes", None]), unit=g.rng.choice([None, "deg", "rad", "bogus", 3]), sigma=g.num(1.0))
        one = g.rng.random() < 0.5
        spec = self.specs["one_wing" if one else "hmf"]
        metric = "wing_stroke_amplitude" if one else "left_stroke_amplitude"
        volts = [60.0, 80.0, 100.0]
        data: Any = {"actuator.waveform.amplitude_v": volts, metric: [0.4, 0.5, 0.6]}
        if g._bad():
            data = g.rng.choice([
                {}, {"actuator.waveform.amplitude_v": [], metric: []}, {"actuator.waveform.amplitude_v": volts, metric: [NAN] * 3},
                {"actuator.waveform.amplitude_v": [60.0, NAN, INF], metric: [0.4, 0.5, 0.6]}, {"actuator.waveform.amplitude_v": volts},
                {metric: [0.4, 0.5, 0.6]}, {"actuator.waveform.amplitude_v": volts, metric: ["a", "b", "c"]}, {"actuator.waveform.amplitude_v": volts, metric: [0.4]},
                {"actuator.waveform.amplitude_v": volts, metric: [0.4, None, 0.6]}, {"bogus": volts, metric: [0.4, 0.5, 0.6]}, None, 3, [[1.0, 2.0]], "table.csv",
                {"actuator.waveform.amplitude_v": [60.0] * 10**5, metric: [0.5] * 10**5}, {"actuator.waveform.amplitude_v": volts, metric: [1e308, -1e308, 0.5]},
                {"actuator.waveform.amplitude_v": volts, "stroke_pp_deg": [40.0, 50.0, 60.0]}, {"actuator.waveform.amplitude_v": [1e300, 1e300, 1e300], metric: [0.4, 0.5, 0.6]},
            ])  # fmt: skip
            if isinstance(data, dict) and g.rng.random() < 0.3:
                import polars as pl

                try:
                    data = pl.DataFrame(data, strict=False)
                except Exception:  # noqa: BLE001 - a table polars itself refuses stays a mapping
                    pass
        params: Any = {"actuator.force_per_volt": (g.num(0.5), g.num(2.0))}
        if g._bad():
            params = g.rng.choice([{"actuator.force_per_volt": (2.0, 0.5)}, {"actuator.force_per_volt": (NAN, 1.0)}, {"actuator.force_per_volt": 5}, {"bogus": (0, 1)}, {}, [1], None, {"drivetrain.kind": (0, 1)}, {"actuator.waveform.amplitude_v": (10.0, 200.0)}, {"actuator.force_per_volt": (0.5, 2.0, 3.0)}, {"actuator.mass_mg": (-1.0, 1e308)}, {"actuator.damping": (0.0, 5.0), "actuator.mass_mg": (0.0, 50.0)}, {"actuator.force_per_volt": ("a", "b")}])
        kwargs: dict[str, Any] = {}
        for name, make in (
            ("measured", lambda: g.rng.choice([None, {"stroke_pp_deg": ps.measured(metric, peak_to_peak=True, unit="deg")}, {metric: "bogus"}, {metric: 3}, {"missing": metric}, {}, [metric]])),
            ("holdout", lambda: g.num(0.3)),
            ("jacobian", lambda: g.name(["auto", "sensitivity", "differences"])),
            ("x0", lambda: g.rng.choice([{"actuator.force_per_volt": g.num(1.0)}, {"bogus": 1.0}, 3])),
            ("labels", lambda: g.rng.choice([["bogus"], "x", [3], []])),
            ("threads", lambda: g.int(1)),
            ("seed", lambda: g.int(3, 0)),
            ("diff_step", lambda: g.num(1e-3)),
            ("xtol", lambda: g.num(1e-6)),
            ("max_wall_ms", lambda: g.num(20_000.0)),
        ):
            if g.rng.random() < 0.15:
                kwargs[name] = make()
        kwargs = {"max_nfev": g.int(2) if g.rng.random() < 0.2 else 2, "progress": False, **kwargs}
        kwargs.setdefault("max_wall_ms", 20_000.0)
        return lambda: ps.calibrate(spec, data=data, params=params, **kwargs)

    # -- the command line
    def cli(self, g: Gen) -> Callable[[], Any]:
        f = self.files
        study = self.tmp / f"study_{g.rng.randrange(10**9)}.toml"
        hmf_path = (EXAMPLES / "hmf.toml").as_posix()
        max_cycles = g.rng.choice(["4", "-1", '"x"'])
        axis = g.rng.choice(["[100.0, 120.0]", "[-1.0]", '"x"', "[]"])
        study.write_text(f'spec = "{hmf_path}"\nmetrics = ["left_stroke_amplitude"]\n[options]\nmax_cycles = {max_cycles}\nsamples_per_cycle = 24\n[grid]\n"actuator.frequency_hz" = {axis}\n')
        out = str(self.tmp / f"out_{g.rng.randrange(10**9)}")
        commands = [
            ["run", str(g.rng.choice([f["good"], f["latin"], f["broken"], f["dir"], f["missing"], f["empty"]])), "--out", g.rng.choice([out, str(f["a_dir"] if "a_dir" in f else f["dir"]), str(self.tmp / "a_file")])],
            ["sweep", str(g.rng.choice([study, f["good"], f["missing"], f["dir"]])), "--out", out, "--quiet", "--threads", str(g.rng.choice([1, 0, -1, "x"]))],
            ["continue", str(g.rng.choice([f["good"], f["missing"], study])), "--out", out],
            ["devices", g.rng.choice(["", "sreetharan2012_3_3_parity", "bogus", "--list"])],
            ["reproduce", g.rng.choice(["--list", "bogus", "fig2.99", "aero.whitney_wood2010", "aero.whitney_wood2010x"]), "--out", g.rng.choice([out, str(self.tmp / "a_file"), str(self.tmp / "a_file" / "x")]), "--quiet"],
            ["optimize", str(self._optimize_study(g)), "--out", g.rng.choice([out, str(self.tmp / "a_file")]), "--quiet"],
            [g.rng.choice(["bogus", "--bogus", "run"])],
        ]
        args = [a for a in g.rng.choice(commands) if a != ""]

        def run() -> Any:
            proc = subprocess.run([sys.executable, "-m", "paritysim", *args], capture_output=True, text=True, timeout=120)
            return {"__cli__": [proc.returncode, proc.stderr[-2000:], args]}

        return run

    def _optimize_study(self, g: Gen) -> Path:
        """An optimisation study file (``paritysim optimize``), one entry hostile sometimes."""
        study = self.tmp / f"optimize_{g.rng.randrange(10**9)}.toml"
        spec = (EXAMPLES / "hmf.toml").as_posix()
        entries = {
            "spec": f'"{spec}"', "objective": '"actuator_power_mean"', "constraints": '["left_stroke_amplitude >= 0.1"]', "method": '"SLSQP"',
            "max_iterations": "2", "tol": "1e-4",
        }  # fmt: skip
        tables = {"params": {'"actuator.waveform.amplitude_v"': "[60.0, 120.0]"}, "options": {k: str(v) for k, v in SMALL.items()}}
        if g._bad():
            key = g.rng.choice(["spec", "objective", "constraints", "method", "max_iterations", "tol", "stability", "sense", "bogus", "params", "x0", "set", "options"])
            bad = g.rng.choice(['"bogus"', "-1", "nan", "inf", "[]", '"x"', "1e308", "true", "{}", '["a >="]', '"ipopt"', '"sreetharan2012_3_4_parity"'])
            if key in ("params", "x0", "set", "options"):
                inner = g.rng.choice(['"actuator.waveform.amplitude_v"', '"bogus"', '"drivetrain.kind"', "max_cycles"])
                tables[key] = {inner: g.rng.choice(["[120.0, 60.0]", "[1.0]", '"x"', "nan", "[nan, 1.0]", "5.0", "[]", "[-1e308, 1e308]"])}
            else:
                entries[key] = bad
        body = "\n".join(f"{k} = {v}" for k, v in entries.items())
        for name, table in tables.items():
            body += f"\n[{name}]\n" + "\n".join(f"{k} = {v}" for k, v in table.items())
        study.write_text(body + "\n")
        return study

    # -- Ctrl-C
    def ctrl_c(self, g: Gen) -> Callable[[], Any]:
        st, np = self.ps.stability, self.np
        slow_hmf = self.specs["hmf"].with_paths({"actuator.frequency_hz": 1e-3, "options.max_wall_ms": 600_000.0, "options.max_cycles": 200})
        calls = {
            "simulate": lambda: self.ps.simulate(slow_hmf),
            "controller": lambda: self.ps.simulate(self.specs["flight"], controller=lambda t, b: {}, control_rate_hz=1000, max_cycles=100000, min_cycles=100000, max_steps=10**8, max_wall_ms=600_000.0),
            "sweep": lambda: self.ps.sweep(slow_hmf, {"actuator.frequency_hz": [1e-3] * 4}, threads=2, progress=False),
            "hill_solution": lambda: st.hill_solution(1.0, 0.2, np.linspace(0, 9990, 10**4)),
            "floquet": lambda: st.floquet(slow_hmf),
            "chart": lambda: st.stability_chart(np.linspace(0, 3, 2000), np.linspace(-1, 30, 2000), brockett=False),
            "continuation": lambda: self.ps.continuation(slow_hmf, "actuator.waveform.frequency_hz", 2e-3, start=1e-3),
            "trim": lambda: self.ps.flight.trim(self.specs["flight"].with_paths({"options.max_cycles": 200, "options.max_wall_ms": 600_000.0})),
            "sensitivity": lambda: self.ps.sensitivity(slow_hmf, ["actuator.waveform.amplitude_v"], progress=False),
            "calibrate_table": lambda: self.ps.calibrate(slow_hmf, data={"actuator.waveform.amplitude_v": [60.0, 80.0, 100.0, 120.0], "left_stroke_amplitude": [0.4, 0.5, 0.6, 0.7]}, params={"actuator.force_per_volt": (0.5, 2.0)}, progress=False),
            "optimize": lambda: self.ps.optimize(slow_hmf, params={"actuator.waveform.amplitude_v": (60.0, 120.0)}, progress=False),
            "optimize_ipopt": lambda: self.ps.optimize(slow_hmf, params={"actuator.waveform.amplitude_v": (60.0, 120.0)}, method="ipopt", progress=False),
            "sweep_gradients": lambda: self.ps.sweep(slow_hmf, {"actuator.waveform.amplitude_v": [60.0, 80.0]}, gradients=["actuator.stiffness"], threads=2, progress=False),
        }
        name = g.rng.choice(sorted(calls))
        call = calls[name]

        def run() -> Any:
            import threading

            sent: list[float] = []

            def fire() -> None:
                sent.append(time.monotonic())
                os.kill(os.getpid(), signal.SIGINT)

            timer = threading.Timer(0.3, fire)
            timer.start()
            try:
                call()
            except KeyboardInterrupt:
                return {"__ctrl_c__": [name, time.monotonic() - sent[0] if sent else 0.0]}
            finally:
                timer.cancel()
            return {"__ctrl_c__": [name, None]}  # finished before the signal

        return run


FAMILIES: dict[str, float] = {
    "spec_mutation": 0.09, "spec_file": 0.05, "spec_dict": 0.04, "spec_misc": 0.03, "simulate": 0.06, "controller": 0.02,
    "sweep": 0.06, "sweep_executor": 0.005, "shared_checkpoint": 0.01, "calibrate": 0.02, "gradients": 0.02, "flight": 0.02, "continuation": 0.015,
    "stability": 0.1, "aero": 0.1, "kinematics": 0.09, "planform": 0.1, "laminate": 0.07, "dynamics": 0.04, "cli": 0.03, "ctrl_c": 0.02,
    "drive_spec": 0.06, "device_ctor": 0.06, "calibrate_table": 0.03,
}  # fmt: skip
#: Families cheap enough for the CI sample (no subprocess of their own, sub-second cases).
FAST = ("spec_mutation", "spec_dict", "spec_misc", "simulate", "gradients", "stability", "aero", "kinematics", "planform", "laminate", "dynamics", "sweep", "drive_spec", "device_ctor", "calibrate_table")


def plan(n: int, seed: int, families: tuple[str, ...]) -> list[str]:
    """The family of each of the ``n`` cases, in proportion to their weights, shuffled."""
    weights = {f: FAMILIES[f] for f in families}
    total = sum(weights.values())
    names = [f for f, w in weights.items() for _ in range(max(1, round(n * w / total)))]
    rng = random.Random(seed)
    while len(names) < n:  # rounding: top up in proportion
        names.append(rng.choices(list(weights), weights=list(weights.values()))[0])
    rng.shuffle(names)
    return names[:n]


# ------------------------------------------------------------------ the worker


def _finite(value: Any, np: Any) -> bool:
    if isinstance(value, dict):
        return all(_finite(v, np) for v in value.values())
    if isinstance(value, list | tuple):
        return all(_finite(v, np) for v in value)
    if isinstance(value, np.ndarray):
        return value.dtype.kind not in "fc" or bool(np.isfinite(value).all())
    if isinstance(value, float | complex):
        return math.isfinite(abs(value))
    if hasattr(value, "columns") and hasattr(value, "height"):  # a polars DataFrame
        return all(_finite(value[c].drop_nulls().to_numpy(), np) for c in value.columns if value[c].dtype.is_float())
    for attr in ("metrics", "columns", "values", "residuals", "multipliers", "branch", "knobs"):  # result objects
        if hasattr(value, attr) and not callable(getattr(value, attr)):
            if not _finite(getattr(value, attr), np):
                return False
    return True


def classify(call: Callable[[], Any], ps: Any, np: Any, ctrl_c_s: float) -> tuple[str, str]:
    try:
        result = call()
    except ps.ParitysimError as exc:
        return (TYPED_FIELD if getattr(exc, "field", None) else TYPED_NO_FIELD), f"{type(exc).__name__}: {str(exc)[:160]}"
    except KeyboardInterrupt:
        return HANG, "KeyboardInterrupt outside a Ctrl-C case"
    except Exception as exc:  # noqa: BLE001 - what we count
        return FOREIGN, f"{type(exc).__name__}: {str(exc)[:160]}"
    if isinstance(result, dict) and "__rows_lost__" in result:
        return ROWS_LOST, f"{result['__rows_lost__']} rows or tables lost"
    if isinstance(result, dict) and "__ctrl_c__" in result:
        name, latency = result["__ctrl_c__"]
        if latency is None:
            return FINITE, f"ctrl-c {name}: finished before the signal"
        return (FINITE if latency <= ctrl_c_s else HANG), f"ctrl-c {name}: {latency * 1e3:.1f} ms"
    if isinstance(result, dict) and "__cli__" in result:
        code, err, argv = result["__cli__"]
        if "Traceback" in err:
            return FOREIGN, "CLI traceback: " + err.strip().splitlines()[-1][:160]
        if code == 0:
            return FINITE, "CLI exit 0"
        lines = [line for line in err.strip().splitlines() if line.strip()]
        named = "`" in err or "--" in err or "argument" in err or "invalid choice" in err or any(len(a) > 2 and a in err for a in argv)
        if code in (1, 2) and lines and named:
            return TYPED_FIELD, f"CLI exit {code}: {lines[-1][:160]}"
        return TYPED_NO_FIELD, f"CLI exit {code}: {(lines[-1] if lines else '')[:160]}"
    return (FINITE if _finite(result, np) else NON_FINITE), type(result).__name__


def worker(seed: int, memory_gb: float, ctrl_c_s: float, families: tuple[str, ...], n: int) -> None:
    """Reads case indices on stdin, writes one JSON outcome line per case on stdout."""
    import resource
    import warnings

    import numpy as np

    import paritysim as ps

    warnings.simplefilter("ignore")
    # Ctrl-C cases need Python's handler even when the run was started with SIGINT ignored (a
    # background job of a shell).
    signal.signal(signal.SIGINT, signal.default_int_handler)
    tmp = Path(tempfile.mkdtemp(prefix="fuzz_surface_"))
    cases = Cases(ps, np, tmp)
    names = plan(n, seed, families)
    vm = int(next(line for line in open("/proc/self/status") if line.startswith("VmSize")).split()[1]) * 1024
    resource.setrlimit(resource.RLIMIT_AS, (vm + int(memory_gb * 2**30), resource.RLIM_INFINITY))
    out = sys.stdout
    sys.stdout = sys.stderr  # the cases' prints (progress bars, CLI) never reach the protocol
    out.write("ready\n")
    out.flush()
    for line in sys.stdin:
        i = int(line)
        family = names[i]
        rng = random.Random(f"{seed}:{i}")
        start = time.monotonic()
        try:
            outcome, detail = classify(getattr(cases, family)(Gen(rng, np)), ps, np, ctrl_c_s)
        except Exception as exc:  # noqa: BLE001 - building the case itself raised (a constructor)
            outcome, detail = (TYPED_FIELD if isinstance(exc, ps.ParitysimError) and getattr(exc, "field", None) else TYPED_NO_FIELD if isinstance(exc, ps.ParitysimError) else FOREIGN), f"{type(exc).__name__}: {str(exc)[:160]}"
        out.write(json.dumps({"i": i, "family": family, "outcome": outcome, "detail": detail, "s": time.monotonic() - start}) + "\n")
        out.flush()


# ------------------------------------------------------------------ the parent


class Worker:
    def __init__(self, args: argparse.Namespace, n: int) -> None:
        cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", "--seed", str(args.seed), "--memory-gb", str(args.memory_gb), "--ctrl-c-s", str(args.ctrl_c_s), "--families", ",".join(args.families), "--n", str(n)]
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, bufsize=1, start_new_session=True)
        line = self._read(120.0)
        if line != "ready":
            raise SystemExit(f"fuzz worker did not start: {line!r}")

    def _read(self, timeout: float) -> str | None:
        """The worker's next line; ``None`` when none came within ``timeout``, ``""`` at the end
        of its output (it died)."""
        assert self.proc.stdout is not None
        ready, _, _ = select.select([self.proc.stdout], [], [], timeout)
        if not ready:
            return None
        return self.proc.stdout.readline().strip()

    def run(self, i: int, timeout: float) -> dict[str, Any]:
        assert self.proc.stdin is not None
        try:
            self.proc.stdin.write(f"{i}\n")
            self.proc.stdin.flush()
        except BrokenPipeError:
            return {"i": i, "outcome": ABORT, "detail": "worker gone"}
        line = self._read(timeout)
        if line is None and self.proc.poll() is None:
            self.kill()
            return {"i": i, "outcome": HANG, "detail": f"no answer within {timeout:g} s"}
        if not line:  # the end of its output: it died (an abort, even if not yet reaped)
            try:
                code = self.proc.wait(timeout=10.0)
            except subprocess.TimeoutExpired:
                self.kill()
                code = self.proc.returncode
            return {"i": i, "outcome": ABORT, "detail": f"worker died ({signal.Signals(-code).name if code < 0 else f'exit {code}'})"}
        return json.loads(line)  # type: ignore[no-any-return]

    def kill(self) -> None:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)  # the worker's own session: its children too
        self.proc.wait()


def run(args: argparse.Namespace, indices: list[int], n: int) -> list[dict[str, Any]]:
    """Runs ``indices`` on ``args.workers`` workers (round robin), replacing dead ones."""
    workers = [Worker(args, n) for _ in range(max(1, args.workers))]
    results: list[dict[str, Any]] = []
    pending = list(indices)
    names = plan(n, args.seed, tuple(args.families))
    try:
        from concurrent.futures import ThreadPoolExecutor

        def drain(k: int) -> None:
            while pending:
                i = pending.pop(0)
                r = workers[k].run(i, args.time_limit)
                r.setdefault("family", names[i])
                results.append(r)
                if r["outcome"] in (ABORT, HANG):
                    workers[k].kill()
                    workers[k] = Worker(args, n)
                if args.verbose:
                    print(f"{i:5d} {r['family']:18s} {r['outcome']:30s} {r.get('detail', '')[:100]}", flush=True)

        with ThreadPoolExecutor(len(workers)) as pool:
            list(pool.map(drain, range(len(workers))))
    finally:
        for w in workers:
            w.kill()
    return sorted(results, key=lambda r: r["i"])


def table(results: list[dict[str, Any]]) -> str:
    total = Counter(r["outcome"] for r in results)
    lines = ["| outcome | count |", "|---|---:|"]
    for c in CLASSES:
        extra = ""
        if c == FOREIGN and total[c]:
            kinds = Counter(r["detail"].split(":")[0] for r in results if r["outcome"] == c)
            extra = " (" + ", ".join(f"{k} {v}" for k, v in kinds.most_common()) + ")"
        lines.append(f"| {c}{extra} | {total[c]} |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=34)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--time-limit", type=float, default=60.0, help="seconds per case before it counts as a hang")
    parser.add_argument("--memory-gb", type=float, default=3.0, help="address space a worker may add after importing")
    parser.add_argument("--ctrl-c-s", type=float, default=0.1, help="Ctrl-C latency bound (s)")
    parser.add_argument("--families", type=lambda s: tuple(s.split(",")), default=tuple(FAMILIES))
    parser.add_argument("--replay", type=int, default=None, help="run only this case index (verbose)")
    parser.add_argument("--verbose", action="store_true")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    unknown = set(args.families) - set(FAMILIES)
    if unknown:
        parser.error(f"unknown families {sorted(unknown)}; known: {', '.join(FAMILIES)}")
    n = len(plan(args.n, args.seed, tuple(args.families)))
    if args.worker:
        worker(args.seed, args.memory_gb, args.ctrl_c_s, tuple(args.families), args.n)
        return
    indices = [args.replay] if args.replay is not None else list(range(n))
    args.verbose |= args.replay is not None
    start = time.monotonic()
    results = run(args, indices, args.n)
    print(f"\n{len(results)} cases in {time.monotonic() - start:.0f} s (seed {args.seed}, {args.workers} workers, {args.time_limit:g} s and +{args.memory_gb:g} GB per case)\n")
    print(table(results))
    per_family: dict[str, Counter[str]] = {}
    for r in results:
        per_family.setdefault(r["family"], Counter())[r["outcome"]] += 1
    print("\nper family:")
    for name, c in sorted(per_family.items()):
        print(f"  {name:18s} " + ", ".join(f"{k}: {v}" for k, v in c.most_common()))
    latencies = [r["detail"] for r in results if r.get("detail", "").startswith("ctrl-c")]
    if latencies:
        print("\nCtrl-C: " + "; ".join(sorted(latencies)))
    bad = [r for r in results if r["outcome"] in BAD]
    if bad:
        print("\nnot clean (replay with --replay I):")
        for r in bad[:60]:
            print(f"  {r['i']:5d} {r['family']:18s} {r['outcome']}: {r.get('detail', '')[:140]}")


if __name__ == "__main__":
    main()
