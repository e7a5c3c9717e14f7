//! The torque-only stroke drag of eq. 2.16, `τ = −Ω1 C |φ̇| φ̇` about the stroke axis, written
//! once over [`Real`] (scalar and SIMD lanes): the drivetrain-coordinate and stroke-plane
//! right-hand sides, their Jacobians, the lanes and the flight wrench all call it.

use paritysim_simd::Real;

/// The drag constant `−Ω1 C` (mN·mm·ms²) of a wing with `omega1` (mg/mm, eq. 3.12) and drag
/// `coefficient`.
#[inline(always)]
pub fn stroke_drag_constant(omega1: f64, coefficient: f64) -> f64 {
    -omega1 * coefficient
}

/// `τ = drag · speed · φ̇` (mN·mm) with `drag = −Ω1 C` ([`stroke_drag_constant`]) and `speed`
/// the held branch's `|φ̇|`: `φ̇` or `−φ̇` on a branch held through a stroke reversal (event
/// location), else `|φ̇|` ([`stroke_drag_torque`]).
#[inline(always)]
pub fn stroke_drag<R: Real>(drag: R, speed: R, phi_dot: R) -> R {
    drag * speed * phi_dot
}

/// eq. 2.16: `τ = −Ω1 C |φ̇| φ̇` (mN·mm) from `drag = −Ω1 C` and the stroke rate `φ̇` (rad/ms).
#[inline(always)]
pub fn stroke_drag_torque<R: Real>(drag: R, phi_dot: R) -> R {
    stroke_drag(drag, phi_dot.abs(), phi_dot)
}

/// `∂τ/∂φ̇ = −2 Ω1 C |φ̇|` of [`stroke_drag_torque`].
#[inline(always)]
pub fn stroke_drag_slope<R: Real>(drag: R, phi_dot: R) -> R {
    R::splat(2.0) * drag * phi_dot.abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The torque opposes the motion, is quadratic in the rate, and its slope is the central
    /// difference of the torque.
    #[test]
    fn stroke_drag_opposes_motion_and_its_slope_is_the_derivative() {
        let drag = stroke_drag_constant(2.5, 1.2);
        for phi_dot in [-3.0, -0.4, 0.7, 5.0] {
            let tau: f64 = stroke_drag_torque(drag, phi_dot);
            assert!(tau * phi_dot < 0.0);
            assert!(
                (stroke_drag_torque(drag, 2.0 * phi_dot) - 4.0 * tau).abs() <= 1e-12 * tau.abs()
            );
            let h = 1e-6;
            let fd = (stroke_drag_torque(drag, phi_dot + h)
                - stroke_drag_torque(drag, phi_dot - h))
                / (2.0 * h);
            assert!((stroke_drag_slope(drag, phi_dot) - fd).abs() <= 1e-6 * fd.abs());
        }
    }
}
