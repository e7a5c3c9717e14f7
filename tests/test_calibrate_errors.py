"""Bad input to the single-point ``ps.calibrate(model, targets, free)``: a typed error naming the
argument, never a foreign exception (polars, numpy) or a silently unused argument; a model whose
outputs turn non-finite during a fit names where they did, not the start."""

from __future__ import annotations

import math

import numpy as np
import polars as pl
import pytest

import paritysim as ps

FREE = {"actuator.force_per_volt": (0.8, 1.5)}
POINT = {"left_stroke_amplitude": 0.6}


@pytest.fixture(scope="module")
def spec() -> ps.Simulation:
    return ps.devices.load("sreetharan2012_3_3_parity").replace(options=ps.Options(samples_per_cycle=40, max_cycles=200))


@pytest.mark.parametrize(
    ("target", "field", "hint"),
    [
        (pl.DataFrame({"left_phi": [0.1, 0.2]}), "targets", "`time_ms` column"),
        (pl.DataFrame({"time_ms": [], "left_phi": []}), "targets", "at least one row"),
        (pl.DataFrame({"time_ms": [0.0, 0.1]}), "targets", "at least one trajectory column"),
        (pl.DataFrame({"time_ms": [0.0, 0.1], "left_phi": ["a", "b"]}), "targets.left_phi", "numbers"),
        (pl.DataFrame({"time_ms": [0.0, 0.1], "left_phi": [0.1, math.nan]}), "targets.left_phi", "finite"),
        (pl.DataFrame({"time_ms": [0.0, 0.1], "left_phi": [0.1, None]}), "targets.left_phi", "finite"),
        (pl.DataFrame({"time_ms": [0.0, math.inf], "left_phi": [0.1, 0.2]}), "targets.time_ms", "finite"),
        (pl.DataFrame({"time_ms": [0.0, 0.2, 0.1], "left_phi": [0.1, 0.2, 0.3]}), "targets.time_ms", "increasing"),
        (pl.DataFrame({"time_ms": [0.0, 0.1], "left_ph": [0.1, 0.2]}), "targets.left_ph", "did you mean `left_phi`"),
    ],
)
def test_a_bad_trajectory_target_is_a_typed_error(spec: ps.Simulation, target: pl.DataFrame, field: str, hint: str) -> None:
    with pytest.raises(ps.InvalidParameterError) as err:
        ps.calibrate(spec, target, FREE, max_nfev=1, progress=False)
    assert err.value.field == field, str(err.value)
    assert hint in str(err.value)


def test_a_trajectory_target_needs_a_simulation() -> None:
    with pytest.raises(ps.InvalidParameterError) as err:
        ps.calibrate(lambda a: {"y": a}, pl.DataFrame({"time_ms": [0.0, 0.1], "left_phi": [0.1, 0.2]}), {"a": (0.0, 1.0)}, progress=False)
    assert err.value.field == "targets" and "Simulation" in str(err.value)


def test_scale_weighs_a_trajectory_column(spec: ps.Simulation) -> None:
    """``scale`` divides a trajectory column's residuals as it does a metric's (it was dropped)."""
    trajectory = ps.simulate(spec.with_paths({"actuator.force_per_volt": 1.3})).trajectory
    target = trajectory.select("time_ms", "left_phi")[::4]
    peak = float(target["left_phi"].abs().max())
    default = ps.calibrate(spec, target, FREE, max_nfev=1, progress=False)
    doubled = ps.calibrate(spec, target, FREE, scale={"left_phi": 2.0 * peak}, max_nfev=1, progress=False)
    # The first evaluation is at the same start: twice the scale, a quarter of the cost.
    assert doubled.iterations["cost"][0] == pytest.approx(default.iterations["cost"][0] / 4.0, rel=1e-9)
    assert default.iterations["cost"][0] > 0


@pytest.mark.parametrize(
    ("kw", "field", "hint"),
    [
        ({"x0": {"actuator.force_per_vol": 1.49}}, "x0.actuator.force_per_vol", "did you mean `actuator.force_per_volt`"),
        ({"x0": 1.2}, "x0", "a mapping"),
        ({"scale": {"left_stroke_amplitud": 1e-9}}, "scale.left_stroke_amplitud", "did you mean `left_stroke_amplitude`"),
        ({"jacobian": "sensitivty"}, "jacobian", "'differences'"),
        ({"jacobian": "sensitivity"}, "jacobian", "data="),
        ({"labels": ["case"]}, "labels", "data="),
        ({"labels": "case"}, "labels", "data="),
        ({"seed": 3}, "seed", "data="),
        ({"threads": 2}, "threads", "data="),
    ],
)
def test_the_single_point_form_refuses_what_it_would_ignore(spec: ps.Simulation, kw: dict, field: str, hint: str) -> None:  # type: ignore[type-arg]
    with pytest.raises(ps.InvalidParameterError) as err:
        ps.calibrate(spec, POINT, FREE, max_nfev=1, progress=False, **kw)
    assert err.value.field == field, str(err.value)
    assert hint in str(err.value)


@pytest.mark.parametrize(
    ("kw", "field", "hint"),
    [
        ({"scale": {"left_stroke_amplitude": 1.0}}, "scale", "sigma"),
        ({"workers": 4}, "workers", "threads="),
        ({"seed": 3}, "seed", "holdout="),
    ],
)
def test_the_table_form_refuses_the_single_point_arguments(spec: ps.Simulation, kw: dict, field: str, hint: str) -> None:  # type: ignore[type-arg]
    data = pl.DataFrame({"actuator.waveform.amplitude_v": [80.0, 120.0], "left_stroke_amplitude": [0.5, 0.6]})
    with pytest.raises(ps.InvalidParameterError) as err:
        ps.calibrate(spec, data=data, params=FREE, max_nfev=1, progress=False, **kw)
    assert err.value.field == field, str(err.value)
    assert hint in str(err.value)


def _breaks_above(edge: float):  # type: ignore[no-untyped-def]
    return lambda a: {"y": a if a < edge else math.nan}


def test_outputs_turning_non_finite_mid_fit_name_where_not_the_start() -> None:
    """The start is finite; the fit walks towards y = 0.9 and the model breaks above 0.6: the
    error names the bounds and the point where it broke (issue 34's message blamed ``x0``)."""
    with pytest.raises(ps.InvalidParameterError) as err:
        ps.calibrate(_breaks_above(0.6), {"y": 0.9}, {"a": (0.0, 1.0)}, x0={"a": 0.5}, progress=False)
    text = str(err.value)
    assert err.value.field == "free", text
    assert "`y` is not finite at {'a': " in text and "from the start {'a': 0.5}" in text
    at = float(text.split("is not finite at {'a': ")[1].split("}")[0])
    assert at >= 0.6 and not math.isnan(_breaks_above(0.6)(0.5)["y"])


def test_outputs_non_finite_at_the_start_name_x0() -> None:
    with pytest.raises(ps.InvalidParameterError) as err:
        ps.calibrate(_breaks_above(0.6), {"y": 0.9}, {"a": (0.0, 1.0)}, x0={"a": 0.7}, progress=False)
    assert err.value.field == "x0" and "{'a': 0.7}" in str(err.value) and "`y` is not finite there" in str(err.value)


def test_the_checked_arguments_still_fit() -> None:
    """The values the checks let through run as before: a known start, a scale, differences."""
    fit = ps.calibrate(_breaks_above(0.6), {"y": 0.3}, {"a": (0.0, 1.0)}, x0={"a": 0.5}, scale={"y": 0.1}, jacobian="differences", workers=1, labels=[], progress=False)
    assert fit.values["a"] == pytest.approx(0.3, abs=1e-6) and fit.iterations["a"][0] == 0.5
    assert np.isfinite(fit.residuals).all()


def test_a_video_longer_than_the_recorded_window_is_refused(spec: ps.Simulation) -> None:
    """np.interp held the window's last value for every later sample: a 3-cycle video against
    a 1-cycle window fitted both parameters to their bounds and said success."""
    video = ps.simulate(spec.replace(options=spec.options.with_fields("options", record_cycles=3))).trajectory.select("time_ms", "left_phi")[::4]
    with pytest.raises(ps.InvalidParameterError) as err:
        ps.calibrate(spec, video, FREE, max_nfev=1, progress=False)
    assert err.value.field == "targets.time_ms" and "record_cycles >= 3" in str(err.value)
    one_cycle = video.filter(pl.col("time_ms") <= video["time_ms"][0] + 1e3 / spec.actuator.waveform.frequency_hz)
    assert ps.calibrate(spec, one_cycle, FREE, max_nfev=1, progress=False) is not None


def test_a_zero_metric_target_needs_a_scale(spec: ps.Simulation) -> None:
    """A residual is divided by its target's size: a zero target's floor of 1e-12 turned a
    metric held at zero by symmetry (round-off) into the largest residual, and the fit stayed
    at its start and said converged."""
    with pytest.raises(ps.InvalidParameterError) as err:
        ps.calibrate(spec, {**POINT, "left_stroke_mean": 0.0}, FREE, max_nfev=1, progress=False)
    assert err.value.field == "targets.left_stroke_mean" and "scale" in str(err.value)
    fit = ps.calibrate(spec, {**POINT, "left_stroke_mean": 0.0}, FREE, scale={"left_stroke_mean": 0.01}, max_nfev=1, progress=False)
    assert fit is not None
