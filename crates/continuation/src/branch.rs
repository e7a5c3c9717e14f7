//! One-parameter continuation of the periodic orbits `P(x; λ) = x` of a forced system:
//! natural or pseudo-arclength, step size adapted to Newton's convergence, with every point's
//! Floquet multipliers and the fold, period-doubling and Neimark–Sacker points located on the way.

use nalgebra::DVector;
use paritysim_error::{Error, Result};

use crate::bifurcation::{crossed, locate, tests};
use crate::map::PeriodMap;
use crate::options::{ContinuationOptions, Method};
use crate::orbit_system::OrbitSystem;
use crate::points::{Bifurcation, Branch, StopReason};
use crate::system::{correct, tangent};

/// Largest accepted distance between the predicted and the corrected point, as a fraction of
/// the pseudo-arclength step.
const MAX_CORRECTION: f64 = 0.5;

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
        let predicted = &current_u + &t * step;
        let attempt = match options.method {
            Method::PseudoArclength => {
                if exact_stop {
                    correct(
                        &system,
                        predicted.clone(),
                        &e_lambda,
                        stop_hat,
                        options.tolerance,
                        options.max_iterations,
                    )
                } else {
                    let target = t.dot(&predicted);
                    correct(
                        &system,
                        predicted.clone(),
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
            // A sharp turn of the tangent, or a correction much longer than the step, means the
            // corrector jumped to another branch (near a fold a step that is too long lands on
            // a neighbouring branch with a similar tangent).
            if options.method == Method::PseudoArclength {
                let detail = if new_t.dot(&t) < 0.8 {
                    Some("the tangent turned sharply")
                } else if (&c.u - &predicted).norm() > MAX_CORRECTION * step {
                    Some("the corrector moved further than the step")
                } else {
                    None
                };
                if let Some(detail) = detail {
                    return Err(Error::OutOfDomain {
                        what: "continuation step".into(),
                        detail: detail.into(),
                    });
                }
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
