//! The drivetrain-coordinate equations of the linear differential map (eq. 2.15) and their
//! analytic Jacobian, written once for both scalar (`f64`) and SIMD-lane (`wide::f64x4`)
//! arithmetic.
//!
//! With `φ_k = J_k q` constant in `q`, `M_q = diag(m) + Σ_k I_k J_kᵀ J_k` constant (`m` the
//! actuator's effective mass on each drive) and no velocity product, the equations are
//! `M_q q̈ = g(t, q, q̇)`, `g = Q(t, q, q̇) + Σ_k J_kᵀ τ_k` with the drive load `Q` of `drive.rs`
//! (`(F − K1 q1 − K1c q1³ − b1 q̇1, P − K2 q2 − K2c q2³ − b2 q̇2)`),
//! `τ_k = τ_aero,k(φ̇_k) − s_k(φ_k)` (the wing's
//! stroke torque: the stroke drag of eq. 2.16 `−Ω_k C φ̇_k |φ̇_k|` or a fixed blade element, and
//! the stroke spring, A.7). So, with stroke drag,
//! `∂g/∂q = ∂Q/∂q − Σ_k s_k'(φ_k) J_kᵀ J_k` (`∂Q/∂q = −diag(K1 + 3K1c q1², K2 + 3K2c q2²)`) and
//! `∂g/∂q̇ = −diag(b1, b2) + Σ_k (−2 Ω_k C |φ̇_k|) J_kᵀ J_k`, and the variational equations
//! `Φ̇ = J Φ` of the state `(q, q̇)` are, per column `(u, v)` of `Φ`: `u̇ = v`,
//! `v̇ = M_q⁻¹ (∂g/∂q u + ∂g/∂q̇ v)`.
//!
//! **Polynomial transmissions** (issue 35): with `φ_k = P(ℓ_k)`, `ℓ_k = J_k q` (the linear
//! stroke, [`paritysim_kinematics::OddPolynomial`]), `φ̇_k = P' ℓ̇_k`, the mass matrix
//! `M_q = Σ_k I_k P'² J_kᵀ J_k` depends on `q` and the velocity product enters the torque:
//! `g = Q + Σ_k J_kᵀ P' (τ_k − I_k P'' ℓ̇_k²)`. Its Jacobian adds, per wing, the derivatives of
//! `e_k = P' (τ_k − I_k P'' ℓ̇²)` in `ℓ_k` and `ℓ̇_k` and `−∂M/∂ℓ_k q̈ = −2 I_k P' P'' (J_k q̈) J_kᵀ`.
//! Both are written so that zero coefficients (`P = ℓ`, `P' = 1`, `P'' = 0`) reproduce the
//! linear map's operations bit for bit (tested).
//!
//! **Dual drives** (`dual_linear`): `J = −T I`, a drive per wing (`DriveSprings` dual): the same
//! equations with the forces `(F_L, F_R)`.
//!
//! Why generic: the scalar path (`Device`'s drivetrain-coordinate form) and the lanes
//! (`lanes::linear_stroke`) call these functions, so a lane's derivative and monodromy are
//! bit-identical to the scalar ones with no mirrored code to keep in step.

use paritysim_simd::Real;

use super::DeviceSpec;
use super::drive::DriveSprings;
use crate::wing::WingAero;
use paritysim_kinematics::Drivetrain;

/// The constants of the linear-map equations (one device, or one device per lane).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LinearMapTerms<S: Real> {
    /// `J` by rows: `(J00, J01, J10, J11)` (row `k` is wing `k`'s `J_k`).
    pub(crate) jacobian: [S; 4],
    /// `M_q` entries `(m00, m01, m11)`.
    pub(crate) mass: [S; 3],
    /// `det M_q`.
    pub(crate) det: S,
    /// `−Ω1 C` per wing (0 without aerodynamics or with a blade element).
    pub(crate) drag: [S; 2],
    /// Whether every wing has stroke drag or no aerodynamics: the torque is
    /// [`paritysim_aero::stroke_drag_torque`] of `drag` and [`variational`] is the Jacobian.
    pub(crate) analytic: bool,
    /// Stroke springs per wing: linear stiffness, cubic coefficient, rest angle.
    pub(crate) stiffness: [S; 2],
    pub(crate) cubic: [S; 2],
    pub(crate) rest: [S; 2],
    /// The drive's springs (dual for `dual_linear`).
    pub(crate) drive: DriveSprings<S>,
    /// Whether the transmission is a polynomial (else `poly` and `inertia` are unused and `M_q`
    /// is the constant `mass`).
    pub(crate) polynomial: bool,
    /// The polynomial's coefficients `(b3, b5, b7, b9)` of `ℓ³, ℓ⁵, ℓ⁷, ℓ⁹`.
    pub(crate) poly: [S; 4],
    /// Stroke inertia `I_k` per wing (mg·mm²).
    pub(crate) inertia: [S; 2],
}

impl LinearMapTerms<f64> {
    /// The constants of `spec`, or `None` unless it is a two-DOF linear differential or a
    /// linear drive per wing (`dual_linear`), linear or polynomial, on two wings.
    pub(crate) fn of(spec: &DeviceSpec, drive: &DriveSprings<f64>) -> Option<Self> {
        let transmission = spec.transmission.as_ref()?;
        let (rows, polynomial) = match transmission.kinematics() {
            Drivetrain::LinearDifferential(d) => (d.rows(), d.polynomial()),
            Drivetrain::DualLinear(d) => (d.rows(), d.polynomial()),
            _ => return None,
        };
        if spec.wings.len() != 2 || transmission.kinematics().dof() != 2 {
            return None;
        }
        // As `LinearDifferential::evaluate` builds it.
        let jacobian = [rows[0][0], rows[0][1], rows[1][0], rows[1][1]];
        let mut inertias = [0.0; 2];
        let drive = *drive;
        // The actuator's effective mass on each drive (0 by default: the sums are today's bits).
        let [mass1, mass2] = drive.masses();
        let (mut m00, mut m01, mut m11) = (mass1, 0.0, mass2);
        let mut drag = [0.0; 2];
        let mut analytic = true;
        let (mut stiffness, mut cubic, mut rest) = ([0.0; 2], [0.0; 2], [0.0; 2]);
        for (k, wing) in spec.wings.iter().enumerate() {
            let (a, b) = (jacobian[2 * k], jacobian[2 * k + 1]);
            let inertia = wing.inertia()[(0, 0)];
            inertias[k] = inertia;
            m00 += inertia * a * a;
            m01 += inertia * a * b;
            m11 += inertia * b * b;
            drag[k] = match wing.aero() {
                WingAero::None => 0.0,
                WingAero::StrokeDrag {
                    omega1,
                    coefficient,
                } => paritysim_aero::stroke_drag_constant(*omega1, *coefficient),
                WingAero::BladeElement(_) | WingAero::WhitneyWood2010(_) => {
                    analytic = false;
                    0.0
                }
            };
            let s = &wing.springs()[0];
            (stiffness[k], cubic[k], rest[k]) = (s.stiffness(), s.cubic(), s.rest_angle());
        }
        Some(Self {
            jacobian,
            mass: [m00, m01, m11],
            det: m00 * m11 - m01 * m01,
            drag,
            analytic,
            stiffness,
            cubic,
            rest,
            drive,
            polynomial: !polynomial.is_linear(),
            poly: polynomial.coefficients(),
            inertia: inertias,
        })
    }
}

/// `(P, P', P'', P‴)` of the polynomial `poly` at the linear stroke `l`
/// ([`paritysim_kinematics::OddPolynomial::evaluate`]'s operations, and the third derivative).
#[inline(always)]
fn polynomial<S: Real>(poly: &[S; 4], l: S) -> (S, S, S, S) {
    let [b3, b5, b7, b9] = *poly;
    let c = |x: f64| S::splat(x);
    let one = c(1.0);
    let l2 = l * l;
    let p = l * (one + l2 * (b3 + l2 * (b5 + l2 * (b7 + l2 * b9))));
    let p1 =
        one + l2 * (c(3.0) * b3 + l2 * (c(5.0) * b5 + l2 * (c(7.0) * b7 + l2 * (c(9.0) * b9))));
    let p2 = l * (c(6.0) * b3 + l2 * (c(20.0) * b5 + l2 * (c(42.0) * b7 + l2 * (c(72.0) * b9))));
    let p3 = c(6.0) * b3 + l2 * (c(60.0) * b5 + l2 * (c(210.0) * b7 + l2 * (c(504.0) * b9)));
    (p, p1, p2, p3)
}

/// `(q̈, aerodynamic power)` of `M_q q̈ = g` at the state `y = (q1, q2, q̇1, q̇2)` and the
/// drive forces `forces` (the actuator's and 0, or a dual drive's left and right), with wing
/// `k`'s aerodynamic stroke torque `aero(k, φ̇_k)` (see the module); `M_q` is solved by
/// Cramer's rule.
#[inline(always)]
pub(crate) fn accelerations<S: Real>(
    terms: &LinearMapTerms<S>,
    forces: [S; 2],
    y: &[S; 4],
    aero: impl Fn(usize, S) -> S,
) -> ([S; 2], S) {
    if terms.polynomial {
        let (q_ddot, aero_power, _, _) = polynomial_accelerations(terms, forces, y, aero);
        return (q_ddot, aero_power);
    }
    let [q1, q2, q1_dot, q2_dot] = *y;
    let [j00, j01, j10, j11] = terms.jacobian;
    let [mut g0, mut g1] = terms.drive.load(forces, [q1, q2], [q1_dot, q2_dot]);
    let mut aero_power = S::splat(0.0);
    for (k, (a, b)) in [(j00, j01), (j10, j11)].into_iter().enumerate() {
        let stroke = a * q1 + b * q2;
        let rate = a * q1_dot + b * q2_dot;
        let tau_aero = aero(k, rate);
        let d = stroke - terms.rest[k];
        let tau = tau_aero - (terms.stiffness[k] * d + terms.cubic[k] * d * d * d);
        g0 = g0 + a * tau;
        g1 = g1 + b * tau;
        aero_power = aero_power + tau_aero * rate;
    }
    let [m00, m01, m11] = terms.mass;
    let det = terms.det;
    (
        [(m11 * g0 - m01 * g1) / det, (m00 * g1 - m01 * g0) / det],
        aero_power,
    )
}

/// [`accelerations`] of a polynomial transmission, with `M_q` (entries `(m00, m01, m11)`) and
/// its determinant at `y`. With zero coefficients every operation is the linear map's
/// (`P' = 1` and `P'' = 0` exactly), so the result is its bits.
#[inline(always)]
pub(crate) fn polynomial_accelerations<S: Real>(
    terms: &LinearMapTerms<S>,
    forces: [S; 2],
    y: &[S; 4],
    aero: impl Fn(usize, S) -> S,
) -> ([S; 2], S, [S; 3], S) {
    let [q1, q2, q1_dot, q2_dot] = *y;
    let [j00, j01, j10, j11] = terms.jacobian;
    let [mut g0, mut g1] = terms.drive.load(forces, [q1, q2], [q1_dot, q2_dot]);
    let zero = S::splat(0.0);
    let [mass1, mass2] = terms.drive.lane_masses();
    let (mut m00, mut m01, mut m11) = (mass1, zero, mass2);
    let mut aero_power = zero;
    for (k, (a, b)) in [(j00, j01), (j10, j11)].into_iter().enumerate() {
        let l = a * q1 + b * q2;
        let l_dot = a * q1_dot + b * q2_dot;
        let (stroke, p1, p2, _) = polynomial(&terms.poly, l);
        let rate = p1 * l_dot;
        let tau_aero = aero(k, rate);
        let d = stroke - terms.rest[k];
        let inertia = terms.inertia[k];
        let tau = tau_aero
            - (terms.stiffness[k] * d + terms.cubic[k] * d * d * d)
            - inertia * p2 * l_dot * l_dot;
        let e = p1 * tau;
        g0 = g0 + a * e;
        g1 = g1 + b * e;
        let w = inertia * p1 * p1;
        m00 = m00 + w * a * a;
        m01 = m01 + w * a * b;
        m11 = m11 + w * b * b;
        aero_power = aero_power + tau_aero * rate;
    }
    let det = m00 * m11 - m01 * m01;
    (
        [(m11 * g0 - m01 * g1) / det, (m00 * g1 - m01 * g0) / det],
        aero_power,
        [m00, m01, m11],
        det,
    )
}

/// `dphi = J(y) phi` for the state `y = (q1, q2, q̇1, q̇2)` and the four columns of `phi`
/// (4 × 4, by columns): the variational equations (see the module). The Jacobian does not
/// depend on time on the linear map (the actuator force only enters `g` additively); a
/// polynomial transmission's does, through `∂M/∂q q̈`, so it takes the drive forces.
#[inline(always)]
pub(crate) fn variational<S: Real>(
    terms: &LinearMapTerms<S>,
    forces: [S; 2],
    y: &[S; 4],
    phi: &[S],
    dphi: &mut [S],
) {
    if terms.polynomial {
        polynomial_variational(terms, forces, y, phi, dphi);
        return;
    }
    let [q1, q2, q1_dot, q2_dot] = *y;
    let [j00, j01, j10, j11] = terms.jacobian;
    let rows = [(j00, j01), (j10, j11)];
    // ∂g/∂q and ∂g/∂q̇, symmetric: entries (00, 01, 11).
    let zero = S::splat(0.0);
    let [slope1, slope2] = terms.drive.slope([q1, q2]);
    let [damping1, damping2] = terms.drive.damping();
    let (mut gq00, mut gq01, mut gq11) = (slope1, zero, slope2);
    let (mut gv00, mut gv01, mut gv11) = (damping1, zero, damping2);
    for (k, (a, b)) in rows.into_iter().enumerate() {
        let stroke = a * q1 + b * q2;
        let rate = a * q1_dot + b * q2_dot;
        let d = stroke - terms.rest[k];
        // s'(φ) of A.7 with the cubic term; ∂(−Ω C φ̇|φ̇|)/∂φ̇ = −2 Ω C |φ̇| (eq. 2.16).
        let spring = terms.stiffness[k] + S::splat(3.0) * terms.cubic[k] * d * d;
        let damping = paritysim_aero::stroke_drag_slope(terms.drag[k], rate);
        gq00 = gq00 - spring * a * a;
        gq01 = gq01 - spring * a * b;
        gq11 = gq11 - spring * b * b;
        gv00 = gv00 + damping * a * a;
        gv01 = gv01 + damping * a * b;
        gv11 = gv11 + damping * b * b;
    }
    let [m00, m01, m11] = terms.mass;
    for c in 0..4 {
        let v = &phi[4 * c..4 * c + 4];
        let w0 = gq00 * v[0] + gq01 * v[1] + gv00 * v[2] + gv01 * v[3];
        let w1 = gq01 * v[0] + gq11 * v[1] + gv01 * v[2] + gv11 * v[3];
        let out = &mut dphi[4 * c..4 * c + 4];
        out[0] = v[2];
        out[1] = v[3];
        // Cramer's rule on M_q, as the right-hand side solves it.
        out[2] = (m11 * w0 - m01 * w1) / terms.det;
        out[3] = (m00 * w1 - m01 * w0) / terms.det;
    }
}

/// [`variational`] of a polynomial transmission (see the module): per wing,
/// `α = ∂e/∂ℓ − 2 I P' P'' (J_k q̈)` and `β = ∂e/∂ℓ̇` with `e = P' (τ − I P'' ℓ̇²)`,
/// `∂τ/∂ℓ = τ_a' P'' ℓ̇ − s' P' − I P‴ ℓ̇²`, `∂τ/∂ℓ̇ = τ_a' P' − 2 I P'' ℓ̇` (`τ_a'` the stroke
/// drag's slope, `s'` the stroke spring's); `∂g/∂q = diag(slope) + Σ α J_kᵀ J_k`,
/// `∂g/∂q̇ = Σ β J_kᵀ J_k`, solved with `M_q(q)`.
#[inline(always)]
fn polynomial_variational<S: Real>(
    terms: &LinearMapTerms<S>,
    forces: [S; 2],
    y: &[S; 4],
    phi: &[S],
    dphi: &mut [S],
) {
    let drag = terms.drag;
    let (q_ddot, _, [m00, m01, m11], det) =
        polynomial_accelerations(terms, forces, y, |k, rate| {
            paritysim_aero::stroke_drag_torque(drag[k], rate)
        });
    let [q1, q2, q1_dot, q2_dot] = *y;
    let [j00, j01, j10, j11] = terms.jacobian;
    let zero = S::splat(0.0);
    let two = S::splat(2.0);
    let [slope1, slope2] = terms.drive.slope([q1, q2]);
    let [damping1, damping2] = terms.drive.damping();
    let (mut gq00, mut gq01, mut gq11) = (slope1, zero, slope2);
    let (mut gv00, mut gv01, mut gv11) = (damping1, zero, damping2);
    for (k, (a, b)) in [(j00, j01), (j10, j11)].into_iter().enumerate() {
        let l = a * q1 + b * q2;
        let l_dot = a * q1_dot + b * q2_dot;
        let (stroke, p1, p2, p3) = polynomial(&terms.poly, l);
        let rate = p1 * l_dot;
        let inertia = terms.inertia[k];
        let tau_aero = paritysim_aero::stroke_drag_torque(drag[k], rate);
        let damping = paritysim_aero::stroke_drag_slope(drag[k], rate);
        let d = stroke - terms.rest[k];
        let spring = terms.stiffness[k] * d + terms.cubic[k] * d * d * d;
        let spring_slope = terms.stiffness[k] + S::splat(3.0) * terms.cubic[k] * d * d;
        let tau = tau_aero - spring - inertia * p2 * l_dot * l_dot;
        let dtau_dl = damping * p2 * l_dot - spring_slope * p1 - inertia * p3 * l_dot * l_dot;
        let dtau_dv = damping * p1 - two * inertia * p2 * l_dot;
        let accel = a * q_ddot[0] + b * q_ddot[1];
        let alpha = p2 * tau + p1 * dtau_dl - two * inertia * p1 * p2 * accel;
        let beta = p1 * dtau_dv;
        gq00 = gq00 + alpha * a * a;
        gq01 = gq01 + alpha * a * b;
        gq11 = gq11 + alpha * b * b;
        gv00 = gv00 + beta * a * a;
        gv01 = gv01 + beta * a * b;
        gv11 = gv11 + beta * b * b;
    }
    for c in 0..4 {
        let v = &phi[4 * c..4 * c + 4];
        let w0 = gq00 * v[0] + gq01 * v[1] + gv00 * v[2] + gv01 * v[3];
        let w1 = gq01 * v[0] + gq11 * v[1] + gv01 * v[2] + gv11 * v[3];
        let out = &mut dphi[4 * c..4 * c + 4];
        out[0] = v[2];
        out[1] = v[3];
        out[2] = (m11 * w0 - m01 * w1) / det;
        out[3] = (m00 * w1 - m01 * w0) / det;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wing::{JointSpring, Wing};
    use nalgebra::{Matrix3, Vector3};
    use paritysim_constraints::Constraints;
    use paritysim_kinematics::SphericalShoulder;
    use paritysim_kinematics::drivetrain::LinearDifferential;

    /// Unequal sprung wings with stroke drag on the §3.3 linear map, and its terms.
    fn terms(dual: bool) -> LinearMapTerms<f64> {
        let wing = |inertia: f64, omega: f64, rest: f64| {
            let mut s = [JointSpring::default(); 6];
            s[0] = JointSpring::nonlinear(40.0, 25.0, rest).unwrap();
            Wing::new(
                SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0).unwrap(),
                Matrix3::from_diagonal(&Vector3::new(inertia, inertia, 1.0)),
                s,
                WingAero::stroke_drag(omega, 1.0).unwrap(),
            )
            .unwrap()
        };
        let kinematics = if dual {
            Drivetrain::DualLinear(
                paritysim_kinematics::drivetrain::DualLinear::new(
                    2.67,
                    paritysim_kinematics::OddPolynomial::LINEAR,
                )
                .unwrap(),
            )
        } else {
            Drivetrain::LinearDifferential(LinearDifferential::new(2.5, 2.5, 0.8).unwrap())
        };
        let spec = DeviceSpec {
            wings: vec![wing(24.0, 17.0, 0.1), wing(31.0, 31.3, -0.2)],
            constraints: Constraints::configuration("drag_parity_fixed").unwrap(),
            transmission: Some(super::super::Transmission::new(kinematics, 35.0).unwrap()),
            actuator: Some(crate::Actuator::thesis(
                crate::Waveform::sine(50.0, 110.0, 0.0, 0.0).unwrap(),
            )),
            formulation: super::super::Formulation::Auto,
        };
        let dual = spec.transmission.as_ref().unwrap().kinematics().is_dual();
        LinearMapTerms::of(&spec, &DriveSprings::of(&spec, dual)).unwrap()
    }

    /// The polynomial equations with zero coefficients are the linear map's bit for bit: the
    /// right-hand side, the aerodynamic power and the variational equations, on random states
    /// (so τ2 = 0 reproduces the linear map whichever path a device takes).
    #[test]
    fn zero_coefficients_give_the_linear_map_bit_for_bit() {
        for dual in [false, true] {
            let linear = terms(dual);
            assert!(!linear.polynomial);
            let zero = LinearMapTerms {
                polynomial: true,
                ..linear
            };
            let mut seed = 7u64;
            let mut uniform = || {
                seed = seed
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                (seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
            };
            for _ in 0..500 {
                let y = [
                    0.2 * uniform(),
                    0.1 * uniform(),
                    2.0 * uniform(),
                    1.0 * uniform(),
                ];
                let forces = [60.0 * uniform(), 40.0 * uniform()];
                let drag = linear.drag;
                let aero = |k: usize, rate: f64| paritysim_aero::stroke_drag_torque(drag[k], rate);
                let (a, pa) = accelerations(&linear, forces, &y, aero);
                let (b, pb) = accelerations(&zero, forces, &y, aero);
                assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "{y:?}");
                assert_eq!(pa.to_bits(), pb.to_bits());
                let phi: Vec<f64> = (0..16).map(|_| uniform()).collect();
                let (mut da, mut db) = ([0.0; 16], [0.0; 16]);
                variational(&linear, forces, &y, &phi, &mut da);
                variational(&zero, forces, &y, &phi, &mut db);
                assert_eq!(da.map(f64::to_bits), db.map(f64::to_bits), "{y:?}");
            }
        }
    }
}
