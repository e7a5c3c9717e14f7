"""paritysim: simulate mechanically intelligent flapping-wing drivetrains.

Units everywhere: mg-mm-ms-rad-V (force mN, torque mN·mm, inertia mg·mm², energy µJ).
Angles are radians unless an argument name says otherwise (``*_deg``).

Quick start::

    import paritysim as ps
    df = ps.trials.fig2_9()          # Fig. 2.9 transmission maps as a Polars DataFrame
    ps.plots.fig2_9(df)              # ... and the figure
"""

from __future__ import annotations

from . import kinematics, plots, trials
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
from .kinematics import Drivetrain

__all__ = [
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
