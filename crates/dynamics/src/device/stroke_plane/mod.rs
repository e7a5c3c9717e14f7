//! The lean right-hand side of a stroke-plane device (§3.4: two rotating wings whose deviation
//! θ is held at zero on α2 = 90° shoulders, stroke φ and hinge ψ free, on the linear map of
//! eq. 2.15): the null-space equations (eq. 3.20 reduced, App. A with θ ≡ θ̇ ≡ 0) in closed form.
//!
//! With θ ≡ 0, `J6 ṗ = a φ̇ + ẑ ψ̇` with `a = (cos ψ, −sin ψ, 0)` (the first column of
//! [`crate::Wing::stroke_plane_terms`]' `J6`, also the stroke axis in frame 6) and
//! `J̇6 ṗ = φ̇ ψ̇ (−sin ψ, −cos ψ, 0)`, so each wing needs one `sin_cos(ψ)`: no rotation
//! matrix, no 3 × 3 mass products, no cos φ (it only multiplies θ̇). The drivetrain's inverse
//! kinematics are the constant `J⁻¹` of the linear map (`q = J⁻¹ φ`, `τ_φ = J⁻ᵀ Q`). Same
//! state as the null-space path (`x`, `ẋ`); tested against it to 1e-12.
//!
//! The reduced mass matrix needs no 4 × 4 factorisation: with θ held, the null basis `N`
//! (orthonormal columns) has zero θ rows, so its `(φ, ψ)` rows form an orthogonal `S`
//! (`(φL, ψL, φR, ψR) = S x`), `M = Sᵀ B S` with `B` the two wings' 2 × 2 blocks, and
//! `M⁻¹ = Sᵀ B⁻¹ S`: `ẍ = Sᵀ B⁻¹ f` for the wings' generalised forces `f = (f_φ, f_ψ)`.

use nalgebra::{Matrix2, SMatrix, SVector, Vector2, Vector3};
use paritysim_aero::Branch;
use paritysim_error::{Error, Result};

use super::Device;
use super::equations::Equations;
use crate::WingAero;
use crate::integrate::{MAX_SWITCHES, State};
use crate::metrics::needs::StrokeNeeds;
use crate::metrics::plane_sample::PlaneSample;

/// Integrated coordinates of a stroke-plane device: `(φ, ψ)` of two wings.
pub(super) const N: usize = 4;

/// The constants of [`Device::rhs_stroke_plane`], precomputed from the null basis and the
/// linear map.
///
/// Its `(φ, ψ)` rows must form an orthogonal matrix (see the module): beyond this deviation of
/// `SᵀS` from `I` the device takes the general path.
const ORTHOGONALITY_TOL: f64 = 1e-12;

#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StrokePlane {
    /// Rows `φ` (3w) and `ψ` (3w + 2) of the null basis `N`, per wing.
    rows: [[[f64; N]; 2]; 2],
    /// The particular solution's `(φ, ψ)` per wing.
    offset: [[f64; 2]; 2],
    /// `J⁻¹` and `J⁻ᵀ` of the linear map.
    inverse: Matrix2<f64>,
    inverse_transpose: Matrix2<f64>,
    /// The drive's part of `∂f_φw/∂x` per wing (constant): `Σ_k (J⁻ᵀ ∂Q/∂q J⁻¹)_wk N_φk`.
    drive_rows: [[f64; N]; 2],
    /// Whether the drive load is linear and undamped (`drive_rows` is its whole Jacobian);
    /// else the Jacobian takes `∂Q/∂q` at the state and `∂Q/∂q̇` on `ẋ`.
    linear_drive: bool,
}

impl StrokePlane {
    /// The lean model when `device` applies: null-space coordinates, two stroke-plane wings
    /// with φ and ψ free (`n = 4`), the 2-DOF linear map.
    pub(super) fn of(device: &Device) -> Option<Self> {
        let applies = device.formulation == super::Formulation::NullSpace
            && device.n_wings() == 2
            && device.stroke_plane == [true, true]
            && device.n_dof == N
            // Its per-wing blocks take no actuator mass (it couples the strokes' inertia): the
            // general form runs that.
            && device.drive.mass == 0.0;
        let jacobian = device.linear_jacobian.filter(|_| applies)?;
        let inverse = jacobian.try_inverse()?;
        let row = |i: usize| -> [f64; N] { std::array::from_fn(|k| device.basis[(i, k)]) };
        let drive = inverse.transpose() * device.drive_load_slope() * inverse;
        let s_rows = [row(0), row(2), row(3), row(5)];
        let orthogonal = (0..N).all(|i| {
            (0..N).all(|j| {
                let sts: f64 = s_rows.iter().map(|r| r[i] * r[j]).sum();
                (sts - f64::from(u8::from(i == j))).abs() <= ORTHOGONALITY_TOL
            })
        });
        if !orthogonal {
            return None;
        }
        let strokes = [row(0), row(3)];
        let drive_rows = [0, 1]
            .map(|w| std::array::from_fn(|j| (0..2).map(|k| drive[(w, k)] * strokes[k][j]).sum()));
        // (The mass is zero here.)
        let linear_drive = device.drive.is_linear_lossless();
        Some(Self {
            drive_rows,
            linear_drive,
            rows: [[row(0), row(2)], [row(3), row(5)]],
            offset: [
                [device.offset[0], device.offset[2]],
                [device.offset[3], device.offset[5]],
            ],
            inverse,
            inverse_transpose: inverse.transpose(),
        })
    }
}

#[inline(always)]
fn dot(a: &[f64; N], b: &[f64]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

impl Device {
    /// The switching functions of a stroke-plane device's blade elements at `y`: per wing
    /// `(ω_x, ω_y, ω_z)` of `ω = φ̇ (cos ψ, −sin ψ, 0) + ψ̇ ẑ` where the model switches (the
    /// stroke reversal, α = π/2 where the fit jumps, the rotational damping's `ω_z = 0`),
    /// `1` elsewhere.
    fn stroke_plane_switching_functions(
        &self,
        lean: &StrokePlane,
        y: &State,
        g: &mut [f64; MAX_SWITCHES],
    ) {
        let (x, x_dot) = (&y.coords[..N], &y.rates[..N]);
        for (w, wing) in self.spec.wings.iter().enumerate() {
            let [row_phi, row_psi] = &lean.rows[w];
            let phi_dot = dot(row_phi, x_dot);
            let psi = lean.offset[w][1] + dot(row_psi, x);
            let (s, c) = paritysim_simd::sin_cos(psi);
            let omega = Vector3::new(c * phi_dot, -s * phi_dot, dot(row_psi, x_dot));
            let values = match wing.aero().switching_blade() {
                Some(model) => model.switching_functions(&omega),
                None => [1.0; 3],
            };
            g[3 * w..3 * w + 3].copy_from_slice(&values);
        }
    }

    /// The right-hand side of a stroke-plane device ([`StrokePlane`]); the blade elements on
    /// `branches` when given (event location), else on the state's own sides.
    ///
    /// # Errors
    /// A drivetrain coordinate beyond the linkage's plausible range (reported by the general
    /// path); a reduced mass matrix that is not positive definite.
    #[inline]
    pub(super) fn rhs_stroke_plane(
        &self,
        lean: &StrokePlane,
        t: f64,
        y: &State,
        branches: Option<[Branch; 2]>,
        dydt: &mut State,
    ) -> Result<()> {
        let Some(step) = self.stroke_plane_step(lean, t, y, branches)? else {
            // The general path names the implausible coordinate.
            return self.rhs_null_space(t, y, dydt);
        };
        *dydt = State::default();
        for i in 0..N {
            dydt.coords[i] = y.rates[i];
            dydt.rates[i] = step.x_ddot[i];
        }
        dydt.work_actuator = self.actuator_power(t, step.force, &step.q_dot);
        dydt.work_aero = step.aero_power;
        Ok(())
    }

    /// The equations of [`Self::rhs_stroke_plane`] at `(t, y)` with what the lean samples
    /// read; `Ok(None)` for a drivetrain coordinate beyond the linkage's plausible range.
    #[inline(always)]
    fn stroke_plane_step(
        &self,
        lean: &StrokePlane,
        t: f64,
        y: &State,
        branches: Option<[Branch; 2]>,
    ) -> Result<Option<PlaneStep>> {
        let (x, x_dot) = (&y.coords[..N], &y.rates[..N]);
        let mut stroke = Vector2::zeros();
        let mut stroke_rate = Vector2::zeros();
        for w in 0..2 {
            stroke[w] = lean.offset[w][0] + dot(&lean.rows[w][0], x);
            stroke_rate[w] = dot(&lean.rows[w][0], x_dot);
        }
        let q = lean.inverse * stroke;
        if !(q.x.abs() <= paritysim_error::plausible::OFFSET_MM
            && q.y.abs() <= paritysim_error::plausible::ANGLE_RAD)
        {
            return Ok(None);
        }
        let q_dot = lean.inverse * stroke_rate;
        let (force, load, _) = self.drive_load(t, &q, &q_dot);
        let drive_torque = lean.inverse_transpose * load;
        let mut inverse_blocks = [[0.0; 3]; 2];
        let mut x_ddot = SVector::<f64, N>::zeros();
        let mut aero_power = 0.0;
        let mut wings = [PlaneWing::default(); 2];
        for (w, wing) in self.spec.wings.iter().enumerate() {
            let [row_phi, row_psi] = &lean.rows[w];
            let (phi, phi_dot) = (stroke[w], stroke_rate[w]);
            let psi = lean.offset[w][1] + dot(row_psi, x);
            let psi_dot = dot(row_psi, x_dot);
            let (s, c) = paritysim_simd::sin_cos(psi);
            let inertia = wing.inertia();
            let a = Vector3::new(c, -s, 0.0);
            let i_a = inertia * a;
            let i_z = inertia.column(2).into_owned();
            let omega = Vector3::new(c * phi_dot, -s * phi_dot, psi_dot);
            let i_omega = i_a * phi_dot + i_z * psi_dot;
            let jdot_pdot = Vector3::new(-s, -c, 0.0) * (phi_dot * psi_dot);
            // c = J6ᵀ (I J̇6ṗ + ω × Iω) (A.13), its φ and ψ rows.
            let v = inertia * jdot_pdot + omega.cross(&i_omega);
            let branch = branches.map(|b| b[w]);
            // The closed-form angle of attack on the branch's own side (and |ψ| < π/2); past
            // a surface the model's own continuation (measured: holding σ and continuing
            // α = π/2 + σψ there instead left rtol-1e-10 periods 1.5e-6 off).
            let own_side = branch.is_none_or(|b| {
                b.chordwise_positive == (omega.x >= 0.0) && b.normal_positive == (omega.y >= 0.0)
            });
            let tau = match wing.aero() {
                WingAero::BladeElement(model) if c > 0.0 && own_side => model
                    .moments_stroke_plane(phi_dot, psi, (s, c), psi_dot, branch)
                    .torque(),
                // The same closed form for Whitney & Wood's blade element, plus its rotational
                // lift (its added mass is in `inertia`).
                WingAero::WhitneyWood2010(model) if c > 0.0 && own_side => {
                    model
                        .blade()
                        .moments_stroke_plane(phi_dot, psi, (s, c), psi_dot, branch)
                        .torque()
                        + model.rotational_lift_torque(&omega, branch)
                }
                aero => aero.torque_about(phi_dot, &omega, &a, branch),
            };
            let (spring_phi, spring_psi) = wing.stroke_plane_springs(phi, psi);
            let aero_phi = a.dot(&tau);
            let f_phi = aero_phi - a.dot(&v) - spring_phi + drive_torque[w];
            let mut f_psi = tau.z - v.z - spring_psi;
            let hinge_damping = wing.hinge_damping();
            if hinge_damping != 0.0 {
                f_psi -= hinge_damping * psi_dot;
            }
            aero_power += aero_phi * phi_dot + tau.z * psi_dot;
            // B = J6ᵀ I J6 on (φ, ψ): aᵀ I a, aᵀ I ẑ, I_zz; (φ̈, ψ̈) = B⁻¹ f, ẍ += Sᵀ (φ̈, ψ̈).
            let (m_pp, m_ps, m_ss) = (a.dot(&i_a), i_a.z, inertia[(2, 2)]);
            let det = m_pp * m_ss - m_ps * m_ps;
            if !(m_pp > 0.0 && det > 0.0) {
                return Err(Error::Singular(format!(
                    "reduced mass matrix is not positive definite at x = {:?}",
                    &y.coords[..N]
                )));
            }
            let inverse = [m_ss / det, -m_ps / det, m_pp / det];
            let (phi_ddot, psi_ddot) = (
                inverse[0] * f_phi + inverse[1] * f_psi,
                inverse[1] * f_phi + inverse[2] * f_psi,
            );
            for i in 0..N {
                x_ddot[i] += row_phi[i] * phi_ddot + row_psi[i] * psi_ddot;
            }
            inverse_blocks[w] = inverse;
            wings[w] = PlaneWing {
                angles: (phi, psi),
                rates: (phi_dot, psi_dot),
                sin_cos_psi: (s, c),
                omega,
                i_a,
                i_omega,
                jdot_pdot,
                coriolis: v,
                aero: tau,
            };
        }
        Ok(Some(PlaneStep {
            inverse_blocks,
            x_ddot,
            q,
            q_dot,
            force,
            aero_power,
            wings,
        }))
    }
}

/// One wing of a [`PlaneStep`].
#[derive(Clone, Copy, Debug, Default)]
struct PlaneWing {
    /// `(φ, ψ)`, `(φ̇, ψ̇)` and `(sin ψ, cos ψ)`.
    angles: (f64, f64),
    rates: (f64, f64),
    sin_cos_psi: (f64, f64),
    /// `ω`, `I a`, `I ω`, `J̇6 ṗ`, `v = I J̇6 ṗ + ω × Iω` and the aerodynamic torque, in
    /// frame 6.
    omega: Vector3<f64>,
    i_a: Vector3<f64>,
    i_omega: Vector3<f64>,
    jdot_pdot: Vector3<f64>,
    coriolis: Vector3<f64>,
    aero: Vector3<f64>,
}

/// The stroke-plane equations at one state.
#[derive(Clone, Debug)]
struct PlaneStep {
    /// `B_w⁻¹` per wing (`[(0,0), (0,1), (1,1)]`): `M⁻¹ = Sᵀ B⁻¹ S` (see the module).
    inverse_blocks: [[f64; 3]; 2],
    x_ddot: SVector<f64, N>,
    q: Vector2<f64>,
    q_dot: Vector2<f64>,
    force: f64,
    aero_power: f64,
    wings: [PlaneWing; 2],
}

impl Device {
    /// The lean sample of a stroke-plane device (see [`crate::trajectory::PlaneSample`]):
    /// `None` when the device has no stroke-plane model or the state leaves its closed form
    /// (the caller takes the general [`crate::trajectory::Sample`], which reports why).
    ///
    /// # Errors
    /// A reduced mass matrix that is not positive definite.
    pub(crate) fn plane_sample(
        &self,
        t: f64,
        y: &State,
        needs: StrokeNeeds,
    ) -> Option<Result<PlaneSample>> {
        let lean = self.form.stroke_plane()?;
        let step = match self.stroke_plane_step(lean, t, y, None) {
            Ok(Some(step)) => step,
            Ok(None) => return None,
            Err(e) => return Some(Err(e)),
        };
        let mut sample = PlaneSample {
            time: t,
            needs,
            phi: [step.wings[0].angles.0, step.wings[1].angles.0],
            psi: [step.wings[0].angles.1, step.wings[1].angles.1],
            roll_aero: [0.0; 2],
            actuator_force: if needs.force { step.force } else { 0.0 },
            q2: step.q.y,
            torque: [Vector3::zeros(); 2],
            total: Vector3::zeros(),
            work: if needs.work {
                (y.work_actuator, y.work_aero)
            } else {
                (0.0, 0.0)
            },
        };
        let mirror = Vector3::new(-1.0, -1.0, 1.0);
        for (w, wing) in self.spec.wings.iter().enumerate() {
            let k = &step.wings[w];
            let (s, c) = k.sin_cos_psi;
            if !needs.torques {
                // The roll component of R_x(φ) R_z(ψ) τ: R_x keeps it.
                let roll = c * k.aero.x - s * k.aero.y;
                sample.roll_aero[w] = if w == 0 { -roll } else { roll };
                continue;
            }
            // τ_react = R6 (τ_aero⁶ − (I ω̇ + ω × Iω)), R6 = R_x(φ) R_z(ψ), and
            // ω̇ = J6 p̈ + J̇6 ṗ = φ̈ a + ψ̈ ẑ + J̇6 ṗ (θ ≡ 0).
            let [row_phi, row_psi] = &lean.rows[w];
            let x_ddot: [f64; N] = step.x_ddot.into();
            let (phi_ddot, psi_ddot) = (dot(row_phi, &x_ddot), dot(row_psi, &x_ddot));
            let inertia = wing.inertia();
            let omega_dot = Vector3::new(c * phi_ddot, -s * phi_ddot, psi_ddot) + k.jdot_pdot;
            let inertial6 = -(inertia * omega_dot + k.omega.cross(&k.i_omega));
            let (sp, cp) = k.angles.0.sin_cos();
            let rotate = |v: &Vector3<f64>| {
                let (u, v_) = (c * v.x - s * v.y, s * v.x + c * v.y);
                Vector3::new(u, cp * v_ - sp * v.z, sp * v_ + cp * v.z)
            };
            let (mut aero, mut inertial) = (rotate(&k.aero), rotate(&inertial6));
            if w == 0 {
                aero = aero.component_mul(&mirror);
                inertial = inertial.component_mul(&mirror);
            }
            sample.roll_aero[w] = aero.x;
            sample.torque[w] = aero + inertial;
            sample.total += sample.torque[w];
        }
        Some(Ok(sample))
    }
}

impl Device {
    /// The right-hand side `f = [ẋ, ẍ]` of [`Self::rhs_stroke_plane`] (the same numbers)
    /// into `f` and `J Φ` from the analytic Jacobian into `dphi` (`Φ` `8 × 8` by columns),
    /// the blade elements on `branches` as the right-hand side.
    ///
    /// With `M(x) ẍ = G(t, x, ẋ)`: `∂ẍ = M⁻¹ (∂G − (∂M) ẍ)`, where `M` depends on the hinge
    /// angles only (`∂(aᵀ I a)/∂ψ = 2 a'ᵀ I a`, `∂(I a)_z/∂ψ = (I a')_z`, `a' = ∂a/∂ψ`),
    /// each wing's `(f_φ, f_ψ)` on its own `(φ, ψ, φ̇, ψ̇)` (App. A: `v = φ̇ψ̇ I a' + ω × Iω`,
    /// the blade element's closed-form slopes, the springs' `V''`) and the drive couples the
    /// strokes through `J⁻ᵀ (∂Q/∂q) J⁻¹`. `None` where the right-hand side takes the general
    /// path (an implausible drivetrain coordinate; `cos ψ <= 0` off event location): the
    /// caller differentiates it numerically there.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn stroke_plane_variational(
        &self,
        lean: &StrokePlane,
        t: f64,
        y: &State,
        branches: Option<[Branch; 2]>,
        f: &mut [f64],
        phi: &[f64],
        dphi: &mut [f64],
    ) -> Option<Result<()>> {
        let step = match self.stroke_plane_step(lean, t, y, branches) {
            Ok(Some(step)) => step,
            Ok(None) => return None,
            Err(e) => return Some(Err(e)),
        };
        let x_ddot: [f64; N] = step.x_ddot.into();
        // The drive's rows on x and ẋ: the constant ones of a linear undamped drive, else
        // `J⁻ᵀ (∂Q/∂q) J⁻¹` at the state's q and `J⁻ᵀ (∂Q/∂q̇) J⁻¹`.
        let lossy_rows = (!lean.linear_drive).then(|| {
            let strokes = Vector2::new(step.wings[0].angles.0, step.wings[1].angles.0);
            let q = lean.inverse * strokes;
            let [s1, s2] = self.drive.slope([q.x, q.y]);
            let [d1, d2] = self.drive.damping();
            let on = |a: f64, b: f64| {
                let m = lean.inverse_transpose * Matrix2::new(a, 0.0, 0.0, b) * lean.inverse;
                [0, 1].map(|w| -> [f64; N] {
                    std::array::from_fn(|j| (0..2).map(|k| m[(w, k)] * lean.rows[k][0][j]).sum())
                })
            };
            (on(s1, s2), on(d1, d2))
        });
        let drive_rows = lossy_rows.as_ref().map_or(&lean.drive_rows, |rows| &rows.0);
        // ∂ẍ = Sᵀ B⁻¹ [∂f − (∂B) (φ̈, ψ̈)] per wing on [∂x | ∂ẋ] (see the module).
        let mut jacobian = SMatrix::<f64, N, { 2 * N }>::zeros();
        let z = Vector3::z();
        for (w, wing) in self.spec.wings.iter().enumerate() {
            let [row_phi, row_psi] = &lean.rows[w];
            let k = &step.wings[w];
            let ((phi, psi), (phi_dot, psi_dot), (s, c)) = (k.angles, k.rates, k.sin_cos_psi);
            let (omega, i_a, i_omega, v, tau) = (k.omega, k.i_a, k.i_omega, k.coriolis, k.aero);
            let inertia = wing.inertia();
            let a = Vector3::new(c, -s, 0.0);
            let a1 = Vector3::new(-s, -c, 0.0);
            let i_a1 = inertia * a1;
            let i_z = inertia.column(2).into_owned();
            // ∂v by φ̇, ψ̇ and ψ (a'' = −a).
            let v_phi_dot = i_a1 * psi_dot + a.cross(&i_omega) + omega.cross(&i_a);
            let v_psi_dot = i_a1 * phi_dot + z.cross(&i_omega) + omega.cross(&i_z);
            let v_psi = -(i_a * (phi_dot * psi_dot))
                + (a1 * phi_dot).cross(&i_omega)
                + omega.cross(&(i_a1 * phi_dot));
            let branch = branches.map(|b| b[w]);
            let [tau_phi_dot, tau_psi, tau_psi_dot] = match wing.aero() {
                WingAero::BladeElement(model) => {
                    model
                        .moments_stroke_plane_jacobian(phi_dot, psi, (s, c), psi_dot, branch)?
                        .1
                }
                WingAero::StrokeDrag {
                    omega1,
                    coefficient,
                } => {
                    // τ = −Ω C |φ̇| φ̇ a (eq. 2.16).
                    let drag = paritysim_aero::stroke_drag_constant(*omega1, *coefficient);
                    let m = paritysim_aero::stroke_drag_torque(drag, phi_dot);
                    let slope = paritysim_aero::stroke_drag_slope(drag, phi_dot);
                    [a * slope, a1 * m, Vector3::zeros()]
                }
                WingAero::None => [Vector3::zeros(); 3],
                WingAero::WhitneyWood2010(model) => {
                    let blade = model
                        .blade()
                        .moments_stroke_plane_jacobian(phi_dot, psi, (s, c), psi_dot, branch)?
                        .1;
                    let lift = model.rotational_lift_stroke_plane_slopes(phi_dot, &omega, branch);
                    [0, 1, 2].map(|k| blade[k] + lift[k])
                }
            };
            let (spring_phi, spring_psi) = wing.stroke_plane_spring_slopes(phi, psi);
            // Rows f_φ = a·τ − a·v − V_φ + τ_drive, f_ψ = τ_z − v_z − V_ψ; columns φ, ψ, φ̇, ψ̇.
            let f_phi = [
                -spring_phi,
                a1.dot(&tau) + a.dot(&tau_psi) - a1.dot(&v) - a.dot(&v_psi),
                a.dot(&tau_phi_dot) - a.dot(&v_phi_dot),
                a.dot(&tau_psi_dot) - a.dot(&v_psi_dot),
            ];
            let f_psi = [
                0.0,
                tau_psi.z - v_psi.z - spring_psi,
                tau_phi_dot.z - v_phi_dot.z,
                tau_psi_dot.z - v_psi_dot.z - wing.hinge_damping(),
            ];
            let (dm_pp, dm_ps) = (a1.dot(&i_a) + a.dot(&i_a1), i_a1.z);
            let (phi_ddot, psi_ddot) = (dot(row_phi, &x_ddot), dot(row_psi, &x_ddot));
            // (∂M/∂ψ) ẍ on the wing's (φ, ψ) rows.
            let (dm_phi, dm_psi) = (dm_pp * phi_ddot + dm_ps * psi_ddot, dm_ps * phi_ddot);
            // The wing's rows by the reduced coordinates: (φ, ψ) ← x, (φ̇, ψ̇) ← ẋ.
            let mut local = [[0.0; 2 * N]; 2];
            for j in 0..N {
                let (rj, sj) = (row_phi[j], row_psi[j]);
                local[0][j] = f_phi[0] * rj + (f_phi[1] - dm_phi) * sj + drive_rows[w][j];
                local[1][j] = f_psi[0] * rj + (f_psi[1] - dm_psi) * sj;
                local[0][N + j] = f_phi[2] * rj + f_phi[3] * sj;
                local[1][N + j] = f_psi[2] * rj + f_psi[3] * sj;
            }
            if let Some((_, rate_rows)) = &lossy_rows {
                for j in 0..N {
                    local[0][N + j] += rate_rows[w][j];
                }
            }
            let [b00, b01, b11] = step.inverse_blocks[w];
            for j in 0..2 * N {
                let (u, v) = (local[0][j], local[1][j]);
                let (phi_part, psi_part) = (b00 * u + b01 * v, b01 * u + b11 * v);
                for i in 0..N {
                    jacobian[(i, j)] += row_phi[i] * phi_part + row_psi[i] * psi_part;
                }
            }
        }
        let m = 2 * N;
        f[..N].copy_from_slice(&y.rates[..N]);
        f[N..m].copy_from_slice(&x_ddot);
        for (column, out) in phi.chunks_exact(m).zip(dphi.chunks_exact_mut(m)).take(m) {
            out[..N].copy_from_slice(&column[N..m]);
            for i in 0..N {
                let mut sum = 0.0;
                for j in 0..m {
                    sum += jacobian[(i, j)] * column[j];
                }
                out[N + i] = sum;
            }
        }
        Some(Ok(()))
    }
}

impl Equations for StrokePlane {
    #[inline]
    fn rhs(
        &self,
        device: &Device,
        t: f64,
        y: &State,
        branches: Option<[Branch; 2]>,
        dydt: &mut State,
    ) -> Result<()> {
        device.rhs_stroke_plane(self, t, y, branches, dydt)
    }

    fn switches(&self, device: &Device, y: &State, g: &mut [f64; MAX_SWITCHES]) -> Result<()> {
        device.stroke_plane_switching_functions(self, y, g);
        Ok(())
    }

    fn variational(
        &self,
        device: &Device,
        t: f64,
        y: &State,
        branches: Option<[Branch; 2]>,
        n: usize,
        rhs: Option<&mut [f64]>,
        phi: &[f64],
        dphi: &mut [f64],
    ) -> Option<Result<()>> {
        if n != device.n_dof {
            return None;
        }
        let mut own = [0.0; 2 * N];
        let f = rhs.unwrap_or(&mut own);
        device.stroke_plane_variational(self, t, y, branches, f, phi, dphi)
    }
}

#[cfg(test)]
mod tests;
