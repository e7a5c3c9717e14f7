//! Inverting the drivetrain map: `q` from the stroke angles `φ` by Newton's method.

use nalgebra::{Matrix2, Vector2};
use paritysim_error::{Error, Result};
use paritysim_kinematics::Drivetrain;

pub(super) fn singular_drive(q: &Vector2<f64>) -> Error {
    Error::Singular(format!(
        "drivetrain Jacobian is singular at q = ({}, {})",
        q.x, q.y
    ))
}

pub(super) const NEWTON_TOL: f64 = 1e-14;
pub(super) const NEWTON_MAX: usize = 30;

/// Solves `φ(q1) = target` for a 1-DOF drivetrain; returns `q1` and `dφ/dq1`.
pub(super) fn invert_1dof(dt: &Drivetrain, target: f64) -> Result<(f64, f64)> {
    let e0 = dt.evaluate(0.0, 0.0)?;
    let mut q1 = (target - e0.stroke.x) / e0.jacobian[(0, 0)];
    for _ in 0..NEWTON_MAX {
        let e = dt
            .evaluate(q1, 0.0)
            .map_err(|e| unreachable_stroke(e, target))?;
        let slope = e.jacobian[(0, 0)];
        let step = (e.stroke.x - target) / slope;
        q1 -= step;
        if step.abs() <= NEWTON_TOL * (1.0 + q1.abs()) {
            let e = dt.evaluate(q1, 0.0)?;
            return Ok((q1, e.jacobian[(0, 0)]));
        }
    }
    Err(Error::OutOfDomain {
        what: "drivetrain inverse".into(),
        detail: format!("no convergence for stroke {target} rad"),
    })
}

/// Solves `φ(q) = target` for a 2-DOF drivetrain; returns `q` and `J(q)`.
pub(super) fn invert_2dof(
    dt: &Drivetrain,
    target: &Vector2<f64>,
) -> Result<(Vector2<f64>, Matrix2<f64>)> {
    let e0 = dt.evaluate(0.0, 0.0)?;
    let j0 = e0.jacobian.lu();
    let mut q = j0
        .solve(&(target - e0.stroke))
        .ok_or_else(|| singular_drive(&Vector2::zeros()))?;
    for _ in 0..NEWTON_MAX {
        let e = dt
            .evaluate(q.x, q.y)
            .map_err(|e| unreachable_stroke(e, target.x))?;
        let step = e
            .jacobian
            .lu()
            .solve(&(e.stroke - target))
            .ok_or_else(|| singular_drive(&q))?;
        q -= step;
        if step.amax() <= NEWTON_TOL * (1.0 + q.amax()) {
            let e = dt.evaluate(q.x, q.y)?;
            return Ok((q, e.jacobian));
        }
    }
    Err(Error::OutOfDomain {
        what: "drivetrain inverse".into(),
        detail: format!(
            "no convergence for strokes ({}, {}) rad",
            target.x, target.y
        ),
    })
}

/// The drivetrain's plausibility check of `q` (its error when `q` is implausible).
#[inline]
pub(super) fn check_plausible(dt: &Drivetrain, q: &Vector2<f64>) -> Result<()> {
    if !(q.x.abs() <= paritysim_error::plausible::OFFSET_MM
        && q.y.abs() <= paritysim_error::plausible::ANGLE_RAD)
    {
        dt.evaluate(q.x, q.y)?;
    }
    Ok(())
}

pub(super) fn unreachable_stroke(e: Error, target: f64) -> Error {
    match e {
        Error::OutOfDomain { what, detail } => Error::OutOfDomain {
            what,
            detail: format!(
                "{detail}; the wings reached a stroke ({target} rad) the drivetrain cannot produce"
            ),
        },
        other => other,
    }
}
