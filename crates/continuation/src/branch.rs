//! One-parameter continuation of the periodic orbits `P(x; λ) = x` of a forced system:
//! natural or pseudo-arclength, step size adapted to Newton's convergence, with every point's
//! Floquet multipliers and the fold, period-doubling and Neimark–Sacker points located on the way.

use nalgebra::{Complex, DMatrix, DVector};
use paritysim_error::{Error, Result, check_positive};

use crate::bifurcation::{crossed, locate, tests};
use crate::map::PeriodMap;
use crate::multipliers::{Stability, multipliers, stability};
use crate::system::{Corrected, Evaluation, System, correct, tangent};

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

/// Settings of [`continue_orbits`].
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

    fn validate(&self, parameters: &[f64], dim: usize) -> Result<()> {
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

/// One periodic orbit of the branch.
#[derive(Clone, Debug, PartialEq)]
pub struct BranchPoint {
    /// The continued parameter.
    pub parameter: f64,
    /// The orbit's state at phase 0 (a fixed point of the period map).
    pub state: DVector<f64>,
    /// Shift of the cyclic coordinate per period (0 without one).
    pub drift: f64,
    /// Non-trivial Floquet multipliers, largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
    /// From the multipliers.
    pub stability: Stability,
    /// Newton iterations the point took.
    pub iterations: usize,
    /// `|P(x) − x − drift|∞` at the point.
    pub residual: f64,
    /// Scaled arclength from the first point.
    pub arclength: f64,
}

/// What changes at a bifurcation of a forced periodic orbit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BifurcationKind {
    /// A multiplier through +1 where the branch turns back (saddle-node of orbits).
    Fold,
    /// A multiplier through −1: an orbit of twice the period is born.
    PeriodDoubling,
    /// A complex pair through the unit circle: a torus (quasi-periodic motion) is born.
    NeimarkSacker,
    /// A multiplier through +1 where the branch does not turn: another branch crosses this one
    /// (symmetry breaking or transcritical). Detected with pseudo-arclength only.
    BranchPoint,
}

impl BifurcationKind {
    /// `fold`, `period_doubling` or `neimark_sacker`.
    pub fn name(self) -> &'static str {
        match self {
            BifurcationKind::Fold => "fold",
            BifurcationKind::PeriodDoubling => "period_doubling",
            BifurcationKind::NeimarkSacker => "neimark_sacker",
            BifurcationKind::BranchPoint => "branch_point",
        }
    }
}

/// A located bifurcation.
#[derive(Clone, Debug, PartialEq)]
pub struct Bifurcation {
    /// Which one.
    pub kind: BifurcationKind,
    /// The orbit at it.
    pub point: BranchPoint,
    /// Index of the branch point after which it lies.
    pub after: usize,
    /// Whether bisection converged (else `point` is the nearer bracketing point).
    pub located: bool,
}

/// Why the continuation ended.
#[derive(Clone, Debug, PartialEq)]
pub enum StopReason {
    /// The branch reached `stop`.
    ReachedStop,
    /// The branch turned and left the interval on the side of the starting parameter.
    LeftInterval,
    /// `max_points` were computed.
    MaxPoints,
    /// Newton failed even at `min_step`; with natural continuation this is usually a fold.
    StepTooSmall(String),
}

/// A branch of periodic orbits.
#[derive(Clone, Debug, PartialEq)]
pub struct Branch {
    /// The orbits in order along the branch.
    pub points: Vec<BranchPoint>,
    /// Bifurcations in order along the branch.
    pub bifurcations: Vec<Bifurcation>,
    /// Why it ended.
    pub stop_reason: StopReason,
    /// Period-map evaluations with the monodromy (the cost).
    pub map_evaluations: usize,
}

/// `G(x, drift, λ̂) = P(x; λ) − x − drift·e_c` over `u = (x without x_c, [drift], λ̂)`.
pub(crate) struct OrbitSystem<'a, M: PeriodMap> {
    pub map: &'a M,
    pub parameters: Vec<f64>,
    pub index: usize,
    pub scale: f64,
    pub cyclic: Option<(usize, f64)>, // (coordinate, its pinned value)
    pub fd_step: f64,
    pub evaluations: std::cell::Cell<usize>,
}

impl<M: PeriodMap> OrbitSystem<'_, M> {
    pub fn n(&self) -> usize {
        self.map.dim()
    }

    /// `(x, drift, λ)` from `u`.
    pub fn unpack(&self, u: &DVector<f64>) -> (DVector<f64>, f64, f64) {
        let n = self.n();
        let lambda = u[n] * self.scale;
        match self.cyclic {
            None => (u.rows(0, n).into_owned(), 0.0, lambda),
            Some((c, pinned)) => {
                let mut x = DVector::zeros(n);
                let mut k = 0;
                for i in 0..n {
                    if i == c {
                        x[i] = pinned;
                    } else {
                        x[i] = u[k];
                        k += 1;
                    }
                }
                (x, u[n - 1], lambda)
            }
        }
    }

    pub fn pack(&self, x: &DVector<f64>, drift: f64, lambda: f64) -> DVector<f64> {
        let n = self.n();
        let mut u = DVector::zeros(n + 1);
        match self.cyclic {
            None => u.rows_mut(0, n).copy_from(x),
            Some((c, _)) => {
                for (k, i) in (0..n).filter(|&i| i != c).enumerate() {
                    u[k] = x[i];
                }
                u[n - 1] = drift;
            }
        }
        u[n] = lambda / self.scale;
        u
    }

    fn with(&self, lambda: f64) -> Vec<f64> {
        let mut p = self.parameters.clone();
        p[self.index] = lambda;
        p
    }

    pub fn point(&self, corrected: &Corrected, tol: f64, arclength: f64) -> BranchPoint {
        let (state, drift, parameter) = self.unpack(&corrected.u);
        let mu = corrected
            .evaluation
            .monodromy
            .as_ref()
            .map(|m| multipliers(m, self.cyclic.is_some()))
            .unwrap_or_default();
        BranchPoint {
            parameter,
            state,
            drift,
            stability: stability(&mu, tol),
            multipliers: mu,
            iterations: corrected.iterations,
            residual: corrected.evaluation.residual.amax(),
            arclength,
        }
    }
}

impl<M: PeriodMap> System for OrbitSystem<'_, M> {
    fn equations(&self) -> usize {
        self.n()
    }

    fn evaluate(&self, u: &DVector<f64>) -> Result<Evaluation> {
        let n = self.n();
        let (x, drift, lambda) = self.unpack(u);
        let (image, monodromy) = self.map.image_and_jacobian(&x, &self.with(lambda))?;
        let eps = self.fd_step * lambda.abs().max(self.scale);
        let up = self.map.image(&x, &self.with(lambda + eps))?;
        let down = self.map.image(&x, &self.with(lambda - eps))?;
        self.evaluations.set(self.evaluations.get() + 1);
        let mut residual = &image - &x;
        let mut jacobian = DMatrix::zeros(n, n + 1);
        let shifted = &monodromy - DMatrix::identity(n, n);
        match self.cyclic {
            None => jacobian.view_mut((0, 0), (n, n)).copy_from(&shifted),
            Some((c, _)) => {
                residual[c] -= drift;
                for (k, i) in (0..n).filter(|&i| i != c).enumerate() {
                    jacobian.set_column(k, &shifted.column(i));
                }
                jacobian[(c, n - 1)] = -1.0;
            }
        }
        jacobian.set_column(n, &((up - down) * (self.scale / (2.0 * eps))));
        Ok(Evaluation {
            residual,
            jacobian,
            monodromy: Some(monodromy),
        })
    }
}

/// Continues the periodic orbit through `x0` at `parameters` (the continued one at
/// `options.parameter`) towards `options.stop`.
///
/// `x0` need not be on the orbit: the first point is corrected from it at the starting
/// parameter.
///
/// # Errors
/// [`Error::InvalidParameter`] for bad options or a state of the wrong size; the first point's
/// correction error if no orbit is found near `x0`. Later failures end the branch with
/// [`StopReason::StepTooSmall`] instead of an error, so the points found are kept.
pub fn continue_orbits<M: PeriodMap>(
    map: &M,
    x0: &DVector<f64>,
    parameters: &[f64],
    options: &ContinuationOptions,
) -> Result<Branch> {
    let n = map.dim();
    options.validate(parameters, n)?;
    if x0.len() != n {
        return Err(Error::Shape(format!(
            "x0 has {} entries, the map has {n}",
            x0.len()
        )));
    }
    let start = parameters[options.parameter];
    let system = OrbitSystem {
        map,
        parameters: parameters.to_vec(),
        index: options.parameter,
        scale: options.parameter_scale,
        cyclic: options.cyclic.map(|c| (c, x0[c])),
        fd_step: options.fd_step,
        evaluations: std::cell::Cell::new(0),
    };
    let direction = (options.stop - start).signum();
    let (lo, hi) = if direction > 0.0 {
        (start, options.stop)
    } else {
        (options.stop, start)
    };
    let last = n; // index of λ̂ in u

    // First point: Newton at the starting parameter.
    let u0 = system.pack(x0, 0.0, start);
    let mut e_lambda = DVector::zeros(n + 1);
    e_lambda[last] = 1.0;
    let first = correct(
        &system,
        u0,
        &e_lambda,
        start / system.scale,
        options.tolerance,
        4 * options.max_iterations,
    )?;
    let mut t = tangent(&first.evaluation.jacobian, &(e_lambda.clone() * direction))?;
    let mut current = system.point(&first, options.multiplier_tolerance, 0.0);
    let mut current_u = first.u;
    let mut current_tests = tests(&current, t[last], options.method);
    let mut points = vec![current.clone()];
    let mut bifurcations = Vec::new();
    let mut h = options.initial_step;
    let mut arclength = 0.0;

    let stop_reason = loop {
        if points.len() >= options.max_points {
            break StopReason::MaxPoints;
        }
        // Land exactly on `stop` when the next step would cross it.
        let lambda_hat = current_u[last];
        let stop_hat = options.stop / system.scale;
        let (mut step, mut exact_stop) = (h, false);
        let toward = match options.method {
            Method::PseudoArclength => t[last],
            Method::Natural => direction,
        };
        if toward != 0.0
            && (stop_hat - lambda_hat) / toward > 0.0
            && (stop_hat - lambda_hat) / toward <= step
        {
            step = (stop_hat - lambda_hat) / toward;
            exact_stop = true;
        }
        let attempt = match options.method {
            Method::PseudoArclength => {
                let predicted = &current_u + &t * step;
                if exact_stop {
                    correct(
                        &system,
                        predicted,
                        &e_lambda,
                        stop_hat,
                        options.tolerance,
                        options.max_iterations,
                    )
                } else {
                    let target = t.dot(&predicted);
                    correct(
                        &system,
                        predicted,
                        &t,
                        target,
                        options.tolerance,
                        options.max_iterations,
                    )
                }
            }
            Method::Natural => {
                let mut predicted = current_u.clone();
                predicted[last] += direction * step;
                let target = predicted[last];
                correct(
                    &system,
                    predicted,
                    &e_lambda,
                    target,
                    options.tolerance,
                    options.max_iterations,
                )
            }
        };
        let accepted = attempt.and_then(|c| {
            let new_t = tangent(&c.evaluation.jacobian, &t)?;
            // A sharp turn of the tangent means the corrector jumped to another branch.
            if new_t.dot(&t) < 0.8 && options.method == Method::PseudoArclength {
                return Err(Error::OutOfDomain {
                    what: "continuation step".into(),
                    detail: "the tangent turned sharply".into(),
                });
            }
            Ok((c, new_t))
        });
        let (next, next_t) = match accepted {
            Ok(v) => v,
            // The caller stopped the run: not a failed step to retry smaller.
            Err(Error::Cancelled) => return Err(Error::Cancelled),
            Err(err) => {
                h *= 0.5;
                if h < options.min_step {
                    break StopReason::StepTooSmall(format!(
                        "at parameter {}: {err}",
                        current.parameter
                    ));
                }
                continue;
            }
        };
        arclength += (&next.u - &current_u).norm();
        let point = system.point(&next, options.multiplier_tolerance, arclength);
        let next_tests = tests(&point, next_t[last], options.method);
        for kind in crossed(&current_tests, &next_tests) {
            let located = if options.locate {
                locate(
                    &system,
                    options,
                    kind,
                    &current_u,
                    &t,
                    &current_tests,
                    step,
                    arclength - (&next.u - &current_u).norm(),
                )
            } else {
                None
            };
            bifurcations.push(match located {
                Some(p) => Bifurcation {
                    kind,
                    point: p,
                    after: points.len() - 1,
                    located: true,
                },
                None => Bifurcation {
                    kind,
                    point: point.clone(),
                    after: points.len() - 1,
                    located: false,
                },
            });
        }
        h = if next.iterations <= 3 {
            (step.max(h) * 1.5).min(options.max_step)
        } else if next.iterations >= 6 {
            (h * 0.5).max(options.min_step)
        } else {
            h
        };
        current = point;
        current_u = next.u;
        t = next_t;
        current_tests = next_tests;
        points.push(current.clone());
        let lambda = current.parameter;
        if exact_stop
            || lambda >= hi + 1e-12 * hi.abs().max(1.0) && direction > 0.0
            || lambda <= lo - 1e-12 * lo.abs().max(1.0) && direction < 0.0
        {
            break StopReason::ReachedStop;
        }
        if (direction > 0.0 && lambda < lo) || (direction < 0.0 && lambda > hi) {
            break StopReason::LeftInterval;
        }
    };
    Ok(Branch {
        points,
        bifurcations,
        stop_reason,
        map_evaluations: system.evaluations.get(),
    })
}
