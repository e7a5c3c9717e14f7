"""Free flight (issue 17, beyond the thesis): a spec with a [body] section runs through
ps.simulate and ps.sweep like any other; fixed bodies are the torque stand, bit for bit."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

import paritysim as ps

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
FAST = {"max_cycles": 30, "samples_per_cycle": 40, "record_cycles": 3}


def _spec(**body: object) -> ps.Simulation:
    spec = ps.load_spec(EXAMPLES / "free_flight.toml")
    spec = spec.replace(options=dataclasses.replace(spec.options, **FAST))
    return spec.with_paths({f"body.{k}": v for k, v in body.items()})


def test_free_flight_reports_attitude_position_and_body_metrics() -> None:
    result = ps.simulate(_spec())
    df = result.trajectory
    for column in ("body_roll", "body_yaw", "body_pitch", "body_qw", "body_omega_roll", "body_x", "lift", "left_phi", "q2"):
        assert column in df.columns, column
    assert df.height == 3 * 40 + 1
    q = df.select(["body_qw", "body_qx", "body_qy", "body_qz"]).to_numpy()
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)
    metrics = result.metrics
    # The §3.4 wings lift more than the 60 mg airframe weighs: it climbs (+x is up).
    assert metrics["lift_to_weight"] > 1.0
    assert df["body_x"][-1] > df["body_x"][0]
    # No gimbal: the body is free to move in every direction.
    assert metrics["body_displacement"] > 0.0


def test_fixed_body_section_changes_nothing() -> None:
    plain = ps.load_spec(EXAMPLES / "drag_parity.toml")
    plain = plain.replace(options=dataclasses.replace(plain.options, max_cycles=5, samples_per_cycle=40))
    fixed = plain.replace(body=ps.spec.Body(mode="fixed", mass_mg=90.0))
    a, b = ps.simulate(plain), ps.simulate(fixed)
    assert a.metrics == b.metrics
    assert a.trajectory.equals(b.trajectory)


def test_sweep_over_a_body_field() -> None:
    spec = _spec(mode="clamped")
    df = ps.sweep(spec, {"body.mass_mg": [60.0, 120.0]}, metrics=["lift_to_weight", "body_torque_roll_mean"], progress=False)
    assert (df["status"] == "ok").all()
    ratio = df["lift_to_weight"].to_list()
    # Clamped: the airframe's mass only sets the weight.
    assert abs(ratio[0] / ratio[1] - 2.0) < 1e-12
    direct = ps.simulate(spec).metrics["lift_to_weight"]
    assert np.float64(direct).tobytes() == np.float64(ratio[0]).tobytes()
