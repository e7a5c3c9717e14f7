"""Appendix A's dynamics terms of one wing, from the Rust model (``Wing::terms``).

:func:`wing_terms` returns the mass matrix ``M(p)`` (A.36), the Coriolis/centrifugal vector
``c(p, ṗ)`` (replacing A.37-A.38, docs/errata.md#1 and #2), the spring gradient ``∇V`` (A.6)
and the Jacobian ``J6`` (A.9) of the Euler-Lagrange form A.13,
``M p̈ + c + ∇V = τ_aero + τ_drive``, so that Appendix A can be checked from Python.
Units: mg·mm², mN·mm, rad, rad/ms.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _core
from ._errors import finite_reals, invalid, whole
from .spec import Configuration, Simulation, Wing

__all__ = ["WingTerms", "wing_terms"]


@dataclass(frozen=True)
class WingTerms:
    """The terms of :func:`wing_terms` (numpy arrays; units mg·mm², mN·mm, µJ)."""

    mass: np.ndarray
    coriolis: np.ndarray
    spring_gradient: np.ndarray
    aero: np.ndarray
    j6: np.ndarray
    omega: np.ndarray
    jdot_pdot: np.ndarray
    rotation: np.ndarray
    theta_w: float
    kinetic: float
    potential: float


def _vec3(x: Any, name: str) -> list[float]:
    a = finite_reals(name, x)
    if a.shape != (3,):
        raise invalid(name, f"shape {a.shape}", "3 values (phi, theta, psi)")
    return [float(v) for v in a]


def wing_terms(wing: Wing | Simulation, p: Any, p_dot: Any, *, index: int = 0) -> WingTerms:
    """``M``, ``c``, ``∇V``, ``J6`` (and ``ω = J6 ṗ``, ``J̇6 ṗ``, the aerodynamic generalised
    torque, energies) of ``wing`` at ``p = (φ, θ, ψ)`` (rad) and ``ṗ`` (rad/ms).

    ``wing`` is a :class:`paritysim.Wing`, or a :class:`paritysim.Simulation` whose wing
    ``index`` is used. Always the general Appendix A terms (the Rust ``Wing::terms``).

    Raises
    ------
    InvalidParameterError
        For a bad wing, index or non-finite ``p``/``p_dot`` (the message names the field).
    OutOfDomainError, SingularError
        Outside the shoulder's joint limit or at a singular pose.
    """
    if not isinstance(wing, Simulation | Wing):
        raise invalid("wing", type(wing).__name__, "a paritysim.Wing or a paritysim.Simulation")
    spec = wing if isinstance(wing, Simulation) else Simulation(wings=(wing,), configuration=Configuration(name=None))
    p3, v3 = _vec3(p, "p"), _vec3(p_dot, "p_dot")
    raw = _core.dynamics_wing_terms(spec.to_json(), whole("index", index, 0, len(spec.wings) - 1), p3, v3)
    bad = [k for k, v in raw.items() if not np.isfinite(np.asarray(v, dtype=float)).all()]
    if bad:
        # Huge finite rates overflow the quadratic terms (issue 34): name the input.
        name, values = ("p_dot", v3) if max(map(abs, v3)) > 0 else ("p", p3)
        i = max(range(3), key=lambda k: abs(values[k]))
        raise invalid(f"{name}[{i}]", values[i], f"small enough that the terms ({', '.join(bad)}) are finite (they overflow here)")
    return WingTerms(**raw)
