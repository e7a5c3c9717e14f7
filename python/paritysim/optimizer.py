"""Co-design: ``ps.optimize(spec, objective, params={path: (low, high)}, constraints=[...])`` puts
the exact steady-state gradients of ``ps.sensitivity`` (``gradients.py``) under ``scipy.optimize``
(SLSQP or trust-constr, or IPOPT through ``cyipopt``): one sensitivity per iterate gives the
objective, every constrained metric and their gradients.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import polars as pl
from matplotlib.figure import Figure

from . import _core
from ._errors import invalid, real, suggest, whole
from ._exceptions import InvalidParameterError, ParitysimError
from ._progress import LongRun
from .devices import as_simulation
from .spec import Simulation, SpecLike, spec_paths

from .gradients import SensitivityResult, sensitivity

__all__ = ["OptimizationResult", "optimize"]

#: A constraint within this distance of its bound (times max(1, |bound|)) is active; one
#: violated by more is not met.
ACTIVE_TOL = 1e-6
#: Restarts of trust-constr's interior point, each with a hundredth of the barrier it stopped at.
TRUST_CONSTR_RESTARTS = 4
#: Step of the one-sided difference of the stability constraint, in scaled parameters ([0, 1]).
STABILITY_STEP = 1e-5
#: Name of the stability constraint in the result's tables.
STABILITY = "stability"

_NAME = r"[A-Za-z_][A-Za-z0-9_]*"
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_CONSTRAINT = re.compile(rf"^\s*(?:abs\s*\(\s*(?P<abs>{_NAME})\s*\)|(?P<name>{_NAME}))\s*(?P<op><=|>=|==)\s*(?P<bound>{_NUMBER})\s*$")


@dataclass(frozen=True)
class _Constraint:
    text: str
    metric: str  # "" for the stability constraint
    absolute: bool
    op: str
    bound: float

    def value(self, values: Mapping[str, float], rho: float) -> float:
        if not self.metric:
            return rho
        v = values[self.metric]
        return abs(v) if self.absolute else v

    def violation(self, value: float) -> float:
        if self.op == ">=":
            return max(0.0, self.bound - value)
        if self.op == "<=":
            return max(0.0, value - self.bound)
        return abs(value - self.bound)

    def tolerance(self) -> float:
        return ACTIVE_TOL * max(1.0, abs(self.bound))

    def scale(self) -> float:
        return abs(self.bound) if self.bound != 0 else 1.0


def _parse_constraint(where: str, text: Any) -> _Constraint:
    grammar = "'metric <= number', 'metric >= number', 'metric == number' or 'abs(metric) <= number'"
    if not isinstance(text, str):
        raise invalid(where, repr(text)[:60], f"a constraint text: {grammar}")
    m = _CONSTRAINT.match(text)
    if m is None:
        raise invalid(where, repr(text)[:60], f"a constraint: {grammar}")
    bound = float(m["bound"])
    if not math.isfinite(bound):
        raise invalid(where, repr(text)[:60], "a finite bound")
    metric = m["abs"] or m["name"]
    return _Constraint(text.strip(), metric, m["abs"] is not None, m["op"], bound)


@dataclass(frozen=True)
class OptimizationResult:
    """What `optimize` found.

    ``success``: the optimiser converged and every constraint is met (within ``ACTIVE_TOL``
    times ``max(1, |bound|)``); ``message`` says why not otherwise, naming the violated
    constraints. ``x``: ``{path: value}`` at the returned point; ``spec``: the input spec with
    those values set (``spec.with_paths(x)``, its own options); ``objective``: the objective
    metric there. ``constraints``: one row per constraint (``constraint``, ``value``, ``bound``,
    ``violation``, ``active``); ``active``: the texts of the active ones. ``multipliers``: the
    orbit's Floquet multipliers there, largest modulus first. ``history``: one row per iteration
    (``iteration``, ``objective``, ``max_violation``, one column per parameter).
    ``evaluations``: the distinct points evaluated (objective, constraints and gradients);
    ``sensitivities``: every `sensitivity` run, those points' and the stability constraint's
    one-sided differences (one more per parameter at each point whose gradients the solver
    asks for; its line-search trials need none): the search's cost, each about one
    steady-state solve plus two periods per parameter (the stability differences read only
    the multipliers and differentiate by one parameter).
    """

    success: bool
    message: str
    x: dict[str, float]
    spec: Simulation
    objective_name: str
    sense: str
    objective: float
    constraints: pl.DataFrame
    active: list[str]
    multipliers: np.ndarray
    history: pl.DataFrame
    iterations: int
    evaluations: int
    bounds: dict[str, tuple[float, float]] = field(repr=False)
    sensitivities: int = 0

    @property
    def constraint_values(self) -> dict[str, float]:
        """``{constraint text: its metric's value}`` at the returned point."""
        return dict(zip(self.constraints["constraint"], self.constraints["value"], strict=True))

    def save(self, path: str | Path) -> Path:
        """Writes the optimal spec as TOML (``Simulation.save``; ``ps.load_spec`` reads it back)."""
        return self.spec.save(path)

    def plot(self, path: str | Path | None = None) -> Figure:
        """Convergence: the objective, the largest constraint violation and the parameters
        (scaled to [0, 1] by their bounds) per iteration; saved to ``path`` when given (the
        suffix picks the format), as every result's plot is."""
        h = self.history
        it = h["iteration"].to_numpy()
        fig = Figure(figsize=(6.4, 6.0), layout="constrained")
        ax_f, ax_v, ax_p = fig.subplots(3, 1, sharex=True)
        ax_f.plot(it, h["objective"].to_numpy(), "o-", ms=3)
        from .plots import label_with_unit  # the plot needs matplotlib anyway

        ax_f.set_ylabel(label_with_unit(self.objective_name))
        ax_f.set_title(f"{self.sense}imise {self.objective_name}: {'converged' if self.success else 'not converged'}")
        violation = h["max_violation"].to_numpy()
        ax_v.semilogy(it, np.maximum(violation, 1e-16), "o-", ms=3, color="C3")
        ax_v.set_ylabel("max violation")
        for name, (low, high) in self.bounds.items():
            ax_p.plot(it, (h[name].to_numpy() - low) / (high - low), "o-", ms=3, label=f"{name} in [{low:g}, {high:g}]")
        ax_p.set_ylim(-0.05, 1.05)
        ax_p.set_ylabel("parameter (scaled)")
        ax_p.set_xlabel("iteration")
        ax_p.legend(fontsize="small")
        if path is not None:
            from .plots import save

            save(fig, path, close=False)
        return fig

    def __repr__(self) -> str:
        status = "success" if self.success else "failed"
        message = " ".join(self.message.split())
        if len(message) > 80:
            message = message[:77] + "..."
        return (
            f"OptimizationResult({status}, {self.objective_name} = {self.objective:.6g} ({self.sense}), "
            f"{self.iterations} iterations, {len(self.active)} active constraint(s), {message!r})"
        )


class _Stop(Exception):
    """An iterate where the problem stops being defined (no orbit, an undefined metric)."""

    def __init__(self, message: str, metric: str | None = None) -> None:
        super().__init__(message)
        self.metric = metric


@dataclass
class _Eval:
    values: dict[str, float]
    grads: dict[str, np.ndarray]  # d metric / d z (scaled parameters)
    multipliers: np.ndarray
    rho: float  # largest non-neutral |multiplier|
    # d rho / d z ("" in `grads` once computed): one solve per parameter, so only at the
    # points whose constraint gradients the solver asks for (not at its line-search trials).
    stability_gradient: Callable[[], np.ndarray] | None = None

    def gradient(self, metric: str) -> np.ndarray:
        """``d metric / d z``; ``""``: the stability bound's, computed on first use."""
        if metric == "" and "" not in self.grads and self.stability_gradient is not None:
            self.grads[metric] = self.stability_gradient()
        return self.grads[metric]


def optimize(
    spec: SpecLike,
    objective: str = "actuator_power_mean",
    params: Mapping[str, Sequence[float]] | None = None,
    constraints: str | Sequence[str] = (),
    *,
    stability: float | None = None,
    sense: str = "min",
    method: str = "SLSQP",
    x0: Mapping[str, float] | None = None,
    max_iterations: int = 100,
    tol: float = 1e-9,
    progress: bool = True,
    options: Mapping[str, Any] | None = None,
    **option_overrides: Any,
) -> OptimizationResult:
    """Minimise (``sense="min"``) or maximise a steady-state metric over continuous spec paths,
    subject to constraints on metrics and on stability, with exact gradients
    (`sensitivity`) under ``scipy.optimize`` (``method`` ``"SLSQP"`` or ``"trust-constr"``) or
    IPOPT (``"ipopt"``, the optional ``ipopt`` extra: cyipopt, with a limited-memory Hessian).

    ``params``: ``{path: (low, high)}``, any continuous path `sensitivity` takes. The optimiser
    works in parameters scaled to [0, 1] by these bounds and in the objective divided by its
    magnitude at the start, so ``tol`` (SLSQP's ``ftol``, trust-constr's ``gtol`` and ``xtol``)
    is relative (IPOPT's ``tol``). ``constraints``: texts ``"metric >= number"``, ``"metric <= number"``,
    ``"metric == number"``, ``"abs(metric) <= number"``. ``stability``: a bound on the largest
    modulus of the orbit's Floquet multipliers other than a family's neutral ones (the
    ``neutral_directions`` of `sensitivity`; a slow mode near 1 counts);
    its gradient is a one-sided difference of step ``1e-5`` in each scaled parameter (one more
    sensitivity per parameter and iterate; the multipliers' modulus is not smooth where two
    of them meet). ``x0``: the start (default: the spec's values, clipped into the bounds).
    ``option_overrides`` replace fields of ``spec.options`` for the runs (e.g. ``rtol=1e-10``),
    not in the returned spec; ``options`` is the same as a mapping, for the names this function
    takes itself (``options={"method": "dopri5"}``: the integrator, where ``method`` is the
    optimiser).

    A metric marked not differentiable at an iterate (see `sensitivity`: a kink, a family of
    orbits) is warned about once (a ``RuntimeWarning`` naming it and the first such iterate);
    the derivative the core gives there is used. An iterate where the orbit or a metric is not
    defined stops the search: the result then has ``success=False`` and says why. A problem
    whose constraints cannot be met returns ``success=False`` naming the violated ones.

    Raises
    ------
    InvalidParameterError
        Naming the argument: an unknown, discrete or out-of-range path or bounds with
        ``low >= high`` (``params``), an ``x0`` outside the bounds, a malformed constraint or an
        unknown metric (``constraints[i]``, ``objective``; with the nearest names), ``sense``,
        ``method``, ``stability``, ``max_iterations``, ``tol``.
    """
    from scipy.optimize import BFGS, Bounds, NonlinearConstraint, minimize

    spec = as_simulation(spec)
    if options is not None and not isinstance(options, Mapping):
        raise invalid("options", type(options).__name__, "a mapping of spec options, e.g. {\"method\": \"dopri5\"}")
    option_overrides = {**{str(k): v for k, v in (options or {}).items()}, **option_overrides}
    run_spec = spec.replace(options=spec.options.with_fields("options", **option_overrides)) if option_overrides else spec
    if sense not in ("min", "max"):
        raise invalid("sense", repr(sense), '"min" or "max"')
    methods = {"slsqp": "SLSQP", "trust-constr": "trust-constr", "ipopt": "ipopt"}
    if not isinstance(method, str) or method.lower() not in methods:
        raise invalid("method", repr(method), '"SLSQP", "trust-constr" or "ipopt"')
    method = methods[method.lower()]
    if method == "ipopt":
        try:
            import cyipopt  # noqa: F401  (the optional `ipopt` extra)
        except ImportError:
            raise invalid("method", '"ipopt"', 'an installed IPOPT: pip install "paritysim[ipopt]" (cyipopt), or "SLSQP"') from None
    max_iterations = whole("max_iterations", max_iterations, 1, 100_000)
    tol = real("tol", tol)
    if not (tol > 0 and math.isfinite(tol)):
        raise invalid("tol", tol, "a positive finite number")
    if stability is not None:
        stability = real("stability", stability)
        if not (stability > 0 and math.isfinite(stability)):
            raise invalid("stability", stability, "None or a positive finite bound on the largest non-neutral |Floquet multiplier|")

    paths, low, high, start = _parameters(spec, params)
    spec_json = spec.to_json()
    valid = list(_core.sweep_metric_names(spec_json))
    if not isinstance(objective, str):
        raise invalid("objective", repr(objective)[:60], "a metric name (str)")
    _check_metric(spec_json, paths[0], "objective", objective, valid)
    if isinstance(constraints, str):
        constraints = [constraints]
    if isinstance(constraints, bytes | Mapping) or not isinstance(constraints, Sequence):
        raise invalid("constraints", repr(constraints)[:60], "a list of constraint texts")
    parsed = [_parse_constraint(f"constraints[{i}]", c) for i, c in enumerate(constraints)]
    for i, c in enumerate(parsed):
        _check_metric(spec_json, paths[0], f"constraints[{i}]", c.metric, valid)
    if stability is not None:
        parsed.append(_Constraint(f"max |multiplier| <= {stability:g}", "", False, "<=", stability))
    metrics = list(dict.fromkeys([objective] + [c.metric for c in parsed if c.metric]))

    width = high - low
    z0 = _start(paths, low, high, start, x0)
    if z0 is None:  # a path whose value only the core knows (an alias): read it at the spec
        start = [float(v) for v in _sensitivity_or_params(run_spec, paths, metrics[:1]).parameter_values]
        z0 = _start(paths, low, high, start, x0)
        assert z0 is not None

    cache: dict[bytes, _Eval] = {}
    warned: dict[str, str] = {}  # metric -> its warning, issued once after the search
    counts = {"evaluations": 0, "sensitivities": 0}

    def solve(spec_: Simulation, wanted: list[str], by: list[str] = paths) -> SensitivityResult:
        counts["sensitivities"] += 1
        return _sensitivity_or_params(spec_, by, wanted)

    def x_of(z: np.ndarray) -> np.ndarray:
        return low + np.clip(z, 0.0, 1.0) * width

    def at(x: np.ndarray) -> Simulation:
        return run_spec.with_paths({p: float(v) for p, v in zip(paths, x, strict=True)})

    def rho_at(z: np.ndarray) -> float:
        # Only the multipliers are read: they are the exact monodromy's at the orbit, whatever
        # the parameters, so one parameter's derivatives (not every path's) come with them.
        s = solve(at(x_of(z)), metrics[:1], paths[:1])
        return s.largest_non_neutral

    def evaluate(z: np.ndarray) -> _Eval:
        z = np.asarray(z, dtype=float)
        key = z.tobytes()
        if key in cache:
            return cache[key]
        x = x_of(z)
        shown = ", ".join(f"{p} = {v:.10g}" for p, v in zip(paths, x, strict=True))
        try:
            s = solve(at(x), metrics)
        except InvalidParameterError:
            raise
        except ParitysimError as exc:
            raise _Stop(f"no steady state to differentiate at {shown}: {exc}") from exc
        counts["evaluations"] += 1
        for path, reason in zip(paths, s.parameter_reasons, strict=True):
            if reason is not None:
                raise _Stop(f"the steady state is not differentiable in {path} at {shown}: it {reason}")
        values: dict[str, float] = {}
        grads: dict[str, np.ndarray] = {}
        # The result's arrays (the columns are `paths`, in order), not its tables.
        for name, value, row, reason in zip(s.metric_names, s.values, s.matrix, s.reasons, strict=True):
            g = row * width
            if not math.isfinite(value):
                raise _Stop(f"{name} is not defined at {shown}", name)
            if not np.isfinite(g).all():
                raise _Stop(f"the gradient of {name} is not defined at {shown}: {reason or 'not finite'}", name)
            if reason is not None and name not in warned:
                warned[name] = f"ps.optimize: {name} is not differentiable at {shown} ({reason}); its derivative there is the core's and may mislead the optimiser"
            values[name], grads[name] = float(value), g
        rho = s.largest_non_neutral

        def stability_gradient() -> np.ndarray:
            g = np.empty(len(paths))
            for k in range(len(paths)):
                step = STABILITY_STEP if z[k] + STABILITY_STEP <= 1.0 else -STABILITY_STEP
                zk = z.copy()
                zk[k] += step
                try:
                    g[k] = (rho_at(zk) - rho) / step
                except ParitysimError as exc:
                    raise _Stop(f"no steady state for the stability derivative near {shown}: {exc}") from exc
            return g

        e = _Eval(values, grads, s.multipliers, rho, stability_gradient if stability is not None else None)
        cache[key] = e
        return e

    f_scale = 1.0
    sign = 1.0 if sense == "min" else -1.0

    def fun(z: np.ndarray) -> float:
        return sign * evaluate(z).values[objective] / f_scale

    def jac(z: np.ndarray) -> np.ndarray:
        return sign * evaluate(z).grads[objective] / f_scale

    ineq = [c for c in parsed if c.op != "=="]
    eq = [c for c in parsed if c.op == "=="]

    def cons(group: list[_Constraint]) -> tuple[Any, Any]:
        def c_fun(z: np.ndarray) -> np.ndarray:
            e = evaluate(z)
            out = []
            for c in group:
                v = c.value(e.values, e.rho)
                out.append(((v - c.bound) if c.op != "<=" else (c.bound - v)) / c.scale())
            return np.array(out)

        def c_jac(z: np.ndarray) -> np.ndarray:
            e = evaluate(z)
            rows = []
            for c in group:
                g = e.gradient(c.metric)
                if c.absolute:
                    g = g * (1.0 if e.values[c.metric] >= 0 else -1.0)
                rows.append((g if c.op != "<=" else -g) / c.scale())
            return np.array(rows).reshape(len(group), len(paths))

        return c_fun, c_jac

    rows: list[dict[str, float]] = []

    def record(z: np.ndarray) -> None:
        e = evaluate(z)
        x = x_of(z)
        worst = max((c.violation(c.value(e.values, e.rho)) for c in parsed), default=0.0)
        row = {"iteration": len(rows), "objective": e.values[objective], "max_violation": worst}
        row.update({p: float(v) for p, v in zip(paths, x, strict=True)})
        rows.append(row)

    with LongRun("optimize", progress, None, unit="iteration") as bar:
        # The start must be defined: an error there is the caller's to see.
        try:
            first = evaluate(z0)
        except _Stop as stop:
            if stop.metric is None and stop.__cause__ is not None:
                raise stop.__cause__ from None  # no orbit at the start
            where = "objective" if stop.metric == objective else next(
                (f"constraints[{i}]" for i, c in enumerate(parsed) if c.metric == stop.metric), "objective"
            )
            raise invalid(where, repr(stop.metric), f"a metric defined at the start x0 ({stop})") from None
        f0 = abs(first.values[objective])
        f_scale = f0 if f0 > 0 else 1.0
        record(z0)
        last_good = z0.copy()

        def callback(zk: np.ndarray, *_: Any) -> None:
            nonlocal last_good
            record(np.asarray(zk, dtype=float))
            last_good = np.asarray(zk, dtype=float).copy()
            bar.done()

        stopped: str | None = None
        res: Any = None
        try:
            if method == "SLSQP":
                scipy_constraints = []
                for kind, group in (("ineq", ineq), ("eq", eq)):
                    if group:
                        c_fun, c_jac = cons(group)
                        scipy_constraints.append({"type": kind, "fun": c_fun, "jac": c_jac})
                res = minimize(
                    fun, z0, jac=jac, method="SLSQP", bounds=Bounds(0.0, 1.0), constraints=scipy_constraints,
                    options={"maxiter": max_iterations, "ftol": tol}, callback=callback,
                )  # fmt: skip
            elif method == "ipopt":
                res = _ipopt(fun, jac, [cons(g) for g in (ineq, eq) if g], [len(ineq)] * bool(ineq) + [0] * bool(eq), z0, max_iterations, tol, callback)
            else:
                nonlinear = []
                for group, lb, ub in ((ineq, 0.0, np.inf), (eq, 0.0, 0.0)):
                    if group:
                        c_fun, c_jac = cons(group)
                        nonlinear.append(NonlinearConstraint(c_fun, lb, ub, jac=c_jac, hess=BFGS()))
                with warnings.catch_warnings():
                    warnings.filterwarnings("ignore", message="delta_grad == 0.0", category=UserWarning)
                    options = {"maxiter": max_iterations, "gtol": tol, "xtol": tol, "barrier_tol": tol}
                    res = minimize(fun, z0, jac=jac, hess=BFGS(), method="trust-constr", bounds=Bounds(0.0, 1.0), constraints=nonlinear, options=options, callback=callback)
                    # scipy's interior point stops on a barrier subproblem's optimality while its
                    # barrier parameter is still large, that far inside an active bound (the §3.4
                    # PARITY: barrier 1.6e-4, power 3.3e-4 above the optimum, reported as
                    # success): restart from there with the barrier a hundredth as large.
                    for _ in range(TRUST_CONSTR_RESTARTS):
                        if not (res.success and _barrier_left(res, tol)):
                            break
                        restart = {**options, "initial_barrier_parameter": 0.01 * res.barrier_parameter, "initial_tr_radius": max(10 * tol, 1e-3)}
                        res = minimize(fun, res.x, jac=jac, hess=BFGS(), method="trust-constr", bounds=Bounds(0.0, 1.0), constraints=nonlinear, options=restart, callback=callback)
        except _Stop as stop:
            stopped = str(stop)

    for text in warned.values():
        warnings.warn(text, RuntimeWarning, stacklevel=2)
    z = last_good if stopped is not None else np.clip(np.asarray(res.x, dtype=float), 0.0, 1.0)
    try:
        final = evaluate(z)
    except _Stop as stop:  # the optimiser's last point is undefined: fall back to the last iterate
        stopped = stopped or str(stop)
        z = last_good
        final = evaluate(z)
    if any(rows[-1][p] != v for p, v in zip(paths, x_of(z), strict=True)):
        record(z)  # the returned point, when the optimiser's last step was not an iteration
    x = {p: float(v) for p, v in zip(paths, x_of(z), strict=True)}

    table_rows = []
    violated = []
    for c in parsed:
        v = c.value(final.values, final.rho)
        violation = c.violation(v)
        active = abs(v - c.bound) <= c.tolerance()
        if violation > c.tolerance():
            violated.append(f"{c.text} (value {v:.6g}, violated by {violation:.3g})")
        table_rows.append({"constraint": c.text, "value": v, "bound": c.bound, "violation": violation, "active": active})
    table = pl.DataFrame(
        table_rows, schema={"constraint": pl.String, "value": pl.Float64, "bound": pl.Float64, "violation": pl.Float64, "active": pl.Boolean}
    )
    iterations = int(getattr(res, "nit", 0) or 0) if res is not None else len(rows) - 1
    if stopped is not None:
        success, message = False, f"stopped: {stopped}"
    elif violated:
        success = False
        message = "infeasible: not met at the returned point: " + "; ".join(violated) + f" (optimiser: {res.message})"
    elif method == "trust-constr" and _barrier_left(res, tol):
        # Still above the barrier tolerance after the restarts: not an optimum to `tol`.
        success = False
        message = (
            f"not converged: trust-constr stopped ({res.message}) with its barrier parameter at {res.barrier_parameter:.1e} "
            f"> barrier_tol {tol:g}, so the point can lie that far inside an active bound; method='SLSQP' solves to the bound"
        )
    else:
        success = bool(res.success)
        message = str(res.message)
    return OptimizationResult(
        success=success,
        message=message,
        x=x,
        spec=spec.with_paths(x),
        objective_name=objective,
        sense=sense,
        objective=final.values[objective],
        constraints=table,
        active=[r["constraint"] for r in table_rows if r["active"]],
        multipliers=final.multipliers,
        history=pl.DataFrame(rows, schema={"iteration": pl.Int64, "objective": pl.Float64, "max_violation": pl.Float64, **{p: pl.Float64 for p in paths}}),
        iterations=iterations,
        evaluations=counts["evaluations"],
        sensitivities=counts["sensitivities"],
        bounds={p: (float(lo), float(hi)) for p, lo, hi in zip(paths, low, high, strict=True)},
    )


def _barrier_left(res: Any, tol: float) -> bool:
    """Whether trust-constr's interior-point run ended with its barrier parameter above
    ``tol`` (its ``barrier_tol``); without inequality constraints it runs no barrier."""
    return getattr(res, "method", "") == "tr_interior_point" and float(getattr(res, "barrier_parameter", 0.0)) > tol


def _ipopt(fun: Any, jac: Any, groups: list[tuple[Any, Any]], inequalities: list[int], z0: np.ndarray, max_iterations: int, tol: float, callback: Any) -> Any:
    """`optimize`'s search by IPOPT (cyipopt's low-level problem: its ``intermediate`` hook
    records each iterate) on the scaled box [0, 1] with a limited-memory Hessian (only
    gradients are exact). ``groups``: (values, Jacobian) of the inequality (>= 0) and equality
    (= 0) constraints; ``inequalities``: per group, how many of its rows are inequalities (all
    or none). Returns a scipy-like result (x, success, message, nit)."""
    from types import SimpleNamespace

    import cyipopt

    sizes = [len(np.atleast_1d(g[0](z0))) for g in groups]
    lower = np.zeros(sum(sizes))
    upper = np.concatenate([np.full(n, np.inf) if k else np.zeros(n) for n, k in zip(sizes, inequalities, strict=True)]) if sizes else lower
    iterations = [0]

    class Problem:
        def objective(self, z: np.ndarray) -> float:
            return float(fun(z))

        def gradient(self, z: np.ndarray) -> np.ndarray:
            return np.asarray(jac(z), dtype=float)

        def constraints(self, z: np.ndarray) -> np.ndarray:
            return np.concatenate([np.atleast_1d(g[0](z)) for g in groups]) if groups else np.zeros(0)

        def jacobian(self, z: np.ndarray) -> np.ndarray:  # dense, row-major
            return np.concatenate([np.asarray(g[1](z), dtype=float).ravel() for g in groups]) if groups else np.zeros(0)

        def intermediate(self, alg_mod: int, iter_count: int, *_: Any) -> bool:
            if iter_count > 0:
                iterations[0] = iter_count
                callback(np.clip(problem.get_current_iterate()["x"], 0.0, 1.0))
            return True

    n = len(z0)
    problem = cyipopt.Problem(n=n, m=len(lower), problem_obj=Problem(), lb=np.zeros(n), ub=np.ones(n), cl=lower, cu=upper)
    for key, value in (("hessian_approximation", "limited-memory"), ("max_iter", max_iterations), ("tol", tol), ("print_level", 0), ("sb", "yes")):
        problem.add_option(key, value)
    x, info = problem.solve(np.asarray(z0, dtype=float))
    message = info["status_msg"].decode() if isinstance(info["status_msg"], bytes) else str(info["status_msg"])
    # IPOPT status 0: solved; 1: solved to the acceptable level.
    return SimpleNamespace(x=x, success=info["status"] in (0, 1), message=f"IPOPT: {message}", nit=iterations[0])


def _sensitivity_or_params(spec: Simulation, paths: list[str], metrics: list[str]) -> SensitivityResult:
    """`sensitivity`, with an error about one of ``paths`` (a value out of its range, different
    values on the wings) renamed to the ``params`` argument."""
    try:
        return sensitivity(spec, paths, metrics=metrics, progress=False)
    except InvalidParameterError as exc:
        if getattr(exc, "field", None) in paths:
            raise invalid("params", repr(exc.field), str(exc).split(": must be ", 1)[-1]) from exc
        raise


def _check_metric(spec_json: str, path: str, where: str, name: str, valid: list[str]) -> None:
    """An unknown or unavailable metric, named as ``where`` with the core's reason (a force
    metric without blade-element wings) or the nearest names."""
    if name in valid:
        return
    try:
        _core.sensitivity(spec_json, [path], [name])  # refuses the metric before any run
    except InvalidParameterError as exc:
        if getattr(exc, "field", None) == "metrics":
            raise invalid(where, repr(name), str(exc).split(": must be ", 1)[-1]) from None
    raise invalid(where, repr(name), suggest(name, valid, "the spec's metrics", "a metric of this spec"))


def _parameters(spec: Simulation, params: Any) -> tuple[list[str], np.ndarray, np.ndarray, list[float | None]]:
    """The paths, their bounds and their values in the spec (None where only the core knows it)."""
    if not isinstance(params, Mapping) or not params:
        raise invalid("params", repr(params)[:60], "a non-empty mapping {path: (low, high)} of continuous spec paths")
    table = spec_paths(spec)
    listed = dict(zip(table["path"], zip(table["allowed"], table["value"], strict=True), strict=True))
    paths, lows, highs, start = [], [], [], []
    for path, bounds in params.items():
        if not isinstance(path, str) or not path.strip():
            raise invalid("params", repr(path)[:60], "continuous spec paths (non-empty text, see ps.spec_paths) as keys")
        if isinstance(bounds, np.ndarray):  # as ps.calibrate takes them
            bounds = bounds.tolist()
        if isinstance(bounds, str | bytes | Mapping) or not isinstance(bounds, Sequence) or len(bounds) != 2:
            raise invalid(f"params[{path}]", repr(bounds)[:60], "bounds (low, high): a pair of numbers")
        lo, hi = (real("params", b) for b in bounds)
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise invalid("params", f"{path!r}: ({lo}, {hi})", "finite bounds (low, high) with low < high")
        targets = [path] if path in listed else [path.replace("wings[*]", f"wings[{i}]", 1) for i in (0, 1)] if path.startswith("wings[*].") else []
        value: float | None = None
        if targets and all(t in listed for t in targets):
            for t in targets:
                allowed, text = listed[t]
                if not allowed.startswith("a number"):
                    raise invalid("params", repr(path), f"a continuous number to optimise ({t}: {allowed} is discrete or not a number)")
                try:
                    value = float(text)
                except ValueError:
                    value = None
        for v in (lo, hi):  # an unknown path (with the nearest ones) or a bound out of the path's range
            try:
                spec.with_paths({path: v})
            except InvalidParameterError as exc:
                raise invalid("params", repr(path) if v == lo and not targets else f"{path!r}: {v}", str(exc).split(": must be ", 1)[-1]) from exc
        paths.append(path)
        lows.append(lo)
        highs.append(hi)
        start.append(value)
    return paths, np.array(lows), np.array(highs), start


def _start(paths: list[str], low: np.ndarray, high: np.ndarray, start: list[float | None], x0: Any) -> np.ndarray | None:
    """The scaled start: ``x0`` (checked against the bounds), else the spec's values clipped
    into the bounds (None when one of them is unknown here)."""
    if x0 is not None:
        if not isinstance(x0, Mapping):
            raise invalid("x0", repr(x0)[:60], "None or a mapping {path: value} over the paths of params")
        for key in x0:
            if key not in paths:
                raise invalid("x0", repr(key)[:60], "a path of params: " + ", ".join(paths))
    z = np.empty(len(paths))
    for k, path in enumerate(paths):
        if x0 is not None and path in x0:
            v = real(f"x0[{path}]", x0[path])
            if not (low[k] <= v <= high[k]):
                raise invalid(f"x0[{path}]", v, f"a number within the bounds [{low[k]:g}, {high[k]:g}] given in params")
        elif start[k] is None:
            return None
        else:
            v = float(np.clip(start[k], low[k], high[k]))
        z[k] = (v - low[k]) / (high[k] - low[k])
    return z
