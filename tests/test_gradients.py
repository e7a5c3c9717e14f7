"""ps.sensitivity (issue 31): derivatives of steady-state metrics against central differences
of whole ps.simulate runs, on the §3.4 blade-element device (passive rotation) and the §3.3
device; neutral families flagged; bad paths named."""

from __future__ import annotations

import numpy as np
import polars as pl
import pytest

import paritysim as ps
from paritysim import InvalidParameterError

TIGHT = {"rtol": 1e-10, "atol": 1e-12, "steady_tol": 1e-10}


def _metrics(spec: ps.Simulation, values: dict[str, float]) -> dict[str, float]:
    r = ps.simulate(_set(spec, values), columns=[], progress=False, **TIGHT)
    assert r.converged
    return dict(r.metrics)


def _set(spec: ps.Simulation, values: dict[str, float]) -> ps.Simulation:
    d = spec.to_dict()
    for path, v in values.items():
        node = d
        keys = path.replace("]", "").replace("[", ".").split(".")
        for k in keys[:-1]:
            node = node[int(k)] if k.isdigit() else node[k]
        node[keys[-1]] = v
    return ps.Simulation.from_dict(d)


def _check_against_whole_runs(spec: ps.Simulation, paths: list[str], base: list[float], rel_step: float, rel: float = 1e-4) -> int:
    s = ps.sensitivity(spec, paths, progress=False, **TIGHT)
    checked = 0
    for path, p0 in zip(paths, base, strict=True):
        h = rel_step * abs(p0)

        def reference(step: float) -> dict[str, float]:
            plus, minus = _metrics(spec, {path: p0 + step}), _metrics(spec, {path: p0 - step})
            return {m: (plus[m] - minus[m]) / (2 * step) for m in plus if plus[m] is not None and minus[m] is not None}

        coarse, fine = reference(h), reference(h / 2)
        for row in s.jacobian.iter_rows(named=True):
            m, m0 = row["metric"], row["value"]
            if not row["differentiable"] or not np.isfinite(m0) or m not in fine:
                continue
            # What whole runs resolve: their own error (~1e-8 of the metric here) over the step.
            resolved = 1e-8 * (1 + abs(m0)) / (h / 2)
            if abs(coarse[m] - fine[m]) > 1e-4 * abs(fine[m]) + resolved:
                continue  # the metric is not smooth over the reference's step
            ours = row[f"d/d({path})"]
            assert abs(ours - fine[m]) <= rel * abs(fine[m]) + resolved, (path, m, ours, fine[m])
            checked += 1
    return checked


def test_blade_element_device_derivatives_equal_whole_run_differences():
    spec = ps.devices.load("sreetharan2012_3_4_parity_1cut")
    spec = _set(spec, {"drivetrain.balance_spring": 30.0})  # K2 > 0: an isolated orbit
    paths = ["wings[0].springs.hinge.stiffness", "actuator.waveform.amplitude_v", "drivetrain.balance_spring"]
    d = spec.to_dict()
    base = [d["wings"][0]["springs"]["hinge"]["stiffness"], d["actuator"]["waveform"]["amplitude_v"], 30.0]
    assert _check_against_whole_runs(spec, paths, base, 1e-3) >= 15


def test_linkage_drivetrain_derivatives_equal_whole_run_differences():
    linkage = ps.devices.load("sreetharan2012_3_3_parity_linkage")
    d = linkage.to_dict()
    assert _check_against_whole_runs(linkage, ["actuator.waveform.amplitude_v", "drivetrain.balance_spring"], [d["actuator"]["waveform"]["amplitude_v"], d["drivetrain"]["balance_spring"]], 1e-3) >= 20


def test_lift_parity_derivatives_equal_whole_run_differences():
    # The §2.5 Lift PARITY: free deviation, switched blade elements, a period-2 orbit at K2 = 30.
    # Its variational monodromy missed the jumps at the switches (d left_stroke_amplitude /
    # d amplitude 3.3 % off); from differences of the fixed-grid map the derivatives agree with
    # whole runs to 2e-5 (strokes, lift) and 3.5e-4 (roll torque mean), a residual whose cause
    # is not established (docs/findings.md §30): checked at 1e-3.
    lift = _set(ps.devices.load("sreetharan2012_2_5_lift_parity_1cut"), {"drivetrain.balance_spring": 30.0})
    assert _check_against_whole_runs(lift, ["actuator.waveform.amplitude_v"], [100.0], 1e-3, rel=1e-3) >= 5


def test_the_frequency_derivative_scales_the_period():
    spec = _set(ps.devices.load("sreetharan2012_3_3_parity"), {"drivetrain.balance_spring": 5.0})
    assert _check_against_whole_runs(spec, ["actuator.waveform.frequency_hz"], [110.0], 1e-3) >= 5


def test_a_neutral_family_is_reported_and_flagged_not_divided_by():
    spec = ps.devices.load("sreetharan2012_3_3_parity_1cut")  # K2 = 0: a whippletree family
    s = ps.sensitivity(spec, ["actuator.waveform.amplitude_v"], progress=False)
    assert s.neutral_directions == 1
    assert np.min(np.abs(s.multipliers - 1)) < 1e-6
    defined = s.jacobian.filter(s.jacobian["value"].is_finite())
    assert defined["d/d(actuator.waveform.amplitude_v)"].is_finite().all()
    assert not s.jacobian["differentiable"].all(), "the stroke means move along the family"
    assert "family" in " ".join(r for r in s.jacobian["reason"].drop_nulls())
    assert "1 neutral direction" in repr(s) and "\n" not in repr(s)


def test_a_parameter_that_breaks_the_family_has_no_derivative_there():
    """At K2 = 0 every stroke offset is an orbit; the balance spring selects one as it leaves
    0. On wings that differ (the 1-Cut) the run from rest ends on a member with an offset, and
    a run at a small K2 on another: the metric jumps (its change does not shrink with the
    step), so the balance spring's column is NaN with the reason, not a slope that looks
    right (it was 55 % off in q2_amplitude). On identical wings symmetry keeps the member."""
    spec = ps.devices.load("sreetharan2012_3_3_parity_1cut")
    at = {k2: _metrics(spec, {"drivetrain.balance_spring": k2})["left_stroke_mean"] for k2 in (0.0, 1e-3, 4e-3)}
    jumps = [abs(at[h] - at[0.0]) for h in (1e-3, 4e-3)]
    assert min(jumps) > 0.9 * max(jumps) and min(jumps) > 1e-4, at  # a jump, not a slope
    paths = ["drivetrain.balance_spring", "actuator.waveform.frequency_hz"]
    s = ps.sensitivity(spec, paths, progress=False)
    assert s.parameter_reasons[1] is None and np.isfinite(s.matrix[:, 1][np.isfinite(s.values)]).all()
    assert s.parameter_reasons[0] is not None and "family" in s.parameter_reasons[0]
    assert np.isnan(s.matrix[:, 0]).all() and np.isnan(s.state_jacobian[:, 0]).all()
    assert s.parameters["differentiable"].to_list() == [False, True]
    assert "1 parameter(s) not differentiable in" in repr(s)
    with pytest.raises(InvalidParameterError, match="drivetrain.balance_spring.*family"):
        s.derivative("q2_amplitude", "drivetrain.balance_spring")
    assert s.derivative("q2_amplitude", "actuator.waveform.frequency_hz") == s.matrix[s.metric_names.index("q2_amplitude"), 1]
    hatched = [p for p in s.plot(metrics=["q2_amplitude"]).axes[0].patches if p.get_hatch()]
    assert len(hatched) == 1  # the balance spring's column
    symmetric = ps.sensitivity(ps.devices.load("sreetharan2012_3_3_parity"), paths, progress=False)
    assert symmetric.parameter_reasons == (None, None)


def test_a_parameter_at_zero_is_stepped_on_the_scale_of_its_units():
    """A drive offset at 0 V was stepped by 1e-8 V (a size floor of 1e-3): the map's change sat
    at round-off, which the slow balance-beam multiplier (1 - 1.6e-3 at K2 = 1) amplified.
    The stroke means are exactly linear in the offset (a DC force on a linear map), so wide
    central differences of whole runs are exact; ours was 5.9e-5 off, 64 % at K2 = 1e-3."""
    spec = ps.devices.load("sreetharan2012_3_3_parity_1cut").with_paths({"drivetrain.balance_spring": 1.0})
    metrics = ["left_stroke_mean", "right_stroke_mean"]
    s = ps.sensitivity(spec, ["actuator.waveform.offset_v"], metrics=metrics, progress=False, **TIGHT)
    assert s.reasons == (None, None) and s.parameter_reasons == (None,)
    plus, minus = _metrics(spec, {"actuator.waveform.offset_v": 1.0}), _metrics(spec, {"actuator.waveform.offset_v": -1.0})
    for k, m in enumerate(metrics):
        reference = (plus[m] - minus[m]) / 2.0
        assert abs(s.matrix[k, 0] - reference) <= 1e-5 * abs(reference), (m, s.matrix[k, 0], reference)


def test_a_metric_along_a_nearly_neutral_direction_is_flagged():
    """At K2 = 1e-3 the balance-beam multiplier is 1 - 1.6e-6 (a sweep treats the point as a
    family): the stroke means' derivatives divide the map's error by that, and are flagged;
    the stroke amplitude, which does not move along the beam, keeps its derivative."""
    spec = ps.devices.load("sreetharan2012_3_3_parity_1cut").with_paths({"drivetrain.balance_spring": 1e-3})
    s = ps.sensitivity(spec, ["actuator.waveform.offset_v"], metrics=["left_stroke_mean", "left_stroke_amplitude"], progress=False)
    assert s.neutral_directions == 0 and 0 < 1 - abs(s.multipliers[0]) < 1e-3
    assert s.reasons[0] is not None and "nearly neutral" in s.reasons[0]
    assert s.reasons[1] is None


def test_metrics_without_work_replay_the_window_and_agree_with_the_integrated_windows():
    """Metrics that read no work integral take the base window from the variational period and
    the neutral-direction check from its Φ (no window integrated again); all metrics integrate
    the windows. Both must give the same values, derivatives and flags (K2 = 0: a family)."""
    spec = ps.devices.load("sreetharan2012_3_3_parity_1cut")
    params = ["actuator.waveform.amplitude_v", "drivetrain.transmission_ratio"]
    stroke = ["left_stroke_mean", "right_stroke_mean", "left_stroke_amplitude", "q2_amplitude", "delta_tau_peak", "tau_r_peak", "imbalance_peak_pct"]
    replayed = ps.sensitivity(spec, params, metrics=stroke, progress=False).jacobian
    integrated = ps.sensitivity(spec, params, progress=False).jacobian.filter(pl.col("metric").is_in(stroke))
    integrated = integrated.sort(pl.col("metric").replace_strict(stroke, list(range(len(stroke)))))
    assert replayed["metric"].to_list() == stroke == integrated["metric"].to_list()
    assert replayed["differentiable"].to_list() == integrated["differentiable"].to_list()
    assert not replayed.filter(pl.col("metric") == "left_stroke_mean")["differentiable"].item()
    np.testing.assert_allclose(replayed["value"], integrated["value"], rtol=1e-9, atol=1e-12)
    for p in params:
        np.testing.assert_allclose(replayed[f"d/d({p})"], integrated[f"d/d({p})"], rtol=1e-6, atol=1e-9)


def test_metric_selection_elasticities_and_plot():
    spec = _set(ps.devices.load("sreetharan2012_3_3_parity"), {"drivetrain.balance_spring": 5.0})
    s = ps.sensitivity(spec, "actuator.amplitude_v", metrics=["right_stroke_amplitude"], progress=False)
    assert s.jacobian["metric"].to_list() == ["right_stroke_amplitude"]
    # A stroke amplitude grows about in proportion to the drive: elasticity near 1 (drag
    # makes it sublinear), and d/d(amplitude) > 0.
    e = s.elasticities()["actuator.amplitude_v"][0]
    assert 0.3 < e < 1.0
    assert s.derivative("right_stroke_amplitude", "actuator.amplitude_v") > 0
    fig = s.plot()
    # Each cell is labelled with its elasticity; a 1 x 1 map keeps room to read it.
    assert [t.get_text() for t in fig.axes[0].texts] == [f"{e:.3g}"]
    assert fig.get_figwidth() >= 4.5 and fig.get_figheight() >= 3.0
    with pytest.raises(InvalidParameterError, match="`metrics` = 'left_stroke_amplitude'"):
        s.plot(metrics=["left_stroke_amplitude"])  # not among the result's metrics


def test_the_heat_map_hatches_what_is_not_differentiable_and_saves(tmp_path):
    spec = ps.devices.load("sreetharan2012_3_3_parity")  # K2 = 0: a neutral whippletree family
    s = ps.sensitivity(spec, ["actuator.amplitude_v", "actuator.stiffness"], metrics=["left_stroke_amplitude", "left_stroke_mean"], progress=False)
    flagged = [r is not None for r in s.reasons]
    assert any(flagged) and not all(flagged)  # the stroke mean moves along the family
    fig = s.plot(path=tmp_path / "map.png")
    hatched = [p for p in fig.axes[0].patches if p.get_hatch()]
    assert len(hatched) == sum(flagged)
    assert (tmp_path / "map.png").stat().st_size > 10_000


def test_the_arrays_are_the_tables_and_the_tables_wait_until_read():
    spec = _set(ps.devices.load("sreetharan2012_3_3_parity"), {"drivetrain.balance_spring": 5.0})
    params = ["actuator.amplitude_v", "drivetrain.balance_spring"]
    s = ps.sensitivity(spec, params, metrics=["right_stroke_amplitude", "delta_tau_peak"], progress=False)
    # The polars tables are built on first use (ps.optimize reads only the arrays).
    assert "jacobian" not in vars(s) and "parameters" not in vars(s)
    assert s.matrix.shape == (2, 2) and list(s.metric_names) == s.jacobian["metric"].to_list()
    for j, p in enumerate(params):
        assert s.matrix[:, j].tolist() == s.jacobian[f"d/d({p})"].to_list()
        assert s.derivative("delta_tau_peak", p) == s.matrix[1, j]
    assert s.values.tolist() == s.jacobian["value"].to_list()
    assert [r is None for r in s.reasons] == s.jacobian["differentiable"].to_list()
    assert s.parameter_values.tolist() == s.parameters["value"].to_list() == [spec.actuator.waveform.amplitude_v, 5.0]
    assert s.jacobian is s.jacobian  # built once


@pytest.mark.parametrize(
    ("params", "named"),
    [
        (["drivetrain.balanse_spring"], "balance_spring"),
        (["drivetrain.kind"], "drivetrain.kind"),
        (["options.samples_per_cycle"], "options.samples_per_cycle"),
        ([], "params"),
        ([3.0], "params"),
        ([""], "params"),
        # The same field twice (polars raised a ShapeError here), or under two spellings.
        (["drivetrain.balance_spring", "drivetrain.balance_spring"], "each spec field once"),
        (["actuator.frequency_hz", "actuator.waveform.frequency_hz"], "= the field of `actuator.frequency_hz`"),
    ],
)
def test_bad_parameters_are_named(params, named):
    spec = ps.devices.load("sreetharan2012_3_3_parity")
    with pytest.raises(InvalidParameterError) as e:
        ps.sensitivity(spec, params, progress=False)
    assert named in str(e.value)


@pytest.mark.parametrize("balance_spring", [5.0, 0.0])
def test_sensitivity_periods_in_lanes_equal_the_scalar_ones(balance_spring: float, monkeypatch: pytest.MonkeyPatch) -> None:
    """A linear-map device's perturbed periods run four at a time in SIMD lanes
    (``crates/dynamics/src/lanes/batch.rs``); ``PARITYSIM_LANES=1`` runs them scalar: the same
    bits, central differences (K2 = 5) and one-sided ones at the range's end (K2 = 0), the
    frequency (a scaled grid) included, and the drives that scale the base drive's sines."""
    spec = ps.devices.load("sreetharan2012_3_3_parity").with_paths({"drivetrain.balance_spring": balance_spring, "wings.left.omega_ratio": 0.7})
    params = [
        "wings[0].aero.omega1",
        "drivetrain.balance_spring",
        "actuator.stiffness",
        "actuator.waveform.amplitude_v",
        "actuator.waveform.frequency_hz",
        "actuator.force_per_volt",
        "drivetrain.transmission_ratio",
    ]
    metrics = ["delta_tau_peak", "tau_r_peak", "tau_l_peak", "imbalance_peak_pct", "left_stroke_amplitude"]
    lanes = ps.sensitivity(spec, params, metrics=metrics, progress=False)
    monkeypatch.setenv("PARITYSIM_LANES", "1")
    scalar = ps.sensitivity(spec, params, metrics=metrics, progress=False)
    assert lanes.jacobian.equals(scalar.jacobian)
    assert np.array_equal(lanes.state_jacobian, scalar.state_jacobian, equal_nan=True)
    # At K2 = 0 on wings that differ the balance spring breaks the family: its column is NaN.
    broken = [r is not None for r in lanes.parameter_reasons]
    assert broken == [r is not None for r in scalar.parameter_reasons] == [p == "drivetrain.balance_spring" and balance_spring == 0.0 for p in params]
    assert np.isfinite(lanes.matrix[:, ~np.array(broken)]).all()


@pytest.mark.parametrize("threads", ["1", "2", "3"])
def test_a_sensitivity_is_the_same_on_any_number_of_threads(threads: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The parameters' perturbed devices and periods run in groups on the sensitivity's
    threads (``PARITYSIM_THREADS``): the same bits on one thread or several, lanes or scalar."""
    spec = ps.devices.load("sreetharan2012_3_3_parity").with_paths({"drivetrain.balance_spring": 5.0, "wings.left.omega_ratio": 0.7})
    params = ["wings[0].aero.omega1", "drivetrain.balance_spring", "actuator.stiffness", "actuator.waveform.amplitude_v", "actuator.waveform.frequency_hz"]
    metrics = ["delta_tau_peak", "tau_r_peak", "left_stroke_amplitude"]
    monkeypatch.setenv("PARITYSIM_THREADS", "1")
    one = ps.sensitivity(spec, params, metrics=metrics, progress=False)
    monkeypatch.setenv("PARITYSIM_THREADS", threads)
    for lanes in ("4", "1"):
        monkeypatch.setenv("PARITYSIM_LANES", lanes)
        several = ps.sensitivity(spec, params, metrics=metrics, progress=False)
        assert several.jacobian.equals(one.jacobian), lanes
        assert np.array_equal(several.state_jacobian, one.state_jacobian), lanes


def _sensitivity_in_child(spec_json: str) -> list[list[float]]:
    # The engine's call itself: polars keeps a thread pool of its own, which a forked child
    # cannot use either (polars documents fork as unsupported).
    from paritysim import _core

    params = ["drivetrain.balance_spring", "actuator.stiffness", "actuator.waveform.amplitude_v"]
    return _core.sensitivity(spec_json, params, ["tau_r_peak"])["jacobian"]


def test_a_forked_child_starts_its_own_thread_pool(monkeypatch: pytest.MonkeyPatch) -> None:
    """The engine keeps its thread pools for the process; a forked child (a process pool's
    worker) has none of their threads and must build its own instead of waiting on them."""
    import multiprocessing

    monkeypatch.setenv("PARITYSIM_THREADS", "2")
    spec = ps.devices.load("sreetharan2012_3_3_parity").with_paths({"drivetrain.balance_spring": 5.0})
    here = _sensitivity_in_child(spec.to_json())  # the parent's pool exists from here on
    with multiprocessing.get_context("fork").Pool(1) as pool:
        child = pool.apply_async(_sensitivity_in_child, (spec.to_json(),)).get(timeout=60)
    assert np.array_equal(child, here)


def test_the_cost_benchmark_computes_its_ratios_and_verdicts() -> None:
    """``benchmarks/sensitivity_cost.py`` (the issue's "at most 3× a simulate", reported, not
    asserted here) runs from a checkout and derives each verdict from its own ratio."""
    import re
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).resolve().parents[1] / "benchmarks" / "sensitivity_cost.py"

    def run(target: str) -> str:
        args = ["--device", "3.3", "--params", "1", "2", "--calls", "1", "--rounds", "1", "--target", target]
        out = subprocess.run([sys.executable, str(script), *args], capture_output=True, text=True, timeout=300)
        assert out.returncode == 0, out.stderr[-2000:]
        return out.stdout

    rows = re.findall(r"^\s+(\d+)\s+([\d.]+)\s+([\d.]+)x\s+(met|NOT met)$", run("1e9"), re.M)
    assert [int(r[0]) for r in rows] == [1, 2]
    assert all(float(r[1]) > 0 and float(r[2]) > 0 and r[3] == "met" for r in rows)
    never = run("1e-9")
    assert never.count("NOT met") == 2 and "2 case(s) above 1e-09x" in never


def test_a_metric_held_at_zero_by_symmetry_is_differentiable_with_slope_zero() -> None:
    # The HMF ties the strokes, so the net pitch torque's mean is zero at every transmission
    # ratio (ps.simulate: ~1e-14). Its replayed windows carry the replay's 1e-9 error on both
    # sides, which the kink check read as one-sided slopes of ±5.8e-5: "not differentiable".
    hmf = ps.devices.load("sreetharan2012_3_4_hmf_1cut")
    path = "drivetrain.transmission_ratio"
    s = ps.sensitivity(hmf, [path], metrics=["pitch_total_mean", "yaw_total_mean"], rtol=1e-11, atol=1e-13)
    row = s.jacobian.filter(pl.col("metric") == "pitch_total_mean").row(0, named=True)
    assert row["differentiable"], row["reason"]
    assert abs(row[f"d/d({path})"]) < 1e-6
    ratio = hmf.drivetrain.transmission_ratio
    step = 1e-3 * ratio
    ends = [ps.simulate(hmf.with_paths({path: ratio + d}), metrics=["pitch_total_mean"], rtol=1e-11, atol=1e-13, progress=False).metrics["pitch_total_mean"] for d in (-step, step)]
    assert max(abs(v) for v in ends) < 1e-10  # zero on both sides: the slope is zero


def test_elasticities_are_null_where_undefined_and_a_nan_derivative_is_named() -> None:
    # balance_spring = 0 gave -0.0 and an undefined metric gave NaN where the docstring says null.
    s = ps.sensitivity("sreetharan2012_3_3_parity", ["drivetrain.balance_spring", "wings.left.omega_ratio"], metrics=["left_stroke_amplitude", "left_rotation_phase_lag"], progress=False)
    e = s.elasticities()
    stroke = e.filter(pl.col("metric") == "left_stroke_amplitude").row(0, named=True)
    assert stroke["drivetrain.balance_spring"] is None  # the parameter is 0
    assert stroke["wings.left.omega_ratio"] == pytest.approx(s.derivative("left_stroke_amplitude", "wings.left.omega_ratio") / s.jacobian["value"][0])
    lag = e.filter(pl.col("metric") == "left_rotation_phase_lag").row(0, named=True)
    assert lag["wings.left.omega_ratio"] is None and lag["drivetrain.balance_spring"] is None
    with pytest.raises(ps.InvalidParameterError) as info:
        s.derivative("left_rotation_phase_lag", "wings.left.omega_ratio")
    assert info.value.field == "metric"
    # An omega_ratio multiplies Ω1: dimensionless, not mg·mm².
    assert s.parameters.filter(pl.col("parameter") == "wings.left.omega_ratio")["unit"].item() == "1"


def test_an_old_spelling_warns_as_in_sweep() -> None:
    # It was accepted silently (sweep, with_paths and calibrate warn).
    with pytest.warns(DeprecationWarning, match="drivetrain.balance_spring"):
        s = ps.sensitivity("sreetharan2012_3_3_parity", ["drivetrain.k2"], metrics=["left_stroke_amplitude"], progress=False)
    assert s.parameter_names == ("drivetrain.k2",)
