"""ps.optimize (issue 31): exact steady-state gradients under scipy.optimize, checked against
optima found independently (brentq on ps.simulate; a grid plus a bounded 1-D refinement along
the active constraint), an infeasible problem, a stability bound, bad input named, the result."""

from __future__ import annotations

import importlib.util
import sys
import warnings

import numpy as np
import pytest
from matplotlib.figure import Figure
from scipy.optimize import brentq, minimize_scalar

import paritysim as ps
from paritysim import InvalidParameterError

TIGHT = {"rtol": 1e-10, "atol": 1e-12, "steady_tol": 1e-10}
V = "actuator.waveform.amplitude_v"
K = "wings[*].springs.hinge.stiffness"


def _with(spec: ps.Simulation, **fields: float) -> ps.Simulation:
    d = spec.to_dict()
    for key, value in fields.items():
        d["drivetrain"][key] = value
    return ps.Simulation.from_dict(d)


@pytest.fixture(scope="module")
def drag_parity() -> ps.Simulation:
    """§3.3 with a balance spring (K2 = 5): an isolated orbit."""
    return _with(ps.devices.load("sreetharan2012_3_3_parity"), balance_spring=5.0)


@pytest.fixture(scope="module")
def blade_element() -> ps.Simulation:
    """§3.4 (blade element, passive rotation) with K2 = 30."""
    return _with(ps.devices.load("sreetharan2012_3_4_parity"), balance_spring=30.0)


@pytest.mark.parametrize("method", ["SLSQP", "ipopt"])
def test_the_least_power_for_a_stroke_amplitude_is_where_the_constraint_binds(drag_parity, method):
    if method == "ipopt":
        pytest.importorskip("cyipopt", reason="the optional ipopt extra (CI installs it)")
    # Power grows with the drive amplitude, so the optimum is the amplitude at which the stroke
    # amplitude is exactly A0: found here by brentq on whole ps.simulate runs.
    a0 = 0.6

    def stroke(volts: float) -> float:
        r = ps.simulate(drag_parity.with_paths({V: volts}), columns=[], progress=False, **TIGHT)
        assert r.converged
        return r.metrics["left_stroke_amplitude"]

    volts = brentq(lambda v: stroke(v) - a0, 20.0, 150.0, xtol=1e-12, rtol=1e-14)
    r = ps.optimize(drag_parity, "actuator_power_mean", {V: (20.0, 150.0)}, [f"left_stroke_amplitude >= {a0}"], method=method, progress=False, **TIGHT)
    assert r.success, r.message
    assert r.x[V] == pytest.approx(volts, rel=1e-6)
    assert r.active == [f"left_stroke_amplitude >= {a0}"]
    # IPOPT (interior point) ends within its tolerance of the bound, SLSQP on it.
    assert r.constraint_values[f"left_stroke_amplitude >= {a0}"] == pytest.approx(a0, abs=1e-9 if method == "SLSQP" else 1e-7)
    assert r.history["iteration"][0] == 0 and r.history[V][0] == 100.0  # started at the spec's value
    assert r.history["objective"][-1] == pytest.approx(r.objective)
    assert r.objective < r.history["objective"][0]


def test_the_most_lift_on_a_power_budget_matches_a_grid_and_a_refinement(blade_element):
    # Lift and power both grow with the drive amplitude, so the best lift for P <= P0 spends the
    # whole budget: along that curve (the amplitude by brentq at each hinge stiffness) the lift
    # has one interior maximum in the hinge stiffness, bracketed on a grid and then refined.
    p0 = 10.0

    def metrics(volts: float, k: float) -> dict[str, float]:
        s = ps.sensitivity(blade_element.with_paths({V: volts, K: k}), [V], metrics=["lift_mean", "actuator_power_mean"], progress=False, **TIGHT)
        return dict(zip(s.jacobian["metric"], s.jacobian["value"], strict=True))

    def on_budget(k: float) -> tuple[float, float]:
        volts = brentq(lambda v: metrics(v, k)["actuator_power_mean"] - p0, 30.0, 200.0, xtol=1e-12, rtol=1e-14)
        return metrics(volts, k)["lift_mean"], volts

    ks = np.linspace(1.0, 5.0, 9)
    lifts = [on_budget(k)[0] for k in ks]
    i = int(np.argmax(lifts))
    assert 0 < i < len(ks) - 1, "an interior maximum"
    best = minimize_scalar(lambda k: -on_budget(k)[0], bounds=(ks[i - 1], ks[i + 1]), method="bounded", options={"xatol": 1e-10})
    k_ref = float(best.x)
    lift_ref, volts_ref = on_budget(k_ref)

    r = ps.optimize(blade_element, "lift_mean", {V: (30.0, 200.0), K: (1.0, 5.0)}, [f"actuator_power_mean <= {p0}"], sense="max", progress=False, **TIGHT)
    assert r.success, r.message
    assert r.x[K] == pytest.approx(k_ref, rel=1e-6)
    assert r.x[V] == pytest.approx(volts_ref, rel=1e-6)
    assert r.objective == pytest.approx(lift_ref, rel=1e-10)
    assert r.active == [f"actuator_power_mean <= {p0}"]
    assert r.objective > max(lifts)  # better than every grid point

    # trust-constr (interior point) stops within its barrier tolerance of the same optimum.
    t = ps.optimize(blade_element, "lift_mean", {V: (30.0, 200.0), K: (1.0, 5.0)}, [f"actuator_power_mean <= {p0}"], sense="max", method="trust-constr", progress=False, **TIGHT)
    assert t.success, t.message
    assert t.x[K] == pytest.approx(k_ref, rel=1e-5) and t.x[V] == pytest.approx(volts_ref, rel=1e-5)
    assert t.objective == pytest.approx(lift_ref, rel=1e-5)

    # IPOPT (the optional extra; CI installs it) reaches the same optimum.
    if importlib.util.find_spec("cyipopt") is not None:
        i = ps.optimize(blade_element, "lift_mean", {V: (30.0, 200.0), K: (1.0, 5.0)}, [f"actuator_power_mean <= {p0}"], sense="max", method="ipopt", progress=False, **TIGHT)
        assert i.success, i.message
        assert i.x[K] == pytest.approx(k_ref, rel=1e-6) and i.x[V] == pytest.approx(volts_ref, rel=1e-6)
        assert i.objective == pytest.approx(lift_ref, rel=1e-8)


def test_a_stability_bound_moves_the_optimum_onto_it(blade_element):
    params = {V: (30.0, 200.0), K: (1.0, 5.0)}
    free = ps.optimize(blade_element, "lift_mean", params, ["actuator_power_mean <= 10"], sense="max", progress=False, **TIGHT)
    rho_free = float(np.abs(free.multipliers[0]))
    loose = ps.optimize(blade_element, "lift_mean", params, ["actuator_power_mean <= 10"], stability=0.95, sense="max", progress=False, **TIGHT)
    assert loose.success and loose.x[K] == pytest.approx(free.x[K], rel=1e-6)
    assert "max |multiplier| <= 0.95" not in loose.active

    bound = rho_free - 4e-4  # just below the free optimum's largest multiplier
    r = ps.optimize(blade_element, "lift_mean", params, ["actuator_power_mean <= 10"], stability=bound, sense="max", progress=False, **TIGHT)
    assert r.success, r.message
    assert len(r.active) == 2
    # The stability differences (a solve per parameter) run only where the solver asks for
    # gradients, not at every line-search trial.
    assert r.evaluations + len(params) <= r.sensitivities < r.evaluations * (1 + len(params))
    assert r.objective < free.objective
    # Both bounds hold at the returned design, recomputed from its spec.
    check = ps.sensitivity(r.spec, [V], metrics=["actuator_power_mean"], progress=False, **TIGHT)
    moduli = np.abs(check.multipliers)
    assert moduli[np.abs(check.multipliers - 1) > 1e-3].max() == pytest.approx(bound, abs=1e-6)
    assert check.jacobian["value"][0] == pytest.approx(10.0, abs=1e-5)


def test_an_infeasible_constraint_is_reported_by_name_not_as_nan(drag_parity):
    r = ps.optimize(drag_parity, "actuator_power_mean", {V: (20.0, 150.0)}, ["left_stroke_amplitude >= 5"], progress=False)
    assert not r.success
    assert "infeasible" in r.message and "left_stroke_amplitude >= 5" in r.message
    assert np.isfinite(r.objective) and np.isfinite(r.x[V])
    row = r.constraints.row(0, named=True)
    assert row["violation"] > 4.0 and not row["active"]


def test_a_metric_not_differentiable_at_an_iterate_is_warned_about_once():
    spec = ps.devices.load("sreetharan2012_3_3_parity_1cut")  # K2 = 0: the stroke means move along a family
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = ps.optimize(spec, "actuator_power_mean", {V: (20.0, 150.0)}, ["abs(left_stroke_mean) <= 0.01", "left_stroke_amplitude >= 0.6"], progress=False)
    named = [w for w in caught if "left_stroke_mean" in str(w.message)]
    assert len(named) == 1 and "not differentiable" in str(named[0].message)
    assert r.evaluations > 1


@pytest.mark.parametrize(
    ("kwargs", "field", "text"),
    [
        ({"params": {"actuator.waveform.amplitud_v": (20, 150)}}, "params", "actuator.waveform.amplitude_v"),
        ({"params": {"actuator.waveform.kind": (0, 1)}}, "params", "discrete"),
        ({"params": {V: (150, 20)}}, "params", "low < high"),
        # NumPy bounds are read as ps.calibrate reads them (they were "not bounds").
        ({"params": {V: np.array([150.0, 20.0])}}, "params", "low < high"),
        ({"params": {V: (20.0,)}}, f"params[{V}]", "a pair of numbers"),
        ({"params": {V: (20, 20000)}}, "params", "10000"),
        ({"params": {}}, "params", "non-empty"),
        ({"x0": {V: 200.0}}, f"x0[{V}]", "[20, 150]"),
        ({"x0": {"actuator.waveform.frequency_hz": 100.0}}, "x0", "params"),
        ({"constraints": ["left_stroke_amplitude >> 0.6"]}, "constraints[0]", "metric >= number"),
        ({"constraints": ["left_stroke_amplitude >= __import__('os')"]}, "constraints[0]", "constraint"),
        ({"constraints": ["left_stroke_amplitude >= 0.6", "left_strok_amplitude <= 1"]}, "constraints[1]", "left_stroke_amplitude"),
        ({"constraints": ["lift_mean >= 0.59"]}, "constraints[0]", "blade-element"),
        ({"objective": "actuator_power_mea"}, "objective", "actuator_power_mean"),
        ({"sense": "minimise"}, "sense", '"min"'),
        ({"method": "nelder-mead"}, "method", "SLSQP"),
        ({"stability": -1.0}, "stability", "positive"),
        ({"max_iterations": 0}, "max_iterations", "integer"),
        # The spec's options as a mapping, for the names optimize takes itself (`method`).
        ({"options": {"methd": "dopri5"}}, "options.methd", "method"),
        ({"options": 5}, "options", "mapping"),
    ],
)
def test_bad_input_is_refused_naming_the_argument(drag_parity, kwargs, field, text):
    args = {"objective": "actuator_power_mean", "params": {V: (20.0, 150.0)}, "constraints": ["left_stroke_amplitude >= 0.6"], "progress": False}
    args.update(kwargs)
    with pytest.raises(InvalidParameterError) as err:
        ps.optimize(drag_parity, **args)
    assert err.value.field == field, str(err.value)
    assert text in str(err.value)


def test_ipopt_without_its_extra_is_refused_naming_the_method(drag_parity, monkeypatch):
    monkeypatch.setitem(sys.modules, "cyipopt", None)  # as if not installed
    with pytest.raises(InvalidParameterError, match='paritysim\\[ipopt\\]') as err:
        ps.optimize(drag_parity, "actuator_power_mean", {V: (20.0, 150.0)}, method="ipopt", progress=False)
    assert err.value.field == "method"


def test_the_result_prints_on_one_line_plots_and_saves_its_spec(drag_parity, tmp_path):
    r = ps.optimize(drag_parity, "actuator_power_mean", {V: (20.0, 150.0)}, ["left_stroke_amplitude >= 0.6"], progress=False)
    text = repr(r)
    assert "\n" not in text and text.startswith("OptimizationResult(success") and "actuator_power_mean" in text
    fig = r.plot(tmp_path / "convergence.pdf")
    assert isinstance(fig, Figure) and len(fig.axes) == 3
    assert (tmp_path / "convergence.pdf").read_bytes()[:4] == b"%PDF"
    saved = ps.load_spec(r.save(tmp_path / "optimum.toml"))
    assert saved.to_dict() == r.spec.to_dict()
    assert saved.to_dict()["actuator"]["waveform"]["amplitude_v"] == r.x[V]
    assert saved.options == drag_parity.options  # the design, with the input's own options
    # The saved design has the optimum's metrics.
    again = ps.simulate(saved, columns=[], progress=False)
    assert again.metrics["left_stroke_amplitude"] == pytest.approx(0.6, abs=1e-6)


def test_spec_options_named_like_optimize_arguments_go_in_options(drag_parity):
    # `paritysim optimize` passed a study's [options] method = "dopri5" as a keyword: TypeError
    # "got multiple values for keyword argument 'method'" (the optimiser's own).
    r = ps.optimize(drag_parity, "actuator_power_mean", {V: (20.0, 150.0)}, ["left_stroke_amplitude >= 0.6"], options={"method": "dopri5"}, max_iterations=2, progress=False)
    assert r.evaluations >= 1 and r.spec.options.method == drag_parity.options.method  # the runs', not the returned spec's


def test_a_slow_real_mode_counts_against_the_stability_bound():
    """Every multiplier within 1e-3 of 1 was left out of the bound as "neutral": at K2 = 0.05
    on the §3.4 1-Cut the orbit decays at |μ| = 0.99987 a cycle (an isolated orbit, no
    family), yet the bound read 0.0497 and an optimiser started near K2 = 0 stopped there.
    Only a family's multipliers (the core's neutral_directions) are left out now."""
    spec = ps.devices.load("sreetharan2012_3_4_parity_1cut")
    for k2, family in ((0.05, False), (0.0, True)):
        point = spec.with_paths({"drivetrain.balance_spring": k2})
        s = ps.sensitivity(point, "actuator.waveform.amplitude_v", metrics=["lift_mean"], progress=False)
        assert s.neutral_directions == int(family)
        result = ps.optimize(point, "actuator_power_mean", params={"actuator.waveform.amplitude_v": (99.0, 101.0)}, stability=0.9, max_iterations=1, progress=False)
        value = result.constraints.filter(result.constraints["constraint"].str.starts_with("max |multiplier|"))["value"].item()
        mu = np.sort(np.abs(result.multipliers))[::-1]
        if family:  # the family's multiplier (1 to round-off) is left out, the next one counts
            assert abs(mu[0] - 1.0) < 1e-6 and value == pytest.approx(mu[1], rel=1e-12)
        else:
            assert value == pytest.approx(mu[0], rel=1e-12) and 0.999 < value < 1.0
            assert not result.success and "max |multiplier|" in result.message


def test_trust_constr_does_not_stop_a_barrier_away_from_the_bound():
    """scipy's interior point stopped on its subproblem's optimality with the barrier parameter
    at 1.6e-4: power 3.3e-4 above SLSQP's optimum, the lift bound 3.4e-4 away, reported as
    success. Restarting with a smaller barrier brings it within 1e-5 (the bound is the answer)."""
    spec = ps.devices.load("sreetharan2012_3_4_parity").with_paths({"drivetrain.balance_spring": 30.0})
    problem = {"params": {"actuator.waveform.amplitude_v": (30.0, 200.0)}, "constraints": ["lift_mean >= 1.1261571"], "progress": False}
    exact = ps.optimize(spec, "actuator_power_mean", **problem)
    interior = ps.optimize(spec, "actuator_power_mean", method="trust-constr", **problem)
    assert exact.success and exact.active == ["lift_mean >= 1.1261571"]
    assert interior.success
    assert interior.objective == pytest.approx(exact.objective, rel=3e-5)
    assert interior.constraints["value"][0] == pytest.approx(1.1261571, rel=3e-5)
