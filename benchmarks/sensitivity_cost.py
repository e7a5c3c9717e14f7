"""What one ``ps.sensitivity`` costs against one ``ps.simulate`` of the same point (issue 31: at
most 3× for up to 10 parameters), by the number of parameters, on two devices:

* ``3.3``: the §3.3 Drag PARITY of ``benchmarks/vs_jax.py`` (linear map, fixed wings, K2 = 0),
  the five Table 3.2 metrics, the 8 parameters of ``benchmarks/gradients_vs_jax.py`` then
  ``wings[0].inertia[0][0]`` and ``actuator.damping``;
* ``3.4``: the §3.4 Drag PARITY 1-Cut at K2 = 30 (blade elements, passive rotation, switched),
  four stroke and rotation metrics, ten parameters of six kinds including the drive frequency.

Both calls run on one engine thread unless ``PARITYSIM_THREADS`` is set (the wall-time counter
then uses it; the instruction counter always runs one). Two counters:

* wall time (default): per call, the median over ``--rounds`` interleaved rounds of ``--calls``
  calls each (every case once per round, in turn);
* ``--instructions``: instruction counts under callgrind (needs ``valgrind``), a child process
  per case making ``--calls`` calls minus one making none (interpreter start-up, imports and the
  first call's one-off work cancel), with OpenBLAS, polars and the engine on one thread each.
  Stable where wall time on a shared machine is not; this is how docs/findings.md §30 measures.

The ratio is the sensitivity's count over the simulate's from the same run; the verdict is
computed against ``--target``.

Run:  python benchmarks/sensitivity_cost.py [--device 3.3 3.4] [--params 1 8 10] [--instructions]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
# One engine thread for both calls unless the caller chose (the engine reads it at each call).
os.environ.setdefault("PARITYSIM_THREADS", "1")
sys.path.insert(0, str(HERE))

import paritysim as ps  # noqa: E402
from gradients_vs_jax import PARAMS  # noqa: E402

# The Jacobian benchmark's eight parameters, then two more kinds.
PARAMS_3_3 = (*PARAMS, "wings[0].inertia[0][0]", "actuator.damping")
PARAMS_3_4 = (
    "wings[0].springs.hinge.stiffness",
    "actuator.waveform.amplitude_v",
    "drivetrain.balance_spring",
    "drivetrain.transmission_ratio",
    "wings[1].springs.hinge.stiffness",
    "actuator.waveform.frequency_hz",
    "actuator.stiffness",
    "actuator.force_per_volt",
    "wings[0].inertia[0][0]",
    "drivetrain.arm_ratio",
)
METRICS_3_4 = ("left_stroke_amplitude", "right_stroke_amplitude", "left_rotation_amplitude", "yaw_total_mean")


def case(device: str) -> tuple[ps.Simulation, tuple[str, ...], list[str]]:
    """The spec, the parameters (in the order they are added) and the metrics of `device`."""
    if device == "3.3":
        from vs_jax import METRICS, spec

        return spec(rtol=1e-8, atol=1e-10, samples=400), PARAMS_3_3, list(METRICS)
    spec = ps.devices.load("sreetharan2012_3_4_parity_1cut").with_paths({"drivetrain.balance_spring": 30.0})
    return spec, PARAMS_3_4, list(METRICS_3_4)


def call(device: str, n_params: int):
    """The call a case times: `ps.simulate` (0 parameters) or `ps.sensitivity` by the first
    `n_params` parameters."""
    spec, params, metrics = case(device)
    if n_params == 0:
        return lambda: ps.simulate(spec, columns=[], metrics=metrics, progress=False)
    return lambda: ps.sensitivity(spec, params=list(params[:n_params]), metrics=metrics, progress=False)


def wall_times(device: str, counts: list[int], calls: int, rounds: int) -> dict[int, float]:
    """Median seconds per call of each parameter count (0: simulate), interleaved rounds."""
    fns = {k: call(device, k) for k in counts}
    for f in fns.values():
        f()  # one-off work (the pool, the device tables) outside the timing
    samples: dict[int, list[float]] = {k: [] for k in counts}
    for _ in range(rounds):
        for k, f in fns.items():
            start = time.perf_counter()
            for _ in range(calls):
                f()
            samples[k].append((time.perf_counter() - start) / calls)
    return {k: statistics.median(v) for k, v in samples.items()}


def collected(device: str, n_params: int, calls: int) -> int:
    """Instructions of a child process that makes one call, then `calls` more, under callgrind."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", POLARS_MAX_THREADS="1",
               PYTHONHASHSEED="0", PARITYSIM_THREADS="1")  # fmt: skip
    cmd = ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", sys.executable, __file__,
           "--child", device, str(n_params), str(calls)]  # fmt: skip
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=False)
    for line in out.stderr.splitlines():
        if "Collected :" in line:
            return int(line.split()[-1])
    raise SystemExit(f"callgrind gave no count for {device} P={n_params}:\n{out.stderr[-2000:]}")


def instructions(device: str, counts: list[int], calls: int) -> dict[int, float]:
    """Instructions per call of each parameter count (0: simulate): `calls` calls minus none."""
    base = {k: collected(device, k, 0) for k in counts}
    return {k: (collected(device, k, calls) - base[k]) / calls for k in counts}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--device", nargs="+", choices=["3.3", "3.4"], default=["3.3", "3.4"])
    parser.add_argument("--params", nargs="+", type=int, default=[1, 4, 8, 10], help="parameter counts (1..10)")
    parser.add_argument("--calls", type=int, default=None, help="calls per round (default 30; 10 for --instructions)")
    parser.add_argument("--rounds", type=int, default=5, help="interleaved rounds (wall time)")
    parser.add_argument("--instructions", action="store_true", help="callgrind instruction counts")
    parser.add_argument("--target", type=float, default=3.0)
    parser.add_argument("--child", nargs=3, metavar=("DEVICE", "P", "CALLS"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        device, k, calls = args.child[0], int(args.child[1]), int(args.child[2])
        f = call(device, k)
        f()
        for _ in range(calls):
            f()
        return
    if not all(1 <= k <= 10 for k in args.params):
        parser.error("--params: counts from 1 to 10")
    if (args.calls is not None and args.calls < 1) or args.rounds < 1:
        parser.error("--calls and --rounds: at least 1")
    if args.instructions and shutil.which("valgrind") is None:
        parser.error("--instructions needs valgrind on PATH")
    counts = [0, *sorted(set(args.params))]
    unit = "M instructions" if args.instructions else "ms"
    print(f"ps.sensitivity against ps.simulate, one engine thread, {unit} per call")
    failures = 0
    for device in args.device:
        if args.instructions:
            per_call = {k: v / 1e6 for k, v in instructions(device, counts, args.calls or 10).items()}
        else:
            per_call = {k: v * 1e3 for k, v in wall_times(device, counts, args.calls or 30, args.rounds).items()}
        simulate = per_call[0]
        print(f"\n§{device}: ps.simulate {simulate:.3f}")
        print(f"{'parameters':>10} {'sensitivity':>12} {'ratio':>7}  verdict (<= {args.target:g}x)")
        for k in counts[1:]:
            ratio = per_call[k] / simulate
            ok = ratio <= args.target
            failures += not ok
            print(f"{k:>10} {per_call[k]:>12.3f} {ratio:>6.2f}x  {'met' if ok else 'NOT met'}")
    print(f"\n{failures} case(s) above {args.target:g}x" if failures else f"\nevery case within {args.target:g}x")


if __name__ == "__main__":
    main()
