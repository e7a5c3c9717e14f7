//! The equations of [`Formulation::DrivetrainCoordinates`]: a stroke-only device (fixed wings
//! on a stroke axis) integrated in the drivetrain coordinates `q` directly, with no inverse
//! kinematics or shoulder evaluations.

use nalgebra::{Matrix2, Vector2};
use paritysim_aero::Branch;
use paritysim_error::Result;

use super::drive::DriveSprings;
use super::drivetrain_inverse::singular_drive;
use super::equations::Equations;
use super::linear_map::{self, LinearMapTerms};
use super::{Device, DeviceSpec};
use crate::integrate::State;

/// Inertias about the stroke axis of a stroke-only device (see
/// [`Formulation::DrivetrainCoordinates`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StrokeOnly {
    pub(super) stroke_inertia: [f64; 2],
    /// The linear map's constants (None for the linkages): its equations are
    /// [`linear_map::accelerations`], with no drivetrain evaluation.
    pub(super) linear: Option<LinearMapTerms<f64>>,
}

/// Why a device cannot use drivetrain coordinates (None when it can).
pub(super) fn stroke_only(
    spec: &DeviceSpec,
    drive: &DriveSprings<f64>,
) -> std::result::Result<StrokeOnly, String> {
    if spec.wings.len() != 2 {
        return Err("it needs two wings".into());
    }
    let Some(tr) = &spec.transmission else {
        return Err("it needs a drivetrain".into());
    };
    let c = &spec.constraints;
    let n = c.null_basis();
    for k in 0..c.n_free() {
        for i in [1, 2, 4, 5] {
            if n[(i, k)].abs() > 1e-12 {
                return Err(
                    "C must fix theta and psi of both wings (a *_fixed configuration)".into(),
                );
            }
        }
    }
    if [1, 2, 4, 5]
        .iter()
        .any(|&i| c.particular()[i].abs() > 1e-15)
    {
        return Err("theta and psi must be held at zero".into());
    }
    if c.n_free() != tr.kinematics.dof() {
        return Err(format!(
            "C leaves {} stroke coordinates but the drivetrain has {} DOF",
            c.n_free(),
            tr.kinematics.dof()
        ));
    }
    let mut stroke_inertia = [0.0; 2];
    for (k, wing) in spec.wings.iter().enumerate() {
        if !wing.has_closed_form_stroke_plane() {
            return Err("the shoulders must have alpha2 = 90 deg (theta_w = 0 at theta = 0) and no springs on joints 2, 3 and 5".into());
        }
        stroke_inertia[k] = wing.inertia()[(0, 0)];
    }
    Ok(StrokeOnly {
        stroke_inertia,
        linear: LinearMapTerms::of(spec, drive),
    })
}

/// One evaluation of the drivetrain-coordinate equations.
pub(super) struct DrivetrainStep {
    pub(super) eval: paritysim_kinematics::DrivetrainEval,
    pub(super) q: Vector2<f64>,
    pub(super) q_dot: Vector2<f64>,
    pub(super) q_ddot: Vector2<f64>,
    pub(super) force: f64,
    pub(super) load: Vector2<f64>,
    pub(super) potential: f64,
    pub(super) aero_power: f64,
}

/// Generalised torques on `(φL, φR)` from the drivetrain load: `τ_φ = J⁻ᵀ Q`; a 1-DOF drivetrain
/// acts through φL only (C ties φR to it).
pub(super) fn stroke_torque(
    dof: usize,
    jac: &Matrix2<f64>,
    q: &Vector2<f64>,
    load: &Vector2<f64>,
) -> Result<Vector2<f64>> {
    if dof == 1 {
        return Ok(Vector2::new(load.x / jac[(0, 0)], 0.0));
    }
    jac.transpose()
        .lu()
        .solve(load)
        .ok_or_else(|| singular_drive(q))
}

impl Device {
    /// The equations of [`Formulation::DrivetrainCoordinates`]:
    /// `M_q q̈ = Σ_k J_kᵀ (τ_k − I_k h_k) + Q` with `M_q = Σ_k I_k J_kᵀ J_k`.
    // Always inlined: it sits in the right-hand side and returns a large struct.
    #[inline(always)]
    pub(super) fn drivetrain_step(
        &self,
        fast: &StrokeOnly,
        t: f64,
        y: &State,
    ) -> Result<DrivetrainStep> {
        let (q, q_dot) = self.drive_coordinates(y);
        let eval = self.drivetrain().evaluate(q.x, q.y)?;
        let phi_dot = eval.jacobian * q_dot;
        let h = eval.velocity_product(&q_dot);
        let (force, load, potential) = self.drive_load(t, &q, &q_dot);
        // M_q = Σ_k I_k J_kᵀ J_k and Q = load + Σ_k J_kᵀ τ_k in scalars (J_k = row k of J):
        // the nalgebra 2×2 temporaries cost more than the arithmetic here.
        let j = &eval.jacobian;
        // The actuator's effective mass on q1 (and on q2 of a dual drive; 0 by default).
        let [mass1, mass2] = self.drive.masses();
        let (mut m00, mut m01, mut m11) = (mass1, 0.0, mass2);
        let (mut g0, mut g1) = (load.x, load.y);
        let mut aero_power = 0.0;
        for k in 0..2 {
            let wing = &self.spec.wings[k];
            let (a, b) = (j[(k, 0)], j[(k, 1)]);
            let inertia = fast.stroke_inertia[k];
            let tau_aero = wing.aero().stroke_torque(phi_dot[k]);
            let tau = tau_aero - wing.springs()[0].torque(eval.stroke[k]) - inertia * h[k];
            m00 += inertia * a * a;
            m01 += inertia * a * b;
            m11 += inertia * b * b;
            g0 += a * tau;
            g1 += b * tau;
            aero_power += tau_aero * phi_dot[k];
        }
        let q_ddot = if self.n_dof == 2 {
            // Cramer's rule on the 2×2 symmetric positive mass matrix.
            let det = m00 * m11 - m01 * m01;
            if det == 0.0 || !det.is_finite() {
                return Err(singular_drive(&q));
            }
            Vector2::new((m11 * g0 - m01 * g1) / det, (m00 * g1 - m01 * g0) / det)
        } else {
            Vector2::new(g0 / m00, 0.0)
        };
        Ok(DrivetrainStep {
            eval,
            q,
            q_dot,
            q_ddot,
            force,
            load,
            potential,
            aero_power,
        })
    }

    /// Right-hand side in drivetrain coordinates (see [`Formulation::DrivetrainCoordinates`]).
    pub(super) fn rhs_drivetrain(
        &self,
        fast: &StrokeOnly,
        t: f64,
        y: &State,
        dydt: &mut State,
    ) -> Result<()> {
        let (q_dot, q_ddot, force, aero_power) = match &fast.linear {
            Some(map) => self.linear_map_step(map, t, y)?,
            None => {
                let step = self.drivetrain_step(fast, t, y)?;
                (step.q_dot, step.q_ddot, step.force, step.aero_power)
            }
        };
        *dydt = State::default();
        for i in 0..self.n_dof {
            dydt.coords[i] = q_dot[i];
            dydt.rates[i] = q_ddot[i];
        }
        dydt.work_actuator = self.actuator_power(t, force, &q_dot);
        dydt.work_aero = aero_power;
        Ok(())
    }

    /// [`Self::drivetrain_step`] for the linear map (eq. 2.15): `φ = J q`, `φ̇ = J q̇`, no
    /// velocity product, the constant `M_q` ([`linear_map::accelerations`], the lanes' code),
    /// or a polynomial transmission on it: `(q̇, q̈, F (the left side's on a dual drive),
    /// aerodynamic power)`.
    #[inline(always)]
    pub(super) fn linear_map_step(
        &self,
        terms: &LinearMapTerms<f64>,
        t: f64,
        y: &State,
    ) -> Result<(Vector2<f64>, Vector2<f64>, f64, f64)> {
        let (q, q_dot) = self.drive_coordinates(y);
        if !(q.x.abs() <= paritysim_error::plausible::OFFSET_MM
            && q.y.abs() <= paritysim_error::plausible::ANGLE_RAD)
        {
            // The drivetrain names the implausible coordinate.
            self.drivetrain().evaluate(q.x, q.y)?;
        }
        if terms.polynomial {
            // A softening polynomial folds over: the drivetrain names where.
            self.drivetrain().evaluate(q.x, q.y)?;
        } else if terms.det == 0.0 || !terms.det.is_finite() {
            return Err(singular_drive(&q));
        }
        let forces = self.drive_forces(t);
        let y = [q.x, q.y, q_dot.x, q_dot.y];
        let wings = &self.spec.wings;
        let (q_ddot, aero_power) = linear_map::accelerations(terms, forces, &y, |k, rate| {
            wings[k].aero().stroke_torque(rate)
        });
        Ok((q_dot, q_ddot.into(), forces[0], aero_power))
    }
}

impl Equations for StrokeOnly {
    #[inline(always)]
    fn rhs(
        &self,
        device: &Device,
        t: f64,
        y: &State,
        _branches: Option<[Branch; 2]>,
        dydt: &mut State,
    ) -> Result<()> {
        device.rhs_drivetrain(self, t, y, dydt)
    }

    fn variational(
        &self,
        device: &Device,
        t: f64,
        y: &State,
        _branches: Option<[Branch; 2]>,
        n: usize,
        rhs: Option<&mut [f64]>,
        phi: &[f64],
        dphi: &mut [f64],
    ) -> Option<Result<()>> {
        let terms = (self.linear.as_ref()).filter(|t| t.analytic && n == 2 && rhs.is_none())?;
        let y = [y.coords[0], y.coords[1], y.rates[0], y.rates[1]];
        linear_map::variational(terms, device.drive_forces(t), &y, phi, dphi);
        Some(Ok(()))
    }
}
