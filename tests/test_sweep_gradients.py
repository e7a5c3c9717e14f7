"""ps.sweep(..., gradients=[paths]) (issue 31): every converged row carries the derivatives
ps.sensitivity gives at that point; rows that did not converge carry none."""

from __future__ import annotations

import math

import pytest

import paritysim as ps
from paritysim import InvalidParameterError

METRICS = ["left_stroke_amplitude", "right_stroke_amplitude", "yaw_total_mean"]


def _spec() -> ps.Simulation:
    d = ps.devices.load("sreetharan2012_3_3_parity").to_dict()
    d["drivetrain"]["balance_spring"] = 5.0  # an isolated orbit
    return ps.Simulation.from_dict(d)


def test_gradient_columns_equal_sensitivity_at_each_point():
    """The rows' derivatives are taken at the sweep's (chained) orbits, ps.sensitivity's at
    the orbit of a run from rest: they agree to the derivatives' own accuracy at the spec's
    rtol 1e-8 (measured: up to 8.7e-6 relative apart on the small cross-derivative
    d(right_stroke_amplitude)/d(left Ω), where each is up to 6.7e-6 off rtol-1e-11 runs), and
    both are that close to the tight derivatives."""
    spec = _spec()
    paths = ["actuator.amplitude_v", "wings[0].aero.omega1"]
    df = ps.sweep(spec, {"actuator.amplitude_v": [80.0, 100.0], "wings.left.omega_ratio": [1.0, 0.6]}, metrics=METRICS, gradients=paths, progress=False)
    assert (df["status"] == "ok").all()
    for row in df.iter_rows(named=True):
        point = spec.with_paths({"actuator.amplitude_v": row["actuator.amplitude_v"], "wings.left.omega_ratio": row["wings.left.omega_ratio"]})
        s = ps.sensitivity(point, paths, metrics=METRICS, progress=False)
        tight = ps.sensitivity(point, paths, metrics=METRICS, progress=False, rtol=1e-11, atol=1e-13, steady_tol=1e-11)
        for m in METRICS:
            for p in paths:
                ours = row[f"d({m})/d({p})"]
                assert ours == pytest.approx(s.derivative(m, p), rel=2e-5, abs=1e-9)
                assert ours == pytest.approx(tight.derivative(m, p), rel=1e-5, abs=1e-9)
    # The stroke amplitude grows with the drive at every point.
    assert (df["d(left_stroke_amplitude)/d(actuator.amplitude_v)"] > 0).all()


def test_rows_without_a_steady_state_have_no_gradients():
    spec = _spec()
    df = ps.sweep(spec, {"actuator.amplitude_v": [100.0, 1e9]}, metrics=METRICS, gradients=["actuator.amplitude_v"], progress=False)
    bad = df.filter(df["status"] != "ok")
    assert bad.height == 1
    assert bad["d(left_stroke_amplitude)/d(actuator.amplitude_v)"].is_null().all()
    good = df.filter(df["status"] == "ok")
    assert math.isfinite(good["d(left_stroke_amplitude)/d(actuator.amplitude_v)"][0])


@pytest.mark.parametrize(
    ("gradients", "named"),
    [
        (["drivetrain.balanse_spring"], "balance_spring"),
        (["drivetrain.kind"], "drivetrain.kind"),
        ([""], "gradients"),
        # Two spellings of one field would be two sets of the same columns.
        (["actuator.frequency_hz", "actuator.waveform.frequency_hz"], "the field of `actuator.frequency_hz`"),
    ],
)
def test_bad_gradient_paths_are_named_before_running(gradients, named):
    with pytest.raises(InvalidParameterError) as e:
        ps.sweep(_spec(), {"actuator.amplitude_v": [100.0]}, gradients=gradients, progress=False)
    assert named in str(e.value)


def test_a_gradient_path_listed_twice_is_one_set_of_columns():
    df = ps.sweep(_spec(), {"actuator.amplitude_v": [100.0]}, metrics=METRICS[:1], gradients=["actuator.stiffness"] * 2, progress=False)
    assert [c for c in df.columns if c.startswith("d(")] == ["d(left_stroke_amplitude)/d(actuator.stiffness)"]


def test_gradients_none_is_a_sweep_without_them():
    grid = {"actuator.amplitude_v": [90.0, 100.0]}
    plain = ps.sweep(_spec(), grid, metrics=METRICS, progress=False)
    none = ps.sweep(_spec(), grid, metrics=METRICS, gradients=None, progress=False)
    assert none.columns == plain.columns and not any(c.startswith("d(") for c in none.columns)
    assert none.select(METRICS).equals(plain.select(METRICS))


def test_a_checkpoint_of_a_sweep_without_gradients_is_not_reused(tmp_path):
    spec = _spec()
    path = tmp_path / "study.parquet"
    grid = {"actuator.amplitude_v": [90.0, 100.0]}
    ps.sweep(spec, grid, metrics=METRICS, checkpoint=path, progress=False)
    with pytest.raises(InvalidParameterError):
        ps.sweep(spec, grid, metrics=METRICS, checkpoint=path, gradients=["actuator.amplitude_v"], progress=False)


def test_a_both_wings_parameter_at_its_lower_bound_takes_the_one_sided_derivative():
    """``wings[*].springs.stroke.cubic`` at 0 (its range's end): the step below is outside the
    range on both wings, so the derivative is one-sided; checked against one-sided second-order
    differences of whole ps.simulate runs."""
    spec = _spec()
    path, metric = "wings[*].springs.stroke.cubic", "left_stroke_amplitude"
    tight = {"rtol": 1e-11, "atol": 1e-13, "steady_tol": 1e-11}
    s = ps.sensitivity(spec, [path], metrics=[metric], progress=False, **tight)

    def m(c: float) -> float:
        return ps.simulate(spec.with_paths({path: c}), columns=[], metrics=[metric], progress=False, **tight).metrics[metric]

    # Steps of 0.03-0.1 mN·mm/rad³ agree to 1e-8 relative; at 0.3-1 the sampled peak moves
    # between samples and the differences wander by 10 %.
    h = 0.05
    reference = (-3 * m(0.0) + 4 * m(h) - m(2 * h)) / (2 * h)
    assert s.derivative(metric, path) == pytest.approx(reference, rel=2e-4)
    assert s.derivative(metric, path) < 0  # a stiffening stroke spring lowers the amplitude
    df = ps.sweep(spec, {"actuator.amplitude_v": [80.0, 100.0]}, metrics=[metric], gradients=[path], progress=False)
    assert (df["status"] == "ok").all() and df["gradient_error"].is_null().all()


def test_a_point_whose_gradient_fails_keeps_its_row_and_says_why():
    # wings[*] needs one value on both wings: the point with different cubic springs cannot be
    # differentiated by it, but its metrics stand; a chunk of only such points too.
    spec = _spec()
    grid = {"wings[0].springs.stroke.cubic": [0.0, 10.0]}
    for values in (grid, {"wings[0].springs.stroke.cubic": [10.0]}):
        df = ps.sweep(spec, values, metrics=METRICS, gradients=["wings[*].springs.stroke.cubic"], progress=False)
        assert (df["status"] == "ok").all() and df["left_stroke_amplitude"].is_not_null().all()
        differ = df.filter(df["wings[0].springs.stroke.cubic"] == 10.0)
        assert differ["gradient_error"][0].startswith("InvalidParameterError") and "wings" in differ["gradient_error"][0]
        assert differ[f"d(left_stroke_amplitude)/d(wings[*].springs.stroke.cubic)"].is_null().all()


def test_gradients_run_on_the_sweeps_own_threads(monkeypatch):
    # The derivative columns are computed with the sweep's `threads`, not the environment's
    # default: an unusable PARITYSIM_THREADS must not matter once `threads` is given.
    monkeypatch.setenv("PARITYSIM_THREADS", "0")
    df = ps.sweep(_spec(), {"actuator.amplitude_v": [90.0, 100.0]}, metrics=METRICS, gradients=["actuator.amplitude_v"], threads=1, progress=False)
    assert (df["status"] == "ok").all()
    assert df["gradient_error"].is_null().all()
    assert (df["d(left_stroke_amplitude)/d(actuator.amplitude_v)"] > 0).all()
