"""A drive frequency typed in the wrong unit fails fast and names the field (issue 33)."""

from __future__ import annotations

import time
import warnings

import pytest

import paritysim as ps
from paritysim import _slow_drive
from paritysim.cli import describe_error

FIELD = "actuator.waveform.frequency_hz"


def _at(name: str, frequency_hz: float) -> ps.Simulation:
    return ps.devices.load(name).with_paths({FIELD: frequency_hz})


@pytest.mark.slow
@pytest.mark.parametrize("name", ps.devices.list())
def test_a_kilohertz_slip_ends_within_seconds_and_names_the_frequency(name: str, monkeypatch):
    # A shorter probe than the default 3 s: either outcome below is accepted, and 8 devices
    # would otherwise spend 24 s of the suite's CPU waiting for it.
    monkeypatch.setattr(_slow_drive, "PROBE_WALL_MS", 750.0)
    started = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = ps.simulate(_at(name, 0.12), columns=[], metrics=[])
        except ps.InvalidParameterError as exc:
            assert exc.field == FIELD and str(exc).startswith(f"invalid `{FIELD}` = 0.12")
            assert "did you mean 120 Hz?" in str(exc) and "\n" not in str(exc)
            assert isinstance(exc.__cause__, ps.IntegrationError)  # the wall budget, measured
        else:  # ran: it must say the result is quasi-static, and why
            assert result.converged
            text = " ".join(str(w.message) for w in caught)
            assert FIELD in text and "quasi-static" in text and "did you mean 120 Hz?" in text
    assert time.perf_counter() - started < 10.0  # a hang guard, generous on a loaded machine


def test_the_refusal_comes_after_the_probe_budget(monkeypatch):
    monkeypatch.setattr(_slow_drive, "PROBE_WALL_MS", 300.0)
    started = time.perf_counter()
    with pytest.raises(ps.InvalidParameterError, match=r"did you mean 120 Hz\?") as caught:
        ps.simulate(_at("sreetharan2012_2_5_lift_parity_1cut", 0.12), columns=[], metrics=[])
    assert time.perf_counter() - started < 3.0
    assert caught.value.field == FIELD and caught.value.problems[0][0] == FIELD
    assert "options.duration_ms" in str(caught.value)  # how to run a slow drive on purpose


def test_a_quasi_static_run_warns_and_a_chosen_duration_does_not():
    with pytest.warns(UserWarning, match=r"quasi-static.*did you mean 120 Hz\?"):
        slow = ps.simulate(_at("sreetharan2012_3_3_parity", 0.12))
    # Quasi-static indeed: the stroke is the static deflection T·(force_per_volt·V)/stiffness.
    a, t = slow.spec.actuator, slow.spec.drivetrain.transmission_ratio
    static = t * a.force_per_volt * a.waveform.amplitude_v / a.stiffness
    assert slow.metrics["left_stroke_amplitude"] == pytest.approx(static, rel=1e-3)
    assert ps.simulate(_at("sreetharan2012_3_3_parity", 120.0)).metrics["left_stroke_amplitude"] < 0.9 * static
    assert _slow_drive.likely_meant(0.12) == 120.0 and _slow_drive.likely_meant(0.0001) is None
    spec = _at("sreetharan2012_3_3_parity", 0.5)
    spec = spec.replace(options=spec.options.with_fields("options", duration_ms=50.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ps.simulate(spec, columns=[], metrics=[])


def test_the_command_line_names_the_responsible_field_first_without_the_state():
    spec = _at("sreetharan2012_3_4_parity", 5.0)
    spec = spec.replace(options=spec.options.with_fields("options", max_wall_ms=30.0))
    with pytest.raises(ps.IntegrationError) as caught:
        ps.simulate(spec, columns=[], metrics=[])
    assert "state = [" in str(caught.value) and len(caught.value.state) > 2  # the API keeps it
    line = describe_error(caught.value)
    assert line.startswith("IntegrationError: `options.max_wall_ms` = 30: must be")
    assert "state" not in line and "\n" not in line and "because: integration failed" in line
