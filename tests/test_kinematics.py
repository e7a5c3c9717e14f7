"""Python-level kinematics: agreement with Rust, physics properties and typed errors."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import paritysim as ps
from paritysim import kinematics as kin

CONFIGS = [(np.pi / 2, 0.0), (np.pi / 2, np.pi / 4), (2 * np.pi / 3, np.pi / 3)]


def rx(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot(axis: np.ndarray, a: float) -> np.ndarray:
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * k @ k


@pytest.mark.parametrize(("alpha2", "alpha3"), CONFIGS)
def test_vectorised_map_matches_single_pose_and_closes_the_loop(alpha2: float, alpha3: float) -> None:
    rng = np.random.default_rng(1)
    phi, theta = rng.uniform(-1.3, 1.3, (2, 500))
    out = kin.shoulder_map(alpha2, alpha3, phi, theta)
    s2 = np.array([np.sin(alpha2), 0, np.cos(alpha2)])
    s3 = np.array([np.sin(alpha3), 0, np.cos(alpha3)])
    assert out["reachable"].any()
    for i in np.flatnonzero(out["reachable"])[:100]:
        pose = kin.shoulder_pose(alpha2, alpha3, phi[i], theta[i], 0.0)
        g = pose["joint_angles"]
        assert g[4] == out["gamma5"][i] and g[1] == out["gamma2"][i]
        # eq. 2.8, evaluated independently in numpy
        lhs = rx(phi[i]) @ ry(g[4]) @ s3
        rhs = ry(theta[i]) @ rot(s2, g[1]) @ s3
        np.testing.assert_allclose(lhs, rhs, atol=1e-12)
    # unreachable entries are masked, never silently NaN
    assert np.isnan(out["theta_w"][~out["reachable"]]).all()
    assert np.isfinite(out["theta_w"][out["reachable"]]).all()


def test_joint_limit_eq_2_10_matches_the_mask() -> None:
    a2, a3 = np.pi / 2, np.pi / 4
    phi, theta = np.meshgrid(np.linspace(-1.5, 1.5, 61), np.linspace(-1.5, 1.5, 61))
    out = kin.shoulder_map(a2, a3, phi, theta)
    ratio = np.cos(theta + a2) * np.sin(phi) / (np.cos(a2) * np.sin(a3) - np.sin(a2) * np.cos(a3))
    np.testing.assert_array_equal(out["reachable"], np.abs(ratio) <= 1)
    assert out["theta_w"].shape == phi.shape


def test_partials_match_numpy_finite_differences() -> None:
    a2, a3, phi, theta = 2 * np.pi / 3, np.pi / 3, 0.4, -0.3
    p = kin.shoulder_partials(a2, a3, phi, theta)
    h = 1e-6
    f = lambda dp, dt: kin.shoulder_map(a2, a3, phi + dp, theta + dt)["gamma5"][()]  # noqa: E731
    fd = [(f(h, 0) - f(-h, 0)) / (2 * h), (f(0, h) - f(0, -h)) / (2 * h)]
    np.testing.assert_allclose(p["gamma5_grad"], fd, rtol=1e-6)
    assert p["j6"].shape == (3, 3) and p["gamma2_hessian"].shape == (2, 2)


def test_drivetrain_python_matches_eq_2_15_linearisation() -> None:
    linkage = ps.Drivetrain.linkage_differential()
    linear = ps.Drivetrain.linear_differential(transmission_ratio=1 / 0.4, arm_length_mm=2.5)
    a = kin.drivetrain_map(linkage, 0.0, 0.0)["jacobian"]
    b = kin.drivetrain_map(linear, 0.0, 0.0)["jacobian"]
    np.testing.assert_allclose(a, b, atol=1e-12)
    hmf = ps.Drivetrain.hmf_four_bar()
    out = kin.drivetrain_map(hmf, [-0.2, 0.2])
    assert abs(np.degrees(out["stroke_left"][0] - out["stroke_left"][1]) - 60.0) < 1.0
    np.testing.assert_array_equal(out["stroke_left"], out["stroke_right"])


def test_biased_pivot_scales_the_differential_mode() -> None:
    for ratio in (0.5, 2.0):
        d = ps.Drivetrain.linkage_differential(arm_ratio=ratio)
        j = kin.drivetrain_map(d, 0.0, 0.0)["jacobian"]
        assert j[0, 1] / -j[1, 1] == pytest.approx(ratio, rel=1e-12)


def test_drivetrain_pickles_and_reprs() -> None:
    import pickle

    d = ps.Drivetrain.linkage_differential(crank_mm=0.35, arm_ratio=0.5)
    assert pickle.loads(pickle.dumps(d)) == d
    assert "linkage_differential" in repr(d) and d.dof == 2


@pytest.mark.parametrize(
    ("call", "exc", "field"),
    [
        (lambda: kin.shoulder_map(4.0, 0.0, [0.0], [0.0]), ps.InvalidParameterError, "alpha2"),
        (lambda: kin.shoulder_map(1.0, 1.2, [0.0], [0.0]), ps.InvalidParameterError, "alpha3"),
        (lambda: kin.shoulder_map(1.0, 0.2, [np.nan], [0.0]), ps.InvalidParameterError, "phi[0]"),
        (lambda: kin.shoulder_pose(np.pi / 2, np.pi / 4, 1.4, 1.2), ps.OutOfDomainError, "phi"),
        (lambda: ps.Drivetrain.hmf_four_bar(crank_mm=-1.0), ps.InvalidParameterError, "drivetrain.crank_mm"),
        (lambda: ps.Drivetrain.linkage_differential(arm_ratio=0.0), ps.InvalidParameterError, "drivetrain.arm_ratio"),
        (lambda: kin.drivetrain_map(ps.Drivetrain.hmf_four_bar(), [0.0, 5.0]), ps.OutOfDomainError, "q1[1]"),
        (lambda: ps.Drivetrain.hmf_four_bar().evaluate(np.zeros(2), np.zeros(3)), ps.ShapeError, None),
    ],
)
def test_bad_input_raises_typed_errors(call, exc, field) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(exc) as info:
        call()
    assert isinstance(info.value, ps.ParitysimError)
    assert info.value.field == field
    if field is not None:
        assert field.split("[")[0] in str(info.value) and "must be" in str(info.value)


def test_exception_tree_mirrors_the_rust_enum() -> None:
    assert issubclass(ps.InvalidParameterError, ValueError)
    assert issubclass(ps.SingularError, ArithmeticError)
    assert issubclass(ps.IntegrationError, RuntimeError)
    for cls in (ps.OutOfDomainError, ps.GeometryError, ps.ShapeError, ps.ConstraintError, ps.CancelledError):
        assert issubclass(cls, ps.ParitysimError)


@settings(max_examples=200, deadline=None)
@given(
    alpha2=st.floats(allow_nan=True, allow_infinity=True, width=64),
    alpha3=st.floats(allow_nan=True, allow_infinity=True, width=64),
    phi=st.floats(-10, 10) | st.just(float("nan")),
    theta=st.floats(-10, 10),
)
def test_random_inputs_never_panic_or_leak_nan(alpha2: float, alpha3: float, phi: float, theta: float) -> None:
    try:
        pose = kin.shoulder_pose(alpha2, alpha3, phi, theta, 0.0)
    except ps.ParitysimError:
        return
    assert np.isfinite(pose["wing_angles"]).all()
    assert np.isfinite(pose["link_rotations"]).all()


def test_fig2_9_grid_stays_within_its_limit() -> None:
    # np.arange overshot: step 7 reached 92 deg, step 200 reached 110 deg.
    for kwargs in ({"step_deg": 7.0}, {"step_deg": 200.0}, {"step_deg": 0.7, "limit_deg": 10.0}):
        df = ps.trials.fig2_9(**kwargs)
        limit = kwargs.get("limit_deg", 90.0)
        assert df["phi_deg"].min() == -limit and df["phi_deg"].max() <= limit
        assert df["theta_deg"].max() <= limit
    assert ps.trials.fig2_9(step_deg=5.0)["phi_deg"].n_unique() == 37  # -90..90 by 5, both ends
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.trials.fig2_9(step_deg="1")  # type: ignore[arg-type]
    assert info.value.field == "step_deg"
