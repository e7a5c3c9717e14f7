"""paritysim: simulate mechanically intelligent flapping-wing drivetrains.

Units everywhere: mg-mm-ms-rad-V (force mN, torque mN·mm, inertia mg·mm², energy µJ).
Angles are radians unless an argument name says otherwise (``*_deg``).

Quick start:

```python
import paritysim as ps
spec = ps.devices.load("sreetharan2012_3_3_parity")  # a named device (ps.devices.list())
result = ps.simulate(spec)                            # run it (Rust, GIL released)
result.plot("drag_parity.png")                        # plot it; result.trajectory is Polars
df = ps.sweep(spec, {"wings.left.omega_ratio": [1.0, 0.8, 0.6]})  # a design study
```

Submodules load on first use (``import paritysim`` stays fast and never touches matplotlib's
backend). Log messages go to the ``"paritysim"`` `logging` logger.
"""

from __future__ import annotations

import importlib
import logging
from typing import TYPE_CHECKING, Any

from . import _cpu

_cpu.check_or_exit()  # before the extension loads: it is compiled for AVX2 on x86-64 (.cargo/config.toml)

from ._core import (  # noqa: E402
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

logging.getLogger(__name__).addHandler(logging.NullHandler())

if TYPE_CHECKING:  # what type checkers see; at run time the names below load lazily
    from . import aero, claims, devices, dynamics, flight, kinematics, laminate, planform, plots, spec, stability, trials
    from .calibration import CalibrationResult, Measured, TableCalibrationResult, calibrate, measured
    from .continuation import ContinuationResult
    from .gradients import SensitivityResult, sensitivity
    from .optimizer import OptimizationResult, optimize
    from .planform import Planform
    from .simulation import SimulationResult, simulate
    from .devices import metric_names, spec_paths
    from .spec import Actuator, Aero, Body, Configuration, Drivetrain, Options, Shoulder, Simulation, Spring, Springs, TunableHinge, Waveform, Wing, load_spec
    from .sweep import grid, sweep

#: Lazily loaded submodules.
_SUBMODULES = ("aero", "calibration", "claims", "continuation", "devices", "dynamics", "flight", "gradients", "kinematics", "laminate", "optimizer", "planform", "plots", "simulation", "spec", "stability", "sweep", "trials")
#: Lazily loaded names -> the submodule defining them.
_NAMES = {
    "CalibrationResult": "calibration",
    "calibrate": "calibration",
    "Measured": "calibration",
    "TableCalibrationResult": "calibration",
    "measured": "calibration",
    "ContinuationResult": "continuation",
    "OptimizationResult": "optimizer",
    "SensitivityResult": "gradients",
    "optimize": "optimizer",
    "sensitivity": "gradients",
    "Planform": "planform",
    "SimulationResult": "simulation",
    "simulate": "simulation",
    "grid": "sweep",
    **{n: "spec" for n in ("Actuator", "Aero", "Body", "Configuration", "Drivetrain", "Options", "Shoulder", "Simulation", "Spring", "Springs", "TunableHinge", "Waveform", "Wing", "load_spec")},
    "spec_paths": "devices",  # any spec argument, a device's name too
    "metric_names": "devices",
}


def __getattr__(name: str) -> Any:
    # `paritysim.sweep` is the sweep module, callable as the sweep function (see sweep.py).
    if name in _SUBMODULES:
        module = importlib.import_module(f"{__name__}.{name}")
        globals()[name] = module
        return module
    if name in _NAMES:
        value = getattr(importlib.import_module(f"{__name__}.{_NAMES[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    # The public names (tab completion), not this file's own imports (`importlib`, `Any`).
    dunders = {n for n in globals() if n.startswith("__")}
    return sorted(dunders | set(__all__) | set(_SUBMODULES))


__all__ = [
    "Actuator",
    "Aero",
    "Body",
    "CalibrationResult",
    "ContinuationResult",
    "CancelledError",
    "Configuration",
    "ConstraintError",
    "Drivetrain",
    "GeometryError",
    "IntegrationError",
    "InvalidParameterError",
    "Measured",
    "Options",
    "OptimizationResult",
    "OutOfDomainError",
    "ParitysimError",
    "Planform",
    "ShapeError",
    "Shoulder",
    "Simulation",
    "SensitivityResult",
    "SimulationResult",
    "SingularError",
    "TableCalibrationResult",
    "Spring",
    "Springs",
    "TunableHinge",
    "Waveform",
    "Wing",
    "__version__",
    "aero",
    "calibrate",
    "claims",
    "continuation",
    "devices",
    "dynamics",
    "grid",
    "kinematics",
    "laminate",
    "load_spec",
    "measured",
    "metric_names",
    "planform",
    "optimize",
    "plots",
    "sensitivity",
    "simulate",
    "spec",
    "spec_paths",
    "stability",
    "sweep",
    "trials",
]
