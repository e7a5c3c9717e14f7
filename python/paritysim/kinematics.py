"""Kinematics: the spherical five-bar shoulder (§2.3.3) and planar drivetrains (§2.3.1-2.4).

All angles in radians, lengths in mm. Loops run in Rust with the GIL released.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from . import _core
from ._errors import chunked, invalid, real, reals, sized
from ._core import Drivetrain

__all__ = ["Drivetrain", "drivetrain_map", "shoulder_map", "shoulder_partials", "shoulder_pose"]

ArrayLike = npt.ArrayLike
FloatArray = npt.NDArray[np.float64]


def _paired(a: ArrayLike, b: ArrayLike, names: tuple[str, str]) -> tuple[FloatArray, FloatArray, tuple[int, ...]]:
    x, y = reals(names[0], a), reals(names[1], b)
    try:
        x, y = np.broadcast_arrays(x, y)
    except ValueError as exc:
        raise invalid(f"{names[0]}, {names[1]}", f"shapes {x.shape} and {y.shape}", "arrays that broadcast together") from exc
    return np.ascontiguousarray(x).ravel(), np.ascontiguousarray(y).ravel(), x.shape


def shoulder_map(alpha2: float, alpha3: float, phi: ArrayLike, theta: ArrayLike) -> dict[str, np.ndarray]:
    """Closed-form shoulder map (eqs. 2.11-2.14) over broadcast arrays of ``phi``, ``theta``.

    Parameters
    ----------
    alpha2, alpha3:
        Shoulder parameters in rad, ``0 <= alpha3 < alpha2 <= pi``.
    phi, theta:
        Input stroke and deviation angles in rad (broadcast together).

    Returns
    -------
    dict with arrays of the broadcast shape: ``gamma2``, ``gamma3``, ``gamma5``,
    ``theta_w`` (= ``gamma5``, the wing deviation angle) and boolean ``reachable``.
    Where ``reachable`` is False (outside the joint limit of eq. 2.10, or at a singular pose
    where eqs. 2.12/2.13 have no unique solution) the angles are NaN.

    Raises
    ------
    InvalidParameterError
        For ``alpha2``/``alpha3`` out of range or non-finite inputs.
    """
    p, t, shape = _paired(phi, theta, ("phi", "theta"))
    a2, a3 = real("alpha2", alpha2), real("alpha3", alpha3)
    sized("phi", f"{p.size} points", p.size, 8 * 8, "the shoulder map")
    out = chunked(lambda x, y: _core.shoulder_map(a2, a3, x, y), [p, t], ("phi", "theta"))
    return {k: v.reshape(shape) for k, v in out.items()}


def shoulder_pose(alpha2: float, alpha3: float, phi: float, theta: float, psi: float = 0.0) -> dict[str, np.ndarray]:
    """Joint angles (6,), link rotations R_i^1 (6, 3, 3) and wing angles (3,) at one pose.

    Raises ``OutOfDomainError`` outside the joint limit, with ``.field == "phi"`` and the
    stroke range eq. 2.10 allows at this ``theta`` in ``.problems``.
    """
    return _core.shoulder_pose(real("alpha2", alpha2), real("alpha3", alpha3), real("phi", phi), real("theta", theta), real("psi", psi))


def shoulder_partials(alpha2: float, alpha3: float, phi: float, theta: float, psi: float = 0.0) -> dict[str, np.ndarray]:
    """Gradients and Hessians of gamma2, gamma3, gamma5 w.r.t. (phi, theta) and J6 (A.9)."""
    return _core.shoulder_partials(real("alpha2", alpha2), real("alpha3", alpha3), real("phi", phi), real("theta", theta), real("psi", psi))


def drivetrain_map(drivetrain: Any, q1: ArrayLike, q2: ArrayLike = 0.0) -> dict[str, Any]:
    """Evaluate a drivetrain over broadcast arrays ``q1`` (mm) and ``q2`` (rad).

    ``drivetrain`` is a :class:`paritysim.Drivetrain` spec or the native kinematic object.
    Returns ``stroke_left``, ``stroke_right`` (rad), ``jacobian`` (..., 2, 2) and
    ``hessian`` (..., 2, 2, 2).
    """
    if not callable(getattr(drivetrain, "evaluate", None)):
        raise invalid("drivetrain", type(drivetrain).__name__, "a paritysim.Drivetrain (e.g. Drivetrain.linkage_differential())")
    a, b, shape = _paired(q1, q2, ("q1", "q2"))
    # Outputs: 14 floats per point, plus the inputs; evaluated in chunks (the native call holds
    # several times its output while it runs).
    sized("q1", f"{a.size} points", a.size, 16 * 8, "the drivetrain map")
    out = chunked(drivetrain.evaluate, [a, b], ("q1", "q2"))
    return {
        "stroke_left": out["stroke_left"].reshape(shape),
        "stroke_right": out["stroke_right"].reshape(shape),
        "jacobian": out["jacobian"].reshape((*shape, 2, 2)),
        "hessian": out["hessian"].reshape((*shape, 2, 2, 2)),
    }
