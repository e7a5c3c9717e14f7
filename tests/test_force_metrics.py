"""Force and power metrics (issue 32, item 1): the wings' cycle-mean lift per wing and net (mN),
the aerodynamic and actuator power (mW) and the efficiencies, streamed on the torque stand like
every other metric, so a sweep has them as columns; the physics is checked in Rust
(crates/spec/tests/force_metrics.rs), here that the sweep rows are ps.simulate of their point."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import paritysim as ps

FORCE = [
    "lift_mean",
    "left_lift_mean",
    "right_lift_mean",
    "lift_rms",
    "lift_peak",
    "aero_force_y_mean",
    "aero_force_z_mean",
    "aero_power_mean",
    "actuator_power_mean",
    "lift_per_power",
    "lift_to_weight",
    "actuator_power_per_weight",
]


@pytest.fixture(scope="module")
def parity() -> ps.Simulation:
    spec = ps.devices.load("sreetharan2012_3_4_parity")
    spec = spec.replace(options=dataclasses.replace(spec.options, samples_per_cycle=100))
    # A fixed body is the torque stand; its mass gives the weight of lift_to_weight.
    return spec.replace(body=ps.spec.Body(mode="fixed", mass_mg=80.0))


def test_sweep_rows_of_the_force_metrics_are_simulate_of_their_point(parity: ps.Simulation) -> None:
    grid = {"wings[0].springs.hinge.stiffness": [2.0, 3.0], "wings[1].aero.omega1": [38.2, 30.0]}
    df = ps.sweep(parity, grid, metrics=[*FORCE, "yaw_total_mean"], progress=False)
    assert (df["status"] == "ok").all()
    for i, row in enumerate(df.select(list(grid)).iter_rows(named=True)):
        direct = ps.simulate(parity.with_paths(row), columns=[]).metrics
        for name in [*FORCE, "yaw_total_mean"]:
            got, want = df[name][i], direct[name]
            scale = float(np.nanmax(np.abs(df[name].to_numpy())))
            # a chained sweep point starts from its neighbour: the same orbit to its accuracy
            assert abs(got - want) <= 1e-6 * scale, (name, i, got, want)
    # The wings lift more than 80 mg weighs, and the cut right wing lifts less than the left.
    assert (df["lift_to_weight"] > 1.0).all()
    assert (df["lift_mean"] - df["left_lift_mean"] - df["right_lift_mean"]).abs().max() < 1e-12
    cut = df.filter(df["wings[1].aero.omega1"] == 30.0)
    assert (cut["right_lift_mean"] < cut["left_lift_mean"]).all()


def test_force_metrics_are_listed_and_documented(parity: ps.Simulation) -> None:
    from pathlib import Path

    names = ps.simulate(parity, columns=[]).metrics
    for name in FORCE:
        assert name in names and names[name] is not None, name
    # Every metric this device reports is in the metric reference, with its unit.
    reference = (Path(__file__).resolve().parents[1] / "docs" / "reference" / "metrics.md").read_text()
    for name in ("lift_mean", "aero_power_mean", "actuator_power_mean", "lift_per_power", "lift_to_weight", "actuator_power_per_weight"):
        assert f"`{name}`" in reference, name
    # Stroke-drag wings have no force model: asking for lift is an error saying so.
    drag = ps.devices.load("sreetharan2012_3_3_parity")
    with pytest.raises(ps.InvalidParameterError, match="metrics.*blade_element"):
        ps.simulate(drag, columns=[], metrics=["lift_mean"])
    with pytest.raises(ps.InvalidParameterError, match="body"):
        ps.simulate(drag, columns=[], metrics=["actuator_power_per_weight"])
