//! The wings' aerodynamic forces at a sample, in the body frame (the force metrics and
//! columns): the blade-element force of the aero law's one home
//! ([`paritysim_aero::wing_aero::wrench`], the same function free flight evaluates) on a
//! shoulder at rest, `R_6^1 (F_L + F_D)` in the wing's shoulder ground frame, the left wing's
//! mirrored through the sagittal plane (`z → −z`, as its torques), so that every wing's force
//! is in the one body frame: `x̂` the stroke axis, the **lift** axis (up in hover), `ŷ` the
//! wing normal at rest (fore-aft), `ẑ` spanwise toward the right wing.
//!
//! Only wings with a force model give forces: the blade element with its force parameter
//! `½ρ∬z²dA` (the spec sets `Ω1 / body.force_radius_mm`) and wings without aerodynamics
//! (zero). The stroke drag of eq. 2.16 is a torque about the stroke axis with no force, so a
//! device with a stroke-drag wing offers no force metric ([`offers_forces`]).

use nalgebra::{Matrix3, Vector3};
use paritysim_aero::WingAero;
use paritysim_error::Result;

use crate::device::{Device, Evaluation};
use crate::integrate::State;

/// The force axes' metric names: `lift` (x̂), `aero_force_y`, `aero_force_z`.
pub(crate) const FORCE_AXES: [&str; 3] = ["lift", "aero_force_y", "aero_force_z"];

/// Whether every wing of `device` has a force model (blade elements with their force
/// parameter, or no aerodynamics), so the force metrics and columns are defined.
pub fn offers_forces(device: &Device) -> bool {
    device.spec().wings.iter().all(|w| match w.aero() {
        WingAero::None => true,
        WingAero::StrokeDrag { .. } => false,
        WingAero::BladeElement(m) => m.omegas().force.is_some(),
        WingAero::WhitneyWood2010(m) => m.blade().omegas().force.is_some(),
    })
}

/// The aerodynamic force (mN) on a wing turning with `omega6` (frame 6, rad/ms) about a
/// shoulder at rest, in its shoulder ground frame (`r61 = R_6^1`); zero without a force
/// model, NaN for a blade element without force parameter (not offered, see
/// [`offers_forces`]).
#[inline]
pub fn wing_force(aero: &WingAero, omega6: &Vector3<f64>, r61: &Matrix3<f64>) -> Vector3<f64> {
    match aero {
        WingAero::BladeElement(_) | WingAero::WhitneyWood2010(_) => {
            // At rest the shoulder velocity is zero and the force radius plays no part.
            paritysim_aero::wing_aero::wrench(aero, omega6, &Vector3::zeros(), r61, 1.0, None)
                .map_or(Vector3::repeat(f64::NAN), |w| w.force)
        }
        WingAero::None | WingAero::StrokeDrag { .. } => Vector3::zeros(),
    }
}

/// `f` of wing `w` in the body frame: the left wing (index 0 of two) mirrored (`z → −z`).
#[inline]
pub(crate) fn to_body(n_wings: usize, w: usize, f: Vector3<f64>) -> Vector3<f64> {
    if n_wings == 2 && w == 0 {
        Vector3::new(f.x, f.y, -f.z)
    } else {
        f
    }
}

/// The wings' forces (body frame) at a full evaluation (its `ω⁶` and `R_6^1` per wing).
pub(crate) fn of_evaluation(device: &Device, e: &Evaluation) -> [Vector3<f64>; 2] {
    let mut out = [Vector3::zeros(); 2];
    let n = device.n_wings();
    for (w, wing) in device.spec().wings.iter().enumerate() {
        let t = &e.wings[w];
        out[w] = to_body(n, w, wing_force(wing.aero(), &t.omega, &t.rotation));
    }
    out
}

/// The wings' forces (body frame) at an integrator state (the lean samples, which carry no
/// evaluation): `(p, ṗ)` of the state, then each wing's rotation and `ω⁶` (closed form on the
/// stroke plane, θ = θ̇ = 0, else the shoulder's kinematics).
///
/// # Errors
/// A state outside the drivetrain's or the shoulder's domain.
pub(crate) fn of_state(device: &Device, y: &State) -> Result<[Vector3<f64>; 2]> {
    let (p, p_dot) = device.coordinates(y)?;
    let mut out = [Vector3::zeros(); 2];
    let n = device.n_wings();
    for (w, wing) in device.spec().wings.iter().enumerate() {
        if matches!(wing.aero(), WingAero::None) {
            continue;
        }
        let k = 3 * w;
        let pw = Vector3::new(p[k], p[k + 1], p[k + 2]);
        let vw = Vector3::new(p_dot[k], p_dot[k + 1], p_dot[k + 2]);
        let terms = if wing.has_closed_form_stroke_plane() && pw.y == 0.0 && vw.y == 0.0 {
            wing.stroke_plane_kinematics(&pw, &vw)
        } else {
            wing.terms(&pw, &vw)?
        };
        out[w] = to_body(n, w, wing_force(wing.aero(), &terms.omega, &terms.rotation));
    }
    Ok(out)
}

/// Power the wings give to the air at a full evaluation (mW = µJ/ms, positive when the air
/// takes energy): `−Σ τ_aero · ṗ` of the generalised aerodynamic torques (the rate of
/// `−work_aero`).
pub(crate) fn aero_power(device: &Device, e: &Evaluation) -> f64 {
    let mut power = 0.0;
    for w in 0..device.n_wings() {
        let k = 3 * w;
        let rates = Vector3::new(e.p_dot[k], e.p_dot[k + 1], e.p_dot[k + 2]);
        power -= e.wings[w].aero.dot(&rates);
    }
    power
}

#[cfg(test)]
mod tests {
    use super::*;
    use paritysim_aero::{BladeElementModel, CoefficientSet, Omegas};

    /// Quasi-steady forces at fixed kinematics scale as the frequency squared: the angle of
    /// attack depends on the direction of `ω` only (eq. 3.4) and the strip force on `W²`, so
    /// the same stroke and rotation at `k` times the frequency (`ω → kω`) give `k²` the force,
    /// at every phase and hence in every cycle mean.
    #[test]
    fn lift_scales_as_frequency_squared_at_fixed_kinematics() {
        let omegas = Omegas::new(46.8, 0.587, 17.5, 0.712)
            .and_then(|o| o.with_force(46.8 / 12.0))
            .unwrap();
        let aero = WingAero::BladeElement(
            BladeElementModel::new(omegas, CoefficientSet::default()).unwrap(),
        );
        // A stroke-plane wing: φ = A sin(2πft), ψ = −B cos(2πft) (rotation lagging stroke by 90°,
        // α < 90° mid-stroke: docs/errata.md#5).
        let (a, b) = (0.6, 0.9);
        let state = |f: f64, t: f64| {
            let w = std::f64::consts::TAU * f;
            let (phi, phi_dot) = (a * (w * t).sin(), a * w * (w * t).cos());
            let (psi, psi_dot) = (-b * (w * t).cos(), b * w * (w * t).sin());
            let r = Matrix3::new(
                1.0,
                0.0,
                0.0,
                0.0,
                phi.cos(),
                -phi.sin(),
                0.0,
                phi.sin(),
                phi.cos(),
            ) * Matrix3::new(
                psi.cos(),
                -psi.sin(),
                0.0,
                psi.sin(),
                psi.cos(),
                0.0,
                0.0,
                0.0,
                1.0,
            );
            let omega = Vector3::new(phi_dot * psi.cos(), -phi_dot * psi.sin(), psi_dot);
            (omega, r)
        };
        let (f1, k) = (0.11, 1.7);
        let n = 64;
        let (mut mean1, mut mean2) = (Vector3::zeros(), Vector3::zeros());
        for i in 0..n {
            let phase = i as f64 / n as f64;
            let (o1, r1) = state(f1, phase / f1);
            let (o2, r2) = state(k * f1, phase / (k * f1));
            let (g1, g2) = (wing_force(&aero, &o1, &r1), wing_force(&aero, &o2, &r2));
            assert!(
                (g2 - g1 * (k * k)).norm() <= 1e-12 * (1.0 + g2.norm()),
                "{g1} {g2}"
            );
            mean1 += g1 / n as f64;
            mean2 += g2 / n as f64;
        }
        assert!(mean1.x > 0.0, "the wing lifts: {mean1}");
        assert!((mean2.x / mean1.x - k * k).abs() < 1e-12);
    }
}
