"""A sweep row equals `ps.simulate` of that point, whatever the grid (issue 30).

Sweeps continue each point from its converged neighbours (continuation chains, SIMD lanes).
The row must not depend on that: any order, chain length (chunk size), thread count or lane
width gives the orbit a standalone `ps.simulate` of the same spec reaches. The accuracy promised
in docs/concepts.md: each metric within `ROW_TOL` of its scale over the grid (an orbit solved
to the Newton tolerance on two different step grids; measured 3e-8 to 1.2e-7).

Where the orbit belongs to a family (a Floquet multiplier at 1: the §3.4 PARITY's whippletree
at K2 = 0), *the* answer is the member a run from the spec's own start reaches; a chain from a
neighbour would land on another member (before the fix: yaw 0.12 mN·mm and stroke offset
0.12 rad off on a 14-point hinge grid, every row `converged`).
"""

from __future__ import annotations

import numpy as np
import polars as pl
import pytest

import paritysim as ps

ROW_TOL = 1e-6  # relative to the metric's scale over the grid (docs/concepts.md)
HINGE = "wings[*].springs.hinge.stiffness"


def _cut_omegas(spec: ps.Simulation, fraction: float) -> dict[str, float]:
    """The right wing's Ω1..Ω4 with a tip cut, scaled as in the §3.4 design-study tutorial."""
    outline = ps.Planform.hmf_like()
    uncut, cut = outline.omegas(), outline.cut(fraction, where="tip").omegas()
    right = spec.wings[1].aero
    return {f"wings.right.aero.omega{k}": getattr(right, f"omega{k}") * cut[f"omega{k}"] / uncut[f"omega{k}"] for k in range(1, 5)}


def _assert_rows_equal_simulate(spec: ps.Simulation, df: pl.DataFrame, paths: list[str], metrics: list[str]) -> None:
    assert (df["status"] == "ok").all(), df.select("status", "error")
    direct = []
    for row in df.iter_rows(named=True):
        result = ps.simulate(spec.with_paths({p: row[p] for p in paths}))
        assert result.converged
        direct.append([result.metrics[m] for m in metrics])
    expected = np.array(direct, dtype=float)
    got = df.select(metrics).to_numpy().astype(float)
    scale = np.maximum(np.nanmax(np.abs(expected), axis=0), 1e-3)
    worst = np.nanmax(np.abs(got - expected) / scale, axis=0)
    assert (worst <= ROW_TOL).all(), dict(zip(metrics, worst.tolist(), strict=True))


def _hinge_cut_grid(spec: ps.Simulation, hinges: list[float], cuts: list[float], hinge_major: bool) -> pl.DataFrame:
    rows = [{HINGE: h, **_cut_omegas(spec, c)} for c in cuts for h in hinges]
    if hinge_major:
        rows = [{HINGE: h, **_cut_omegas(spec, c)} for h in hinges for c in cuts]
    return pl.DataFrame(rows)


@pytest.mark.parametrize(
    ("order", "chunk_size", "threads", "lanes"),
    [("hinge", None, 1, "4"), ("cut", 5, 2, "4"), ("reversed", 3, 1, "1")],
)
def test_3_4_parity_k2_0_hinge_by_cut_rows_equal_simulate(monkeypatch: pytest.MonkeyPatch, order: str, chunk_size: int | None, threads: int, lanes: str) -> None:
    monkeypatch.setenv("PARITYSIM_LANES", lanes)
    spec = ps.devices.load("sreetharan2012_3_4_parity")
    assert spec.drivetrain.balance_spring == 0.0  # the neutral whippletree family
    grid = _hinge_cut_grid(spec, list(np.linspace(0.6, 12.0, 7)), [0.0, 0.2], hinge_major=order == "hinge")
    if order == "reversed":
        grid = grid.reverse()
    metrics = ["yaw_total_mean", "right_stroke_mean", "left_stroke_amplitude", "right_rotation_amplitude"]
    df = ps.sweep(spec, grid, metrics=metrics, threads=threads, chunk_size=chunk_size, progress=False)
    _assert_rows_equal_simulate(spec, df, grid.columns, metrics)


# A continuous parameter every shipped device has, and three values of it near the default.
AMPLITUDE = "actuator.waveform.amplitude_v"


@pytest.mark.parametrize("name", ps.devices.list())
def test_every_shipped_device_rows_equal_simulate(name: str) -> None:
    spec = ps.devices.load(name)
    base = spec.actuator.waveform.amplitude_v
    grid = {AMPLITUDE: [0.9 * base, 0.95 * base, base]}
    metric_names = [m for m in ("left_stroke_amplitude", "right_stroke_amplitude", "left_rotation_amplitude", "q2_mean", "yaw_total_mean") if ps.simulate(spec).metrics.get(m) is not None]
    df = ps.sweep(spec, grid, metrics=metric_names, progress=False)
    _assert_rows_equal_simulate(spec, df, [AMPLITUDE], metric_names)


@pytest.mark.parametrize("name", ["sreetharan2012_3_4_parity", "sreetharan2012_3_4_parity_1cut", "sreetharan2012_3_4_parity_2cut"])
def test_a_family_point_after_a_stiff_neighbour_equals_simulate(name: str) -> None:
    """K2 = 0 (a family) or nearly (1e-3, 1e-9) right after a stiffer K2: the neighbour's
    Jacobian put the slow multiplier at 0.974 where it is 1, so the chain's Newton stayed on
    (or ran along the family to) another member and the row said `ok` (stroke offset 0.0001
    against simulate's 0.0217 rad; up to 10 rad in a study). The variational equations at a
    soft point's orbit now decide, and a family point runs from the spec's own start."""
    spec = ps.devices.load(name)
    k2 = "drivetrain.balance_spring"
    rows = pl.DataFrame({k2: [10.0, 0.0, 2.0, 1e-3, 0.5, 0.0, 30.0, 1e-9], "wings.left.omega_ratio": [1.0, 1.0, 0.8, 0.8, 1.0, 1.0, 1.0, 1.0]})
    metrics = ["left_stroke_mean", "right_stroke_mean", "yaw_total_mean", "left_rotation_amplitude"]
    df = ps.sweep(spec, rows, metrics=metrics, threads=1, progress=False)
    _assert_rows_equal_simulate(spec, df, [k2, "wings.left.omega_ratio"], metrics)


def test_unconverged_rows_are_not_ok() -> None:
    """A point stopped by `max_cycles` before its steady state is `unconverged`, with the reason,
    and the sweep warns with their number."""
    spec = ps.devices.load("sreetharan2012_3_3_parity")
    with pytest.warns(RuntimeWarning, match=r"3 of 3 sweep points did not converge"):
        df = ps.sweep(spec, {AMPLITUDE: [80.0, 90.0, 100.0]}, options={"steady_state": "transient", "max_cycles": 2}, progress=False)
    assert not df["converged"].any()
    assert df["status"].to_list() == ["unconverged"] * 3
    assert df["error_kind"].to_list() == ["Unconverged"] * 3
    assert all("max_cycles" in e for e in df["error"].to_list())
    ok = ps.sweep(spec, {AMPLITUDE: [90.0]}, progress=False)
    assert ok["converged"].all() and ok["status"].to_list() == ["ok"] and ok["error"].is_null().all()
