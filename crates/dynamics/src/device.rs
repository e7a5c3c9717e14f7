//! A device: wings + constraints + drivetrain + actuator, and its right-hand side.
//!
//! Configuration `p = (φL, θL, ψL, φR, θR, ψR)` (eq. 3.21; one wing uses the first three).
//! Under the massless-mechanism assumption (§3.2.2 item 5) the drivetrain adds no inertia: its
//! springs (actuator K1 on `q1`, balance beam K2 on `q2`) and the actuator force act on the
//! stroke angles through the drivetrain Jacobian `J = ∂φ/∂q`: `Q = Jᵀ τ_φ`, so
//! `τ_φ = J⁻ᵀ Q` with `Q = (F(t) − K1 q1, −K2 q2)`. `q` is recovered from `φ` by Newton's method
//! on the drivetrain map.

use nalgebra::{Matrix2, Vector2, Vector3};
use paritysim_constraints::{Constraints, Mat6, Vec6};
use paritysim_error::{Result, bail};
use paritysim_kinematics::Drivetrain;

use crate::actuator::Actuator;
use crate::integrate::State;
use crate::wing::{Wing, WingTerms};

mod drive;
pub(crate) use drive::DriveSprings;
mod drivetrain_coordinates;
mod drivetrain_inverse;
mod equations;
mod evaluation;
mod form;
mod free_deviation;
pub(crate) mod linear_map;
mod null_space;
mod ode_system;
mod soft_direction;
mod stroke_plane;
mod switches;
mod transmission;

pub use evaluation::{DriveState, Evaluation};
pub use transmission::Transmission;

use drivetrain_coordinates::stroke_only;

/// How the constraints are enforced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Formulation {
    /// [`Formulation::DrivetrainCoordinates`] when the device allows it, else
    /// [`Formulation::NullSpace`] (the default).
    #[default]
    Auto,
    /// Reduced coordinates `p = p_part + N z` (cannot drift).
    NullSpace,
    /// Lagrange-multiplier projection of eq. 3.20 (with docs/errata.md#4's `Cᵀ`) on the full `p`.
    Projection,
    /// Fixed wings only stroking (θ = ψ = 0 imposed by `C`, α2 = 90° shoulders so θ_w ≡ 0, no
    /// springs on joints 2, 3, 5): integrate the drivetrain coordinates `q` directly with
    /// `M_q = Σ_k I_k J_kᵀ J_k`, `Q = Σ_k J_kᵀ (τ_k − I_k h_k) + (F − K1 q1, −K2 q2)`. Same
    /// physics as the null-space form without inverse kinematics or shoulder evaluations.
    DrivetrainCoordinates,
}

/// Everything needed to build a [`Device`].
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceSpec {
    /// One or two wings (left first).
    pub wings: Vec<Wing>,
    /// `C p = c0`.
    pub constraints: Constraints,
    /// Drivetrain from the actuator to the stroke angles (required with an actuator).
    pub transmission: Option<Transmission>,
    /// Piezo actuator on `q1`.
    pub actuator: Option<Actuator>,
    /// Constraint formulation.
    pub formulation: Formulation,
}

/// The validated, immutable model (`Send + Sync`; shared across threads by sweeps).
#[derive(Clone, Debug, PartialEq)]
pub struct Device {
    spec: DeviceSpec,
    n_coords: usize,
    /// Columns of the coordinate map `p = offset + basis · x`: `N` (null space) or `I`.
    basis: Mat6,
    offset: Vec6,
    n_dof: usize,
    formulation: Formulation,
    /// The equations it integrates, chosen once ([`form::Form::choose`]).
    form: form::Form,
    /// Wings whose deviation C holds at zero on an α2 = 90° shoulder: their terms are closed form
    /// ([`Wing::stroke_plane_terms`]).
    stroke_plane: [bool; 2],
    /// Wings with a free deviation on an α2 = 90°, α3 = 0 shoulder: closed-form terms
    /// ([`Wing::free_deviation_terms`]).
    free_deviation: [bool; 2],
    /// The constant Jacobian of a 2-DOF linear-map drivetrain (eq. 2.15): its inverse
    /// kinematics need no drivetrain evaluations.
    linear_jacobian: Option<Matrix2<f64>>,
    /// The drive's springs (`K1`, `K2`, dual or not): the one drive load.
    drive: drive::DriveSprings<f64>,
    /// Switching functions of the right-hand side (three per wing with blade elements whose
    /// `ω` has a closed form; see [`Self::blade_switching_functions`]).
    n_switches: usize,
}

/// Stroke angles `(φL, φR)`, their rates and the whippletree angle `q2` (see
/// [`Device::stroke_state`]).
pub type StrokeState = (Vector2<f64>, Vector2<f64>, f64);

/// Stroke kinematics and actuator force of a drivetrain-coordinate state (see
/// [`Device::stroke_motion_unchecked`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StrokeMotion {
    /// `(φL, φR)` (rad).
    pub stroke: Vector2<f64>,
    /// `(φ̇L, φ̇R)` (rad/ms).
    pub rate: Vector2<f64>,
    /// `(φ̈L, φ̈R)` (rad/ms²).
    pub accel: Vector2<f64>,
    /// Whippletree angle `q2` (rad).
    pub q2: f64,
    /// Actuator force F(t) (mN).
    pub actuator_force: f64,
}

impl Device {
    /// Validates the spec and precomputes the coordinate map.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`](paritysim_error::Error::InvalidParameter) for a wrong wing count; [`Error::Shape`](paritysim_error::Error::Shape) when `C` does not have
    /// 3 columns per wing; [`Error::Constraint`](paritysim_error::Error::Constraint) when an actuator has no drivetrain, a 2-DOF
    /// drivetrain has one wing, or a 1-DOF drivetrain drives two wings whose strokes `C` does not
    /// tie together (`φL = φR`).
    pub fn new(spec: DeviceSpec) -> Result<Self> {
        let n_wings = spec.wings.len();
        if !(1..=2).contains(&n_wings) {
            bail!(invalid "wings", n_wings, "1 or 2 wings");
        }
        let n_coords = 3 * n_wings;
        if spec.constraints.n_coords() != n_coords {
            bail!(Shape "C has {} columns but {n_wings} wing(s) need {n_coords}", spec.constraints.n_coords());
        }
        if spec.actuator.is_some() && spec.transmission.is_none() {
            bail!(Constraint "an actuator needs a transmission (drivetrain) to act on the wings");
        }
        if let Some(tr) = &spec.transmission {
            let dof = tr.kinematics.dof();
            if dof == 2 && n_wings != 2 {
                bail!(Constraint "the {} drivetrain drives two wings but the device has one", tr.kinematics.name());
            }
            if dof == 1 && n_wings == 2 && !ties_strokes(&spec.constraints) {
                bail!(Constraint
                    "the 1-DOF {} drivetrain requires C to impose phi_L = phi_R (e.g. configuration hmf)",
                    tr.kinematics.name());
            }
        }
        // The drive load's terms, built once (the forms and the model share this copy).
        let dual = spec.actuator.is_some()
            && spec
                .transmission
                .as_ref()
                .is_some_and(|tr| tr.kinematics.is_dual());
        let drive = drive::DriveSprings::of(&spec, dual);
        let fast = stroke_only(&spec, &drive);
        let formulation = match (spec.formulation, &fast) {
            (Formulation::Auto, Ok(_)) => Formulation::DrivetrainCoordinates,
            (Formulation::Auto, Err(_)) => Formulation::NullSpace,
            (Formulation::DrivetrainCoordinates, Err(why)) => {
                bail!(Constraint "drivetrain coordinates are not available for this device: {why}")
            }
            (f, _) => f,
        };
        let stroke_only = fast
            .ok()
            .filter(|_| formulation == Formulation::DrivetrainCoordinates);
        let (basis, offset, n_dof) = match formulation {
            Formulation::NullSpace | Formulation::Auto | Formulation::DrivetrainCoordinates => (
                *spec.constraints.null_basis(),
                *spec.constraints.particular(),
                spec.constraints.n_free(),
            ),
            Formulation::Projection => {
                let mut b = Mat6::zeros();
                for i in 0..n_coords {
                    b[(i, i)] = 1.0;
                }
                (b, Vec6::zeros(), n_coords)
            }
        };
        let mut stroke_plane = [false; 2];
        if formulation != Formulation::Projection {
            let c = &spec.constraints;
            for (w, wing) in spec.wings.iter().enumerate() {
                let row = 3 * w + 1;
                let theta_held = (0..c.n_free()).all(|k| c.null_basis()[(row, k)].abs() <= 1e-12)
                    && c.particular()[row] == 0.0;
                stroke_plane[w] = theta_held && wing.has_closed_form_stroke_plane();
            }
        }
        let mut free_deviation = [false; 2];
        for (w, wing) in spec.wings.iter().enumerate() {
            free_deviation[w] = !stroke_plane[w] && wing.has_closed_form_free_deviation();
        }
        let linear_jacobian = match spec.transmission.as_ref().map(|tr| &tr.kinematics) {
            Some(Drivetrain::LinearDifferential(map)) if map.polynomial().is_linear() => {
                Some(map.evaluate(0.0, 0.0).jacobian)
            }
            _ => None,
        };
        let mut device = Self {
            spec,
            n_coords,
            basis,
            offset,
            n_dof,
            formulation,
            form: form::Form::General(null_space::General),
            stroke_plane,
            free_deviation,
            linear_jacobian,
            drive,
            n_switches: 0,
        };
        device.form = form::Form::choose(&device, stroke_only);
        device.n_switches = device.blade_switches();
        Ok(device)
    }

    /// The spec this model was built from.
    pub fn spec(&self) -> &DeviceSpec {
        &self.spec
    }

    /// Number of wings.
    pub fn n_wings(&self) -> usize {
        self.spec.wings.len()
    }

    /// Number of configuration coordinates (3 or 6).
    pub fn n_coords(&self) -> usize {
        self.n_coords
    }

    /// Number of integrated coordinates (`n_free` for null-space, `n_coords` for projection).
    pub fn n_dof(&self) -> usize {
        self.n_dof
    }

    /// The formulation in use (`Auto` resolved).
    pub fn formulation(&self) -> Formulation {
        self.formulation
    }

    /// Drive period (ms), if there is an actuator.
    pub fn period(&self) -> Option<f64> {
        self.spec.actuator.as_ref().map(|a| a.waveform().period())
    }

    /// `(p, ṗ)` from an integrator state.
    ///
    /// # Errors
    /// With drivetrain coordinates, [`Error::OutOfDomain`](paritysim_error::Error::OutOfDomain) when `q` is beyond the linkage's reach.
    #[inline]
    pub fn coordinates(&self, y: &State) -> Result<(Vec6, Vec6)> {
        if self.form.stroke_only().is_some() {
            let (q, q_dot) = self.drive_coordinates(y);
            let e = self.drivetrain().evaluate(q.x, q.y)?;
            let phi_dot = e.jacobian * q_dot;
            let p = Vec6::new(e.stroke.x, 0.0, 0.0, e.stroke.y, 0.0, 0.0);
            let p_dot = Vec6::new(phi_dot.x, 0.0, 0.0, phi_dot.y, 0.0, 0.0);
            return Ok((p, p_dot));
        }
        let mut x = Vec6::zeros();
        let mut xd = Vec6::zeros();
        for i in 0..self.n_dof {
            x[i] = y.coords[i];
            xd[i] = y.rates[i];
        }
        Ok((self.offset + self.basis * x, self.basis * xd))
    }

    #[inline]
    fn drivetrain(&self) -> &Drivetrain {
        &self
            .spec
            .transmission
            .as_ref()
            .expect("validated: stroke-only devices have a drivetrain")
            .kinematics
    }

    /// `(q, q̇)` of a drivetrain-coordinate state (`q2 ≡ 0` for a 1-DOF drivetrain).
    #[inline]
    fn drive_coordinates(&self, y: &State) -> (Vector2<f64>, Vector2<f64>) {
        let two = self.n_dof == 2;
        (
            Vector2::new(y.coords[0], if two { y.coords[1] } else { 0.0 }),
            Vector2::new(y.rates[0], if two { y.rates[1] } else { 0.0 }),
        )
    }

    /// `(φ, φ̇, q2)`: stroke angles, stroke rates and `q2` of a drivetrain-coordinate state
    /// (the forward map only); `None` for other formulations.
    pub fn stroke_state(&self, y: &State) -> Option<Result<StrokeState>> {
        self.form.stroke_only()?;
        Some(self.stroke_state_unchecked(y))
    }

    /// [`Self::stroke_state`] for a device known to integrate drivetrain coordinates.
    #[inline]
    pub(crate) fn stroke_state_unchecked(&self, y: &State) -> Result<StrokeState> {
        let (q, q_dot) = self.drive_coordinates(y);
        let e = self.drivetrain().evaluate(q.x, q.y)?;
        Ok((e.stroke, e.jacobian * q_dot, q.y))
    }

    /// Stroke angles, rates and accelerations `(φ, φ̇, φ̈)`, `q2` and the actuator force of a
    /// drivetrain-coordinate state (`φ̈ = J q̈ + h`, eq. 2.18 generalised to the drivetrain's
    /// map): what the body torques of stroke-only wings need, without the mass matrices and
    /// rotations of [`Self::evaluate_state`].
    ///
    /// # Errors
    /// A drivetrain evaluation outside the linkage's domain; a singular drivetrain mass matrix.
    #[inline]
    pub(crate) fn stroke_motion_unchecked(&self, t: f64, y: &State) -> Result<StrokeMotion> {
        let fast = self
            .form
            .stroke_only()
            .expect("only called for drivetrain-coordinate devices");
        if let Some(terms) = fast.linear.as_ref().filter(|t| !t.polynomial) {
            // φ̈ = J q̈: the linear map has no velocity product.
            let (q_dot, q_ddot, force, _) = self.linear_map_step(terms, t, y)?;
            let (q, _) = self.drive_coordinates(y);
            let [j00, j01, j10, j11] = terms.jacobian;
            let j = Matrix2::new(j00, j01, j10, j11);
            return Ok(StrokeMotion {
                stroke: j * q,
                rate: j * q_dot,
                accel: j * q_ddot,
                q2: q.y,
                actuator_force: force,
            });
        }
        let step = self.drivetrain_step(fast, t, y)?;
        let e = &step.eval;
        Ok(StrokeMotion {
            stroke: e.stroke,
            rate: e.jacobian * step.q_dot,
            accel: e.jacobian * step.q_ddot + e.velocity_product(&step.q_dot),
            q2: step.q.y,
            actuator_force: step.force,
        })
    }

    /// Actuator force `F(t)` (the left side's on a dual drivetrain), drivetrain load `Q`
    /// ([`drive::DriveSprings::load`]) and the drive springs' energy.
    // Always inlined: every right-hand side calls it (a call and its spills cost more than it).
    #[inline(always)]
    fn drive_load(
        &self,
        t: f64,
        q: &Vector2<f64>,
        q_dot: &Vector2<f64>,
    ) -> (f64, Vector2<f64>, f64) {
        let forces = self.drive_forces(t);
        let [q1, q2] = [q.x, q.y];
        let [l1, l2] = self.drive.load(forces, [q1, q2], [q_dot.x, q_dot.y]);
        (forces[0], Vector2::new(l1, l2), self.drive.energy([q1, q2]))
    }

    /// Whether the device has the closed-form stroke-plane model (§3.4 rotating wings:
    /// `device/stroke_plane/`), whose lean samples are [`crate::trajectory::PlaneSample`]s.
    pub fn has_stroke_plane_model(&self) -> bool {
        self.form.stroke_plane().is_some()
    }

    /// Whether the device has the closed-form free-deviation model (§2.5 Lift / Dual PARITY:
    /// θ free). Such devices have coexisting stable orbits at one drive (docs/findings.md §23:
    /// the Lift PARITY is bistable near 96 V), so a sweep does not continue their points from a
    /// neighbour's orbit ([`crate::sweep::run_points`]).
    pub fn has_free_deviation_model(&self) -> bool {
        self.form.free_deviation().is_some()
    }

    /// The drive forces [`Self::drive_load`] applies at `t`: the actuator's and 0, or a dual
    /// drivetrain's left and right sides'.
    #[inline(always)]
    pub(crate) fn drive_forces(&self, t: f64) -> [f64; 2] {
        match (self.spec.actuator.as_ref(), self.is_dual()) {
            (Some(a), true) => [a.side_force(t, 0), a.side_force(t, 1)],
            (Some(a), false) => [a.force(t), 0.0],
            (None, _) => [0.0, 0.0],
        }
    }

    /// `∂Q/∂q` of [`Self::drive_load`] at `q = 0` ([`drive::DriveSprings::slope`]; the
    /// constant slope of a drive without cubic springs).
    pub(crate) fn drive_load_slope(&self) -> nalgebra::Matrix2<f64> {
        let [s1, s2] = self.drive.slope([0.0, 0.0]);
        nalgebra::Matrix2::new(s1, 0.0, 0.0, s2)
    }

    /// Whether the drivetrain is a dual one (one actuator per wing, `q2` the right drive).
    #[inline]
    pub fn is_dual(&self) -> bool {
        self.spec
            .transmission
            .as_ref()
            .is_some_and(|tr| tr.kinematics.is_dual())
    }

    /// Actuator power `F q̇1` (plus `F_R q̇2` on a dual drivetrain) for a drive at `t` whose
    /// (left) force is `force` (µJ/ms).
    #[inline]
    pub fn actuator_power(&self, t: f64, force: f64, q_dot: &Vector2<f64>) -> f64 {
        let right = match (&self.spec.actuator, self.is_dual()) {
            (Some(a), true) => a.side_force(t, 1) * q_dot.y,
            _ => 0.0,
        };
        force * q_dot.x + right
    }

    /// An integrator state from `(p, ṗ)` after checking `C p = c0`, `C ṗ = 0`.
    ///
    /// # Errors
    /// [`Error::Constraint`](paritysim_error::Error::Constraint) for an inconsistent initial state; [`Error::InvalidParameter`](paritysim_error::Error::InvalidParameter) for
    /// non-finite values.
    pub fn state_from(&self, p: &Vec6, p_dot: &Vec6) -> Result<State> {
        paritysim_error::check_all_finite("initial.p", p.as_slice())?;
        paritysim_error::check_all_finite("initial.p_dot", p_dot.as_slice())?;
        self.spec.constraints.check_consistent(p, p_dot, 1e-10)?;
        if self.form.stroke_only().is_some() {
            let drive = self.drive(0.0, p, p_dot)?;
            let mut y = State::default();
            for i in 0..self.n_dof {
                y.coords[i] = drive.q[i];
                y.rates[i] = drive.q_dot[i];
            }
            return Ok(y);
        }
        let x = self.basis.transpose() * (p - self.offset);
        let xd = self.basis.transpose() * p_dot;
        let mut y = State::default();
        for i in 0..self.n_dof {
            y.coords[i] = x[i];
            y.rates[i] = xd[i];
        }
        Ok(y)
    }

    /// The right-hand side `ẏ = f(t, y)`; also integrates the actuator work and the
    /// aerodynamic work into the last two state entries.
    #[inline]
    pub fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> Result<()> {
        use equations::Equations;
        self.form.rhs(self, t, y, None, dydt)
    }
}

/// Whether `C` of a two-wing device imposes `φL = φR` (every free direction strokes both wings
/// alike): what a 1-DOF drivetrain on two wings needs.
pub fn ties_strokes(constraints: &Constraints) -> bool {
    let n = constraints.null_basis();
    (0..constraints.n_free()).all(|k| (n[(0, k)] - n[(3, k)]).abs() < 1e-12)
}

fn empty_terms() -> WingTerms {
    WingTerms {
        mass: nalgebra::Matrix3::identity(),
        coriolis: Vector3::zeros(),
        spring: Vector3::zeros(),
        aero: Vector3::zeros(),
        aero_frame6: Vector3::zeros(),
        j6: nalgebra::Matrix3::identity(),
        omega: Vector3::zeros(),
        jdot_pdot: Vector3::zeros(),
        rotation: nalgebra::Matrix3::identity(),
        theta_w: 0.0,
        potential: 0.0,
        kinetic: 0.0,
    }
}
