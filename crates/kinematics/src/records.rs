//! Plain serde records of the kinematics results (what the Python bindings hand over through
//! one generic converter). Matrices are row-major nested arrays; a masked value is `None`.

use nalgebra::{Matrix2, Matrix3};
use serde::Serialize;

use crate::drivetrain::ROD_CRANK;
use crate::{Drivetrain, Error, Result, SphericalShoulder};

fn m2(m: &Matrix2<f64>) -> [[f64; 2]; 2] {
    [[m[(0, 0)], m[(0, 1)]], [m[(1, 0)], m[(1, 1)]]]
}

fn m3(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]))
}

/// The closed-form shoulder map over paired `(φ, θ)`: the dependent angles, None where
/// `reachable` is false (outside the joint limit of eq. 2.10, or a singular pose).
#[derive(Clone, Debug, Default, Serialize)]
pub struct ShoulderMap {
    /// γ2, rad.
    pub gamma2: Vec<Option<f64>>,
    /// γ3, rad.
    pub gamma3: Vec<Option<f64>>,
    /// θ_w (= γ5), rad.
    pub theta_w: Vec<Option<f64>>,
    /// γ5, rad.
    pub gamma5: Vec<Option<f64>>,
    /// Whether the pose is reachable.
    pub reachable: Vec<bool>,
}

impl ShoulderMap {
    /// [`ShoulderMap::of`] after checking the arrays pair up and are finite.
    ///
    /// # Errors
    /// `Error::Shape` for unequal lengths, `Error::InvalidParameter` naming the first
    /// non-finite element.
    pub fn checked(sh: &SphericalShoulder, phi: &[f64], theta: &[f64]) -> Result<Self> {
        paritysim_error::check_same_len(("phi", phi.len()), ("theta", theta.len()))?;
        paritysim_error::check_all_finite("phi", phi)?;
        paritysim_error::check_all_finite("theta", theta)?;
        Ok(Self::of(sh, phi, theta))
    }

    /// The map of `sh` over the pairs `phi[i]`, `theta[i]` (equal lengths).
    pub fn of(sh: &SphericalShoulder, phi: &[f64], theta: &[f64]) -> Self {
        let mut m = Self::default();
        for (&p, &t) in phi.iter().zip(theta) {
            let angles = sh.dependent_angles(p, t).ok();
            m.gamma2.push(angles.map(|a| a.0));
            m.gamma3.push(angles.map(|a| a.1));
            m.theta_w.push(angles.map(|a| a.2));
            m.gamma5.push(angles.map(|a| a.2));
            m.reachable.push(angles.is_some());
        }
        m
    }
}

/// One shoulder pose.
#[derive(Clone, Debug, Serialize)]
pub struct PoseRecord {
    /// γ1..γ6, rad.
    pub joint_angles: [f64; 6],
    /// `R_i^1` of links 1..6, (6, 3, 3).
    pub link_rotations: [[[f64; 3]; 3]; 6],
    /// `(φ_w, θ_w, ψ_w)`, rad.
    pub wing_angles: [f64; 3],
}

impl PoseRecord {
    /// The pose of `sh` at `(phi, theta, psi)`.
    ///
    /// # Errors
    /// As [`SphericalShoulder::pose`].
    pub fn of(sh: &SphericalShoulder, phi: f64, theta: f64, psi: f64) -> Result<Self> {
        let pose = sh
            .pose(phi, theta, psi)
            .map_err(|e| sh.attribute_joint_limit(e, phi, theta))?;
        let w = pose.wing_angles;
        Ok(Self {
            joint_angles: pose.joint_angles,
            link_rotations: std::array::from_fn(|k| m3(&pose.link_rotations[k])),
            wing_angles: [w[0], w[1], w[2]],
        })
    }
}

/// Partials of γ2, γ3, γ5 with respect to `(φ, θ)` and the Jacobian J6 (A.9).
#[derive(Clone, Debug, Serialize)]
pub struct PartialsRecord {
    /// ∇γ2.
    pub gamma2_grad: [f64; 2],
    /// Hessian of γ2.
    pub gamma2_hessian: [[f64; 2]; 2],
    /// ∇γ3.
    pub gamma3_grad: [f64; 2],
    /// Hessian of γ3.
    pub gamma3_hessian: [[f64; 2]; 2],
    /// ∇γ5.
    pub gamma5_grad: [f64; 2],
    /// Hessian of γ5.
    pub gamma5_hessian: [[f64; 2]; 2],
    /// J6, 3×3.
    pub j6: [[f64; 3]; 3],
}

impl PartialsRecord {
    /// The partials of `sh` at `(phi, theta, psi)`.
    ///
    /// # Errors
    /// As [`SphericalShoulder::pose`] and [`SphericalShoulder::partials`].
    pub fn of(sh: &SphericalShoulder, phi: f64, theta: f64, psi: f64) -> Result<Self> {
        let pose = sh
            .pose(phi, theta, psi)
            .map_err(|e| sh.attribute_joint_limit(e, phi, theta))?;
        let p = sh.partials(phi, theta)?;
        let g = |v: nalgebra::Vector2<f64>| [v[0], v[1]];
        Ok(Self {
            gamma2_grad: g(p.gamma2),
            gamma2_hessian: m2(&p.gamma2_hessian),
            gamma3_grad: g(p.gamma3),
            gamma3_hessian: m2(&p.gamma3_hessian),
            gamma5_grad: g(p.gamma5),
            gamma5_hessian: m2(&p.gamma5_hessian),
            j6: m3(&sh.jacobian(&pose, &p)),
        })
    }
}

/// A drivetrain over paired `(q1, q2)`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct DrivetrainMap {
    /// φL, rad.
    pub stroke_left: Vec<f64>,
    /// φR, rad.
    pub stroke_right: Vec<f64>,
    /// `J[k][i] = ∂φ_k/∂q_i`, (n, 2, 2).
    pub jacobian: Vec<[[f64; 2]; 2]>,
    /// `H[k][i][j] = ∂²φ_k/∂q_i∂q_j`, (n, 2, 2, 2).
    pub hessian: Vec<[[[f64; 2]; 2]; 2]>,
}

impl DrivetrainMap {
    /// `d` at each pair `q1[i]` (mm), `q2[i]` (rad).
    ///
    /// # Errors
    /// `Error::Shape` for unequal lengths; as [`Drivetrain::evaluate`], naming the first
    /// unreachable index.
    pub fn of(d: &Drivetrain, q1: &[f64], q2: &[f64]) -> Result<Self> {
        paritysim_error::check_same_len(("q1", q1.len()), ("q2", q2.len()))?;
        let mut m = Self::default();
        for (i, (&a, &b)) in q1.iter().zip(q2).enumerate() {
            let e = d
                .evaluate(a, b)
                .map_err(|e| attribute_reach(d, e, a, b).at_index(i, None))?;
            m.stroke_left.push(e.stroke[0]);
            m.stroke_right.push(e.stroke[1]);
            m.jacobian.push(m2(&e.jacobian));
            m.hessian.push([m2(&e.hessian[0]), m2(&e.hessian[1])]);
        }
        Ok(m)
    }
}

/// Attributes a rod-crank that cannot reach the pose `(q1, q2)` to `q1` with the lift the
/// linkage allows ([`crate::RodCrank::reach`]); other errors are returned unchanged.
fn attribute_reach(d: &Drivetrain, err: Error, q1: f64, q2: f64) -> Error {
    match (d.rod_crank(), &err) {
        (Some(side), Error::OutOfDomain { what, .. }) if what == ROD_CRANK => {
            let allowed = format!(
                "a rod-top lift within the rod-crank's reach at q2 = {q2} rad: at most {:.6} mm \
                 along the rod (sqrt(L2^2 + 2 L2 L3) - L2, crank {} mm, rod {} mm)",
                side.reach(),
                side.crank(),
                side.rod()
            );
            err.attributed("q1", q1, allowed)
        }
        _ => err,
    }
}
