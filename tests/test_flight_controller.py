"""A Python controller in free flight (issue 17): `ps.simulate(spec, controller=fn,
control_rate_hz=...)` calls fn between integration legs; a PD written in Python must fly the
same trajectory as the Rust PD of `[body.control]` with the same gains and rate."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import paritysim as ps
from paritysim.flight import with_body

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
FAST = {"max_cycles": 30, "samples_per_cycle": 20, "record_cycles": 3}
GAINS = {"kp": 20.0, "kd": 200.0, "rate_hz": 2000.0, "limit": 2.0}


def _spec(**body: object) -> ps.Simulation:
    spec = ps.load_spec(EXAMPLES / "free_flight.toml")
    spec = spec.replace(options=dataclasses.replace(spec.options, **FAST))
    return with_body(spec, mode="roll", initial_attitude_rad=(0.2, 0.0, 0.0), **body)


def _python_pd(calls: list[float]):
    def controller(t_ms: float, body: dict[str, float]) -> dict[str, float]:
        calls.append(t_ms)
        u = -GAINS["kp"] * body["body_roll"] - GAINS["kd"] * body["body_omega_roll"]
        return {"q2_bias": min(max(u, -GAINS["limit"]), GAINS["limit"])}

    return controller


def test_python_pd_matches_the_rust_pd() -> None:
    rust = ps.simulate(_spec(control={"input": "q2_bias", "axis": "roll", **GAINS}))
    calls: list[float] = []
    python = ps.simulate(_spec(), controller=_python_pd(calls), control_rate_hz=GAINS["rate_hz"])
    open_loop = ps.simulate(_spec())
    a, b, c = (r.trajectory["body_roll"].to_numpy() for r in (rust, python, open_loop))
    # The controller acts (the comparison can fail) ...
    assert np.max(np.abs(a - c)) > 1e-3
    # ... and both implementations fly the same trajectory.
    np.testing.assert_allclose(b, a, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(python.trajectory["q2"].to_numpy(), rust.trajectory["q2"].to_numpy(), rtol=0, atol=1e-12)
    # One call per control tick from the release: 3 wingbeats at 110 Hz, 2 kHz.
    window = 3 * python.period_ms
    assert len(calls) == int(np.ceil(window * GAINS["rate_hz"] / 1000.0 - 1e-9))
    np.testing.assert_allclose(np.diff(calls), 1000.0 / GAINS["rate_hz"], rtol=1e-9)


def test_an_exception_in_the_controller_propagates_as_is() -> None:
    class Stop(Exception):
        pass

    def controller(t_ms: float, body: dict[str, float]) -> dict[str, float]:
        raise Stop(f"at {t_ms}")

    with pytest.raises(Stop, match="at "):
        ps.simulate(_spec(), controller=controller, control_rate_hz=500.0)


def test_bad_controller_output_and_arguments_name_the_field() -> None:
    with pytest.raises(ps.InvalidParameterError, match="q3_bias"):
        ps.simulate(_spec(), controller=lambda t, b: {"q3_bias": 1.0}, control_rate_hz=500.0)
    with pytest.raises(ps.InvalidParameterError, match="finite"):
        ps.simulate(_spec(), controller=lambda t, b: {"q2_bias": float("nan")}, control_rate_hz=500.0)
    with pytest.raises(ps.InvalidParameterError, match="control_rate_hz"):
        ps.simulate(_spec(), controller=lambda t, b: {}, control_rate_hz=0.0)
    with pytest.raises(ps.InvalidParameterError, match="control_rate_hz"):
        ps.simulate(_spec(), controller=lambda t, b: {})
    fixed = with_body(_spec(), mode="fixed")
    with pytest.raises(ps.InvalidParameterError, match="body.mode"):
        ps.simulate(fixed, controller=lambda t, b: {}, control_rate_hz=500.0)


def test_python_controller_drives_eq_5_1_like_the_rust_pd() -> None:
    """The same PD on roll through ln q3 (eq. 5.1's torque ratio) in Python and in
    ``[body.control]``: the same trajectory; an input the drivetrain has no place for (a side
    drive without a dual four-bar) raises naming it."""
    gains = {"kp": 0.5, "kd": 5.0, "rate_hz": 1000.0, "limit": 0.3}
    rust = ps.simulate(_spec(control={"input": "log_q3", "axis": "roll", **gains}))

    def controller(t_ms: float, body: dict[str, float]) -> dict[str, float]:
        u = -gains["kp"] * body["body_roll"] - gains["kd"] * body["body_omega_roll"]
        return {"log_q3": min(max(u, -gains["limit"]), gains["limit"])}

    python = ps.simulate(_spec(), controller=controller, control_rate_hz=gains["rate_hz"])
    a, b, c = (r.trajectory["body_roll"].to_numpy() for r in (rust, python, ps.simulate(_spec())))
    assert np.max(np.abs(a - c)) > 1e-4
    np.testing.assert_allclose(b, a, rtol=0.0, atol=1e-12)
    with pytest.raises(ps.InvalidParameterError, match="side_"):
        ps.simulate(_spec(), controller=lambda t, b: {"side_gain_left": 0.1}, control_rate_hz=500.0)
