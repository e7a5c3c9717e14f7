//! The coupled body + wing equations of motion (Kane's equations on one set of
//! generalized speeds).
//!
//! Generalized speeds `u = (V, Ω, ẋ)`: `V` the velocity of the body's centre of mass `B`
//! (world frame), `Ω` the body angular velocity (body frame), `ẋ` the wing null-space rates
//! (`p = p₀ + N x`, eq. 3.21 with the constraints `C p = c0` of §3.2.5). Every rigid body `i`
//! (the airframe and each wing) has a velocity Jacobian for its centre of mass `v_i = J_v u`
//! (world) and its angular velocity `ω_i = J_ω u` (own frame), and accelerations
//! `a_i = J_v u̇ + a_i⁰`, `α_i = J_ω u̇ + α_i⁰` with exact velocity-product terms. Then
//!
//! ```text
//! Σ_i [J_vᵀ m_i J_v + J_ωᵀ I_i J_ω] u̇ = Σ_i J_vᵀ (F_i − m_i a_i⁰) + J_ωᵀ (τ_i − I_i α_i⁰ − ω_i × I_i ω_i) + Q
//! ```
//!
//! the Euler-Lagrange equations of the total kinetic energy (so momentum and energy are
//! conserved exactly by the continuous system), with `Q` the joint springs (A.6), the
//! drivetrain `τ_φ = J⁻ᵀ Q_q` of the fixed device (massless, body-mounted: unchanged) and
//! the mechanisms, all acting on `ẋ` only (internal forces).
//!
//! Wing `k` (frame 6, `R = R_6^1`, `w = J6 ṗ`, `G = J6 N_k`; `P` the wing frame-1 to body map,
//! `I` or the sagittal mirror `diag(1, 1, −1)`, and `A = det(P) P` its action on axial
//! vectors; `s` the shoulder relative to `B`, `c` the wing's centre of mass in frame 6,
//! `ρ = s + P R c`, `R_b` body to world):
//!
//! ```text
//! ω⁶ = Rᵀ A Ω + w                      J_ω = [0, Rᵀ A, G]      α⁰ = −w × (Rᵀ A Ω) + J̇6 ṗ
//! v_c = V + R_b (Ω × ρ + P R (w × c))  J_v = [I, −R_b[ρ]×, −R_b P R [c]× G]
//! a⁰ = R_b (Ω × (Ω × ρ) + 2 Ω × ρ̇ + P R (J̇6ṗ × c + w × (w × c))),   ρ̇ = P R (w × c)
//! ```
//!
//! The wing inertia of the spec is about the shoulder; about its centre of mass it is
//! `I − m (|c|² 1 − c cᵀ)`. Body modes lock entries of `(V, Ω)` (a gimbal about `B` is a
//! holonomic constraint on them) by dropping their rows and columns.

use std::ops::AddAssign;

use nalgebra::{Matrix2, Matrix3, SMatrix, SVector, UnitQuaternion, Vector2, Vector3, Vector6};
use paritysim_constraints::{Mat6, Vec6};
use paritysim_dynamics::device::{DeviceSpec, DriveState, Formulation};
use paritysim_dynamics::wing::WingTerms;
use paritysim_dynamics::{Device, State, Wing, WingAero};
use paritysim_error::{Error, Result};

use crate::aero::{Wrench, switching, wrench_and_wing_torque};
use crate::body::{Body, BodyMode};
use crate::mechanisms::{DriveCoordinate, Mechanism};
use paritysim_aero::Branch;
use paritysim_dynamics::integrate::{MAX_SWITCHES, Sides};

/// Length of the flight state array:
/// `[quaternion (w, x, y, z), position (3), x (6), V (3), Ω (3), ẋ (6), work_actuator, work_aero]`.
pub const STATE_LEN: usize = 27;
/// Index of the quaternion.
pub const QUAT: usize = 0;
/// Index of the position of `B` (world, mm).
pub const POS: usize = 4;
/// Index of the wing null-space coordinates.
pub const X: usize = 7;
/// Index of `V` (world, mm/ms).
pub const VEL: usize = 13;
/// Index of `Ω` (body frame, rad/ms).
pub const OMEGA: usize = 16;
/// Index of `ẋ`.
pub const XDOT: usize = 19;
/// Index of the actuator work (µJ).
pub const WORK_ACTUATOR: usize = 25;
/// Index of the aerodynamic work (µJ).
pub const WORK_AERO: usize = 26;

const NU: usize = 12;
type MatU = SMatrix<f64, NU, NU>;
type VecU = SVector<f64, NU>;
type Jac = SMatrix<f64, 3, NU>;

/// Slow inputs held during an integration leg (set points + controller outputs).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Inputs {
    /// Whippletree bias torque (mN·mm).
    pub q2_bias: f64,
    /// Added actuator force (mN).
    pub actuator_offset: f64,
    /// Relative actuator amplitude change.
    pub actuator_gain: f64,
    /// `ln q3` of eq. 5.1: the whippletree holds `τL/τR = q3` ([`crate::control`]).
    pub log_q3: f64,
    /// Dual drivetrain: relative change of each drive's force (left, right).
    pub side_gain: [f64; 2],
    /// Dual drivetrain: added force on each drive (left, right; mN).
    pub side_offset: [f64; 2],
}

impl Inputs {
    /// The sum of two sets of inputs (set points, controllers).
    pub fn plus(&self, other: &Inputs) -> Inputs {
        let add2 = |a: [f64; 2], b: [f64; 2]| [a[0] + b[0], a[1] + b[1]];
        Inputs {
            q2_bias: self.q2_bias + other.q2_bias,
            actuator_offset: self.actuator_offset + other.actuator_offset,
            actuator_gain: self.actuator_gain + other.actuator_gain,
            log_q3: self.log_q3 + other.log_q3,
            side_gain: add2(self.side_gain, other.side_gain),
            side_offset: add2(self.side_offset, other.side_offset),
        }
    }
}

/// The flight model: the device (null-space form, body-mounted drivetrain), the wings'
/// aerodynamics and the body. Immutable, `Send + Sync`.
#[derive(Clone, Debug)]
pub struct FlightModel {
    /// The device as given (its aerodynamics, its formulation): steady states on the clamped
    /// body.
    source: Device,
    device: Device,
    aero: [WingAero; 2],
    body: Body,
    mechanisms: Vec<Mechanism>,
    n_wings: usize,
    n: usize,
    basis: Mat6,
    inertia_cm: [Matrix3<f64>; 2],
    polar: [Matrix3<f64>; 2],
    axial: [Matrix3<f64>; 2],
    shoulder: [Vector3<f64>; 2],
    /// Diagonals of `polar` and `axial` (both are `±1` diagonal matrices).
    polar_sign: [Vector3<f64>; 2],
    axial_sign: [Vector3<f64>; 2],
    active: Vec<usize>,
    /// How the active speeds are solved for.
    plan: SolvePlan,
    /// Wings whose deviation the constraints hold at zero on an α2 = 90° shoulder: closed-form
    /// terms ([`Wing::stroke_plane_terms`], as the device uses them).
    stroke_plane: [bool; 2],
}

/// Everything at one instant (what the samples are built from).
#[derive(Clone, Copy, Debug)]
pub struct FlightEval {
    /// Wing configuration, rates, accelerations.
    pub p: Vec6,
    /// `ṗ`.
    pub p_dot: Vec6,
    /// `p̈`.
    pub p_ddot: Vec6,
    /// Per-wing terms (aero fields: the flight wrench).
    pub wings: [WingTerms; 2],
    /// Drivetrain state (stroke torques include mechanisms and inputs).
    pub drive: DriveState,
    /// Attitude (body to world).
    pub attitude: UnitQuaternion<f64>,
    /// Position of `B` (world, mm).
    pub position: Vector3<f64>,
    /// `V` (world, mm/ms).
    pub velocity: Vector3<f64>,
    /// `Ω` (body, rad/ms).
    pub omega: Vector3<f64>,
    /// `V̇` (world) and `Ω̇` (body).
    pub body_accel: Vector6<f64>,
    /// Per wing: aerodynamic torque about the shoulder (body frame, mN·mm).
    pub aero_torque: [Vector3<f64>; 2],
    /// Per wing: inertial reaction torque about the shoulder (body frame, mN·mm).
    pub inertial_torque: [Vector3<f64>; 2],
    /// Total aerodynamic force on the wings (body frame, mN).
    pub aero_force: Vector3<f64>,
    /// Per wing: aerodynamic force (body frame, mN; the left wing's mirrored back).
    pub wing_aero_force: [Vector3<f64>; 2],
    /// Force the wings exert on the airframe (body frame, mN): aerodynamic + gravity on the
    /// wings − their inertial forces.
    pub wing_force: Vector3<f64>,
    /// Torque the wings exert on the airframe about `B` (body frame, mN·mm).
    pub wing_torque: Vector3<f64>,
    /// Kinetic energy of body + wings (µJ).
    pub kinetic: f64,
    /// Springs + drivetrain springs (µJ).
    pub potential: f64,
    /// Gravity potential `−Σ m g · r` (µJ).
    pub gravity_potential: f64,
    /// Total linear momentum (world, mg·mm/ms).
    pub momentum: Vector3<f64>,
    /// Total angular momentum about the world origin (world, mg·mm²/ms).
    pub angular_momentum: Vector3<f64>,
    /// Aerodynamic power on the system (µJ/ms).
    pub aero_power: f64,
    /// Actuator power (µJ/ms).
    pub actuator_power: f64,
}

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

impl FlightModel {
    /// Builds the flight model of `device` on `body`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a bad body, a wing whose inertia about its centre of
    /// mass is not positive definite; the device's own errors when rebuilt in null-space form.
    pub fn new(source: &Device, body: Body, mechanisms: Vec<Mechanism>) -> Result<Self> {
        body.validate()?;
        let device = source;
        let spec = device.spec();
        let n_wings = spec.wings.len();
        let mut aero = [WingAero::None, WingAero::None];
        let mut wings = Vec::with_capacity(n_wings);
        for (k, w) in spec.wings.iter().enumerate() {
            aero[k] = match w.aero() {
                WingAero::BladeElement(m) if m.omegas().force.is_none() => {
                    let omegas = m
                        .omegas()
                        .with_force(m.omegas().omega1 / body.force_radius)?;
                    WingAero::BladeElement(
                        paritysim_aero::BladeElementModel::new(omegas, *m.coefficient_model())?
                            .with_rotational_damping(m.rotational_damping())?
                            .with_normal_force_law(m.normal_force_law()),
                    )
                }
                WingAero::WhitneyWood2010(m) if m.blade().omegas().force.is_none() => {
                    let b = m.blade();
                    let omegas = b
                        .omegas()
                        .with_force(b.omegas().omega1 / body.force_radius)?;
                    let blade =
                        paritysim_aero::BladeElementModel::new(omegas, *b.coefficient_model())?
                            .with_rotational_damping(b.rotational_damping())?
                            .with_normal_force_law(b.normal_force_law());
                    WingAero::WhitneyWood2010(paritysim_aero::WhitneyWoodModel::new(
                        blade,
                        *m.omegas(),
                        *m.terms(),
                    )?)
                }
                other => other.clone(),
            };
            // The flight model evaluates aerodynamics itself (with body motion); the inertia
            // keeps the law's added inertia (`Wing::inertia` includes it).
            let mut bare = Wing::new(*w.shoulder(), *w.inertia(), *w.springs(), WingAero::None)?;
            if let Some(h) = w.tunable_hinge() {
                bare = bare.with_tunable_hinge(*h);
            }
            wings.push(bare.with_hinge_damping(w.hinge_damping())?);
        }
        // The actuator's effective mass is in the fixed-body forms' mass matrices only.
        if let Some(a) = spec.actuator.as_ref().filter(|a| a.mass() != 0.0) {
            return Err(Error::invalid(
                "actuator.mass_mg",
                a.mass(),
                "0 with a moving body (free flight does not take the actuator's mass yet)",
            ));
        }
        for m in &mechanisms {
            let two = spec
                .transmission
                .as_ref()
                .is_some_and(|t| t.kinematics().dof() == 2);
            if m.coordinate() == DriveCoordinate::Q2 && !two {
                return Err(Error::invalid(
                    "body.mechanisms.coordinate",
                    "\"q2\"",
                    "q1 unless the drivetrain has a whippletree (2 DOF)",
                ));
            }
            if spec.transmission.is_none() {
                return Err(Error::Constraint(
                    "body mechanisms act on the drivetrain: the device has none".into(),
                ));
            }
        }
        let device = Device::new(DeviceSpec {
            wings,
            constraints: spec.constraints.clone(),
            transmission: spec.transmission.clone(),
            actuator: spec.actuator.clone(),
            formulation: Formulation::NullSpace,
        })?;
        let mut inertia_cm = [Matrix3::identity(); 2];
        let mut polar = [Matrix3::identity(); 2];
        let mut axial = [Matrix3::identity(); 2];
        let mut shoulder = [Vector3::zeros(); 2];
        let mirror = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
        for k in 0..n_wings {
            let m = body.wing_mass[k];
            let c = body.wing_center_of_mass[k];
            let i_c = *device.spec().wings[k].inertia()
                - (Matrix3::identity() * c.norm_squared() - c * c.transpose()) * m;
            if i_c.cholesky().is_none() {
                return Err(Error::invalid(
                    format!("body.wing_mass_mg[{k}]"),
                    m,
                    "small enough that the wing's inertia about its centre of mass stays positive definite",
                ));
            }
            inertia_cm[k] = i_c;
            // Body index of the shoulder: with two wings the first is the (mirrored) left.
            let (si, left) = if n_wings == 2 {
                (k, k == 0)
            } else {
                (1, false)
            };
            if left {
                polar[k] = mirror;
                axial[k] = -mirror;
            }
            shoulder[k] = body.shoulders[si] - body.center_of_mass;
        }
        let mut stroke_plane = [false; 2];
        {
            let c = &device.spec().constraints;
            for (k, wing) in device.spec().wings.iter().enumerate() {
                let row = 3 * k + 1;
                let held = (0..c.n_free()).all(|j| c.null_basis()[(row, j)].abs() <= 1e-12)
                    && c.particular()[row] == 0.0;
                stroke_plane[k] = held && wing.has_closed_form_stroke_plane();
            }
        }
        let active: Vec<usize> = body
            .mode
            .active()
            .iter()
            .enumerate()
            .filter(|(_, a)| **a)
            .map(|(i, _)| i)
            .chain(6..6 + device.n_dof())
            .collect();
        let massless = body.wing_mass[..n_wings].iter().all(|m| *m == 0.0);
        let plan = SolvePlan::new(&active, massless);
        let polar_sign = polar.map(|m| m.diagonal());
        let axial_sign = axial.map(|m| m.diagonal());
        Ok(Self {
            polar_sign,
            axial_sign,
            plan,
            source: source.clone(),
            n: device.n_dof(),
            basis: *device.spec().constraints.null_basis(),
            device,
            aero,
            body,
            mechanisms,
            n_wings,
            inertia_cm,
            polar,
            axial,
            shoulder,
            active,
            stroke_plane,
        })
    }

    /// The device in null-space form (aerodynamics stripped: the flight model owns them).
    pub fn device(&self) -> &Device {
        &self.device
    }

    /// The device as given (aerodynamics included, any formulation).
    pub fn source(&self) -> &Device {
        &self.source
    }

    /// A device state of [`Self::source`] as a state of [`Self::device`] (null-space form).
    ///
    /// # Errors
    /// As [`Device::coordinates`] and [`Device::state_from`].
    pub fn convert_state(&self, source_state: &State) -> Result<State> {
        let (p, p_dot) = self.source.coordinates(source_state)?;
        self.device.state_from(&p, &p_dot)
    }

    /// The body.
    pub fn body(&self) -> &Body {
        &self.body
    }

    /// The same model with another body mode.
    pub fn with_mode(&self, mode: BodyMode) -> Self {
        let mut out = self.clone();
        out.body.mode = mode;
        out.active = mode
            .active()
            .iter()
            .enumerate()
            .filter(|(_, a)| **a)
            .map(|(i, _)| i)
            .chain(6..6 + self.n)
            .collect();
        let massless = self.body.wing_mass[..self.n_wings]
            .iter()
            .all(|m| *m == 0.0);
        out.plan = SolvePlan::new(&out.active, massless);
        out
    }

    /// Total mass of body and wings (mg).
    pub fn total_mass(&self) -> f64 {
        self.body.mass + self.body.wing_mass[..self.n_wings].iter().sum::<f64>()
    }

    /// Number of wing null-space coordinates.
    pub fn n_dof(&self) -> usize {
        self.n
    }

    /// A flight state: attitude, position, velocity and rate of the body, and a device state
    /// (null-space coordinates, as [`Device::state_from`] makes them).
    pub fn state(
        &self,
        attitude: &UnitQuaternion<f64>,
        position: &Vector3<f64>,
        velocity: &Vector3<f64>,
        omega: &Vector3<f64>,
        wings: &State,
    ) -> [f64; STATE_LEN] {
        let mut y = [0.0; STATE_LEN];
        let q = attitude.quaternion();
        y[QUAT..QUAT + 4].copy_from_slice(&[q.w, q.i, q.j, q.k]);
        y[POS..POS + 3].copy_from_slice(position.as_slice());
        let active = self.body.mode.active();
        for i in 0..3 {
            y[VEL + i] = if active[i] { velocity[i] } else { 0.0 };
            y[OMEGA + i] = if active[3 + i] { omega[i] } else { 0.0 };
        }
        y[X..X + self.n].copy_from_slice(&wings.coords[..self.n]);
        y[XDOT..XDOT + self.n].copy_from_slice(&wings.rates[..self.n]);
        y
    }

    /// The device state inside a flight state.
    pub fn wing_state(&self, y: &[f64; STATE_LEN]) -> State {
        let mut s = State::default();
        s.coords[..self.n].copy_from_slice(&y[X..X + self.n]);
        s.rates[..self.n].copy_from_slice(&y[XDOT..XDOT + self.n]);
        s.work_actuator = y[WORK_ACTUATOR];
        s.work_aero = y[WORK_AERO];
        s
    }

    /// The right-hand side on the flight state.
    ///
    /// # Errors
    /// Model errors (shoulder domain, drivetrain reach, a singular mass matrix).
    #[inline]
    pub fn rhs(
        &self,
        t: f64,
        y: &[f64; STATE_LEN],
        inputs: &Inputs,
        dydt: &mut [f64; STATE_LEN],
    ) -> Result<()> {
        self.rhs_on(t, y, inputs, None, dydt)
    }

    /// Number of switching functions of the wings' aerodynamics ([`Self::switches`]): three
    /// per wing, none when no wing has aerodynamics.
    pub fn n_switches(&self) -> usize {
        if self.aero[..self.n_wings]
            .iter()
            .all(|a| matches!(a, WingAero::None))
        {
            0
        } else {
            3 * self.n_wings
        }
    }

    /// The wings' switching functions ([`crate::aero::switching`] of wing `k` in
    /// `g[3k..3k + 3]`): where the right-hand side jumps or kinks (stroke reversal).
    ///
    /// # Errors
    /// As [`Self::rhs`].
    pub fn switches(&self, y: &[f64; STATE_LEN], g: &mut [f64; MAX_SWITCHES]) -> Result<()> {
        let attitude =
            UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(y[0], y[1], y[2], y[3]));
        let r_b = *attitude.to_rotation_matrix().matrix();
        let velocity = Vector3::new(y[VEL], y[VEL + 1], y[VEL + 2]);
        let omega = Vector3::new(y[OMEGA], y[OMEGA + 1], y[OMEGA + 2]);
        let (p, p_dot) = self.device.coordinates(&self.wing_state(y))?;
        let v_body = r_b.transpose() * velocity;
        for k in 0..self.n_wings {
            let o = 3 * k;
            let pw = Vector3::new(p[o], p[o + 1], p[o + 2]);
            let vw = Vector3::new(p_dot[o], p_dot[o + 1], p_dot[o + 2]);
            let wing = &self.device.spec().wings[k];
            let terms = if self.stroke_plane[k] && wing.tunable_hinge().is_none() {
                wing.stroke_plane_kinematics(&pw, &vw)
            } else if self.stroke_plane[k] {
                wing.stroke_plane_terms(&pw, &vw)
            } else {
                wing.terms(&pw, &vw)?
            };
            let r = terms.rotation;
            let om6 = r.transpose() * omega.component_mul(&self.axial_sign[k]) + terms.omega;
            let v6 = r.transpose()
                * (v_body + omega.cross(&self.shoulder[k])).component_mul(&self.polar_sign[k]);
            let gk = switching(&self.aero[k], &om6, &v6, &r, self.body.force_radius);
            g[o..o + 3].copy_from_slice(&gk);
        }
        Ok(())
    }

    /// The wings' aerodynamic branches named by the sides of [`Self::switches`].
    pub fn branches(&self, sides: Sides) -> [Branch; 2] {
        std::array::from_fn(|k| Branch {
            chordwise_positive: sides.positive(3 * k),
            normal_positive: sides.positive(3 * k + 1),
            spanwise_positive: sides.positive(3 * k + 2),
        })
    }

    /// [`Self::rhs`] with the wings' aerodynamics on `branches` (event location: the smooth
    /// branch held between the roots of [`Self::switches`]), or on the state's own sides.
    ///
    /// # Errors
    /// As [`Self::rhs`].
    #[inline]
    pub fn rhs_on(
        &self,
        t: f64,
        y: &[f64; STATE_LEN],
        inputs: &Inputs,
        branches: Option<&[Branch; 2]>,
        dydt: &mut [f64; STATE_LEN],
    ) -> Result<()> {
        let e = self.evaluate_with(t, y, inputs, false, branches)?;
        *dydt = [0.0; STATE_LEN];
        // q̇ = ½ q ⊗ (0, Ω) on the stored (unnormalised) quaternion.
        let (w, a, b, c) = (y[0], y[1], y[2], y[3]);
        let (ox, oy, oz) = (e.omega.x, e.omega.y, e.omega.z);
        dydt[0] = 0.5 * (-a * ox - b * oy - c * oz);
        dydt[1] = 0.5 * (w * ox + b * oz - c * oy);
        dydt[2] = 0.5 * (w * oy + c * ox - a * oz);
        dydt[3] = 0.5 * (w * oz + a * oy - b * ox);
        for i in 0..3 {
            dydt[POS + i] = e.velocity[i];
            dydt[VEL + i] = e.body_accel[i];
            dydt[OMEGA + i] = e.body_accel[3 + i];
        }
        dydt[X..X + self.n].copy_from_slice(&y[XDOT..XDOT + self.n]);
        let x_ddot = self.basis.transpose() * e.p_ddot;
        for i in 0..self.n {
            dydt[XDOT + i] = x_ddot[i];
        }
        dydt[WORK_ACTUATOR] = e.actuator_power;
        dydt[WORK_AERO] = e.aero_power;
        Ok(())
    }

    /// Extra drivetrain load `ΔQ = (ΔF, τ_q2)` from the inputs and mechanisms, mapped to the
    /// stroke angles: `τ_φ = J⁻ᵀ ΔQ`; on a dual drivetrain `ΔQ = (ΔF_L, ΔF_R)`. `ln q3` adds
    /// the whippletree load that makes `τL/τR = q3` ([`crate::control`], eq. 5.1).
    fn extra_stroke_torque(
        &self,
        t: f64,
        drive: &DriveState,
        inputs: &Inputs,
        r_b: &Matrix3<f64>,
        omega: &Vector3<f64>,
    ) -> Result<(Vector2<f64>, f64)> {
        let Some(tr) = &self.device.spec().transmission else {
            return Ok((Vector2::zeros(), 0.0));
        };
        let actuator = self.device.spec().actuator.as_ref();
        let dual = self.device.is_dual();
        // Inputs this drivetrain has no place for are errors, not silently dropped (the spec
        // checks its own set points and controller; an external controller lands here).
        let sided = inputs.side_gain != [0.0; 2] || inputs.side_offset != [0.0; 2];
        if sided && !dual {
            return Err(Error::invalid(
                "side_gain/side_offset",
                format!("{:?}/{:?}", inputs.side_gain, inputs.side_offset),
                format!(
                    "0: side_* inputs need a dual_four_bar drivetrain, the drivetrain is {}",
                    tr.kinematics().name()
                ),
            ));
        }
        if dual && inputs.q2_bias != 0.0 {
            return Err(Error::invalid(
                "q2_bias",
                inputs.q2_bias,
                "0: a dual_four_bar has no whippletree (q2 is the right drive)",
            ));
        }
        let mut dq = if dual {
            let right = actuator.map_or(0.0, |a| a.side_force(t, 1));
            let common = |f: f64, k: usize| {
                inputs.actuator_offset
                    + inputs.side_offset[k]
                    + (inputs.actuator_gain + inputs.side_gain[k]) * f
            };
            Vector2::new(common(drive.actuator_force, 0), common(right, 1))
        } else {
            Vector2::new(
                inputs.actuator_offset + inputs.actuator_gain * drive.actuator_force,
                inputs.q2_bias,
            )
        };
        let g = &self.body.gravity;
        for m in &self.mechanisms {
            match m.coordinate() {
                DriveCoordinate::Q1 => dq.x += m.force(r_b, omega, g, drive.q.x),
                DriveCoordinate::Q2 => dq.y += m.force(r_b, omega, g, drive.q.y),
            }
        }
        if dq == Vector2::zeros() && inputs.log_q3 == 0.0 {
            return Ok((Vector2::zeros(), 0.0));
        }
        let kin = tr.kinematics();
        let jac = kin.evaluate(drive.q.x, drive.q.y)?.jacobian;
        let log_q3 = inputs.log_q3;
        if log_q3 != 0.0 {
            if kin.dof() != 2 || dual {
                return Err(Error::invalid(
                    "log_q3",
                    log_q3,
                    format!(
                        "0: eq. 5.1 needs a whippletree (a 2-DOF differential), the drivetrain is {}",
                        kin.name()
                    ),
                ));
            }
            // Eq. 5.1: Q2 = Q1 (J01 q3 + J11) / (J00 q3 + J10) gives τL/τR = q3.
            let q3 = log_q3.exp();
            let q1_load = drive.load.x + dq.x;
            let den = jac[(0, 0)] * q3 + jac[(1, 0)];
            if den == 0.0 || !den.is_finite() {
                return Err(Error::Singular(format!(
                    "eq. 5.1 torque ratio q3 = {q3} is not reachable at q = {:?}",
                    drive.q
                )));
            }
            dq.y += q1_load * (jac[(0, 1)] * q3 + jac[(1, 1)]) / den;
        }
        let tau = if kin.dof() == 1 {
            Vector2::new(dq.x / jac[(0, 0)], 0.0)
        } else {
            let jt: Matrix2<f64> = jac.transpose();
            jt.lu().solve(&dq).ok_or_else(|| {
                Error::Singular(format!(
                    "drivetrain Jacobian is singular at q = {:?}",
                    drive.q
                ))
            })?
        };
        Ok((tau, dq.dot(&drive.q_dot)))
    }

    /// Full evaluation at `(t, y)`.
    ///
    /// # Errors
    /// As [`Self::rhs`].
    pub fn evaluate(&self, t: f64, y: &[f64; STATE_LEN], inputs: &Inputs) -> Result<FlightEval> {
        self.evaluate_with(t, y, inputs, true, None)
    }

    /// [`Self::evaluate`]; the reactions on the airframe and the per-wing shoulder torques
    /// only when `reactions` (samples, not the right-hand side).
    #[inline(always)]
    fn evaluate_with(
        &self,
        t: f64,
        y: &[f64; STATE_LEN],
        inputs: &Inputs,
        reactions: bool,
        branches: Option<&[Branch; 2]>,
    ) -> Result<FlightEval> {
        let attitude =
            UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(y[0], y[1], y[2], y[3]));
        let r_b = *attitude.to_rotation_matrix().matrix();
        let position = Vector3::new(y[POS], y[POS + 1], y[POS + 2]);
        let velocity = Vector3::new(y[VEL], y[VEL + 1], y[VEL + 2]);
        let omega = Vector3::new(y[OMEGA], y[OMEGA + 1], y[OMEGA + 2]);
        let (p, p_dot) = self.device.coordinates(&self.wing_state(y))?;
        let mut drive = self.device.drive(t, &p, &p_dot)?;
        let (extra, extra_power) = self.extra_stroke_torque(t, &drive, inputs, &r_b, &omega)?;
        drive.stroke_torque += extra;
        let g = self.body.gravity;

        let mut mass = MatU::zeros();
        let mut force = VecU::zeros();
        // The airframe.
        let mb = self.body.mass;
        let jb = self.body.inertia;
        let h_b = jb * omega;
        for i in 0..3 {
            mass[(i, i)] += mb;
        }
        mass.fixed_view_mut::<3, 3>(3, 3).add_assign(&jb);
        let gyro = omega.cross(&h_b);
        force.fixed_rows_mut::<3>(0).add_assign(&(g * mb));
        force.fixed_rows_mut::<3>(3).add_assign(&(-gyro));
        // Energies and momenta: samples only (`reactions`), not the right-hand side.
        let (mut kinetic, mut momentum, mut angular_momentum, mut gravity_potential) = if reactions
        {
            (
                0.5 * mb * velocity.norm_squared() + 0.5 * omega.dot(&h_b),
                velocity * mb,
                position.cross(&(velocity * mb)) + r_b * h_b,
                -mb * g.dot(&position),
            )
        } else {
            (0.0, Vector3::zeros(), Vector3::zeros(), 0.0)
        };
        let v_body = r_b.transpose() * velocity;
        let n = self.n;

        // Joint springs and the drivetrain on p, reduced by Nᵀ.
        let mut generalized_p = Vec6::zeros();
        generalized_p[0] += drive.stroke_torque.x;
        if self.n_wings == 2 {
            generalized_p[3] += drive.stroke_torque.y;
        }
        let mut wings = [empty_terms(); 2];
        let mut jw = [(Matrix3::zeros(), SMatrix::<f64, 3, 6>::zeros()); 2];
        let mut bias_w = [Vector3::zeros(); 2];
        let mut jv = [Jac::zeros(); 2];
        let mut bias_v = [Vector3::zeros(); 2];
        let mut omega6 = [Vector3::zeros(); 2];
        let mut wrenches = [Wrench::default(); 2];
        let mut aero_power = 0.0;
        let mut potential = drive.potential;
        let mut aero_force = Vector3::zeros();
        let mut wing_aero_force = [Vector3::zeros(); 2];
        for k in 0..self.n_wings {
            let o = 3 * k;
            let pw = Vector3::new(p[o], p[o + 1], p[o + 2]);
            let vw = Vector3::new(p_dot[o], p_dot[o + 1], p_dot[o + 2]);
            let wing = &self.device.spec().wings[k];
            let mut terms = if self.stroke_plane[k] && !reactions && wing.tunable_hinge().is_none()
            {
                wing.stroke_plane_kinematics(&pw, &vw)
            } else if self.stroke_plane[k] {
                wing.stroke_plane_terms(&pw, &vw)
            } else {
                wing.terms(&pw, &vw)?
            };
            potential += terms.potential;
            for i in 0..3 {
                generalized_p[o + i] -= terms.spring[i];
            }
            let hinge_damping = wing.hinge_damping();
            if hinge_damping != 0.0 {
                generalized_p[o + 2] -= hinge_damping * vw.z;
            }
            let r = terms.rotation;
            let w = terms.omega;
            let pk = &self.polar[k];
            let (ps, sa) = (&self.polar_sign[k], &self.axial_sign[k]);
            // G = J6 N_k on the n free columns (N's other columns are zero).
            let mut gk = SMatrix::<f64, 3, 6>::zeros();
            for j in 0..n {
                let nj = Vector3::new(
                    self.basis[(o, j)],
                    self.basis[(o + 1, j)],
                    self.basis[(o + 2, j)],
                );
                gk.set_column(j, &(terms.j6 * nj));
            }
            // Rᵀ A with A = diag(sa): Rᵀ's columns scaled.
            let mut rt_a = r.transpose();
            for j in 0..3 {
                for i in 0..3 {
                    rt_a[(i, j)] *= sa[j];
                }
            }
            let a_r = rt_a.transpose();
            let om_local = rt_a * omega;
            let om6 = om_local + w;
            omega6[k] = om6;
            // Angular Jacobian (frame 6) J_ω = [0, Rᵀ A, G], assembled by blocks.
            jw[k] = (rt_a, gk);
            bias_w[k] = -w.cross(&om_local) + terms.jdot_pdot;
            let ic = self.inertia_cm[k];
            let h6 = ic * om6;
            mass.fixed_view_mut::<3, 3>(3, 3)
                .add_assign(&(a_r * ic * rt_a));
            let euler = ic * bias_w[k] + om6.cross(&h6);
            force.fixed_rows_mut::<3>(3).add_assign(&(-(a_r * euler)));
            let mut ic_g = [Vector3::zeros(); 6];
            for j in 0..n {
                let gj = gk.column(j).into_owned();
                ic_g[j] = ic * gj;
                let c = a_r * ic_g[j];
                for i in 0..3 {
                    mass[(3 + i, 6 + j)] += c[i];
                    mass[(6 + j, 3 + i)] += c[i];
                }
                for i in 0..j {
                    let v = gk.column(i).dot(&ic_g[j]);
                    mass[(6 + i, 6 + j)] += v;
                    mass[(6 + j, 6 + i)] += v;
                }
                mass[(6 + j, 6 + j)] += gj.dot(&ic_g[j]);
                force[6 + j] -= gj.dot(&euler);
            }
            if reactions {
                kinetic += 0.5 * om6.dot(&h6);
                angular_momentum += r_b * (r * h6).component_mul(sa);
            }
            // Linear Jacobian of the wing's centre of mass (world).
            let m = self.body.wing_mass[k];
            let c = self.body.wing_center_of_mass[k];
            let s = self.shoulder[k];
            let prc = pk * (r * c);
            let rho = s + prc;
            if m > 0.0 {
                let rho_dot = pk * (r * w.cross(&c));
                let mut jl = Jac::zeros();
                jl.fixed_view_mut::<3, 3>(0, 0)
                    .copy_from(&Matrix3::identity());
                jl.fixed_view_mut::<3, 3>(0, 3)
                    .copy_from(&(-r_b * skew(&rho)));
                let jx: SMatrix<f64, 3, 6> = -r_b * pk * r * skew(&c) * gk;
                jl.fixed_view_mut::<3, 6>(0, 6).copy_from(&jx);
                let a0 = r_b
                    * (omega.cross(&omega.cross(&rho))
                        + omega.cross(&rho_dot) * 2.0
                        + pk * (r * (terms.jdot_pdot.cross(&c) + w.cross(&w.cross(&c)))));
                jv[k] = jl;
                bias_v[k] = a0;
                mass += jl.transpose() * jl * m;
                force += jl.transpose() * (g * m - a0 * m);
                let v_c = velocity + r_b * (omega.cross(&rho) + rho_dot);
                kinetic += 0.5 * m * v_c.norm_squared();
                momentum += v_c * m;
                let r_c = position + r_b * rho;
                angular_momentum += r_c.cross(&(v_c * m));
                gravity_potential -= m * g.dot(&r_c);
            }
            // Aerodynamics: wrench at the shoulder.
            let v_sh_body = v_body + omega.cross(&s);
            let v6 = r.transpose() * v_sh_body.component_mul(ps);
            let (wr, tau6) = wrench_and_wing_torque(
                &self.aero[k],
                &om6,
                &v6,
                &r,
                self.body.force_radius,
                branches.map(|b| b[k]),
            )?;
            wrenches[k] = wr;
            let f_body = wr.force.component_mul(ps);
            let tau_body = wr.torque.component_mul(sa);
            aero_force += f_body;
            wing_aero_force[k] = f_body;
            force.fixed_rows_mut::<3>(0).add_assign(&(r_b * f_body));
            force
                .fixed_rows_mut::<3>(3)
                .add_assign(&(s.cross(&f_body) + tau_body));
            for j in 0..n {
                force[6 + j] += gk.column(j).dot(&tau6);
            }
            aero_power += f_body.dot(&v_sh_body) + tau_body.dot(&(r * om6).component_mul(sa));
            terms.aero = terms.j6.transpose() * tau6;
            terms.aero_frame6 = tau6;
            wings[k] = terms;
        }
        let reduced: SVector<f64, 6> = self.basis.transpose() * generalized_p;
        force.fixed_rows_mut::<6>(6).add_assign(&reduced);

        // Solve on the active speeds (Cholesky on the coupled active block only).
        let mut u_dot = VecU::zeros();
        if !self.plan.solve(&mut mass, &force, &mut u_dot) {
            return Err(Error::Singular(format!(
                "flight mass matrix is not positive definite at p = {:?}",
                p.as_slice()
            )));
        }
        let mut x_ddot = Vec6::zeros();
        for i in 0..self.n {
            x_ddot[i] = u_dot[6 + i];
        }
        let p_ddot = self.basis * x_ddot;
        let body_accel = Vector6::from_fn(|i, _| u_dot[i]);

        // Reactions of the wings on the airframe (body frame), and per-wing shoulder torques.
        let mut wing_force = Vector3::zeros();
        let mut wing_torque = Vector3::zeros();
        let mut aero_torque = [Vector3::zeros(); 2];
        let mut inertial_torque = [Vector3::zeros(); 2];
        for k in (0..self.n_wings).filter(|_| reactions) {
            let (pk, ak) = (&self.polar[k], &self.axial[k]);
            let r = wings[k].rotation;
            let s = self.shoulder[k];
            let omega_dot = Vector3::new(u_dot[3], u_dot[4], u_dot[5]);
            let x_dd = SVector::<f64, 6>::from_fn(|i, _| u_dot[6 + i]);
            let alpha6 = jw[k].0 * omega_dot + jw[k].1 * x_dd + bias_w[k];
            let om6 = omega6[k];
            // About the shoulder, with the inertia about the shoulder (the fixed-body torques).
            let i_s = self.device.spec().wings[k].inertia();
            let inertial6 = -(i_s * alpha6 + om6.cross(&(i_s * om6)));
            inertial_torque[k] = ak * (r * inertial6);
            aero_torque[k] = ak * wrenches[k].torque;
            let f_aero = pk * wrenches[k].force;
            // Newton-Euler of the wing about its centre of mass.
            let m = self.body.wing_mass[k];
            let rho = s + pk * (r * self.body.wing_center_of_mass[k]);
            let a_c = r_b.transpose() * (jv[k] * u_dot + bias_v[k]);
            let f_on_body = f_aero + (r_b.transpose() * g - a_c) * m;
            let ic = self.inertia_cm[k];
            let dh = ak * (r * (ic * alpha6 + om6.cross(&(ic * om6))));
            // τ about B of the wing on the body = external wrench on the wing − its rate of
            // change of angular momentum about B (body frame, B accelerating with the body).
            let t_on_body =
                s.cross(&f_aero) + aero_torque[k] + rho.cross(&((r_b.transpose() * g) * m))
                    - rho.cross(&(a_c * m))
                    - dh;
            wing_force += f_on_body;
            wing_torque += t_on_body;
        }
        let actuator_power = self
            .device
            .actuator_power(t, drive.actuator_force, &drive.q_dot)
            + extra_power;
        Ok(FlightEval {
            p,
            p_dot,
            p_ddot,
            wings,
            drive,
            attitude,
            position,
            velocity,
            omega,
            body_accel,
            aero_torque,
            inertial_torque,
            aero_force,
            wing_aero_force,
            wing_force,
            wing_torque,
            kinetic,
            potential,
            gravity_potential,
            momentum,
            angular_momentum,
            aero_power,
            actuator_power,
        })
    }
}

/// How the active generalized speeds are solved for.
#[derive(Clone, Debug, PartialEq)]
struct SolvePlan {
    /// Translational speeds of a body with massless wings: their block is `m_b 1` with no
    /// coupling to the others (`V̇ = F / m_b`).
    direct: Vec<usize>,
    /// The rest, by Cholesky.
    coupled: Vec<usize>,
    /// The first coupled index when they are consecutive (solved in place).
    consecutive: Option<usize>,
}

impl SolvePlan {
    fn new(active: &[usize], massless_wings: bool) -> Self {
        let (direct, coupled): (Vec<usize>, Vec<usize>) =
            active.iter().partition(|&&i| massless_wings && i < 3);
        let consecutive = coupled
            .windows(2)
            .all(|w| w[1] == w[0] + 1)
            .then(|| coupled.first().copied().unwrap_or(0));
        Self {
            direct,
            coupled,
            consecutive,
        }
    }

    /// `u̇` on the active speeds of `mass u̇ = force` (`mass` is overwritten). False when the
    /// coupled block is not positive definite.
    #[inline]
    fn solve(&self, mass: &mut MatU, force: &VecU, u_dot: &mut VecU) -> bool {
        for &i in &self.direct {
            u_dot[i] = force[i] / mass[(i, i)];
        }
        let nc = self.coupled.len();
        if nc == 0 {
            return true;
        }
        if let Some(off) = self.consecutive {
            // A fixed-size block: nalgebra's unrolled Cholesky.
            macro_rules! fixed {
                ($($k:literal)+) => {
                    match nc {
                        $($k => return solve_block::<$k>(mass, force, off, u_dot),)+
                        _ => {}
                    }
                };
            }
            fixed!(1 2 3 4 5 6 7 8 9 10 11 12);
        }
        let mut m_a = [0.0; NU * NU];
        let mut f_a = [0.0; NU];
        for (i, &ii) in self.coupled.iter().enumerate() {
            f_a[i] = force[ii];
            for (j, &jj) in self.coupled.iter().enumerate() {
                m_a[i * NU + j] = mass[(ii, jj)];
            }
        }
        if !solve_spd(&mut m_a, &mut f_a, 0, nc) {
            return false;
        }
        for (i, &ii) in self.coupled.iter().enumerate() {
            u_dot[ii] = f_a[i];
        }
        true
    }
}

/// Solves the `N × N` block of `mass u̇ = force` at `(off, off)` into `u_dot` by the
/// Cholesky factorisation of [`solve_spd`] on fixed-size arrays (unrolled, no bounds checks);
/// false when it is not positive definite.
#[inline]
#[allow(clippy::needless_range_loop)] // the index form mirrors the factorisation
fn solve_block<const N: usize>(mass: &MatU, force: &VecU, off: usize, u_dot: &mut VecU) -> bool {
    let mut a = [[0.0; N]; N];
    let mut b = [0.0; N];
    for i in 0..N {
        b[i] = force[off + i];
        for j in 0..=i {
            a[i][j] = mass[(off + i, off + j)];
        }
    }
    for j in 0..N {
        let mut d = a[j][j];
        for k in 0..j {
            d -= a[j][k] * a[j][k];
        }
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let d = d.sqrt();
        a[j][j] = d;
        for i in j + 1..N {
            let mut v = a[i][j];
            for k in 0..j {
                v -= a[i][k] * a[j][k];
            }
            a[i][j] = v / d;
        }
    }
    for i in 0..N {
        let mut v = b[i];
        for k in 0..i {
            v -= a[i][k] * b[k];
        }
        b[i] = v / a[i][i];
    }
    for i in (0..N).rev() {
        let mut v = b[i];
        for k in i + 1..N {
            v -= a[k][i] * b[k];
        }
        b[i] = v / a[i][i];
    }
    for i in 0..N {
        u_dot[off + i] = b[i];
    }
    true
}

/// Solves `A x = b` for a symmetric positive definite `A` (the `n × n` block at `(off, off)`
/// of a row-major `NU × NU` array, `b`'s entries `off..off + n`) by an in-place Cholesky
/// factorisation; `b` becomes `x`. False when `A` is not positive definite.
#[inline]
fn solve_spd(a: &mut [f64; NU * NU], b: &mut [f64; NU], off: usize, n: usize) -> bool {
    let a = &mut a[off * NU + off..];
    let b = &mut b[off..];
    for j in 0..n {
        let mut d = a[j * NU + j];
        for k in 0..j {
            d -= a[j * NU + k] * a[j * NU + k];
        }
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let d = d.sqrt();
        a[j * NU + j] = d;
        for i in j + 1..n {
            let mut v = a[i * NU + j];
            for k in 0..j {
                v -= a[i * NU + k] * a[j * NU + k];
            }
            a[i * NU + j] = v / d;
        }
    }
    for i in 0..n {
        let mut v = b[i];
        for k in 0..i {
            v -= a[i * NU + k] * b[k];
        }
        b[i] = v / a[i * NU + i];
    }
    for i in (0..n).rev() {
        let mut v = b[i];
        for k in i + 1..n {
            v -= a[k * NU + i] * b[k];
        }
        b[i] = v / a[i * NU + i];
    }
    true
}

fn empty_terms() -> WingTerms {
    WingTerms {
        mass: Matrix3::identity(),
        coriolis: Vector3::zeros(),
        spring: Vector3::zeros(),
        aero: Vector3::zeros(),
        aero_frame6: Vector3::zeros(),
        j6: Matrix3::identity(),
        omega: Vector3::zeros(),
        jdot_pdot: Vector3::zeros(),
        rotation: Matrix3::identity(),
        theta_w: 0.0,
        potential: 0.0,
        kinetic: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lean_stroke_plane_kinematics_match_the_wing() {
        let mut springs = [paritysim_dynamics::JointSpring::default(); 6];
        springs[0] = paritysim_dynamics::JointSpring::nonlinear(3.0, 0.4, 0.1).unwrap();
        springs[5] = paritysim_dynamics::JointSpring::linear(2.5, 0.2).unwrap();
        let wing = Wing::new(
            paritysim_kinematics::SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0).unwrap(),
            Matrix3::new(49.0, 0.0, 4.2, 0.0, 50.5, 0.0, 4.2, 0.0, 1.56),
            springs,
            WingAero::None,
        )
        .unwrap();
        assert!(wing.has_closed_form_stroke_plane());
        for (p, v) in [
            (Vector3::new(0.7, 0.0, -1.1), Vector3::new(0.2, 0.0, 0.5)),
            (Vector3::new(-0.4, 0.0, 0.0), Vector3::new(-0.3, 0.0, 0.1)),
        ] {
            let a = wing.stroke_plane_kinematics(&p, &v);
            let b = wing.stroke_plane_terms(&p, &v);
            assert_eq!(a.rotation, b.rotation);
            assert_eq!(a.j6, b.j6);
            assert_eq!(a.omega, b.omega);
            assert_eq!(a.jdot_pdot, b.jdot_pdot);
            assert_eq!(a.spring, b.spring);
            assert_eq!(a.potential, b.potential);
        }
    }

    #[test]
    fn cholesky_solve_matches_nalgebra() {
        let n = 7;
        let b = SMatrix::<f64, 7, 7>::from_fn(|i, j| ((i * 7 + j) as f64 * 0.37).sin());
        let spd = b * b.transpose() + SMatrix::<f64, 7, 7>::identity() * 0.5;
        let rhs = SVector::<f64, 7>::from_fn(|i, _| (i as f64).cos());
        let expected = spd.cholesky().unwrap().solve(&rhs);
        let mut a = [0.0; NU * NU];
        let mut x = [0.0; NU];
        for i in 0..n {
            x[i] = rhs[i];
            for j in 0..n {
                a[i * NU + j] = spd[(i, j)];
            }
        }
        assert!(solve_spd(&mut a, &mut x, 0, n));
        for i in 0..n {
            assert!(
                (x[i] - expected[i]).abs() < 1e-12,
                "{i}: {} vs {}",
                x[i],
                expected[i]
            );
        }
        let mut bad = [0.0; NU * NU];
        bad[0] = -1.0;
        assert!(!solve_spd(&mut bad, &mut [1.0; NU], 0, 1));
        // The same system at an offset (the block at (off, off) of a larger array).
        let off = 3;
        let mut a = [f64::NAN; NU * NU];
        let mut x = [f64::NAN; NU];
        for i in 0..n {
            x[off + i] = rhs[i];
            for j in 0..n {
                a[(off + i) * NU + off + j] = spd[(i, j)];
            }
        }
        assert!(solve_spd(&mut a, &mut x, off, n));
        for i in 0..n {
            assert!((x[off + i] - expected[i]).abs() < 1e-12);
        }
    }
}
