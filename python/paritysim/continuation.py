"""Continuation of periodic orbits with Floquet bifurcation detection.

A driven device's periodic steady state is a fixed point of its period map. `continuation`
follows it as one spec parameter changes — pseudo-arclength by default, so it turns around
folds and follows the unstable branch — and reports every point's Floquet multipliers, its
stability and its orbit metrics. Between points it watches the test functions of the
codimension-one bifurcations of a forced orbit and locates each by bisection:

* ``fold``: a multiplier through +1 where the branch turns back;
* ``period_doubling``: a multiplier through −1;
* ``neimark_sacker``: a complex pair through the unit circle;
* ``branch_point``: a multiplier through +1 without a turn (symmetry breaking: e.g. the Drag
  PARITY whippletree of a symmetric device).

```python
import paritysim as ps
spec = ps.devices.load("sreetharan2012_3_3_parity_linkage")
branch = ps.continuation(spec, "drivetrain.balance_spring", start=1000.0, stop=100.0)
branch.bifurcations        # the whippletree loses stability near K2 = 377 mN·mm/rad
branch.plot("q2_amplitude", path="branch.png")   # stable solid, unstable dashed
```

A located fold or period doubling can be followed in a second parameter with
`ContinuationResult.follow`. The numerics are in the Rust crate ``paritysim-continuation``
(validated on a linear oscillator, the Duffing folds against harmonic balance and the driven
pendulum's period doubling against simulation).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from . import _core
from ._core import InvalidParameterError
from ._errors import invalid, of_kind, real, suggest, whole
from ._progress import LongRun
from .devices import as_simulation
from .spec import Simulation, SpecLike

if TYPE_CHECKING:
    import polars as pl
    from matplotlib.figure import Figure

__all__ = ["ContinuationResult", "continuation"]

#: Keywords of `continuation` passed to the Rust settings (``ContinuationSettings`` of
#: ``paritysim_spec::continuation``) and the kind of value each takes: `_settings` checks the
#: kind by name before serialising (JSON has no NaN, and serde's type errors named only
#: ``settings``); the core checks the ranges and how they combine, and names the setting.
SETTINGS: dict[str, str] = {
    "method": "text",
    "initial_step": "number",
    "min_step": "number",
    "max_step": "number",
    "max_points": "count",
    "tolerance": "number",
    "parameter_scale": "number",
    "multiplier_tolerance": "number",
    "cyclic": "count",
    "locate": "flag",
    "metrics": "flag",
}


@dataclass(frozen=True)
class ContinuationResult:
    """A branch of periodic orbits.

    Attributes
    ----------
    path:
        The continued parameter path (the branch's first column).
    spec:
        The spec that was continued.
    branch:
        One row per orbit, in branch order: the parameter, ``stability`` (``stable``,
        ``unstable``, ``marginal``), ``spectral_radius`` (largest non-trivial |μ|),
        ``multiplier_modulus`` and ``multiplier_angle`` (lists, rad), ``iterations``,
        ``residual``, ``arclength``, ``drift`` (cyclic coordinate shift per period), the orbit's
        state ``x0..`` and its metrics (as `paritysim.simulate` names them).
    bifurcations:
        ``kind``, the parameter, ``after`` (branch row it follows), ``located`` and the
        ``critical_modulus`` / ``critical_angle`` of the multiplier that crossed.
    stop_reason:
        Why the branch ended (``ReachedStop``, ``LeftInterval``, ``MaxPoints``, ``StepTooSmall``).
    map_evaluations:
        Period-map evaluations with the monodromy: the cost.
    """

    path: str
    spec: Simulation
    branch: pl.DataFrame
    bifurcations: pl.DataFrame
    stop_reason: str
    map_evaluations: int
    _native: Any

    def follow(self, bifurcation: int, path: str, stop: float, start: float | None = None, max_step: float | None = None) -> pl.DataFrame:
        """Follows fold or period-doubling ``bifurcation`` (row of `bifurcations`) in a second
        parameter ``path`` from ``start`` (default: the spec's value) to ``stop``: the curve of
        (first parameter, second parameter) along which the bifurcation persists. ``max_step``
        (scaled arclength; the first step is a quarter of it) defaults to the branch's; the curve's Newton tolerance is at least
        1e-7 (its test function is a derivative of the computed map)."""
        import polars as pl

        n = self.bifurcations.height
        try:
            index = whole("bifurcation", bifurcation, 0, n - 1)
        except InvalidParameterError:
            found = f": an integer in [0, {n - 1}] (the branch has {n})" if n else f", but the branch has none (stop_reason {self.stop_reason})"
            raise invalid("bifurcation", repr(bifurcation), f"a row of `bifurcations`{found}") from None
        if not isinstance(path, str):
            raise invalid("path", repr(path), "a parameter path (see paritysim.spec_paths)")
        second_start = _current(self.spec, path) if start is None else real("start", start)
        step = None if max_step is None else real("max_step", max_step)
        curve = self._native.follow(index, path, second_start, real("stop", stop), step)
        return pl.DataFrame(
            {
                self.path: list(curve["first"]),
                path: list(curve["second"]),
                "spectral_radius": [max((math.hypot(*m) for m in ms), default=float("nan")) for ms in curve["multipliers"]],
            },
            schema={self.path: pl.Float64, path: pl.Float64, "spectral_radius": pl.Float64},
        ).with_columns(pl.lit(curve["stop_reason"]).alias("stop_reason"))

    def plot(self, y: str = "spectral_radius", path: str | Path | None = None, ax: Any = None) -> Figure:
        """Branch diagram: ``y`` against the parameter, stable segments solid, unstable dashed,
        marginal dotted, bifurcations marked and labelled; saved as PNG when ``path`` is given."""
        import matplotlib.pyplot as plt

        from .plots import label_with_unit

        if y not in self.branch.columns:
            raise invalid("y", repr(y), suggest(str(y), self.branch.columns, what="a column of the branch"))
        if ax is None:
            fig, ax = plt.subplots(figsize=(7, 4.2), constrained_layout=True)
        else:
            fig = ax.figure
        x = self.branch[self.path].to_list()
        values = self.branch[y].to_list()
        kinds = self.branch["stability"].to_list()
        style = {"stable": "-", "unstable": "--", "marginal": ":"}
        drawn: set[str] = set()
        start = 0
        for i in range(1, len(x) + 1):
            if i == len(x) or kinds[i] != kinds[start]:
                end = min(i + 1, len(x))  # overlap one point so segments join
                label = kinds[start] if kinds[start] not in drawn else None
                drawn.add(kinds[start])
                ax.plot(x[start:end], values[start:end], style[kinds[start]], color="C0", label=label)
                start = i
        for row in self.bifurcations.iter_rows(named=True):
            k = row["after"]
            xb = row[self.path]
            yb = values[k] if k + 1 >= len(values) else values[k] + (values[k + 1] - values[k]) * ((xb - x[k]) / (x[k + 1] - x[k]) if x[k + 1] != x[k] else 0.0)
            ax.plot([xb], [yb], "o", color="C3")
            ax.annotate(f"{row['kind']} {xb:.4g}", (xb, yb), textcoords="offset points", xytext=(5, 5), fontsize=8)
        ax.set_xlabel(_path_label(self.spec, self.path))
        ax.set_ylabel(label_with_unit(y))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        ax.set_title(f"periodic orbits continued in {self.path}")
        if path is not None:
            from .plots import save

            save(fig, path, close=False)
        return fig


def _path_label(spec: Simulation, path: str) -> str:
    """``path (unit)`` with the unit the Rust spec declares for it (aliases: the plot label rules)."""
    from .plots import label_with_unit

    units = {row[0]: row[1] for row in _core.spec_paths(spec.to_json())}
    unit = units.get(path, "")
    return f"{path} ({unit})" if unit and unit != "1" else label_with_unit(path)


def _current(spec: Simulation, path: str) -> float:
    from .spec import spec_paths

    table = spec_paths(spec)
    match = table.filter(table["path"] == path)
    if match.height == 0:
        try:  # an unknown path: the core names it with the nearest valid ones
            spec.with_paths({path: 1.0})
        except _core.InvalidParameterError as exc:
            if "<unknown parameter path>" in str(exc):
                raise
        raise invalid("start", "None", f"a number: `{path}` is an alias, not a canonical path, so its current value is not known")
    value = json.loads(match["value"][0])
    if not isinstance(value, int | float) or isinstance(value, bool):
        raise invalid("start", "None", f"a number: `{path}` holds {value!r}")
    return float(value)


def _settings(settings: dict[str, Any]) -> dict[str, Any]:
    """The keyword ``settings`` of `continuation` checked by name for their kind (`SETTINGS`;
    None: the default), or an ``InvalidParameterError`` naming the setting: an unknown one
    with the nearest known ones, a number that is not finite, a count that is not a
    non-negative integer, a flag that is not a bool."""
    unknown = sorted(set(settings) - set(SETTINGS))
    if unknown:
        raise invalid(unknown[0], "<unknown setting>", suggest(unknown[0], SETTINGS, what="a setting of paritysim.continuation"))
    return {name: of_kind(name, value, SETTINGS[name]) for name, value in settings.items() if value is not None}


#: Wall budget of a whole `continuation` by default (ms); each orbit also has the spec's
#: ``options.max_wall_ms``.
MAX_WALL_MS = 600_000.0


def continuation(spec: SpecLike, path: str, stop: float, *, start: float | None = None, max_wall_ms: float = MAX_WALL_MS, progress: bool = True, **settings: Any) -> ContinuationResult:
    """Follows the periodic orbit of ``spec`` as ``path`` goes from ``start`` (default: the
    spec's value) to ``stop``.

    Keyword settings (all optional): ``method`` (``"arclength"`` or ``"natural"``),
    ``initial_step``, ``min_step``, ``max_step`` (scaled arclength), ``max_points``,
    ``tolerance`` (Newton, on the state), ``parameter_scale`` (parameter units per state unit;
    default |stop − start| / 10), ``multiplier_tolerance``, ``cyclic`` (index of a cyclic
    integrated coordinate, e.g. 1 for ``q2`` of a K2 = 0 linear whippletree), ``locate``,
    ``metrics`` (orbit metrics per point, default True); None for any of them: its default.
    The spec's ``options`` set the integration (rtol capped at 1e-10 for shooting).
    ``max_wall_ms`` (default 600 000, 10 min) bounds the whole branch; Ctrl-C stops it
    within tens of milliseconds. A branch that runs for more than a few seconds shows its
    wall time against that budget on stderr (``progress=False``: no bar; the CLI's
    ``--quiet``: none).

    Raises
    ------
    InvalidParameterError
        For an unknown path or setting (named, with the nearest valid one), a setting out of
        its range (`SETTINGS`) or a ``start`` the path does not allow.
    IntegrationError, OutOfDomainError
        When no periodic orbit is found at ``start``. Failures later on end the branch
        (``stop_reason``) and keep the points found.
    """
    import polars as pl

    spec = as_simulation(spec)
    if not isinstance(path, str):
        raise invalid("path", repr(path), "a parameter path (see paritysim.spec_paths)")
    settings_json = json.dumps(_settings(settings))
    first = _current(spec, path) if start is None else real("start", start)
    if start is not None:  # checked as the spec checks the path (the core's run names it twice)
        spec.with_paths({path: first})
    budget_ms = real("max_wall_ms", max_wall_ms)
    try:
        with LongRun("continuation", progress, budget_ms):
            native = _core.continuation(spec.to_json(), path, first, real("stop", stop), settings_json, budget_ms)
    except _core.ParitysimError as exc:
        if not getattr(exc, "field", None):
            import re

            budget = re.search(r"`options\.([a-z_]+)`", str(exc))
            if budget:  # a run stopped by a budget of the spec's options: that option
                exc.field = f"options.{budget.group(1)}"  # type: ignore[attr-defined]
            else:  # no periodic orbit at the start: its value is named
                exc.field = "start"  # type: ignore[attr-defined]
                exc.problems = [("start", repr(first), f"a value of `{path}` where the spec has a periodic orbit")]  # type: ignore[attr-defined]
        raise
    record = native.record  # paritysim_spec::continuation::BranchRecord
    mus = record["multipliers"]
    states = record["states"]
    columns: dict[str, Any] = {
        path: [float(v) for v in record["parameter"]],
        "stability": record["stability"],
        "spectral_radius": [max((math.hypot(*m) for m in row), default=float("nan")) for row in mus],
        "multiplier_modulus": [[math.hypot(*m) for m in row] for row in mus],
        "multiplier_angle": [[math.atan2(m[1], m[0]) for m in row] for row in mus],
        **{name: [v.item() for v in record[name]] for name in ("iterations", "residual", "arclength", "drift")},
    }
    for k in range(len(states[0]) if len(states) else 0):
        columns[f"x{k}"] = [float(s[k]) for s in states]
    metric_rows = record["metrics"]
    names = list(dict.fromkeys(name for row in metric_rows for name, _ in row))
    for name in names:
        values = [dict(row).get(name) for row in metric_rows]
        columns[name] = [v if v is not None and math.isfinite(v) else None for v in values]
    branch = pl.DataFrame(columns, strict=False)
    bif = record["bifurcations"]

    def critical(kind: str, ms: Any) -> tuple[float, float]:
        target = {"fold": 1.0, "branch_point": 1.0, "period_doubling": -1.0}.get(kind)
        if len(ms) == 0:
            return (float("nan"), float("nan"))
        if target is None:  # Neimark-Sacker: the complex pair nearest the unit circle
            m = min((m for m in ms if abs(m[1]) > 0), key=lambda m: abs(math.hypot(*m) - 1.0), default=ms[0])
        else:
            m = min(ms, key=lambda m: math.hypot(m[0] - target, m[1]))
        return (math.hypot(*m), math.atan2(m[1], m[0]))

    crit = [critical(b["kind"], b["multipliers"]) for b in bif]
    bifurcations = pl.DataFrame(
        {
            "kind": [b["kind"] for b in bif],
            path: [b["parameter"] for b in bif],
            "after": [b["after"] for b in bif],
            "located": [b["located"] for b in bif],
            "critical_modulus": [c[0] for c in crit],
            "critical_angle": [c[1] for c in crit],
        },
        schema={"kind": pl.String, path: pl.Float64, "after": pl.Int64, "located": pl.Boolean, "critical_modulus": pl.Float64, "critical_angle": pl.Float64},
    )
    return ContinuationResult(path=path, spec=spec, branch=branch, bifurcations=bifurcations, stop_reason=record["stop_reason"], map_evaluations=record["map_evaluations"], _native=native)


# `paritysim.continuation` is this module and, called, the `continuation` function.
from ._callable_module import make_callable  # noqa: E402

make_callable(__name__, "continuation")
