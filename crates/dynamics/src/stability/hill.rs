//! §2.6: the linearised (Hill-type) equation 2.25: Taylor-series monodromy, multipliers,
//! regions of Fig. 2.13 (docs/errata.md#9) and the parallel stability chart.

use std::f64::consts::{FRAC_PI_2, PI};

use nalgebra::{Complex, Matrix2};
use paritysim_error::{Error, Result, bail, check_finite};

use crate::integrate::budget;

/// Highest Taylor coefficient kept per step of the eq. 2.25 integrator. The solutions are
/// entire, but `cos` grows like `cosh` off the real axis, so the Taylor coefficients decay
/// only like `e^{|β0| cosh r} / r^n` (Cauchy); with steps `h = STEP/λ` the truncation stays at
/// round-off (checked against 128-fold subdivision for β0 in [−3, 30], κ in [−5, 300]).
pub const TAYLOR_ORDER: usize = 20;

/// Step of the eq. 2.25 integrator in units of `1/λ`, `λ = max(1, |β0|, √|κ|)`.
pub const STEP: f64 = 0.4;

/// Largest `|β0|` accepted by the eq. 2.25 functions (beyond it `e^{±2β0}` leaves f64 range
/// for any useful κ).
pub const MAX_ABS_BETA0: f64 = 300.0;
/// Largest `|κ|` accepted by the eq. 2.25 functions.
pub const MAX_ABS_KAPPA: f64 = 1.0e6;

const fn inverse_factorials() -> [f64; TAYLOR_ORDER + 1] {
    let mut out = [1.0; TAYLOR_ORDER + 1];
    let mut k = 1;
    while k <= TAYLOR_ORDER {
        out[k] = out[k - 1] / k as f64;
        k += 1;
    }
    out
}

const INV_FACTORIAL: [f64; TAYLOR_ORDER + 1] = inverse_factorials();

pub(crate) fn check_hill(beta0: f64, kappa: f64) -> Result<()> {
    check_finite("beta0", beta0)?;
    check_finite("kappa", kappa)?;
    if beta0.abs() > MAX_ABS_BETA0 {
        bail!(invalid "beta0", beta0, format!("in [-{MAX_ABS_BETA0}, {MAX_ABS_BETA0}]"));
    }
    if kappa.abs() > MAX_ABS_KAPPA {
        bail!(invalid "kappa", kappa, format!("in [-{MAX_ABS_KAPPA:e}, {MAX_ABS_KAPPA:e}]"));
    }
    Ok(())
}

const fn pair_inverses() -> [f64; TAYLOR_ORDER + 1] {
    let mut out = [0.0; TAYLOR_ORDER + 1];
    let mut n = 0;
    while n + 2 <= TAYLOR_ORDER {
        out[n] = 1.0 / ((n + 1) * (n + 2)) as f64;
        n += 1;
    }
    out
}

/// `1/((n+1)(n+2))`, the divisor of the Taylor recursion.
const PAIR_INVERSE: [f64; TAYLOR_ORDER + 1] = pair_inverses();

/// One Taylor step of `ẍ = −σβ0 cos(t) ẋ − κ x` from `t` to `t + h` for both columns of `x`
/// (row 0: x, row 1: ẋ).
#[inline]
fn taylor_step(g_scale: f64, kappa: f64, t: f64, h: f64, x: &mut Matrix2<f64>) {
    // Taylor coefficients of g(t + s) = σβ0 cos(t + s): cos^(k)(t) = cos(t + kπ/2).
    let (s, c) = t.sin_cos();
    let cycle = [c, -s, -c, s];
    let mut g = [0.0; TAYLOR_ORDER + 1];
    for (k, gk) in g.iter_mut().enumerate() {
        *gk = g_scale * cycle[k % 4] * INV_FACTORIAL[k];
    }
    // Coefficients x_n of both columns, and d_n = n x_n (those of ẋ, shifted).
    let mut xs = [[0.0; 2]; TAYLOR_ORDER + 1];
    let mut ds = [[0.0; 2]; TAYLOR_ORDER + 1];
    xs[0] = [x[(0, 0)], x[(0, 1)]];
    xs[1] = [x[(1, 0)], x[(1, 1)]];
    ds[1] = xs[1];
    // (n+1)(n+2) x_{n+2} = −κ x_n − Σ_{k=0}^{n} g_k (n−k+1) x_{n−k+1}
    for n in 0..=TAYLOR_ORDER - 2 {
        let mut acc = [kappa * xs[n][0], kappa * xs[n][1]];
        for (gk, d) in g[..=n].iter().zip(ds[1..=n + 1].iter().rev()) {
            acc[0] += gk * d[0];
            acc[1] += gk * d[1];
        }
        let inv = PAIR_INVERSE[n];
        let next = [-acc[0] * inv, -acc[1] * inv];
        xs[n + 2] = next;
        let m = (n + 2) as f64;
        ds[n + 2] = [m * next[0], m * next[1]];
    }
    for j in 0..2 {
        let (mut pos, mut vel) = (xs[TAYLOR_ORDER][j], ds[TAYLOR_ORDER][j]);
        for n in (1..TAYLOR_ORDER).rev() {
            pos = pos * h + xs[n][j];
            vel = vel * h + ds[n][j];
        }
        x[(0, j)] = pos * h + xs[0][j];
        x[(1, j)] = vel;
    }
}

/// The solution matrix `Π(t1, t0)` of eq. 2.25 (eq. 2.33): columns are the solutions with
/// `(x, ẋ)(t0) = (1, 0)` and `(0, 1)`. `t1 ≥ t0`; the interval is split where `|cos t|` has a
/// kink (`t = π/2 + kπ`) and each smooth piece is integrated with Taylor steps.
///
/// # Errors
/// [`Error::InvalidParameter`] for non-finite or out-of-range arguments or `t1 < t0`;
/// [`Error::OutOfDomain`] when the solution overflows.
pub fn hill_solution_matrix(beta0: f64, kappa: f64, t0: f64, t1: f64) -> Result<Matrix2<f64>> {
    check_hill(beta0, kappa)?;
    check_finite("t0", t0)?;
    check_finite("t1", t1)?;
    if t1 < t0 {
        bail!(invalid "t1", t1, format!(">= t0 = {t0}"));
    }
    if t1 - t0 > 1.0e4 {
        bail!(invalid "t1", t1, format!("within 1e4 of t0 = {t0}"));
    }
    let lambda = 1.0f64.max(beta0.abs()).max(kappa.abs().sqrt());
    let mut x = Matrix2::identity();
    let mut t = t0;
    while t < t1 {
        let k = ((t - FRAC_PI_2) / PI).floor() + 1.0;
        let mut kink = FRAC_PI_2 + k * PI;
        if kink <= t + 1e-13 {
            kink += PI;
        }
        let end = kink.min(t1);
        let sigma = (0.5 * (t + end)).cos().signum();
        let n = ((end - t) * lambda / STEP).ceil().max(1.0) as usize;
        let h = (end - t) / n as f64;
        for i in 0..n {
            taylor_step(sigma * beta0, kappa, t + i as f64 * h, h, &mut x);
        }
        t = end;
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(Error::OutOfDomain {
            what: "eq. 2.25 solution".into(),
            detail: format!("overflow for beta0 = {beta0}, kappa = {kappa} over [{t0}, {t1}]"),
        });
    }
    Ok(x)
}

/// The monodromy matrix `M(t0) = Π(t0 + π, t0)` of eq. 2.25 (eq. 2.30).
pub fn hill_monodromy(beta0: f64, kappa: f64, t0: f64) -> Result<Matrix2<f64>> {
    hill_solution_matrix(beta0, kappa, t0, t0 + PI)
}

/// A region of the trace-determinant plane of Fig. 2.13.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Region {
    /// Stable: `b ≤ 1` and `|a| ≤ (1 + b)/2` (the Schur–Cohn triangle, docs/errata.md#9).
    I,
    /// Complex multipliers with `|ρ| = √b > 1` (`b > a²`, `b > 1`).
    II,
    /// Real multipliers, `a > 0`, one of them above 1: `a > (1 + b)/2` (docs/errata.md#9: the
    /// printed bound `(b − 1)/2` is wrong) or `b > 1`.
    III,
    /// Real multipliers, `a < 0`, one of them below −1: `a < −(1 + b)/2` or `b > 1`.
    IV,
}

impl Region {
    /// 1, 2, 3 or 4.
    pub fn index(self) -> u8 {
        match self {
            Region::I => 1,
            Region::II => 2,
            Region::III => 3,
            Region::IV => 4,
        }
    }

    /// Whether every multiplier has `|ρ| ≤ 1` (Region I).
    pub fn is_stable(self) -> bool {
        self == Region::I
    }
}

/// The region of Fig. 2.13 for half trace `a` and determinant `b` of a 2×2 monodromy matrix.
///
/// Region I is `b ≤ 1, |a| ≤ (1 + b)/2` (docs/errata.md#9): the roots of `ρ² − 2aρ + b` (eq. 2.36)
/// have `|ρ| ≤ 1` exactly there. Outside it, complex roots with `b > 1` are Region II and real
/// roots are Region III (`a > 0`) or IV (`a < 0`).
///
/// # Errors
/// [`Error::InvalidParameter`] for non-finite `a` or `b`.
pub fn region(a: f64, b: f64) -> Result<Region> {
    check_finite("a", a)?;
    check_finite("b", b)?;
    Ok(if b <= 1.0 && a.abs() <= 0.5 * (1.0 + b) {
        Region::I
    } else if b > a * a {
        Region::II
    } else if a > 0.0 {
        Region::III
    } else {
        Region::IV
    })
}

/// The roots `ρ = a ± √(a² − b)` of eq. 2.36 (eq. 2.37), larger modulus first. Real roots use
/// `ρ2 = b/ρ1` to avoid cancellation.
pub fn multipliers(a: f64, b: f64) -> [Complex<f64>; 2] {
    let disc = a * a - b;
    if disc < 0.0 {
        let im = (-disc).sqrt();
        [Complex::new(a, im), Complex::new(a, -im)]
    } else {
        let r1 = a + a.signum() * disc.sqrt();
        let r1 = if a == 0.0 { disc.sqrt() } else { r1 };
        let r2 = if r1 == 0.0 { 0.0 } else { b / r1 };
        [Complex::new(r1, 0.0), Complex::new(r2, 0.0)]
    }
}

/// Floquet analysis of eq. 2.25 at one `(β0, κ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HillFloquet {
    /// β0.
    pub beta0: f64,
    /// κ.
    pub kappa: f64,
    /// `M(−π/2)`, the matrix of eq. 2.50 when κ = 0 (trace and determinant do not depend on t0).
    pub monodromy: Matrix2<f64>,
    /// `a = tr M / 2`.
    pub a: f64,
    /// `b = det M` (`e^{−2β0}`, eq. 2.45).
    pub b: f64,
    /// The Floquet multipliers (eq. 2.37), larger modulus first.
    pub multipliers: [Complex<f64>; 2],
    /// Region of Fig. 2.13 (of the computed `a`, `b`; see [`Self::is_marginal`]).
    pub region: Region,
    /// Error estimate of the multipliers' moduli ([`multiplier_error`]).
    pub multiplier_error: f64,
}

impl HillFloquet {
    /// Whether `max |ρ|` is within [`Self::multiplier_error`] of 1: the computed multipliers
    /// cannot tell stable from unstable (the undamped line β0 = 0, the κ = 0 line of eq. 2.50).
    pub fn is_marginal(&self) -> bool {
        (self.spectral_radius() - 1.0).abs() <= self.multiplier_error
    }

    /// `max |ρ|`.
    pub fn spectral_radius(&self) -> f64 {
        self.multipliers[0].norm().max(self.multipliers[1].norm())
    }

    /// Largest real part of the Floquet exponents `γ = ln(ρ)/π` (eq. 2.31–2.32).
    pub fn max_exponent(&self) -> f64 {
        self.spectral_radius().ln() / PI
    }
}

/// Monodromy, multipliers and region of eq. 2.25 at `(β0, κ)`.
pub fn hill_floquet(beta0: f64, kappa: f64) -> Result<HillFloquet> {
    let m = hill_monodromy(beta0, kappa, -FRAC_PI_2)?;
    let a = 0.5 * m.trace();
    let b = m.determinant();
    // [−π/2, π/2] is one smooth piece of |cos t|: the step count of `hill_solution_matrix`.
    let lambda = 1.0f64.max(beta0.abs()).max(kappa.abs().sqrt());
    let steps = (PI * lambda / STEP).ceil().max(1.0) as usize;
    Ok(HillFloquet {
        beta0,
        kappa,
        monodromy: m,
        a,
        b,
        multipliers: multipliers(a, b),
        region: region(a, b)?,
        multiplier_error: multiplier_error(&m, beta0, steps),
    })
}

/// Safety factor of [`multiplier_error`] over its first-order round-off estimate.
pub const MULTIPLIER_ERROR_SAFETY: f64 = 4.0;

/// Error estimate of the multipliers' moduli for the computed monodromy `m` of eq. 2.25
/// (`steps` Taylor steps, exact determinant `e^{−2β0}` by eq. 2.45).
///
/// Entries: round-off accumulated over the steps, `δM = steps · ε · max(1, max|M_ij|)`.
/// Determinant: the larger of the Liouville residual `|det M − e^{−2β0}|` (a measured error)
/// and `δM Σ|M_ij|`. The roots `ρ = a ± √(a² − b)` of eq. 2.36 then move by at most
/// `δa + min(δΔ / (2√|Δ|), √δΔ)` with `Δ = a² − b`, `δΔ = 2|a|δa + δb` (the square root's
/// first-order and Hölder bounds), times [`MULTIPLIER_ERROR_SAFETY`].
pub fn multiplier_error(m: &Matrix2<f64>, beta0: f64, steps: usize) -> f64 {
    let entry = steps as f64 * f64::EPSILON * m.amax().max(1.0);
    let a = 0.5 * m.trace();
    let b = m.determinant();
    let abs_sum = m.iter().map(|v| v.abs()).sum::<f64>();
    let db = (b - (-2.0 * beta0).exp()).abs().max(entry * abs_sum);
    let disc = (a * a - b).abs();
    let ddisc = 2.0 * a.abs() * entry + db;
    let root = if disc > 0.0 {
        (ddisc / (2.0 * disc.sqrt())).min(ddisc.sqrt())
    } else {
        ddisc.sqrt()
    };
    MULTIPLIER_ERROR_SAFETY * (entry + root)
}

/// A Floquet stability chart over a (β0, κ) grid: row-major, β0 outer, κ inner. A point whose
/// analysis failed (its solution overflows f64) is kept as a marked entry: region `None`,
/// NaN numbers, not marginal, and its error in [`Self::errors`].
#[derive(Clone, Debug, PartialEq, Default)]
pub struct StabilityChart {
    /// β0 of each point.
    pub beta0: Vec<f64>,
    /// κ of each point.
    pub kappa: Vec<f64>,
    /// Half trace `a` of the monodromy matrix (NaN for a failed point).
    pub a: Vec<f64>,
    /// Determinant `b` (NaN for a failed point).
    pub b: Vec<f64>,
    /// `max |ρ|` (NaN for a failed point).
    pub spectral_radius: Vec<f64>,
    /// Region of Fig. 2.13 (`None` for a failed point).
    pub region: Vec<Option<Region>>,
    /// [`HillFloquet::multiplier_error`] (NaN for a failed point).
    pub multiplier_error: Vec<f64>,
    /// [`HillFloquet::is_marginal`] (false for a failed point).
    pub marginal: Vec<bool>,
    /// The failed points: flat index (`i_beta0 * kappa.len() + i_kappa`) and error, in index
    /// order.
    pub errors: Vec<(usize, Error)>,
}

impl StabilityChart {
    /// Whether each point is stable: Region I and not marginal (false for a failed point).
    pub fn stable(&self) -> Vec<bool> {
        let points = self.region.iter().zip(&self.marginal);
        points
            .map(|(r, &m)| r.is_some_and(Region::is_stable) && !m)
            .collect()
    }

    /// The region of each point as its number 1-4, 0 for a failed point.
    pub fn region_numbers(&self) -> Vec<i64> {
        let number = |r: &Option<Region>| r.map_or(0, |r| i64::from(r.index()));
        self.region.iter().map(number).collect()
    }
}

/// Points of one task of [`stability_chart`] on the sweep engine's pool.
const CHART_CHUNK: usize = 1024;

/// Largest number of points of one [`stability_chart`] call.
pub const MAX_CHART_POINTS: usize = 4_000_000;

/// Evaluates [`hill_floquet`] on every `(β0, κ)` of the grid `beta0 × kappa`, in parallel on
/// the sweep engine's own pool ([`super::rows`]; `PARITYSIM_THREADS`).
///
/// A point that fails (its solution overflows: [`Error::OutOfDomain`], e.g. κ = −1e6) is a
/// marked entry of the chart (see [`StabilityChart`]); the other points are kept.
///
/// # Errors
/// [`Error::InvalidParameter`] naming the first bad element (`beta0[i]`, `kappa[j]`), an
/// empty axis or more than [`MAX_CHART_POINTS`] points; [`Error::Cancelled`] or the wall
/// budget's error when the caller's budget stops the chart.
pub fn stability_chart(beta0: &[f64], kappa: &[f64]) -> Result<StabilityChart> {
    if beta0.is_empty() || kappa.is_empty() {
        bail!(invalid "beta0, kappa", format!("{} x {}", beta0.len(), kappa.len()), "non-empty axes");
    }
    let n = beta0.len().saturating_mul(kappa.len());
    if n > MAX_CHART_POINTS {
        bail!(invalid "beta0, kappa", format!("{n} points"), format!("at most {MAX_CHART_POINTS} points"));
    }
    for (i, &b) in beta0.iter().enumerate() {
        check_hill(b, 0.0).map_err(|e| e.at_index(i, Some("beta0")))?;
    }
    for (j, &k) in kappa.iter().enumerate() {
        check_hill(0.0, k).map_err(|e| e.at_index(j, Some("kappa")))?;
    }
    let nk = kappa.len();
    // On the sweep engine's own pool, in chunks (a point takes microseconds). Every point
    // checks the caller's budget (its cancel flag): a spent budget fails the chunk, hence the
    // chart; a failing point (only by overflow once the axes are validated) is its entry.
    let chunks = n.div_ceil(CHART_CHUNK);
    let rows = super::rows::run_rows(chunks, None, None, |c| {
        (c * CHART_CHUNK..((c + 1) * CHART_CHUNK).min(n))
            .map(|idx| {
                budget::check(0.0)?;
                Ok(hill_floquet(beta0[idx / nk], kappa[idx % nk])
                    .map_err(|e| e.at_index(idx, None)))
            })
            .collect::<Result<Vec<Result<HillFloquet>>>>()
    })?;
    let points: Vec<Result<HillFloquet>> = rows
        .into_iter()
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect();
    let mut chart = StabilityChart {
        beta0: Vec::with_capacity(n),
        kappa: Vec::with_capacity(n),
        a: Vec::with_capacity(n),
        b: Vec::with_capacity(n),
        spectral_radius: Vec::with_capacity(n),
        region: Vec::with_capacity(n),
        multiplier_error: Vec::with_capacity(n),
        marginal: Vec::with_capacity(n),
        errors: Vec::new(),
    };
    for (idx, point) in points.into_iter().enumerate() {
        let p = match point {
            Ok(p) => p,
            Err(e) => {
                chart.beta0.push(beta0[idx / nk]);
                chart.kappa.push(kappa[idx % nk]);
                for column in [
                    &mut chart.a,
                    &mut chart.b,
                    &mut chart.spectral_radius,
                    &mut chart.multiplier_error,
                ] {
                    column.push(f64::NAN);
                }
                chart.region.push(None);
                chart.marginal.push(false);
                chart.errors.push((idx, e));
                continue;
            }
        };
        chart.beta0.push(p.beta0);
        chart.kappa.push(p.kappa);
        chart.a.push(p.a);
        chart.b.push(p.b);
        chart.spectral_radius.push(p.spectral_radius());
        chart.region.push(Some(p.region));
        chart.multiplier_error.push(p.multiplier_error);
        chart.marginal.push(p.is_marginal());
    }
    Ok(chart)
}
