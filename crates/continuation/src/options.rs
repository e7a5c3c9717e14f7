//! Settings of a one-parameter continuation.

use paritysim_error::{Error, Result, check_positive};

/// How the next point is constrained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// The parameter is stepped and held fixed while Newton corrects the state: simple, but
    /// stops at a fold.
    Natural,
    /// Steps along the curve's arclength in `(x, λ / parameter_scale)`: turns around folds and
    /// follows the unstable branch.
    PseudoArclength,
}

/// Settings of [`crate::continue_orbits`].
#[derive(Clone, Debug, PartialEq)]
pub struct ContinuationOptions {
    /// Index of the continued parameter in the parameter vector.
    pub parameter: usize,
    /// The continuation runs from the starting parameter towards `stop` and ends when the
    /// branch leaves the interval between them.
    pub stop: f64,
    /// Natural or pseudo-arclength.
    pub method: Method,
    /// First step (scaled arclength, or parameter / `parameter_scale` for natural).
    pub initial_step: f64,
    /// Smallest step before giving up.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Most points on the branch.
    pub max_points: usize,
    /// Newton tolerance on the residual `|P(x) − x|∞` (state units).
    pub tolerance: f64,
    /// Newton iterations per point.
    pub max_iterations: usize,
    /// Parameter units per state unit in the arclength.
    pub parameter_scale: f64,
    /// `|μ| − 1` within this is marginal.
    pub multiplier_tolerance: f64,
    /// Index of a cyclic state coordinate (its shift maps orbits to orbits): solved as a relative
    /// periodic orbit with a drift per period, and its trivial multiplier removed.
    pub cyclic: Option<usize>,
    /// Relative step of the central difference for `∂P/∂λ`.
    pub fd_step: f64,
    /// Locate each detected bifurcation by bisection (else report the bracketing points).
    pub locate: bool,
}

impl ContinuationOptions {
    /// Defaults for continuing `parameter` up (or down) to `stop`.
    pub fn new(parameter: usize, stop: f64) -> Self {
        ContinuationOptions {
            parameter,
            stop,
            method: Method::PseudoArclength,
            initial_step: 1e-2,
            min_step: 1e-7,
            max_step: 0.1,
            max_points: 2000,
            tolerance: 1e-10,
            max_iterations: 8,
            parameter_scale: 1.0,
            multiplier_tolerance: 1e-6,
            cyclic: None,
            fd_step: 1e-6,
            locate: true,
        }
    }

    pub(crate) fn validate(&self, parameters: &[f64], dim: usize) -> Result<()> {
        if self.parameter >= parameters.len() {
            return Err(Error::invalid(
                "parameter",
                self.parameter,
                format!("an index < {}", parameters.len()),
            ));
        }
        paritysim_error::check_finite("stop", self.stop)?;
        crate::system::check_steps(self.initial_step, self.min_step, self.max_step)?;
        if !(2..=1_000_000).contains(&self.max_points) {
            return Err(Error::invalid(
                "max_points",
                self.max_points,
                "in [2, 1000000]",
            ));
        }
        check_positive("tolerance", self.tolerance)?;
        if !(1..=100).contains(&self.max_iterations) {
            return Err(Error::invalid(
                "max_iterations",
                self.max_iterations,
                "in [1, 100]",
            ));
        }
        check_positive("parameter_scale", self.parameter_scale)?;
        check_positive("multiplier_tolerance", self.multiplier_tolerance)?;
        paritysim_error::check_in_closed("fd_step", self.fd_step, 1e-12, 1e-2)?;
        if let Some(c) = self.cyclic {
            if c >= dim {
                return Err(Error::invalid(
                    "cyclic",
                    c,
                    format!("a state index < {dim}"),
                ));
            }
        }
        if self.stop == parameters[self.parameter] {
            return Err(Error::invalid(
                "stop",
                self.stop,
                "different from the starting parameter",
            ));
        }
        Ok(())
    }
}
