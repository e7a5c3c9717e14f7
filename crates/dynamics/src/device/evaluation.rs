//! What a device evaluates at one state, beyond the right-hand side: the drivetrain state
//! recovered from the stroke angles, the full evaluation (accelerations, per-wing terms), the
//! energy and the dissipated power, the actuator's reflected inertia.

use nalgebra::{Matrix2, Vector2, Vector3};
use paritysim_constraints::Vec6;
use paritysim_error::{Error, Result};

use super::drivetrain_coordinates::stroke_torque;
use super::drivetrain_inverse::{
    NEWTON_MAX, NEWTON_TOL, check_plausible, invert_1dof, invert_2dof, singular_drive,
    unreachable_stroke,
};
use super::{Device, empty_terms};
use crate::integrate::State;
use crate::wing::WingTerms;

/// The drivetrain state recovered from the stroke angles.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct DriveState {
    /// `(q1, q2)` (mm, rad).
    pub q: Vector2<f64>,
    /// `(q̇1, q̇2)`.
    pub q_dot: Vector2<f64>,
    /// Actuator force F(t) (mN).
    pub actuator_force: f64,
    /// The drive load `Q` on `(q1, q2)` (mN, mN·mm): the actuator and the drivetrain springs
    /// (see `device/drive.rs`).
    pub load: Vector2<f64>,
    /// Generalised torques on `(φL, φR)` from the drivetrain (mN·mm).
    pub stroke_torque: Vector2<f64>,
    /// Drivetrain spring energy ½K1q1² + ½K2q2² (µJ).
    pub potential: f64,
}

/// A full evaluation of the model at `(t, p, ṗ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evaluation {
    /// Configuration.
    pub p: Vec6,
    /// Velocities.
    pub p_dot: Vec6,
    /// Accelerations.
    pub p_ddot: Vec6,
    /// Per-wing terms (the second is unused for one wing).
    pub wings: [WingTerms; 2],
    /// Drivetrain state.
    pub drive: DriveState,
}

impl Device {
    /// Drivetrain state at `(t, p, ṗ)`.
    pub fn drive(&self, t: f64, p: &Vec6, p_dot: &Vec6) -> Result<DriveState> {
        let Some(tr) = &self.spec.transmission else {
            return Ok(DriveState::default());
        };
        let dt = &tr.kinematics;
        if dt.dof() == 1 {
            let (q1, slope) = invert_1dof(dt, p[0])?;
            let q = Vector2::new(q1, 0.0);
            let q_dot = Vector2::new(p_dot[0] / slope, 0.0);
            let (force, load, potential) = self.drive_load(t, &q, &q_dot);
            return Ok(DriveState {
                q,
                q_dot,
                actuator_force: force,
                load,
                stroke_torque: stroke_torque(1, &Matrix2::new(slope, 0.0, slope, 0.0), &q, &load)?,
                potential,
            });
        }
        let target = Vector2::new(p[0], p[3]);
        if let Some(jac) = &self.linear_jacobian {
            // The linear map (eq. 2.15): the Newton inverse of `invert_2dof` with the constant
            // Jacobian's one LU factorisation and no drivetrain evaluations (same numbers).
            let lu = jac.lu();
            let mut q = lu
                .solve(&target)
                .ok_or_else(|| singular_drive(&Vector2::zeros()))?;
            let mut converged = false;
            for _ in 0..NEWTON_MAX {
                check_plausible(dt, &q).map_err(|e| unreachable_stroke(e, target.x))?;
                let step = lu
                    .solve(&(jac * q - target))
                    .ok_or_else(|| singular_drive(&q))?;
                q -= step;
                if step.amax() <= NEWTON_TOL * (1.0 + q.amax()) {
                    converged = true;
                    break;
                }
            }
            if !converged {
                return Err(Error::OutOfDomain {
                    what: "drivetrain inverse".into(),
                    detail: format!(
                        "no convergence for strokes ({}, {}) rad",
                        target.x, target.y
                    ),
                });
            }
            check_plausible(dt, &q)?;
            let q_dot = lu
                .solve(&Vector2::new(p_dot[0], p_dot[3]))
                .ok_or_else(|| singular_drive(&q))?;
            let (force, load, potential) = self.drive_load(t, &q, &q_dot);
            return Ok(DriveState {
                q,
                q_dot,
                actuator_force: force,
                load,
                stroke_torque: stroke_torque(2, jac, &q, &load)?,
                potential,
            });
        }
        let (q, jac) = invert_2dof(dt, &target)?;
        let q_dot = jac
            .lu()
            .solve(&Vector2::new(p_dot[0], p_dot[3]))
            .ok_or_else(|| singular_drive(&q))?;
        let (force, load, potential) = self.drive_load(t, &q, &q_dot);
        Ok(DriveState {
            q,
            q_dot,
            actuator_force: force,
            load,
            stroke_torque: stroke_torque(2, &jac, &q, &load)?,
            potential,
        })
    }

    /// Full evaluation from an integrator state. Drivetrain-coordinate devices use the forward
    /// map and their own equations (no inverse kinematics); others go through [`Self::evaluate`].
    pub fn evaluate_state(&self, t: f64, y: &State) -> Result<Evaluation> {
        let Some(fast) = self.form.stroke_only() else {
            let (p, p_dot) = self.coordinates(y)?;
            return self.evaluate(t, &p, &p_dot);
        };
        let step = self.drivetrain_step(fast, t, y)?;
        let e = &step.eval;
        let phi_dot = e.jacobian * step.q_dot;
        let phi_ddot = e.jacobian * step.q_ddot + e.velocity_product(&step.q_dot);
        let p = Vec6::new(e.stroke.x, 0.0, 0.0, e.stroke.y, 0.0, 0.0);
        let p_dot = Vec6::new(phi_dot.x, 0.0, 0.0, phi_dot.y, 0.0, 0.0);
        let p_ddot = Vec6::new(phi_ddot.x, 0.0, 0.0, phi_ddot.y, 0.0, 0.0);
        let mut wings = [empty_terms(); 2];
        for (k, wing) in self.spec.wings.iter().enumerate() {
            let (pk, vk) = (
                Vector3::new(p[3 * k], 0.0, 0.0),
                Vector3::new(p_dot[3 * k], 0.0, 0.0),
            );
            wings[k] = wing.stroke_plane_terms(&pk, &vk);
        }
        let drive = DriveState {
            q: step.q,
            q_dot: step.q_dot,
            actuator_force: step.force,
            load: step.load,
            stroke_torque: stroke_torque(self.n_dof, &e.jacobian, &step.q, &step.load)?,
            potential: step.potential,
        };
        Ok(Evaluation {
            p,
            p_dot,
            p_ddot,
            wings,
            drive,
        })
    }

    /// Mechanical energy: kinetic + joint springs + drivetrain springs + the actuator mass's
    /// kinetic energy (µJ).
    pub fn energy(&self, e: &Evaluation) -> f64 {
        e.wings
            .iter()
            .take(self.n_wings())
            .map(|w| w.kinetic + w.potential)
            .sum::<f64>()
            + e.drive.potential
            + self.drive.kinetic([e.drive.q_dot.x, e.drive.q_dot.y])
    }

    /// The actuator's effective mass seen on the strokes `(φL, φR)` at the drive state `drive`
    /// and the force its velocity product applies: with `φ̈ = J q̈ + h`, the mass `m` on `q1`
    /// (and `q2` of a dual drive) adds `A = J⁻ᵀ diag(m) J⁻¹` to the mass matrix and `A h` to
    /// the generalised force; `None` without actuator mass. A 1-DOF drivetrain acts through
    /// φL only (`A = m / J²`).
    ///
    /// # Errors
    /// A drivetrain evaluation outside the linkage's domain; a singular drivetrain Jacobian.
    pub(crate) fn actuator_inertia(
        &self,
        drive: &DriveState,
    ) -> Result<Option<(Matrix2<f64>, Vector2<f64>)>> {
        let [m1, m2] = self.drive.masses();
        if m1 == 0.0 {
            return Ok(None);
        }
        let e = self.drivetrain().evaluate(drive.q.x, drive.q.y)?;
        let h = e.velocity_product(&drive.q_dot);
        if self.drivetrain().dof() == 1 {
            let j = e.jacobian[(0, 0)];
            let a = m1 / (j * j);
            return Ok(Some((
                Matrix2::new(a, 0.0, 0.0, 0.0),
                Vector2::new(a * h.x, 0.0),
            )));
        }
        let inverse = e
            .jacobian
            .try_inverse()
            .ok_or_else(|| singular_drive(&drive.q))?;
        let a = inverse.transpose() * Matrix2::new(m1, 0.0, 0.0, m2) * inverse;
        Ok(Some((a, a * h)))
    }
}
