//! The Newton kernels of shooting, written once: the residual, the trial step (least squares
//! with the neutral-direction rule), Broyden's update, the tolerances and the iteration limit.
//! The scalar shooting ([`super::grid::shoot`]), the SIMD-lane points (`crate::lanes`) and the
//! stability shooting (`crate::stability::periodic_orbit`) all call these.

use nalgebra::{DMatrix, DVector};
use paritysim_error::Error;

use crate::integrate::State;

/// Newton steps of a steady-state shooting pass (the limit every caller uses).
pub(crate) const MAX_NEWTON: usize = 20;

/// Newton's convergence tolerance for a run's `steady_tol` and `rtol`: the predicted error of
/// the next iterate, relative to `1 + ‖y‖∞`. Below the integration's own accuracy (~rtol) a
/// tighter orbit changes nothing.
pub(crate) fn newton_tolerance(steady_tol: f64, rtol: f64) -> f64 {
    (1e-2 * steady_tol).min(0.1 * rtol)
}

/// `(P(y) − y, ‖P(y) − y‖∞ / (1 + ‖y‖∞))`.
pub(crate) fn residual(n: usize, y: &State, py: &State) -> (DVector<f64>, f64) {
    let (yv, pv) = (y.compact(n), py.compact(n));
    let f = pv - &yv;
    let r = f.amax() / (1.0 + yv.amax());
    (f, r)
}

/// Whether a failed trial is the run's end rather than Newton's: a cancel, or the run's
/// budget (wall time) spent, which the transient fallback would only exceed further.
pub(crate) fn out_of_budget(e: &Error) -> bool {
    matches!(e, Error::Cancelled) || crate::integrate::budget::check_current().is_err()
}

/// Singular values of `DP − I` below this fraction of the largest are a neutral direction
/// (a multiplier within it of 1: a mode that needs more than a million periods to decay, which
/// no transient resolves either), left where it is by the Newton step.
///
/// Why not round-off (the former cutoff `1e-10`): `DP` comes from variational equations
/// integrated at the grid tolerance (`rtol / 100`, 1e-10 by default) or from Broyden updates,
/// so an exact multiplier 1 shows up as a singular value of about that size. Measured on two
/// identical §3.4 rotating wings (linear differential, K2 = 0: the differential stroke offset
/// is cyclic): the neutral singular value was 2.2e-10 against a cutoff of 1.5e-10, the step
/// divided the residual's round-off antisymmetric part (4e-15) by it and moved the orbit
/// 7e-4 rad along the neutral family: a valid but asymmetric orbit (docs/findings.md §10).
pub(crate) const NEUTRAL_SINGULAR_TOL: f64 = 1e-6;

/// The least-squares Newton step `Δ` of `(DP − I) Δ = −f` with the neutral directions
/// ([`NEUTRAL_SINGULAR_TOL`]) left out: the minimum-norm solution, which does not move the
/// state along a family of orbits (a symmetric start stays symmetric). `None` when the SVD
/// fails (a non-finite Jacobian).
pub(crate) fn least_squares_step(
    jac_minus_eye: DMatrix<f64>,
    f: &DVector<f64>,
) -> Option<DVector<f64>> {
    LeastSquares::new(jac_minus_eye)?.step(f)
}

/// The SVD of `DP − I` behind [`least_squares_step`], kept for several right-hand sides (a
/// sensitivity's parameters) and for its neutral directions.
pub(crate) struct LeastSquares {
    svd: nalgebra::SVD<f64, nalgebra::Dyn, nalgebra::Dyn>,
    cutoff: f64,
}

impl LeastSquares {
    /// `None` for a non-finite matrix.
    pub(crate) fn new(jac_minus_eye: DMatrix<f64>) -> Option<Self> {
        if jac_minus_eye.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let svd = jac_minus_eye.svd(true, true);
        let cutoff = NEUTRAL_SINGULAR_TOL * svd.singular_values.max().max(f64::MIN_POSITIVE);
        Some(Self { svd, cutoff })
    }

    /// The step `Δ` of `(DP − I) Δ = −f` ([`least_squares_step`]); `None` for a non-finite `f`.
    pub(crate) fn step(&self, f: &DVector<f64>) -> Option<DVector<f64>> {
        if f.iter().any(|v| !v.is_finite()) {
            return None;
        }
        self.svd.solve(&(-f), self.cutoff).ok()
    }

    /// The part of `f` no step reaches: the norm of its components along the left singular
    /// vectors of the neutral directions (the solvability residuals `uᵀ f`); 0 without
    /// neutral directions.
    pub(crate) fn unreachable(&self, f: &DVector<f64>) -> f64 {
        let values = &self.svd.singular_values;
        let Some(u) = &self.svd.u else {
            return 0.0;
        };
        (0..values.len())
            .filter(|&i| values[i] <= self.cutoff)
            .map(|i| u.column(i).dot(f).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// The nearly neutral directions: right singular vectors whose singular values lie above
    /// the cutoff and at or below `limit` times the largest, with those values (relative).
    pub(crate) fn slow_directions(&self, limit: f64) -> Vec<(f64, DVector<f64>)> {
        let values = &self.svd.singular_values;
        let largest = values.max().max(f64::MIN_POSITIVE);
        match &self.svd.v_t {
            Some(v_t) => (0..values.len())
                .filter(|&i| values[i] > self.cutoff && values[i] <= limit * largest)
                .map(|i| (values[i] / largest, v_t.row(i).transpose()))
                .collect(),
            None => Vec::new(),
        }
    }

    /// The neutral directions: right singular vectors of singular values at or below the
    /// cutoff.
    pub(crate) fn neutral_directions(&self) -> Vec<DVector<f64>> {
        let values = &self.svd.singular_values;
        match &self.svd.v_t {
            Some(v_t) => (0..values.len())
                .filter(|&i| values[i] <= self.cutoff)
                .map(|i| v_t.row(i).transpose())
                .collect(),
            None => Vec::new(),
        }
    }
}

/// Tolerances of the adaptive period that picks the grid, relative to the run's: the fixed-grid
/// maps then need no rejected steps and the orbit and its recorded window are accurate to about
/// the run's `rtol` (on the §3.3 grid at rtol 1e-8, the grid at the run's own tolerance left
/// torques 3.5e-7 off the rtol-1e-12 reference, amplified by slow multipliers up to 0.98).
pub(crate) const GRID_TOLERANCE_FACTOR: f64 = 1e-2;

/// A grid picked by an adaptive period from a start whose first residual exceeds this is
/// picked again at the converged state before the recorded period.
///
/// Why: the drag's `φ̇|φ̇|` (and a blade element's `sgn`) is not smooth at stroke reversal, so
/// the steps the adaptive period took around the *start's* reversals are the grid's truncation
/// error on an orbit whose reversals lie elsewhere. Measured on the §3.3 device in a 4 × 4
/// sweep (chained starts 1.2e-3 to 1.4e-2 off their orbit, Newton converged to residuals of
/// 7e-11): τR peak off the rtol-1e-12 reference by up to 5.8e-7 (a direct run: 1.1e-9). Warmed-up
/// cold starts and fine sweeps' neighbours begin closer (first residuals 1e-5 to 1e-4).
pub(crate) const REPICK_RESIDUAL: f64 = 1e-3;

/// One Newton trial ([`trial`]).
pub(crate) struct Trial {
    /// The step `Δ` ([`least_squares_step`]).
    pub(crate) delta: DVector<f64>,
    /// `‖Δ‖∞ / (1 + ‖y‖∞)`.
    pub(crate) step: f64,
    /// The contraction of the error Newton's model predicts for this step.
    pub(crate) contraction: f64,
    /// The next iterate `y + Δ`.
    pub(crate) y_new: State,
    /// Whether it is the last: its predicted error (step × contraction) is below `tol`.
    pub(crate) last: bool,
}

/// The Newton trial from `y` with the map's Jacobian `jac` (`eye` its identity) and residual
/// `f`: `last_step` is the previous step's size, `fresh` whether `jac` is exact here,
/// `guess_contraction` the contraction a guessed Jacobian achieved before (its pass's). `None`
/// for a singular step.
pub(crate) fn trial(
    n: usize,
    y: &State,
    (jac, eye, f): (&DMatrix<f64>, &DMatrix<f64>, &DVector<f64>),
    (last_step, fresh, guess_contraction): (Option<f64>, bool, Option<f64>),
    tol: f64,
) -> Option<Trial> {
    let delta = least_squares_step(jac - eye, f)?;
    let scale = 1.0 + y.compact(n).amax();
    let step = delta.amax() / scale;
    // The next iterate's error: the step times the contraction seen so far (Newton's
    // quadratic model after a fresh Jacobian; unknown, so 1, after a neighbour's).
    let contraction = match last_step {
        Some(s) => step / s,
        None if fresh => step,
        None => guess_contraction.unwrap_or(1.0),
    }
    .min(1.0);
    let y_new = State::from_compact(n, &(y.compact(n) + &delta));
    let last = contraction * step <= tol || step <= 1e-3 * tol;
    Some(Trial {
        delta,
        step,
        contraction,
        y_new,
        last,
    })
}

/// Good Broyden: the secant condition on the step `delta` just taken, from the residual `f`
/// to `f_new`.
pub(crate) fn broyden_update(
    jac: &mut DMatrix<f64>,
    eye: &DMatrix<f64>,
    delta: &DVector<f64>,
    (f, f_new): (&DVector<f64>, &DVector<f64>),
) {
    let s_dot = delta.dot(delta);
    if s_dot > 0.0 {
        let mismatch = (f_new - f) - (&*jac - eye) * delta;
        *jac += mismatch * delta.transpose() / s_dot;
    }
}
