"""Quasi-steady blade-element aerodynamics of §3.2.4: coefficients and moments.

Conventions (see the Rust crate ``paritysim-aero`` for the derivations):

* ``alpha`` in [0, pi] rad is the angle between the chord (toward the leading edge) and the
  wing's velocity: < pi/2 while the leading edge leads. ``alpha = pi/2 + psi_rw*sgn(phi_dot_rw)``,
  i.e. eq. 3.4 with the sign of ``psi_rw`` flipped (docs/errata.md#5), so that passive rotation
  (psi lagging phi by ~90°) gives alpha = 90° - |psi|.
* ``C_N = C_L cos a + C_D sin a`` (normal), ``C_T = C_D cos a - C_L sin a`` (chordwise, toward
  the trailing edge).
* Moments in the wing frame (x chordwise, y normal, z hinge), mN·mm:
  ``M_N = -Ω1 sgn(ω_x) W² C_N``, ``M_T = -Ω1 W² C_T``,
  ``M_r = -(Ω3 d_cp - Ω4) sgn(ω_x) W² C_N``, ``M_rd = -Ω2 C_rd ω_z|ω_z|``.
* Body axes ``[roll, yaw, pitch]`` = shoulder-ground ``[x, y, z]`` (Fig. 2.10).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from . import _core
from ._errors import chunked, finite_reals, invalid, real, reals, sized, suggest, whole

__all__ = [
    "AIR_DENSITY",
    "DEFAULT_ROTATIONAL_DAMPING",
    "MODELS",
    "TABLE_3_3",
    "center_of_pressure",
    "coefficients",
    "moments",
]

FloatArray = npt.NDArray[np.float64]

#: Air at sea level, 1.2 kg/m³ in mg/mm³.
AIR_DENSITY: float = _core.AERO_AIR_DENSITY
#: C_rd of eq. 3.10 (Whitney & Wood 2010, J. Fluid Mech. 660).
DEFAULT_ROTATIONAL_DAMPING: float = _core.AERO_DEFAULT_ROTATIONAL_DAMPING
#: Built-in coefficient models.
MODELS: tuple[str, ...] = tuple(_core.aero_model_names())

#: Table 3.3 (mg·mm²): inertia (frame of Fig. 3.10) and Ω1..Ω4 per wing and trial.
TABLE_3_3: dict[str, dict[str, float]] = {
    "left": {"ixx": 49.0, "iyy": 50.5, "izz": 1.56, "ixz": 4.20,
             "omega1": 46.8, "omega2": 0.587, "omega3": 17.5, "omega4": 0.712},
    "right_uncut": {"ixx": 47.1, "iyy": 48.6, "izz": 1.49, "ixz": 3.87,
                    "omega1": 38.2, "omega2": 0.438, "omega3": 13.5, "omega4": 0.952},
    "right_1cut": {"ixx": 40.6, "iyy": 42.0, "izz": 1.43, "ixz": 3.38,
                   "omega1": 28.7, "omega2": 0.419, "omega3": 10.6, "omega4": 0.787},
    "right_2cut": {"ixx": 32.8, "iyy": 34.1, "izz": 1.29, "ixz": 2.97,
                   "omega1": 21.2, "omega2": 0.387, "omega3": 9.10, "omega4": 0.691},
}  # fmt: skip


def _flat(a: npt.ArrayLike, name: str = "alpha") -> tuple[FloatArray, tuple[int, ...]]:
    x = reals(name, a)
    return np.ascontiguousarray(x).ravel(), x.shape


def _model(name: str, value: Any) -> str:
    if not isinstance(value, str):
        raise invalid(name, repr(value)[:60], "a name (str)")
    return value


def _finite_out(out: dict[str, FloatArray], inputs: dict[str, FloatArray]) -> None:
    """An overflow (a non-finite output of finite inputs) is an error naming the input with the
    largest magnitude at the first such point (issue 34: huge finite rates gave inf/NaN)."""
    for values in out.values():
        values = np.asarray(values)
        if values.dtype.kind == "f" and not np.isfinite(values).all():
            i = int(np.argwhere(~np.isfinite(values.reshape(values.shape[0], -1)))[0][0])
            name = max(inputs, key=lambda k: abs(float(inputs[k][i if inputs[k].size > 1 else 0])))
            v = float(inputs[name][i if inputs[name].size > 1 else 0])
            raise invalid(f"{name}[{i}]" if inputs[name].size > 1 else name, v, "small enough that the blade-element terms stay finite (they overflow here)")


def coefficients(alpha: npt.ArrayLike, model: str = _core.AERO_DEFAULT_MODEL) -> dict[str, FloatArray]:
    """Force coefficients at angles of attack ``alpha`` (rad, each in [0, pi]), vectorised.

    ``model`` is ``"dickinson1999"`` (eqs. 3.5-3.6, extended past 90° by flat-plate symmetry)
    or ``"whitney_wood2010"`` (C_L = 1.8 sin 2a, C_D = 1.9 - 1.5 cos 2a).

    Returns arrays of ``alpha``'s shape: ``lift``, ``drag``, ``normal``, ``tangential`` and
    ``center_of_pressure`` (eq. 3.7, fraction of chord behind the leading edge).

    Raises ``InvalidParameterError`` for an unknown model or an angle outside [0, pi].
    """
    a, shape = _flat(alpha)
    name = _model("model", model)
    sized("alpha", f"{a.size} angles", a.size, 6 * 8, "the coefficients")
    try:
        out = chunked(lambda x: _core.aero_coefficients(x, name), [a], ("alpha",))
    except _core.InvalidParameterError as exc:
        if shape == () and getattr(exc, "field", None) == "alpha[0]":  # a lone angle is `alpha`
            raise invalid("alpha", a[0], str(exc).split(": must be ", 1)[-1]) from None
        raise
    return {k: v.reshape(shape) for k, v in out.items()}


def center_of_pressure(alpha: npt.ArrayLike) -> FloatArray:
    """Eq. 3.7: ``0.82 alpha / pi + 0.05`` (fraction of the chord behind the leading edge) at
    angles of attack ``alpha`` (rad, each in [0, pi]): the core's law, as :func:`coefficients`
    returns it (an angle outside the range is an ``InvalidParameterError`` there too)."""
    out: FloatArray = coefficients(alpha)["center_of_pressure"]
    return out


def moments(
    omegas: Any,
    phi: npt.ArrayLike = 0.0,
    theta: npt.ArrayLike = 0.0,
    psi: npt.ArrayLike = 0.0,
    phi_dot: npt.ArrayLike = 0.0,
    theta_dot: npt.ArrayLike = 0.0,
    psi_dot: npt.ArrayLike = 0.0,
    *,
    model: str = _core.AERO_DEFAULT_MODEL,
    rotational_damping: float = DEFAULT_ROTATIONAL_DAMPING,
    normal_force_law: str = _core.AERO_DEFAULT_NORMAL_FORCE_LAW,
) -> dict[str, FloatArray]:
    """Blade-element moments (eqs. 3.8-3.11) over broadcast wing states.

    Parameters
    ----------
    omegas:
        A dict with ``omega1..omega4`` (mg·mm²) and optionally ``force`` (mg·mm), e.g.
        ``Planform.omegas()`` or ``TABLE_3_3["left"]``; or a sequence ``[Ω1, Ω2, Ω3, Ω4]``.
    phi, theta, psi:
        Wing stroke, deviation and rotation angles (rad).
    phi_dot, theta_dot, psi_dot:
        Their rates (rad/ms).
    normal_force_law:
        ``"coefficient"`` (eq. 3.8, Ω1 C_N φ̇²) or ``"unit"`` (eq. 2.16, Ω φ̇²; docs/errata.md#12).

    Returns
    -------
    ``normal``, ``tangential``, ``rotational``, ``rotational_damping`` (mN·mm), ``alpha``,
    ``phi_dot_rw``, ``psi_rw``, ``psi_dot_rw`` of the broadcast shape, ``torque_wing``
    (..., 3); when ``omegas`` has ``force``, also ``lift``, ``drag`` (mN), ``lift_torque``,
    ``drag_torque`` and ``torque_body`` (mN·mm), each (..., 3) in body axes [roll, yaw, pitch].
    """
    force: float | None = None
    if isinstance(omegas, dict):
        # Table 3.3's inertia entries and Ω5..Ω8 (Planform.quasi_steady_omegas) may come along;
        # any other key is a misspelling (a `forse` dropped the lift outputs without a word).
        known = (*(f"omega{k}" for k in range(1, 9)), "force", "ixx", "iyy", "izz", "ixy", "ixz", "iyz")
        for key in omegas:
            if key not in known:
                raise invalid(f"omegas[{key!r}]", "<unknown key>", suggest(str(key), known, what="a key of Planform.omegas() or TABLE_3_3"))
        missing = [f"omega{k}" for k in range(1, 5) if f"omega{k}" not in omegas]
        if missing:
            raise invalid("omegas", f"keys {sorted(map(str, omegas))}", "a dict with omega1..omega4 (and optionally force), e.g. Planform.omegas()")
        values = [real(f"omegas['omega{k}']", omegas[f"omega{k}"]) for k in range(1, 5)]
        if omegas.get("force") is not None:
            force = real("omegas['force']", omegas["force"])
    else:
        if isinstance(omegas, (str, bytes)) or not hasattr(omegas, "__len__"):
            raise invalid("omegas", repr(omegas)[:60], "a dict with omega1..omega4 or a sequence [Ω1, Ω2, Ω3, Ω4]")
        values = [real(f"omegas[{i}]", v) for i, v in enumerate(omegas)]
        if len(values) != 4:
            err = _core.ShapeError(f"`omegas` must have 4 values [Ω1, Ω2, Ω3, Ω4], got {len(values)}")
            err.field = "omegas"  # type: ignore[attr-defined]
            raise err
    names = ("phi", "theta", "psi", "phi_dot", "theta_dot", "psi_dot")
    given = [reals(n, v) for n, v in zip(names, (phi, theta, psi, phi_dot, theta_dot, psi_dot), strict=True)]
    try:
        arrays = np.broadcast_arrays(*given)
    except ValueError as exc:
        raise invalid(", ".join(names), "shapes " + ", ".join(str(g.shape) for g in given), "arrays that broadcast together") from exc
    shape = arrays[0].shape
    flat = [np.ascontiguousarray(a).ravel() for a in arrays]
    damping = real("rotational_damping", rotational_damping)
    model_name, law = _model("model", model), _model("normal_force_law", normal_force_law)
    # 26 floats per point out (with force), six in: chunked (the native call peaked at ~20x).
    sized("phi_dot", f"{flat[0].size} points", flat[0].size, 32 * 8, "the moments")

    def call(*x: FloatArray) -> dict[str, FloatArray]:
        return _core.aero_moments(values, *x, model_name, damping, law, force)

    out = chunked(call, flat, names)
    scales = {f"omegas[{i}]": np.array([v]) for i, v in enumerate(values)}
    if force is not None:
        scales["omegas['force']"] = np.array([force])
    _finite_out(out, {**dict(zip(names, flat, strict=True)), **scales})
    return {k: (v.reshape((*shape, 3)) if v.ndim == 2 else v.reshape(shape)) for k, v in out.items()}
