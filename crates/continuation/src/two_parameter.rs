//! Two-parameter continuation of a fold or period doubling: the curve in `(λ1, λ2)` along which
//! the orbit keeps a multiplier at +1 (fold) or −1 (period doubling).
//!
//! Minimally extended system over `u = (x, λ1, λ2)`: `P(x; λ) − x = 0` and `g(x, λ) = 0`, where
//! `g` is the bordered test function of `A = ∂P/∂x ∓ I`:
//! `[[A, b], [cᵀ, 0]] [v; g] = [0; 1]` with `b`, `c` the singular vectors of `A`'s smallest
//! singular value at the start (Govaerts, *Numerical Methods for Bifurcations of Dynamical
//! Equilibria*, 2000, §3.4). `∇g` is taken by central differences of the monodromy.

use nalgebra::{DMatrix, DVector};
use paritysim_error::{Error, Result, check_positive};

use crate::map::PeriodMap;
use crate::multipliers::multipliers;
use crate::points::{Bifurcation, BifurcationKind, StopReason};
use crate::system::{Evaluation, System, correct, tangent};
use nalgebra::Complex;

/// Settings of [`continue_fold_curve`].
#[derive(Clone, Debug, PartialEq)]
pub struct CurveOptions {
    /// Index of the second parameter.
    pub second: usize,
    /// The curve runs from the second parameter's value towards `stop`.
    pub stop: f64,
    /// First step (scaled arclength).
    pub initial_step: f64,
    /// Smallest step.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Most points.
    pub max_points: usize,
    /// Newton tolerance.
    pub tolerance: f64,
    /// Newton iterations per point.
    pub max_iterations: usize,
    /// Parameter units per state unit, for the first and the second parameter.
    pub parameter_scales: (f64, f64),
    /// Relative finite-difference step.
    pub fd_step: f64,
}

impl CurveOptions {
    /// Defaults for following the curve in parameter `second` towards `stop`.
    pub fn new(second: usize, stop: f64) -> Self {
        CurveOptions {
            second,
            stop,
            initial_step: 1e-2,
            min_step: 1e-7,
            max_step: 0.05,
            max_points: 500,
            tolerance: 1e-9,
            max_iterations: 8,
            parameter_scales: (1.0, 1.0),
            fd_step: 1e-5,
        }
    }
}

/// A point of a bifurcation curve.
#[derive(Clone, Debug, PartialEq)]
pub struct CurvePoint {
    /// `(λ1, λ2)`.
    pub parameters: (f64, f64),
    /// The orbit's state at phase 0.
    pub state: DVector<f64>,
    /// Floquet multipliers, largest modulus first (one is ±1 on the curve).
    pub multipliers: Vec<Complex<f64>>,
}

/// A followed bifurcation curve.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Points along the curve.
    pub points: Vec<CurvePoint>,
    /// Why it ended.
    pub stop_reason: StopReason,
}

struct BifurcationSystem<'a, M: PeriodMap> {
    map: &'a M,
    parameters: Vec<f64>,
    indices: (usize, usize),
    scales: (f64, f64),
    sign: f64, // A = P_x − sign·I: +1 fold, −1 period doubling
    border: (DVector<f64>, DVector<f64>),
    fd_step: f64,
}

impl<M: PeriodMap> BifurcationSystem<'_, M> {
    fn unpack(&self, u: &DVector<f64>) -> (DVector<f64>, Vec<f64>) {
        let n = self.map.dim();
        let mut p = self.parameters.clone();
        p[self.indices.0] = u[n] * self.scales.0;
        p[self.indices.1] = u[n + 1] * self.scales.1;
        (u.rows(0, n).into_owned(), p)
    }

    fn test_function(&self, monodromy: &DMatrix<f64>) -> Result<f64> {
        let n = self.map.dim();
        let mut a = DMatrix::zeros(n + 1, n + 1);
        a.view_mut((0, 0), (n, n))
            .copy_from(&(monodromy - DMatrix::identity(n, n) * self.sign));
        a.view_mut((0, n), (n, 1)).copy_from(&self.border.0);
        a.view_mut((n, 0), (1, n))
            .copy_from(&self.border.1.transpose());
        let mut rhs = DVector::zeros(n + 1);
        rhs[n] = 1.0;
        let sol = a.lu().solve(&rhs).ok_or_else(|| {
            Error::Singular("singular bordered matrix of the test function".into())
        })?;
        Ok(sol[n])
    }
}

impl<M: PeriodMap> System for BifurcationSystem<'_, M> {
    fn equations(&self) -> usize {
        self.map.dim() + 1
    }

    fn evaluate(&self, u: &DVector<f64>) -> Result<Evaluation> {
        let n = self.map.dim();
        let (x, p) = self.unpack(u);
        let (image, monodromy) = self.map.image_and_jacobian(&x, &p)?;
        let mut residual = DVector::zeros(n + 1);
        residual.rows_mut(0, n).copy_from(&(&image - &x));
        residual[n] = self.test_function(&monodromy)?;
        let mut jacobian = DMatrix::zeros(n + 1, n + 2);
        jacobian
            .view_mut((0, 0), (n, n))
            .copy_from(&(&monodromy - DMatrix::identity(n, n)));
        for (k, (index, scale)) in [
            (self.indices.0, self.scales.0),
            (self.indices.1, self.scales.1),
        ]
        .into_iter()
        .enumerate()
        {
            let eps = self.fd_step * p[index].abs().max(scale);
            let (mut up, mut down) = (p.clone(), p.clone());
            up[index] += eps;
            down[index] -= eps;
            let column =
                (self.map.image(&x, &up)? - self.map.image(&x, &down)?) * (scale / (2.0 * eps));
            jacobian.view_mut((0, n + k), (n, 1)).copy_from(&column);
        }
        for j in 0..n + 2 {
            let eps = self.fd_step * u[j].abs().max(1.0);
            let (mut up, mut down) = (u.clone(), u.clone());
            up[j] += eps;
            down[j] -= eps;
            let g = |v: &DVector<f64>| -> Result<f64> {
                let (x, p) = self.unpack(v);
                self.test_function(&self.map.image_and_jacobian(&x, &p)?.1)
            };
            jacobian[(n, j)] = (g(&up)? - g(&down)?) / (2.0 * eps);
        }
        Ok(Evaluation {
            residual,
            jacobian,
            monodromy: Some(monodromy),
        })
    }
}

/// Follows a located fold or period doubling of a branch in a second parameter.
///
/// `parameters` are the branch's parameters; `first` is the branch's continued parameter (its
/// value is taken from the bifurcation).
///
/// # Errors
/// [`Error::InvalidParameter`] for bad options or a Neimark–Sacker point (not supported: its
/// test function needs the bialternate product); the first correction's error if the start is
/// not on the curve.
pub fn continue_fold_curve<M: PeriodMap>(
    map: &M,
    bifurcation: &Bifurcation,
    parameters: &[f64],
    first: usize,
    options: &CurveOptions,
) -> Result<Curve> {
    let n = map.dim();
    let sign = match bifurcation.kind {
        BifurcationKind::Fold => 1.0,
        BifurcationKind::PeriodDoubling => -1.0,
        BifurcationKind::NeimarkSacker | BifurcationKind::BranchPoint => {
            return Err(Error::invalid(
                "bifurcation",
                bifurcation.kind.name(),
                "a fold or a period doubling (Neimark-Sacker and branch-point curves are not supported)",
            ));
        }
    };
    if options.second >= parameters.len() || options.second == first || first >= parameters.len() {
        return Err(Error::invalid(
            "second",
            options.second,
            format!(
                "a parameter index < {} other than {first}",
                parameters.len()
            ),
        ));
    }
    crate::system::check_steps(options.initial_step, options.min_step, options.max_step)?;
    check_positive("parameter_scales.0", options.parameter_scales.0)?;
    check_positive("parameter_scales.1", options.parameter_scales.1)?;
    let mut p = parameters.to_vec();
    p[first] = bifurcation.point.parameter;
    let start_second = p[options.second];
    if options.stop == start_second {
        return Err(Error::invalid(
            "stop",
            options.stop,
            "different from the starting value",
        ));
    }
    let x = &bifurcation.point.state;
    let a = map.image_and_jacobian(x, &p)?.1 - DMatrix::identity(n, n) * sign;
    let svd = a.svd(true, true);
    let smallest = (0..n)
        .min_by(|&i, &j| svd.singular_values[i].total_cmp(&svd.singular_values[j]))
        .unwrap_or(0);
    let (Some(u_mat), Some(v_t)) = (svd.u, svd.v_t) else {
        return Err(Error::Singular("SVD failed at the bifurcation".into()));
    };
    let system = BifurcationSystem {
        map,
        parameters: p.clone(),
        indices: (first, options.second),
        scales: options.parameter_scales,
        sign,
        border: (
            u_mat.column(smallest).into_owned(),
            v_t.row(smallest).transpose(),
        ),
        fd_step: options.fd_step,
    };
    let mut u = DVector::zeros(n + 2);
    u.rows_mut(0, n).copy_from(x);
    u[n] = p[first] / options.parameter_scales.0;
    u[n + 1] = start_second / options.parameter_scales.1;
    // First point: the second parameter held at its value.
    let mut e2 = DVector::zeros(n + 2);
    e2[n + 1] = 1.0;
    let direction = (options.stop - start_second).signum();
    let first_point = correct(
        &system,
        u,
        &e2,
        start_second / options.parameter_scales.1,
        options.tolerance,
        4 * options.max_iterations,
    )?;
    let point = |c: &crate::system::Corrected| {
        let (x, p) = system.unpack(&c.u);
        CurvePoint {
            parameters: (p[first], p[options.second]),
            state: x,
            multipliers: c
                .evaluation
                .monodromy
                .as_ref()
                .map(|m| multipliers(m, false))
                .unwrap_or_default(),
        }
    };
    let mut t = tangent(&first_point.evaluation.jacobian, &(e2.clone() * direction))?;
    let mut u = first_point.u.clone();
    let mut points = vec![point(&first_point)];
    let (lo, hi) = if direction > 0.0 {
        (start_second, options.stop)
    } else {
        (options.stop, start_second)
    };
    let mut h = options.initial_step;
    let stop_reason = loop {
        if points.len() >= options.max_points {
            break StopReason::MaxPoints;
        }
        let predicted = &u + &t * h;
        let target = t.dot(&predicted);
        let attempt = correct(
            &system,
            predicted,
            &t,
            target,
            options.tolerance,
            options.max_iterations,
        )
        .and_then(|c| Ok((tangent(&c.evaluation.jacobian, &t)?, c)));
        match attempt {
            Ok((new_t, c)) if new_t.dot(&t) > 0.8 => {
                h = if c.iterations <= 3 {
                    (h * 1.5).min(options.max_step)
                } else {
                    h
                };
                t = new_t;
                u = c.u.clone();
                let pt = point(&c);
                let second = pt.parameters.1;
                points.push(pt);
                if second > hi || second < lo {
                    break if (second - options.stop) * direction >= 0.0 {
                        StopReason::ReachedStop
                    } else {
                        StopReason::LeftInterval
                    };
                }
            }
            Err(Error::Cancelled) => return Err(Error::Cancelled),
            other => {
                h *= 0.5;
                if h < options.min_step {
                    let why = match other {
                        Err(e) => e.to_string(),
                        Ok(_) => "the tangent turned sharply".into(),
                    };
                    break StopReason::StepTooSmall(why);
                }
            }
        }
    };
    Ok(Curve {
        points,
        stop_reason,
    })
}
