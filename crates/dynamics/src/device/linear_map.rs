//! The drivetrain-coordinate equations of the linear differential map (eq. 2.15) and their
//! analytic Jacobian, written once for both scalar (`f64`) and SIMD-lane (`wide::f64x4`)
//! arithmetic.
//!
//! With `φ_k = J_k q` constant in `q`, `M_q = Σ_k I_k J_kᵀ J_k` constant and no velocity
//! product, the equations are `M_q q̈ = g(t, q, q̇)`,
//! `g = (F(t) − K1 q1, −K2 q2) + Σ_k J_kᵀ τ_k`, `τ_k = τ_aero,k(φ̇_k) − s_k(φ_k)` (the wing's
//! stroke torque: the stroke drag of eq. 2.16 `−Ω_k C φ̇_k |φ̇_k|` or a fixed blade element, and
//! the stroke spring, A.7). So, with stroke drag,
//! `∂g/∂q = −diag(K1, K2) − Σ_k s_k'(φ_k) J_kᵀ J_k` and
//! `∂g/∂q̇ = Σ_k (−2 Ω_k C |φ̇_k|) J_kᵀ J_k`, and the variational equations
//! `Φ̇ = J Φ` of the state `(q, q̇)` are, per column `(u, v)` of `Φ`: `u̇ = v`,
//! `v̇ = M_q⁻¹ (∂g/∂q u + ∂g/∂q̇ v)`.
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
    /// The drive's springs (a single drive: the linear map is never dual).
    pub(crate) drive: DriveSprings<S>,
}

impl LinearMapTerms<f64> {
    /// The constants of `spec`, or `None` unless it is a two-DOF linear differential (not a
    /// dual drive) on two wings.
    pub(crate) fn of(spec: &DeviceSpec) -> Option<Self> {
        let transmission = spec.transmission.as_ref()?;
        let Drivetrain::LinearDifferential(d) = transmission.kinematics() else {
            return None;
        };
        if spec.wings.len() != 2 || transmission.kinematics().dof() != 2 {
            return None;
        }
        let t = d.transmission_ratio();
        let (hl, hr) = d.arms();
        // As `LinearDifferential::evaluate` builds it.
        let jacobian = [-t, t * hl, -t, -t * hr];
        let (mut m00, mut m01, mut m11) = (0.0, 0.0, 0.0);
        let mut drag = [0.0; 2];
        let mut analytic = true;
        let (mut stiffness, mut cubic, mut rest) = ([0.0; 2], [0.0; 2], [0.0; 2]);
        for (k, wing) in spec.wings.iter().enumerate() {
            let (a, b) = (jacobian[2 * k], jacobian[2 * k + 1]);
            let inertia = wing.inertia()[(0, 0)];
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
            drive: DriveSprings::of(spec, false),
        })
    }
}

/// `(q̈, aerodynamic power)` of `M_q q̈ = g` at the state `y = (q1, q2, q̇1, q̇2)` and the
/// actuator force `force`, with wing `k`'s aerodynamic stroke torque `aero(k, φ̇_k)` (see the
/// module); `M_q` is solved by Cramer's rule.
#[inline(always)]
pub(crate) fn accelerations<S: Real>(
    terms: &LinearMapTerms<S>,
    force: S,
    y: &[S; 4],
    aero: impl Fn(usize, S) -> S,
) -> ([S; 2], S) {
    let [q1, q2, q1_dot, q2_dot] = *y;
    let [j00, j01, j10, j11] = terms.jacobian;
    let [mut g0, mut g1] = terms.drive.load([force, S::splat(0.0)], [q1, q2]);
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

/// `dphi = J(y) phi` for the state `y = (q1, q2, q̇1, q̇2)` and the four columns of `phi`
/// (4 × 4, by columns): the variational equations (see the module). The Jacobian does not
/// depend on time (the actuator force only enters `g` additively).
#[inline(always)]
pub(crate) fn variational<S: Real>(
    terms: &LinearMapTerms<S>,
    y: &[S; 4],
    phi: &[S],
    dphi: &mut [S],
) {
    let [q1, q2, q1_dot, q2_dot] = *y;
    let [j00, j01, j10, j11] = terms.jacobian;
    let rows = [(j00, j01), (j10, j11)];
    // ∂g/∂q and ∂g/∂q̇, symmetric: entries (00, 01, 11).
    let zero = S::splat(0.0);
    let [slope1, slope2] = terms.drive.slope();
    let (mut gq00, mut gq01, mut gq11) = (slope1, zero, slope2);
    let (mut gv00, mut gv01, mut gv11) = (zero, zero, zero);
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
