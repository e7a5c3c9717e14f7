"""Design gradients: ``ps.sensitivity(spec, params=[paths])``, derivatives of steady-state metrics.

The periodic orbit ``x*`` solves ``P(x*, p) = x*`` (``P``: the period map). The core takes
``dx*/dp = -(dP/dx - I)^+ dP/dp`` at the orbit (implicit function theorem; ``dP/dx`` is the
exact monodromy, ``dP/dp`` a central difference of the period map on the shooting's fixed step
grid, a smooth function of ``p``) and differentiates each metric along ``(dx*/dp, 1)`` on that
grid. No finite difference runs through the shooting's convergence, so the derivatives are
smooth and cost a few periods per parameter; directions along a family of orbits (a Floquet
multiplier at 1, e.g. the whippletree at K2 = 0) are reported and left out, never divided by.

``ps.optimize`` (``optimizer.py``) puts these exact gradients under ``scipy.optimize``.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import polars as pl
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from . import _core
from ._errors import invalid, unknown_name
from ._progress import LongRun
from .devices import as_simulation
from .spec import Simulation, SpecLike

__all__ = ["SensitivityResult", "sensitivity"]


@dataclass(frozen=True, eq=False)
class SensitivityResult:
    """Derivatives of the steady-state metrics with respect to spec paths.

    As arrays: ``metric_names``, ``values`` (the metrics at the spec's point), ``matrix``
    (``d metric / d parameter``, metrics x parameters, metric units per parameter unit),
    ``reasons`` (per metric: why its derivatives are not to be trusted, ``None`` where they
    are: a kink such as a peak switching between two maxima, a metric that moves along a
    family of orbits, or one not defined here), ``parameter_names``, ``units``,
    ``parameter_values`` and ``parameter_reasons`` (per parameter: why the orbit is not
    differentiable in it here, ``None`` where it is: a parameter that breaks a family of
    orbits, whose ``matrix`` column is then NaN).
    As tables (built on first use): ``jacobian``, one row per metric: ``metric``, ``value``,
    one column ``d/d(<path>)`` per parameter, ``differentiable`` and ``reason``;
    ``parameters``: ``parameter``, ``unit``, ``value``, ``differentiable`` and ``reason``.
    ``multipliers``: Floquet multipliers of the exact monodromy, largest modulus first.
    ``neutral_directions``: directions with a multiplier at 1, left out of ``dx*/dp``;
    ``largest_non_neutral``: the largest |multiplier| but those.
    ``state_jacobian``: ``dx*/dp``, the orbit's start state (coordinates, then rates) per
    parameter. ``residual``: the orbit's period-map residual on its grid.
    """

    metric_names: tuple[str, ...]
    values: np.ndarray
    matrix: np.ndarray
    reasons: tuple[str | None, ...]
    parameter_names: tuple[str, ...]
    units: tuple[str, ...]
    parameter_values: np.ndarray
    parameter_reasons: tuple[str | None, ...]
    multipliers: np.ndarray
    neutral_directions: int
    state_jacobian: np.ndarray
    residual: float

    @cached_property
    def jacobian(self) -> pl.DataFrame:
        """One row per metric: ``metric``, ``value``, ``d/d(<path>)`` per parameter,
        ``differentiable``, ``reason``."""
        # One constructor from rows: a with_columns per parameter cost 0.15 ms each, and rows
        # build the §3.3 benchmark's table in 0.13 ms against 0.31 ms from numpy columns.
        derivatives = {f"d/d({name})": pl.Float64 for name in self.parameter_names}
        return pl.DataFrame(
            [
                (metric, float(value), *(float(d) for d in row), reason is None, reason)
                for metric, value, row, reason in zip(self.metric_names, self.values, self.matrix, self.reasons, strict=True)
            ],
            schema={"metric": pl.String, "value": pl.Float64, **derivatives, "differentiable": pl.Boolean, "reason": pl.String},
            orient="row",
        )

    @cached_property
    def parameters(self) -> pl.DataFrame:
        """``parameter``, ``unit``, ``value``, ``differentiable``, ``reason``."""
        return pl.DataFrame(
            [
                (name, unit, float(value), reason is None, reason)
                for name, unit, value, reason in zip(self.parameter_names, self.units, self.parameter_values, self.parameter_reasons, strict=True)
            ],
            schema={"parameter": pl.String, "unit": pl.String, "value": pl.Float64, "differentiable": pl.Boolean, "reason": pl.String},
            orient="row",
        )

    @property
    def largest_non_neutral(self) -> float:
        """The largest |multiplier| but a family's: the ``neutral_directions`` nearest 1 are left
        out (0.0 when none is left). A slow real mode counts, however close to 1 (K2 = 0.05 on
        the §3.4 1-Cut decays at 0.99987 a cycle); ``ps.optimize``'s ``stability`` bounds this."""
        mu = np.abs(np.delete(self.multipliers, np.argsort(np.abs(self.multipliers - 1.0))[: self.neutral_directions]))
        return float(mu.max()) if mu.size else 0.0

    def derivative(self, metric: str, parameter: str) -> float:
        """``d metric / d parameter`` (names as given to `sensitivity`)."""
        if metric not in self.metric_names:
            raise invalid("metric", metric, "one of the result's metrics: " + ", ".join(self.metric_names[:5]))
        if parameter not in self.parameter_names:
            raise invalid("parameter", parameter, "one of " + ", ".join(self.parameter_names))
        row, column = self.metric_names.index(metric), self.parameter_names.index(parameter)
        slope = float(self.matrix[row, column])
        if self.parameter_reasons[column] is not None:
            raise invalid("parameter", parameter, f"a parameter the orbit is differentiable in here (it {self.parameter_reasons[column]})")
        if not math.isfinite(slope):  # a metric not defined at this point (a phase lag of a still wing)
            raise invalid("metric", metric, f"a metric defined at this point ({metric} is {self.jacobian['value'][row]}: {self.reasons[row] or 'not finite'})")
        return slope

    def elasticities(self) -> pl.DataFrame:
        """``(p / m) dm/dp``: the relative change of each metric per relative change of each
        parameter (null where the metric or the parameter is 0, or the metric or its
        derivative is not defined there)."""
        out = self.jacobian.select("metric")
        value = self.jacobian["value"]
        for name, p in zip(self.parameters["parameter"], self.parameters["value"], strict=True):
            slope = self.jacobian[f"d/d({name})"]
            defined = (value != 0) & value.is_finite() & slope.is_finite() & pl.lit(p != 0 and math.isfinite(p))
            out = out.with_columns(pl.when(defined).then(slope * p / value).otherwise(None).alias(name))
        return out

    def plot(self, metrics: Sequence[str] | None = None, path: str | Path | None = None) -> Figure:
        """A heat map of the elasticities (metrics x parameters), each cell labelled with its
        value; a row whose metric, or a column whose parameter, is not differentiable there is
        hatched, a cell whose metric is 0 (no elasticity) is blank. ``metrics``: the rows to show (default all); ``path``: also
        save the figure there."""
        e = self.elasticities()
        flags = self.jacobian["differentiable"]
        if metrics is not None:
            wanted = _names("metrics", metrics)
            for m in wanted:
                if m not in self.metric_names:
                    raise unknown_name("metrics", m, self.metric_names, what="a metric of this result")
            keep = pl.Series([m in set(wanted) for m in e["metric"]])
            e, flags = e.filter(keep), flags.filter(keep)
        names = list(self.parameters["parameter"])
        grid = e.select(names).to_numpy().astype(float)
        # Room for the rotated parameter names, the metric names and the colour bar: a 1 x 1
        # map stays readable, a 10 x 10 one grows with its cells.
        fig = Figure(figsize=(max(4.8, 2.6 + 0.9 * len(names)), max(3.0, 1.8 + 0.42 * e.height)), layout="constrained")
        ax = fig.subplots()
        bound = float(np.nanmax(np.abs(grid))) if np.isfinite(grid).any() else 1.0
        bound = bound if bound > 0 else 1.0
        image = ax.imshow(grid, cmap="RdBu_r", vmin=-bound, vmax=bound, aspect="auto")
        ax.set_xticks(range(len(names)), names, rotation=30, ha="right")
        ax.set_yticks(range(e.height), list(e["metric"]))
        if grid.size <= 150:  # the numbers themselves, where they fit
            for (i, j), v in np.ndenumerate(grid):
                if np.isfinite(v):
                    ax.text(j, i, f"{v + 0.0:.3g}", ha="center", va="center", fontsize=8, color="white" if abs(v) > 0.6 * bound else "black")
        for i, ok in enumerate(flags):
            if not ok:
                ax.add_patch(Rectangle((-0.5, i - 0.5), len(names), 1.0, fill=False, hatch="///", edgecolor="0.35", lw=0.0))
        for j, reason in enumerate(self.parameter_reasons):
            if reason is not None:
                ax.add_patch(Rectangle((j - 0.5, -0.5), 1.0, e.height, fill=False, hatch="\\\\\\", edgecolor="0.35", lw=0.0))
        fig.colorbar(image, ax=ax, label="elasticity (p/m) dm/dp")
        hatched = not all(flags) or any(r is not None for r in self.parameter_reasons)
        ax.set_title("steady-state sensitivities" + (" (hatched: not differentiable)" if hatched else ""), fontsize=10)
        if path is not None:
            from .plots import save

            save(fig, path, close=False)
        return fig

    def __repr__(self) -> str:
        bad = sum(reason is not None for reason in self.reasons)
        broken = sum(reason is not None for reason in self.parameter_reasons)
        largest = abs(self.multipliers[0]) if len(self.multipliers) else float("nan")
        return (
            f"SensitivityResult({len(self.metric_names)} metrics x {len(self.parameter_names)} parameters, "
            f"{bad} not differentiable, " + (f"{broken} parameter(s) not differentiable in, " if broken else "") + f"{self.neutral_directions} neutral direction(s), "
            f"largest |multiplier| {largest:.4g}, orbit residual {self.residual:.1e})"
        )


def sensitivity(
    spec: SpecLike,
    params: str | Sequence[str],
    *,
    metrics: str | Sequence[str] | None = None,
    progress: bool = True,
    **option_overrides: Any,
) -> SensitivityResult:
    """Derivatives of ``spec``'s steady-state metrics with respect to the continuous spec
    paths ``params`` (any spelling ``ps.spec_paths(spec)`` lists: ``wings[*].springs.hinge.stiffness``,
    ``drivetrain.balance_spring``, ``actuator.frequency_hz``, ...).

    ``metrics``: the metrics to differentiate (default: all). ``option_overrides`` replace
    fields of ``spec.options`` (e.g. ``rtol=1e-10``): the derivatives are as accurate as the
    orbit (measured against central differences of whole ``ps.simulate`` runs at rtol 1e-11:
    within 1e-5 relative, ``crates/dynamics/tests/dynamics/sensitivity.rs``).

    Cost: one steady-state run whose last Newton period also integrates the variational
    equations (the base window and its Φ), then per parameter two perturbed periods whose
    windows are their own samples moved by Φ (four at a time in SIMD lanes on a linear-map
    device asked for stroke metrics, on the calling thread; otherwise parameters in pairs on
    the engine's threads, ``PARITYSIM_THREADS``). Metrics that read work integrals (the
    powers, the work per cycle) integrate each window instead. On the §3.3 benchmark point
    about 1.7× a `paritysim.simulate` with one parameter, 2.8× with eight, 3.1× with ten, in
    instructions and in wall time (about 1.5 simulates, then a sixth of one per parameter;
    reading the ``jacobian`` and ``parameters`` tables, built on first use, adds 0.1 to 0.2
    of a simulate); on the §3.4 1-Cut (no SIMD lanes: its perturbed periods run scalar)
    about 1.8× with one parameter, 2.6× with three and 5.7× with ten.
    ``benchmarks/sensitivity_cost.py`` measures these ratios (wall time or instructions) on
    your machine; docs/findings.md §30.

    At an orbit with a neutral direction (``neutral_directions`` > 0, e.g. a linear
    whippletree at ``drivetrain.balance_spring = 0``), a metric that changes along the family
    is flagged (which member is meant decides its derivative), and a parameter that breaks
    the family (the balance spring itself, on wings that differ) is not differentiable there:
    as it moves the steady state jumps to the member the parameter selects, so its column is
    NaN and ``parameter_reasons`` / the ``parameters`` table say why (the numbers a
    first-order method gives there were up to 55 % off whole runs; docs/findings.md §30).
    Near such a point (a multiplier within 1e-3 of 1, K2 below about 0.6 on the §3.3 1-Cut)
    the orbit is nearly a family: a metric that moves along the slow direction is flagged (its
    derivative divides the period map's error by the small distance to 1); the others keep
    theirs. Differentiate the balance spring well off 0 (K2 = 1 agrees with whole runs to
    1e-7).

    Raises
    ------
    InvalidParameterError
        A path that is unknown (with the nearest ones), discrete (a name, a kind, a count),
        with different values on the wings of a ``wings[*]`` path, or naming a field another
        parameter names already (the same path twice, or two spellings of it); a flying spec.
    IntegrationError
        When the spec does not reach a periodic steady state (nothing to differentiate).
    """
    spec = as_simulation(spec)
    names = _names("params", params)
    if not names:
        raise invalid("params", "[]", "at least one continuous spec path (see ps.spec_paths)")
    wanted = None if metrics is None else _names("metrics", metrics)
    if option_overrides:
        spec = spec.replace(options=spec.options.with_fields("options", **option_overrides))
    with LongRun("sensitivity", progress, spec.options.max_wall_ms):
        raw = _core.sensitivity(spec.to_json(), names, wanted)
    for note in raw.get("notes", ()):  # an old spelling warns here as in sweep and with_paths
        warnings.warn(note, DeprecationWarning, stacklevel=2)
    multipliers = np.array([complex(re, im) for re, im in raw["multipliers"]], dtype=complex)
    state = np.asarray(raw["state_jacobian"], dtype=float).T if len(raw["state_jacobian"]) else np.zeros((0, 0))
    parameter_names, metric_names = tuple(raw["parameter"]), tuple(raw["metric"])
    # The core's Jacobian comes by columns (one per parameter, over the metrics).
    matrix = np.asarray(raw["jacobian"], dtype=float).reshape(len(parameter_names), len(metric_names)).T
    return SensitivityResult(
        metric_names=metric_names,
        values=np.asarray(raw["value"], dtype=float),
        matrix=matrix,
        reasons=tuple(reason or None for reason in raw["not_differentiable"]),
        parameter_names=parameter_names,
        units=tuple(raw["unit"]),
        parameter_values=np.asarray(raw["parameter_value"], dtype=float),
        parameter_reasons=tuple(reason or None for reason in raw["parameter_not_differentiable"]),
        multipliers=multipliers,
        neutral_directions=int(raw["neutral_directions"]),
        state_jacobian=state,
        residual=float(raw["residual"]),
    )


def _names(field: str, value: Any) -> list[str]:
    """A lone string is one name; otherwise a sequence of strings."""
    if isinstance(value, str):
        return [value]
    if isinstance(value, bytes | Mapping) or not isinstance(value, Sequence):
        raise invalid(field, repr(value)[:60], "a path or a list of paths (str)")
    out = list(value)
    for v in out:
        if not isinstance(v, str) or not v.strip():
            raise invalid(field, repr(v)[:60], "non-empty names (str)")
    return out
