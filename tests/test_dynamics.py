"""Appendix A from Python: ``ps.dynamics.wing_terms`` (Rust ``Wing::terms``) against finite
differences of the energies, and the θ̈, ψ̈ trajectory columns against differentiated rates.

Independent formulation: the kinetic energy is rebuilt from the wing's rotation matrix alone
(``ω̂ = Rᵀ Ṙ`` by central differences along ṗ, ``T = ½ ωᵀ I ω``), so neither ``J6`` nor the
shoulder partials enter the reference. A (120°, 60°) shoulder is used: at α2 = 90° the printed
joint-2 axis would coincide with the right one (docs/errata.md#2).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import paritysim as ps

INERTIA = np.array([[49.0, 0.0, 4.2], [0.0, 50.5, 0.0], [4.2, 0.0, 1.56]])
SPRINGS = tuple(ps.Spring(stiffness=k, cubic=k3, rest_angle=g0) for k, k3, g0 in ((0.7, 0.2, 0.1), (1.3, 0.0, -0.2), (0.4, 0.5, 0.3), (2.0, 0.0, 0.05), (0.9, 0.1, -0.1), (2.5, 0.3, 0.0)))
WING = ps.Wing(
    inertia=tuple(tuple(r) for r in INERTIA),
    shoulder=ps.Shoulder(alpha2=math.radians(120.0), alpha3=math.radians(60.0)),
    springs=SPRINGS,
    tunable_hinge=ps.TunableHinge(1.0, 0.3, 2.0),
)
STATES = [((0.3, 0.2, -0.4), (0.5, -0.3, 1.2)), ((-0.6, -0.1, 0.7), (-0.2, 0.4, -0.9)), ((0.05, 0.35, 0.1), (1.0, 0.2, 0.3))]


def rotation(p: np.ndarray) -> np.ndarray:
    return ps.dynamics.wing_terms(WING, p, np.zeros(3)).rotation


def kinetic_from_rotations(p: np.ndarray, p_dot: np.ndarray, h: float = 1e-5) -> float:
    """½ ωᵀ I ω with ω̂ = Rᵀ Ṙ, Ṙ by a central difference of R along ṗ (fourth order)."""
    r_dot = (8 * (rotation(p + h * p_dot) - rotation(p - h * p_dot)) - (rotation(p + 2 * h * p_dot) - rotation(p - 2 * h * p_dot))) / (12 * h)
    skew = rotation(p).T @ r_dot
    omega = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
    return 0.5 * omega @ INERTIA @ omega


@pytest.mark.parametrize(("p", "p_dot"), STATES)
def test_mass_matrix_is_the_hessian_of_the_kinetic_energy(p: tuple[float, ...], p_dot: tuple[float, ...]) -> None:
    """M_ij = ∂²T/∂ṗ_i∂ṗ_j (A.36), with T from rotation matrices only. T is quadratic in ṗ, so
    the polarisation identity M_ij = T(e_i + e_j) − T(e_i) − T(e_j) is exact."""
    p = np.asarray(p)
    terms = ps.dynamics.wing_terms(WING, p, p_dot)
    eye = np.eye(3)
    t = {i: kinetic_from_rotations(p, eye[i]) for i in range(3)}
    m_ref = np.array([[2 * t[i] if i == j else kinetic_from_rotations(p, eye[i] + eye[j]) - t[i] - t[j] for j in range(3)] for i in range(3)])
    np.testing.assert_allclose(terms.mass, m_ref, rtol=1e-8, atol=1e-8 * np.abs(m_ref).max())
    np.testing.assert_allclose(terms.mass, terms.mass.T, rtol=0, atol=1e-12 * np.abs(m_ref).max())
    assert np.all(np.linalg.eigvalsh(terms.mass) > 0)
    assert terms.kinetic == pytest.approx(kinetic_from_rotations(p, np.asarray(p_dot)), rel=1e-8)


@pytest.mark.parametrize(("p", "p_dot"), STATES)
def test_spring_gradient_is_the_gradient_of_the_potential(p: tuple[float, ...], p_dot: tuple[float, ...]) -> None:
    """∇V (A.6, plus the tunable hinge of §2.5.1) against central differences of V(p)."""
    p = np.asarray(p)
    h = 1e-6
    potential = lambda q: ps.dynamics.wing_terms(WING, q, np.zeros(3)).potential  # noqa: E731
    grad = np.array([(potential(p + h * e) - potential(p - h * e)) / (2 * h) for e in np.eye(3)])
    terms = ps.dynamics.wing_terms(WING, p, p_dot)
    np.testing.assert_allclose(terms.spring_gradient, grad, rtol=1e-6, atol=1e-8)


@pytest.mark.parametrize(("p", "p_dot"), STATES)
def test_coriolis_follows_from_the_lagrangian(p: tuple[float, ...], p_dot: tuple[float, ...]) -> None:
    """Euler-Lagrange: d/dt ∂T/∂ṗ − ∂T/∂p = M p̈ + c, so c = Ṁ ṗ − ∂T/∂p with Ṁ = Σ_k ∂M/∂p_k ṗ_k
    and ∂T/∂p_k = ½ ṗᵀ ∂M/∂p_k ṗ (docs/errata.md#1: the printed A.37-A.38 are not used)."""
    p, v = np.asarray(p), np.asarray(p_dot)
    h = 1e-5
    mass = lambda q: ps.dynamics.wing_terms(WING, q, np.zeros(3)).mass  # noqa: E731
    dm = [(mass(p + h * e) - mass(p - h * e)) / (2 * h) for e in np.eye(3)]
    m_dot = sum(dm[k] * v[k] for k in range(3))
    dt_dp = np.array([0.5 * v @ dm[k] @ v for k in range(3)])
    c_ref = m_dot @ v - dt_dp
    terms = ps.dynamics.wing_terms(WING, p, v)
    np.testing.assert_allclose(terms.coriolis, c_ref, rtol=1e-6, atol=1e-8 * np.abs(c_ref).max())
    # ω = J6 ṗ (A.9-A.10) and c is quadratic in ṗ
    np.testing.assert_allclose(terms.omega, terms.j6 @ v, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(ps.dynamics.wing_terms(WING, p, 2 * v).coriolis, 4 * terms.coriolis, rtol=1e-12, atol=1e-14)


def test_wing_terms_reject_bad_input() -> None:
    with pytest.raises(ps.InvalidParameterError) as e:
        ps.dynamics.wing_terms(WING, (0.0, float("nan"), 0.0), (0.0, 0.0, 0.0))
    assert e.value.field == "p[1]"
    with pytest.raises(ps.InvalidParameterError) as e:
        ps.dynamics.wing_terms(WING, (0.0, 0.0), (0.0, 0.0, 0.0))
    assert e.value.field == "p"
    spec = ps.Simulation(wings=(WING,), configuration=ps.Configuration(name=None))
    with pytest.raises(ps.InvalidParameterError) as e:
        ps.dynamics.wing_terms(spec, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), index=1)
    assert e.value.field == "index"  # the argument that picks the wing
    with pytest.raises(ps.OutOfDomainError):
        ps.dynamics.wing_terms(WING, (1.5, 1.5, 0.0), (0.0, 0.0, 0.0))


def test_theta_and_psi_accelerations_integrate_to_the_rates() -> None:
    """The trajectory's θ̈, ψ̈ (like φ̈) are the model's p̈: their running integral (trapezoid)
    must reproduce the recorded rates (an integral, not a difference: the aerodynamic
    coefficients jump at α = 90°, docs/errata.md#P2, so p̈ has kinks). A free-deviation Lift
    PARITY wing so θ moves."""
    from scipy.integrate import cumulative_trapezoid

    from paritysim.trials import section_2_5 as s25

    spec = s25.device("lift_parity", "1-Cut", hinge_k2=20.0, hinge_stiffness=2.5, max_cycles=20)
    df = ps.simulate(spec, max_cycles=20, samples_per_cycle=2000, rtol=1e-11, atol=1e-13).trajectory
    t = df["time_ms"].to_numpy()
    for wing in ("left", "right"):
        for angle in ("phi", "theta", "psi"):
            rate = df[f"{wing}_{angle}_dot"].to_numpy()
            accel = df[f"{wing}_{angle}_ddot"].to_numpy()
            scale = np.abs(rate).max()
            assert scale > 1e-3, (wing, angle)
            np.testing.assert_allclose(cumulative_trapezoid(accel, t, initial=0.0), rate - rate[0], atol=2e-4 * scale, err_msg=f"{wing}_{angle}")


def test_recorded_accelerations_satisfy_the_euler_lagrange_equations() -> None:
    """A.13 at every sample of a free (unconstrained, undriven, vacuum) wing: the trajectory's
    (φ̈, θ̈, ψ̈) and ``wing_terms`` at the recorded (p, ṗ) give M p̈ + c + ∇V = 0."""
    spec = ps.Simulation(
        wings=(WING,),
        configuration=ps.Configuration(name=None),
        options=ps.Options(duration_ms=3.0, initial_p=(0.3, 0.2, -0.4), initial_p_dot=(0.1, -0.06, 0.24), samples_per_cycle=100, rtol=1e-11, atol=1e-13),
    )
    df = ps.simulate(spec).trajectory
    assert np.ptp(df["wing_theta"].to_numpy()) > 0.1 and np.abs(df["wing_theta_ddot"].to_numpy()).max() > 0.01
    angles = ("phi", "theta", "psi")
    for row in df.iter_rows(named=True):
        p = np.array([row[f"wing_{a}"] for a in angles])
        v = np.array([row[f"wing_{a}_dot"] for a in angles])
        acc = np.array([row[f"wing_{a}_ddot"] for a in angles])
        t = ps.dynamics.wing_terms(WING, p, v)
        residual = t.mass @ acc + t.coriolis + t.spring_gradient - t.aero
        assert np.abs(residual).max() <= 1e-12 * np.abs(t.spring_gradient).max(), (row["time_ms"], residual)
