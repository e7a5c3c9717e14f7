"""Free flight (issue 17, beyond the thesis): helpers around a spec's ``body`` section.

The coupled body + wing dynamics run in Rust (``crates/flight``): :func:`paritysim.simulate`
on a spec whose ``body.mode`` is not ``"fixed"`` flies it (``clamped``, gimbals ``roll``,
``yaw``, ``pitch``, ``roll_pitch_yaw``, or ``free`` in 6 DOF under gravity) and adds the
``body_*`` trajectory columns and metrics. This package adds:

* :func:`with_body`: a copy of a spec with body fields set (the ``body`` section is plain
  data, validated in Rust);
* :func:`trim`: the drive for which cycle-averaged lift equals weight and the cycle-averaged
  body torques vanish (:class:`Trim`);
* :func:`twist_angle`, :func:`tilt_angle`: attitude angles that stay continuous through
  full turns (the Euler angles of ``body_roll``/``body_yaw``/``body_pitch`` wrap, and are
  singular at yaw = ±90°);
* :mod:`paritysim.flight.plots`: attitude and position against time, a 3-D trajectory, an
  animation of body and wings.

Body axes (the thesis' names, §3.2.3): ``x`` the stroke axis ("up" in hover), roll about it
(the drag-torque axis Drag PARITY regulates); ``y`` the wing normal at rest, yaw about it (the
lift-asymmetry axis); ``z`` spanwise toward the right wing, pitch about it.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import polars as pl

from ..devices import as_simulation
from ..spec import Simulation, SpecLike
from .trim import Trim, trim

__all__ = ["AXES", "Trim", "body_of", "tilt_angle", "trim", "twist_angle", "with_body"]

#: Body axis name -> index (x roll, y yaw, z pitch).
AXES = {"roll": 0, "yaw": 1, "pitch": 2}


def _plain_body(body: Any) -> dict[str, Any]:
    """A body section (``ps.spec.Body`` or a mapping) as a plain dict."""
    if body is None:
        return {}
    return dict(body.to_dict()) if hasattr(body, "to_dict") else dict(body)


def body_of(spec: Simulation) -> dict[str, Any]:
    """The spec's ``body`` section as plain data with every default filled in (canonicalised
    in Rust); an empty dict without a body section."""
    if getattr(spec, "body", None) is None:
        return {}
    canonical = Simulation.from_dict(spec.to_dict())
    return _plain_body(canonical.body)


def with_body(spec: SpecLike, **fields: Any) -> Simulation:
    """A copy of ``spec`` with ``body`` fields replaced (e.g. ``mode="free"``,
    ``mass_mg=80.0``, ``mechanisms=[{"kind": "gravity_pendulum", "moment_mg_mm": 100.0}]``);
    a spec without a body section gets one (defaults for the fields not given). The result's
    ``body`` is a :class:`paritysim.spec.Body`.

    Raises
    ------
    InvalidParameterError
        For an unknown field or a value out of range (raised in Rust, naming ``body.<field>``).
    """
    spec = as_simulation(spec)
    body = _plain_body(getattr(spec, "body", None))
    body.update(fields)
    return Simulation.from_dict({**spec.to_dict(), "body": body})


#: The attitude quaternion's columns of a free-flight trajectory.
_QUATERNION = ("body_qw", "body_qx", "body_qy", "body_qz")


def _quaternions(df: pl.DataFrame) -> np.ndarray:
    columns = getattr(df, "columns", None)
    if columns is None or not set(_QUATERNION) <= set(columns):
        from .._errors import invalid

        what = type(df).__name__ if columns is None else f"columns {', '.join(columns[:4])}, ..."
        raise invalid("df", what, "a free-flight trajectory (body.mode = \"free\" or a gimbal) with the columns " + ", ".join(_QUATERNION))
    return np.column_stack([df[c].to_numpy() for c in _QUATERNION])


def twist_angle(df: pl.DataFrame, axis: str) -> np.ndarray:
    """The body's rotation about its own ``axis`` ("roll", "yaw" or "pitch"), rad, unwrapped
    over the trajectory: the twist of the swing-twist decomposition of the attitude
    quaternion, ``2 atan2(q_axis, q_w)``. Exact for a single-axis gimbal; for a general motion
    it is the rotation about that axis left after the tilt of the axis is removed."""
    if axis not in AXES:
        from .._errors import invalid

        raise invalid("axis", repr(axis), "one of " + ", ".join(f'"{a}"' for a in AXES))
    q = _quaternions(df)
    k = 1 + AXES[axis]
    # The half angle jumps by 2π at the branch cut and by π where q turns into −q (the same
    # attitude): unwrapped with period π, both disappear.
    half = np.arctan2(q[:, k], q[:, 0])
    return 2.0 * np.unwrap(half, period=np.pi) if len(q) else np.zeros(0)


def tilt_angle(df: pl.DataFrame) -> np.ndarray:
    """Angle (rad) between the body's stroke axis ``x̂`` and the world ``x`` axis (vertical
    under the default gravity), in [0, π]: how far the mean lift vector has tipped."""
    q = _quaternions(df)
    w, x, y, z = q.T
    # x̂ of the body in the world: the first column of the rotation matrix; its x component.
    cos_tilt = 1.0 - 2.0 * (y * y + z * z)
    return np.arccos(np.clip(cos_tilt, -1.0, 1.0))
