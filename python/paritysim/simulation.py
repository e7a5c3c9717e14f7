"""``paritysim.simulate``: run a spec in Rust and get Polars results back."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import polars as pl
from matplotlib.figure import Figure

from . import _core
from ._errors import invalid
from .spec import Simulation

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
    """

    metrics: dict[str, float | None]
    cycles_run: int
    converged: bool
    period_ms: float
    spec: Simulation
    residual: float | None
    columns: dict[str, np.ndarray] = field(repr=False)

    @cached_property
    def trajectory(self) -> pl.DataFrame:
        """The recorded window as a Polars DataFrame (built on first access from the numpy
        columns the Rust core returned)."""
        return pl.DataFrame(self.columns)

    @property
    def cycle(self) -> pl.DataFrame:
        """The last steady cycle of the recorded window (including its closing sample)."""
        if not np.isfinite(self.period_ms):
            return self.trajectory
        t_end = self.trajectory["time_ms"][-1]
        return self.trajectory.filter(pl.col("time_ms") >= t_end - self.period_ms - 1e-9)

    @property
    def metrics_frame(self) -> pl.DataFrame:
        """The metrics as a one-row DataFrame."""
        return pl.DataFrame({k: [v] for k, v in self.metrics.items()})

    def plot(self, path: str | Path | None = None) -> Figure:
        """Angles and torques over the recorded window; saved as PNG when ``path`` is given."""
        from . import plots

        fig = plots.simulation(self)
        if path is not None:
            plots.save(fig, path)
        return fig


def simulate(spec: Simulation | dict[str, Any], **option_overrides: Any) -> SimulationResult:
    """Run ``spec`` to periodic steady state (or for ``options.duration_ms``) in Rust.

    ``spec`` is a `Simulation` or its dict (``Simulation.to_dict()``). ``option_overrides``
    replace fields of ``spec.options`` for this run, e.g. ``simulate(spec, record_cycles=3)``.

    Raises
    ------
    InvalidParameterError, ConstraintError, ShapeError
        For an invalid spec (the message names the field).
    IntegrationError, OutOfDomainError
        When integration fails; ``.time`` and ``.state`` say where, and ``.field`` names the
        field most responsible with ``.problems`` giving its allowed range (e.g. a drive
        amplitude that moves the rod-crank past its reach). Also when one integration needs
        more than ``options.max_steps`` steps or the run takes longer than
        ``options.max_wall_ms`` (default 60 000 ms); ``.field`` names the option.
    KeyboardInterrupt
        On Ctrl-C: the run stops inside the integration (within about 20 ms).
    """
    if isinstance(spec, dict):
        spec = Simulation.from_dict(spec)
    elif not isinstance(spec, Simulation):
        raise invalid("spec", type(spec).__name__, "a paritysim.Simulation or its dict")
    if option_overrides:
        spec = spec.replace(options=spec.options.with_fields("options", **option_overrides))
    raw = _core.simulate(spec.to_json())
    return SimulationResult(
        metrics={k: (v if math.isfinite(v) else None) for k, v in raw.metrics},
        cycles_run=raw.cycles_run,
        converged=raw.converged,
        period_ms=raw.period_ms,
        spec=spec,
        residual=raw.residual if math.isfinite(raw.residual) else None,
        columns={"time_ms": raw.time_ms, **raw.columns},
    )
