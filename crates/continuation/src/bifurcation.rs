//! Detection and location of the bifurcations of a branch: test functions evaluated at each
//! point, sign changes between neighbours, and bisection on the continuation step.

use nalgebra::DVector;

use crate::map::PeriodMap;
use crate::multipliers::{fold_test, neimark_sacker_test, period_doubling_test};
use crate::options::{ContinuationOptions, Method};
use crate::orbit_system::OrbitSystem;
use crate::points::{BifurcationKind, BranchPoint};
use crate::system::{Corrected, correct, tangent};

/// Test-function values at a point, used to detect sign changes between neighbours.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tests {
    fold: f64,
    unit_multiplier: f64,
    period_doubling: f64,
    neimark_sacker: (f64, usize),
}

pub(crate) fn tests(point: &BranchPoint, tangent_lambda: f64, method: Method) -> Tests {
    Tests {
        // Along the arclength a fold is where the parameter turns back; stepping the parameter
        // cannot pass one, so there the multiplier product marks it.
        fold: match method {
            Method::PseudoArclength => tangent_lambda,
            Method::Natural => fold_test(&point.multipliers),
        },
        unit_multiplier: fold_test(&point.multipliers),
        period_doubling: period_doubling_test(&point.multipliers),
        neimark_sacker: neimark_sacker_test(&point.multipliers),
    }
}

pub(crate) fn crossed(a: &Tests, b: &Tests) -> Vec<BifurcationKind> {
    let mut out = Vec::new();
    if a.fold * b.fold < 0.0 {
        out.push(BifurcationKind::Fold);
    } else if a.unit_multiplier * b.unit_multiplier < 0.0 {
        out.push(BifurcationKind::BranchPoint);
    }
    if a.period_doubling * b.period_doubling < 0.0 {
        out.push(BifurcationKind::PeriodDoubling);
    }
    if a.neimark_sacker.1 == b.neimark_sacker.1
        && a.neimark_sacker.1 > 0
        && a.neimark_sacker.0 * b.neimark_sacker.0 < 0.0
    {
        out.push(BifurcationKind::NeimarkSacker);
    }
    out
}

fn value(kind: BifurcationKind, t: &Tests) -> f64 {
    match kind {
        BifurcationKind::Fold => t.fold,
        BifurcationKind::BranchPoint => t.unit_multiplier,
        BifurcationKind::PeriodDoubling => t.period_doubling,
        BifurcationKind::NeimarkSacker => t.neimark_sacker.0,
    }
}

/// Bisection (Illinois regula falsi) on the step from `u_a` along `t_a` for the zero of the
/// test function of `kind`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn locate<M: PeriodMap>(
    system: &OrbitSystem<'_, M>,
    options: &ContinuationOptions,
    kind: BifurcationKind,
    u_a: &DVector<f64>,
    t_a: &DVector<f64>,
    tests_a: &Tests,
    step: f64,
    arclength_a: f64,
) -> Option<BranchPoint> {
    let last = system.n();
    let mut e_lambda = DVector::zeros(last + 1);
    e_lambda[last] = 1.0;
    let evaluate = |s: f64| -> Option<(Corrected, Tests)> {
        let c = match options.method {
            Method::PseudoArclength => {
                let predicted = u_a + t_a * s;
                let target = t_a.dot(&predicted);
                correct(
                    system,
                    predicted,
                    t_a,
                    target,
                    options.tolerance,
                    options.max_iterations,
                )
            }
            Method::Natural => {
                let mut predicted = u_a.clone();
                predicted[last] += (options.stop - u_a[last] * system.scale).signum() * s;
                let target = predicted[last];
                correct(
                    system,
                    predicted,
                    &e_lambda,
                    target,
                    options.tolerance,
                    options.max_iterations,
                )
            }
        }
        .ok()?;
        let tt = tangent(&c.evaluation.jacobian, t_a).ok()?;
        let p = system.point(&c, options.multiplier_tolerance, 0.0);
        let ts = tests(&p, tt[last], options.method);
        Some((c, ts))
    };
    let (mut s_lo, mut f_lo) = (0.0, value(kind, tests_a));
    let (mut s_hi, mut f_hi) = (step, evaluate(step).map(|(_, t)| value(kind, &t))?);
    let mut best: Option<Corrected> = None;
    let mut side = 0i8;
    for _ in 0..60 {
        if (s_hi - s_lo).abs() <= 1e-10 * step.max(1e-12) {
            break;
        }
        let mut s = (s_lo * f_hi - s_hi * f_lo) / (f_hi - f_lo);
        if !(s > s_lo && s < s_hi) {
            s = 0.5 * (s_lo + s_hi);
        }
        let (c, t) = evaluate(s)?;
        let f = value(kind, &t);
        best = Some(c);
        if f == 0.0 {
            break;
        }
        if f * f_lo > 0.0 {
            s_lo = s;
            f_lo = f;
            if side == -1 {
                f_hi *= 0.5;
            }
            side = -1;
        } else {
            s_hi = s;
            f_hi = f;
            if side == 1 {
                f_lo *= 0.5;
            }
            side = 1;
        }
    }
    let best = best?;
    let along = (&best.u - u_a).norm();
    Some(system.point(&best, options.multiplier_tolerance, arclength_a + along))
}
