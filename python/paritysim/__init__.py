"""paritysim: simulate mechanically intelligent flapping-wing drivetrains.

Units everywhere: mg-mm-ms-rad-V (force mN, torque mN·mm, inertia mg·mm², energy µJ).
Angles are radians unless an argument name says otherwise (``*_deg``).

Quick start::

    import paritysim as ps
    spec = ps.load_spec("examples/drag_parity.toml")   # build a model
    result = ps.simulate(spec)                          # run it (Rust, GIL released)
    result.plot("drag_parity.png")                      # plot it; result.trajectory is Polars
"""

from __future__ import annotations

from . import aero, kinematics, laminate, planform, plots, spec, stability, trials
from ._core import (
    CancelledError,
    ConstraintError,
    GeometryError,
    IntegrationError,
    InvalidParameterError,
    OutOfDomainError,
    ParitysimError,
    ShapeError,
    SingularError,
    __version__,
)
from .calibration import CalibrationResult, calibrate
from .planform import Planform
from .simulation import SimulationResult, simulate

# `paritysim.sweep` is the function (the module stays importable as paritysim.sweep via importlib).
from .sweep import grid, sweep  # noqa: E402
from .spec import Actuator, Aero, Configuration, Drivetrain, Options, Shoulder, Simulation, Spring, Springs, TunableHinge, Waveform, Wing, load_spec, spec_paths

__all__ = [
    "Actuator",
    "Aero",
    "CalibrationResult",
    "Planform",
    "calibrate",
    "aero",
    "laminate",
    "planform",
    "Configuration",
    "Options",
    "Shoulder",
    "Simulation",
    "SimulationResult",
    "Spring",
    "Springs",
    "spec_paths",
    "TunableHinge",
    "Waveform",
    "Wing",
    "load_spec",
    "simulate",
    "stability",
    "grid",
    "sweep",
    "spec",
    "CancelledError",
    "ConstraintError",
    "Drivetrain",
    "GeometryError",
    "IntegrationError",
    "InvalidParameterError",
    "OutOfDomainError",
    "ParitysimError",
    "ShapeError",
    "SingularError",
    "__version__",
    "kinematics",
    "plots",
    "trials",
]
