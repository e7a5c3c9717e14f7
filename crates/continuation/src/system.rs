//! Underdetermined systems `G(u) = 0`, `G: R^(m+1) -> R^m`, and the two numerical kernels every
//! continuation shares: the tangent of the solution curve and the Newton corrector.

use nalgebra::{DMatrix, DVector};
use paritysim_error::{Error, Result, check_positive};

/// The residual, its `m × (m+1)` Jacobian, and the monodromy at the point (if the system has
/// one) so that multipliers cost no extra integration.
pub(crate) struct Evaluation {
    pub residual: DVector<f64>,
    pub jacobian: DMatrix<f64>,
    pub monodromy: Option<DMatrix<f64>>,
}

pub(crate) trait System {
    /// `m`: equations (the unknowns are `m + 1`).
    fn equations(&self) -> usize;
    fn evaluate(&self, u: &DVector<f64>) -> Result<Evaluation>;
}

/// A converged point of the curve.
pub(crate) struct Corrected {
    pub u: DVector<f64>,
    pub evaluation: Evaluation,
    pub iterations: usize,
}

/// The unit tangent `t` with `J t = 0`, oriented along `previous` (`t·previous > 0`).
pub(crate) fn tangent(jacobian: &DMatrix<f64>, previous: &DVector<f64>) -> Result<DVector<f64>> {
    let m = jacobian.nrows();
    let mut a = DMatrix::zeros(m + 1, m + 1);
    a.view_mut((0, 0), (m, m + 1)).copy_from(jacobian);
    a.row_mut(m).copy_from(&previous.transpose());
    let mut rhs = DVector::zeros(m + 1);
    rhs[m] = 1.0;
    let t = a.lu().solve(&rhs).ok_or_else(|| {
        Error::Singular(
            "the continuation curve has no unique tangent here (a branch point?)".into(),
        )
    })?;
    let norm = t.norm();
    if !(norm.is_finite() && norm > 0.0) {
        return Err(Error::Singular("degenerate tangent".into()));
    }
    let t = t / norm;
    Ok(if t.dot(previous) < 0.0 { -t } else { t })
}

/// Newton's method on `[G(u); row·u − target] = 0` from `u0`.
///
/// # Errors
/// [`Error::Singular`] if the bordered Jacobian is singular; [`Error::Integration`]-style
/// errors of the system; [`Error::OutOfDomain`] when it does not converge in `max_iterations`.
pub(crate) fn correct<S: System>(
    system: &S,
    u0: DVector<f64>,
    row: &DVector<f64>,
    target: f64,
    tolerance: f64,
    max_iterations: usize,
) -> Result<Corrected> {
    let m = system.equations();
    let mut u = u0;
    for iteration in 0..=max_iterations {
        let evaluation = system.evaluate(&u)?;
        let constraint = row.dot(&u) - target;
        let size = evaluation.residual.amax().max(constraint.abs());
        if !size.is_finite() {
            return Err(Error::OutOfDomain {
                what: "continuation corrector".into(),
                detail: "non-finite residual".into(),
            });
        }
        if size <= tolerance {
            return Ok(Corrected {
                u,
                evaluation,
                iterations: iteration,
            });
        }
        if iteration == max_iterations {
            break;
        }
        let mut a = DMatrix::zeros(m + 1, m + 1);
        a.view_mut((0, 0), (m, m + 1))
            .copy_from(&evaluation.jacobian);
        a.row_mut(m).copy_from(&row.transpose());
        let mut rhs = DVector::zeros(m + 1);
        rhs.rows_mut(0, m).copy_from(&(-&evaluation.residual));
        rhs[m] = -constraint;
        let du = a
            .lu()
            .solve(&rhs)
            .ok_or_else(|| Error::Singular("singular bordered Jacobian in the corrector".into()))?;
        u += du;
    }
    Err(Error::OutOfDomain {
        what: "continuation corrector".into(),
        detail: format!("Newton did not converge in {max_iterations} iterations"),
    })
}

/// Step sizes of a continuation: each positive and `min_step <= initial_step <= max_step`.
pub(crate) fn check_steps(initial: f64, min: f64, max: f64) -> Result<()> {
    check_positive("initial_step", initial)?;
    check_positive("min_step", min)?;
    check_positive("max_step", max)?;
    if !(min <= initial && initial <= max) {
        return Err(Error::invalid(
            "initial_step",
            initial,
            format!("in [min_step, max_step] = [{min}, {max}]"),
        ));
    }
    Ok(())
}
