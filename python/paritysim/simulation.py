"""``paritysim.simulate``: run a spec in Rust and get Polars results back."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

import numpy as np
import polars as pl
from matplotlib.figure import Figure

from . import _core, _slow_drive
from ._errors import invalid, real, suggest
from ._progress import LongRun
from .devices import as_simulation
from .spec import Simulation, SpecLike

__all__ = ["SimulationResult", "simulate"]


@dataclass(frozen=True)
class SimulationResult:
    """The outcome of :func:`simulate`.

    Attributes
    ----------
    trajectory:
        Polars DataFrame over the recorded window: ``time_ms`` and, per wing (``left_``,
        ``right_`` or ``wing_``), angles, rates, aerodynamic / spring torques, body roll, yaw and
        pitch torques (aerodynamic and inertial parts), plus ``q1, q2``, actuator force and
        power, work integrals and mechanical energy. Units: rad, rad/ms, mN·mm, mN, µJ.
    metrics:
        Dict of scalar metrics (stroke and rotation amplitude and mean per wing, phase lag of
        rotation behind stroke, peak and mean torques, work per cycle...). A metric that is
        undefined for this run is ``None``, never NaN: ``*_rotation_phase_lag`` of a wing that
        does not rotate (fixed wings), the Table 3.2 imbalance percentages when the right wing's
        roll torque is zero.
    residual:
        Relative change of the state over the last cycle before recording (the Newton residual
        with ``options.steady_state = "shooting"``); ``None`` without a periodic drive.
    orbit_cycles:
        Drive periods per period of the steady state: 1, or 2 when the orbit has
        period-doubled (the state repeats every second wingbeat: the period-1 orbit lost
        stability through a flip). The recorded window, :attr:`cycle` and the metrics then span
        ``orbit_cycles`` wingbeats per recorded cycle, and ``residual`` is the two-cycle change.
    """

    metrics: dict[str, float | None]
    cycles_run: int
    converged: bool
    period_ms: float
    spec: Simulation
    residual: float | None
    columns: dict[str, np.ndarray] = field(repr=False)
    orbit_cycles: int = 1

    @cached_property
    def trajectory(self) -> pl.DataFrame:
        """The recorded window as a Polars DataFrame (built on first access from the numpy
        columns the Rust core returned)."""
        return pl.DataFrame(self.columns)

    @property
    def cycle(self) -> pl.DataFrame:
        """The last period of the steady state in the recorded window (``orbit_cycles``
        wingbeats, including the closing sample)."""
        if not np.isfinite(self.period_ms):
            return self.trajectory
        t_end = self.trajectory["time_ms"][-1]
        return self.trajectory.filter(pl.col("time_ms") >= t_end - self.orbit_cycles * self.period_ms - 1e-9)

    @cached_property
    def units(self) -> dict[str, str]:
        """Each trajectory column's unit as the core defines it (``left_phi_dot``: ``rad/ms``,
        ``actuator_power``: ``uJ/ms`` = mW, ``body_omega_roll``: ``rad/ms``), ``time_ms`` first."""
        recorded = set(self.columns)
        return {"time_ms": "ms", **{name: unit for name, unit in _core.trajectory_column_units(self.spec.to_json()) if name in recorded}}

    @property
    def metrics_frame(self) -> pl.DataFrame:
        """The metrics as a one-row DataFrame."""
        return pl.DataFrame({k: [v] for k, v in self.metrics.items()})

    def plot(self, path: str | Path | None = None, columns: Sequence[str] | None = None) -> Figure:
        """Angles, body torques and (where computed) lift over the recorded window, or the
        trajectory ``columns`` against time, one panel per unit (angles in degrees); saved to
        ``path`` when given (the suffix picks the format: ``.png``, ``.pdf``, ``.svg``)."""
        from . import plots

        fig = plots.simulation(self, columns)
        if path is not None:
            plots.save(fig, path, close=False)
        return fig


#: The inputs a Python controller may set (as in ``[[body.set_points]]``): whippletree bias
#: torque (mN·mm), added actuator force (mN), relative actuator amplitude change (1), eq. 5.1's
#: ln q3 (1), and the per-side drives of a ``dual_four_bar`` (relative, mN; ``*_difference``:
#: +u left, −u right).
CONTROL_INPUTS = (
    "q2_bias",
    "actuator_offset",
    "actuator_gain",
    "log_q3",
    "side_gain_left",
    "side_gain_right",
    "side_offset_left",
    "side_offset_right",
    "side_gain_difference",
    "side_offset_difference",
)

Controller = Callable[[float, dict[str, float]], Mapping[str, float]]


def _control_call(controller: Controller) -> Callable[[float, list[tuple[str, float]]], list[tuple[str, float]]]:
    """The callback the core calls: the body state as a dict in, checked inputs out."""

    def call(t_ms: float, values: list[tuple[str, float]]) -> list[tuple[str, float]]:
        out = controller(t_ms, dict(values))
        if not isinstance(out, Mapping):
            raise invalid("controller", type(out).__name__, f"a dict of {', '.join(CONTROL_INPUTS)}")
        checked = []
        for name in out:
            if name not in CONTROL_INPUTS:
                raise invalid(f"controller[{name!r}]", out[name], suggest(str(name), CONTROL_INPUTS, what="a control input"))
            v = real(f"controller[{name!r}]", out[name])
            if not math.isfinite(v):
                raise invalid(f"controller[{name!r}]", v, "a finite number")
            checked.append((str(name), v))
        return checked

    return call


def _names(names: Sequence[str] | None, field: str) -> list[str] | None:
    """A column or metric selection as the core reads it (a lone string is one name)."""
    if names is None:
        return None
    if isinstance(names, str):
        return [names]
    if isinstance(names, bytes | Mapping) or not isinstance(names, Iterable):
        raise invalid(field, repr(names)[:60], "a name or a list of names (str)")
    listed = list(names)
    for n in listed:
        if not isinstance(n, str):
            raise invalid(field, repr(n)[:60], "names (str)")
    if field == "columns":  # every trajectory has its time column: naming it is no error
        listed = [n for n in listed if n != "time_ms"]
    return listed


def simulate(
    spec: SpecLike,
    *,
    controller: Controller | None = None,
    control_rate_hz: float | None = None,
    columns: Sequence[str] | None = None,
    metrics: Sequence[str] | None = None,
    progress: bool = True,
    **option_overrides: Any,
) -> SimulationResult:
    """Run ``spec`` to periodic steady state (or for ``options.duration_ms``) in Rust.

    ``spec`` is a `Simulation` or its dict (``Simulation.to_dict()``). ``option_overrides``
    replace fields of ``spec.options`` for this run, e.g. ``simulate(spec, record_cycles=3)``.

    ``columns`` and ``metrics`` choose what is built: ``None`` (default) all trajectory
    columns and metrics, a list only those (``[]``: none, e.g. ``columns=[]`` for metrics
    only). Asking for less is faster: unasked columns are never recorded, and on fixed-wing
    drivetrain devices the samples compute only what the asked metrics need. Unknown names
    raise ``InvalidParameterError`` naming ``columns`` / ``metrics`` and the nearest valid
    name.

    ``controller`` (a flying spec only: ``[body]`` mode other than ``fixed``) is a Python
    function ``controller(t_ms, body) -> {input: value}`` called every ``1 / control_rate_hz``
    from the release (zero-order hold in between). ``body`` holds the ``body_*`` trajectory
    columns at ``t_ms`` (``body_roll``, ``body_omega_roll``, ``body_x``, ...); the returned
    inputs (any of :data:`CONTROL_INPUTS`: ``q2_bias``, ``actuator_offset``, ``actuator_gain``,
    ``log_q3``, the ``side_*`` drives of a ``dual_four_bar``; missing ones are 0) add to
    ``[body].set_points`` and ``[body.control]``; one the drivetrain has no place for (``side_*``
    without a dual drivetrain, ``q2_bias`` on one) raises ``InvalidParameterError``. Slow: each call crosses into Python
    and restarts the integrator, so keep the rate low (100-1000 Hz); the Rust PD controller
    (``[body.control]``) is the fast path. An exception raised by ``controller`` stops the run
    and propagates as is.

    ``progress`` (default True): a run that takes more than a few seconds shows a bar on
    stderr (wall time against ``options.max_wall_ms``); ``False`` turns it off.

    Raises
    ------
    InvalidParameterError, ConstraintError, ShapeError
        For an invalid spec (the message names the field).
    IntegrationError, OutOfDomainError
        When integration fails; ``.time`` and ``.state`` say where, and ``.field`` names the
        field most responsible with ``.problems`` giving its allowed range (e.g. a drive
        amplitude that moves the rod-crank past its reach). Also when one integration needs
        more than ``options.max_steps`` steps or the run takes longer than
        ``options.max_wall_ms`` (default 60 000 ms); ``.field`` names the option. A sine drive
        slower than 1 Hz (``frequency_hz = 0.12`` meaning 120 Hz) that does not finish within
        3 s raises ``InvalidParameterError`` naming ``actuator.waveform.frequency_hz`` with the
        likely value; one that finishes warns that its result is quasi-static (set
        ``options.duration_ms`` to simulate a slow drive on purpose).
    KeyboardInterrupt
        On Ctrl-C: the run stops inside the integration (within about 20 ms).
    """
    spec = as_simulation(spec)
    if option_overrides:
        spec = spec.replace(options=spec.options.with_fields("options", **option_overrides))
    if controller is None:
        if control_rate_hz is not None:
            raise invalid("control_rate_hz", control_rate_hz, "given only with a controller")
        with LongRun("simulate", progress, spec.options.max_wall_ms):
            # A drive typed in kHz runs for its whole wall budget: probed first, refused by field.
            raw = _slow_drive.guarded(spec, lambda s: _core.simulate(s.to_json(), _names(columns, "columns"), _names(metrics, "metrics")))
    else:
        if not callable(controller):
            raise invalid("controller", type(controller).__name__, "a callable (t_ms, body) -> dict")
        if control_rate_hz is None:
            raise invalid("control_rate_hz", None, "a positive control rate (Hz) with a controller")
        rate = real("control_rate_hz", control_rate_hz)
        with LongRun("simulate", progress, spec.options.max_wall_ms):
            raw = _core.simulate_controlled(spec.to_json(), _control_call(controller), rate, _names(columns, "columns"), _names(metrics, "metrics"))
    return SimulationResult(
        metrics={k: (v if math.isfinite(v) else None) for k, v in raw.metrics},
        cycles_run=raw.cycles_run,
        converged=raw.converged,
        period_ms=raw.period_ms,
        spec=spec,
        residual=raw.residual if math.isfinite(raw.residual) else None,
        columns={"time_ms": raw.time_ms, **raw.columns},
        orbit_cycles=raw.orbit_cycles,
    )
