//! Stability of periodic flapping (thesis §2.6), disturbance rejection (§2.7), and the Floquet
//! analysis of the full nonlinear model's limit cycle.
//!
//! * **Linearised model (§2.6).** The monodromy matrix of `ẍ + β0|cos t|ẋ + κx = 0` (eq. 2.25,
//!   period π) is integrated with a Taylor-series method of order [`TAYLOR_ORDER`] on the
//!   pieces where `|cos t|` is smooth (truncation at round-off level; closed forms of eqs.
//!   2.45, 2.50 and 2.54 hold to 1e-9 or better in `tests/dynamics/floquet.rs`); its
//!   half trace `a`, determinant `b` (eq. 2.36), multipliers (eq. 2.37) and region of Fig. 2.13
//!   ([`Region`], with the corrected Region III bound of ERRATA item 9) follow. A
//!   [`stability_chart`] over a (β0, κ) grid is computed in parallel with rayon. [`brockett`]
//!   is the criterion of eqs. 2.57–2.58 and [`PhysicalParameters::hill`] maps a device to
//!   (β0, κ1, κ2) with the factors of ERRATA item 7.
//! * **Disturbance rejection (§2.7).** [`LtiModel`] is eq. 2.59; [`linearise`] derives its
//!   `β*` (cycle-averaged aerodynamic damping of the whippletree mode) and `κ0` from a device
//!   and its periodic orbit, and [`disturbance_response`] measures the same transfer on the
//!   full nonlinear model by injecting a sinusoidal roll torque on the wings
//!   ([`RollDisturbance`], an [`OdeSystem`] wrapped around the device).
//! * **Full nonlinear model.** [`periodic_orbit`] finds the limit cycle by shooting (Newton on
//!   the stroboscopic map over one drive period, cycle-to-cycle simulation as the fallback);
//!   [`floquet`] differentiates the stroboscopic map by central finite differences over the
//!   coordinates and rates the device integrates (work integrals excluded) and returns the
//!   Floquet multipliers; [`balance_stiffness_sweep`] repeats that over K2 in parallel.
//!
//! Errata (ERRATA.md next to the thesis) relied on here, each verified numerically in
//! `tests/dynamics/floquet.rs`: item 7 (the drag forces of eqs. 2.17–2.19 carry `T³`, so
//! `β0 = 2ΩΦ/I`), item 8 (eq. 2.27's coefficient is `−¼β0²cos²t`), item 9 (Region I is
//! `b ≤ 1, |a| ≤ (1 + b)/2`), item 10 (eq. 2.52 is `M = exp(TQ)`, eq. 2.53 is `M^(n+1)`, eq. 2.54
//! lacks a factor π).

use std::f64::consts::{FRAC_PI_2, PI};

use nalgebra::{Complex, DMatrix, DVector, Matrix2, Vector2};
use paritysim_constraints::Vec6;
use paritysim_error::{Error, Result, bail, check_finite, check_positive};
use rayon::prelude::*;

use crate::device::{Device, DeviceSpec, Formulation, Transmission};
use crate::integrate::{Integrator, Method, OdeSystem, RungeKutta, STATE_LEN, State};

// ============================================================================================
// §2.6: the linearised (Hill-type) equation 2.25
// ============================================================================================

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

fn check_hill(beta0: f64, kappa: f64) -> Result<()> {
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
    /// Stable: `b ≤ 1` and `|a| ≤ (1 + b)/2` (the Schur–Cohn triangle, ERRATA item 9).
    I,
    /// Complex multipliers with `|ρ| = √b > 1` (`b > a²`, `b > 1`).
    II,
    /// Real multipliers, `a > 0`, one of them above 1: `a > (1 + b)/2` (ERRATA item 9: the
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
/// Region I is `b ≤ 1, |a| ≤ (1 + b)/2` (ERRATA item 9): the roots of `ρ² − 2aρ + b` (eq. 2.36)
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
    /// Region of Fig. 2.13.
    pub region: Region,
}

impl HillFloquet {
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
    Ok(HillFloquet {
        beta0,
        kappa,
        monodromy: m,
        a,
        b,
        multipliers: multipliers(a, b),
        region: region(a, b)?,
    })
}

/// A Floquet stability chart over a (β0, κ) grid: row-major, β0 outer, κ inner.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct StabilityChart {
    /// β0 of each point.
    pub beta0: Vec<f64>,
    /// κ of each point.
    pub kappa: Vec<f64>,
    /// Half trace `a` of the monodromy matrix.
    pub a: Vec<f64>,
    /// Determinant `b`.
    pub b: Vec<f64>,
    /// `max |ρ|`.
    pub spectral_radius: Vec<f64>,
    /// Region of Fig. 2.13.
    pub region: Vec<Region>,
}

/// Largest number of points of one [`stability_chart`] call.
pub const MAX_CHART_POINTS: usize = 4_000_000;

/// Evaluates [`hill_floquet`] on every `(β0, κ)` of the grid `beta0 × kappa`, in parallel.
///
/// # Errors
/// [`Error::InvalidParameter`] naming the first bad element (`beta0[i]`, `kappa[j]`), an
/// empty axis or more than [`MAX_CHART_POINTS`] points; [`Error::OutOfDomain`] on overflow.
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
    let points: Vec<HillFloquet> = (0..n)
        .into_par_iter()
        .with_min_len(64)
        .map(|idx| {
            hill_floquet(beta0[idx / nk], kappa[idx % nk]).map_err(|e| e.at_index(idx, None))
        })
        .collect::<Result<_>>()?;
    let mut chart = StabilityChart {
        beta0: Vec::with_capacity(n),
        kappa: Vec::with_capacity(n),
        a: Vec::with_capacity(n),
        b: Vec::with_capacity(n),
        spectral_radius: Vec::with_capacity(n),
        region: Vec::with_capacity(n),
    };
    for p in points {
        chart.beta0.push(p.beta0);
        chart.kappa.push(p.kappa);
        chart.a.push(p.a);
        chart.b.push(p.b);
        chart.spectral_radius.push(p.spectral_radius());
        chart.region.push(p.region);
    }
    Ok(chart)
}

// --------------------------------------------------------------------------------------------
// §2.6.4: Brockett's criterion
// --------------------------------------------------------------------------------------------

/// The outcome of Brockett's sufficient condition for bounded solutions of
/// `ẍ + g(t)ẋ + x = 0`, `g(t + T) = g(t)`, `|g| ≤ 2δ` (eqs. 2.56–2.58).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Brockett {
    /// δ (half the bound on |g|).
    pub delta: f64,
    /// Period T.
    pub period: f64,
    /// `∫_0^T g dt`.
    pub damping_integral: f64,
    /// The smallest positive integer n whose interval of eq. 2.57 contains T, if any.
    pub n: Option<u64>,
    /// That interval `[2(n−1)(π − asin s)/s, 2n asin(s)/s]`, `s = √(1 − δ²)`.
    pub interval: Option<(f64, f64)>,
    /// Eq. 2.58: `∫ g ≥ 0`.
    pub damping_condition: bool,
    /// Both conditions hold: all solutions are guaranteed bounded. `false` guarantees nothing.
    pub bounded: bool,
}

/// Brockett's criterion (eqs. 2.57–2.58) for damping bound δ (`|g| ≤ 2δ`), period `T` and
/// `∫_0^T g dt`. For δ ≥ 1 eq. 2.57 has no interval and nothing is guaranteed.
///
/// # Errors
/// [`Error::InvalidParameter`] for δ < 0, T ≤ 0 or non-finite values.
pub fn brockett(delta: f64, period: f64, damping_integral: f64) -> Result<Brockett> {
    if !(delta.is_finite() && delta >= 0.0) {
        bail!(invalid "delta", delta, "finite and >= 0");
    }
    check_positive("period", period)?;
    check_finite("damping_integral", damping_integral)?;
    let damping_condition = damping_integral >= 0.0;
    let (mut n, mut interval) = (None, None);
    if delta < 1.0 {
        let s = (1.0 - delta * delta).sqrt();
        let asin = s.asin();
        let upper = |n: f64| 2.0 * n * asin / s;
        let lower = |n: f64| 2.0 * (n - 1.0) * (PI - asin) / s;
        // The upper ends grow with n: the smallest admissible n is the only candidate, since
        // the lower ends grow too (π − asin s ≥ asin s).
        let n_min = (period / upper(1.0)).ceil().max(1.0);
        // Closed intervals, with a relative rounding guard of 1e-12 at their ends (for δ = 1/2
        // the n = 2 interval is a single point).
        for cand in [n_min - 1.0, n_min] {
            let tol = 1e-12 * period;
            if cand >= 1.0 && lower(cand) <= period + tol && period <= upper(cand) + tol {
                n = Some(cand as u64);
                interval = Some((lower(cand), upper(cand)));
                break;
            }
        }
    }
    Ok(Brockett {
        delta,
        period,
        damping_integral,
        n,
        interval,
        damping_condition,
        bounded: damping_condition && n.is_some(),
    })
}

/// Brockett's criterion applied to eq. 2.25 after rescaling time by `√κ`: `g = (β0/√κ)|cos|`,
/// `T = π√κ`, `δ = |β0|/(2√κ)`, `∫g = 2β0`.
///
/// # Errors
/// [`Error::InvalidParameter`] unless κ > 0 (the criterion needs a restoring spring).
pub fn brockett_hill(beta0: f64, kappa: f64) -> Result<Brockett> {
    check_hill(beta0, kappa)?;
    check_positive("kappa", kappa)?;
    let root = kappa.sqrt();
    brockett(beta0.abs() / (2.0 * root), PI * root, 2.0 * beta0)
}

// --------------------------------------------------------------------------------------------
// §2.6.1: from physical parameters to (β0, κ1, κ2), and §2.7's LTI model
// --------------------------------------------------------------------------------------------

/// The physical parameters of the linearised Drag PARITY model of §2.6.1 (units mg-mm-ms-rad).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhysicalParameters {
    /// Wing inertia about the stroke axis I (mg·mm²).
    pub inertia: f64,
    /// Drag parameter Ω of eq. 2.16 (mg·mm²; `Ω1 C_N(90°)` for eq. 3.8, ERRATA item 12).
    pub drag: f64,
    /// Transmission ratio T (rad/mm).
    pub transmission_ratio: f64,
    /// Whippletree arm L (mm).
    pub arm_length: f64,
    /// Actuator stiffness K1 (mN/mm).
    pub k1: f64,
    /// Balance-beam stiffness K2 (mN·mm/rad).
    pub k2: f64,
    /// Wing stroke amplitude Φ = T·A (rad).
    pub stroke_amplitude: f64,
    /// Flapping frequency (Hz).
    pub frequency_hz: f64,
}

/// The non-dimensional parameters of eqs. 2.23–2.24.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HillParameters {
    /// `β0 = 2ΩTA/I = 2ΩΦ/I` (ERRATA item 7; the printed `2ΩA/I` lacks T).
    pub beta0: f64,
    /// `κ1 = K1/(2 I T² ω0²)`.
    pub kappa1: f64,
    /// `κ2 = K2/(2 I T² L² ω0²)`.
    pub kappa2: f64,
}

impl PhysicalParameters {
    fn validate(&self) -> Result<()> {
        check_positive("inertia", self.inertia)?;
        check_positive("transmission_ratio", self.transmission_ratio)?;
        check_positive("arm_length", self.arm_length)?;
        check_positive("frequency_hz", self.frequency_hz)?;
        for (name, v) in [
            ("drag", self.drag),
            ("k1", self.k1),
            ("k2", self.k2),
            ("stroke_amplitude", self.stroke_amplitude),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                bail!(invalid name, v, "finite and >= 0");
            }
        }
        Ok(())
    }

    /// Angular drive frequency ω0 (rad/ms).
    pub fn omega0(&self) -> f64 {
        2.0 * PI * self.frequency_hz * 1e-3
    }

    /// (β0, κ1, κ2) of §2.6.1 with the factors corrected by ERRATA item 7: the drag force on q2
    /// is `−4ΩT³L²|q̇1|q̇2`, so linearising about `q1 = A sin ω0t` and dividing by the modal
    /// inertia `2IT²L²` gives the damping `2ΩTA ω0 |cos τ|/I` per unit ω0.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a non-positive inertia, T, L or frequency, or negative
    /// drag, stiffnesses or amplitude.
    pub fn hill(&self) -> Result<HillParameters> {
        self.validate()?;
        let w2 = self.omega0().powi(2);
        let t2 = self.transmission_ratio.powi(2);
        let i = self.inertia;
        Ok(HillParameters {
            beta0: 2.0 * self.drag * self.stroke_amplitude / i,
            kappa1: self.k1 / (2.0 * i * t2 * w2),
            kappa2: self.k2 / (2.0 * i * t2 * self.arm_length.powi(2) * w2),
        })
    }

    /// Eq. 2.59's LTI model for sinusoidal flapping: `κ0 = K2/(2IT²L²)` and β* the cycle
    /// average of `2Ω|φ̇|/I`, i.e. `(2/π) β0 ω0`.
    pub fn lti(&self) -> Result<LtiModel> {
        let h = self.hill()?;
        let w = self.omega0();
        LtiModel::new(2.0 / PI * h.beta0 * w, h.kappa2 * w * w)
    }
}

/// Eq. 2.59: `τ/τ_d = κ0/(s² + β* s + κ0)` from a wing roll disturbance torque to the body roll
/// torque, with `s` in rad/ms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LtiModel {
    /// Constant damping β* of the whippletree mode (1/ms).
    pub beta_star: f64,
    /// Stiffness κ0 = K2 / (modal inertia) (1/ms²).
    pub kappa0: f64,
}

impl LtiModel {
    /// `beta_star`, `kappa0` finite (negative values describe an unstable averaged mode, as
    /// the rod-crank linkage's geometric stiffness can produce; see [`DeviceLinearisation`]).
    pub fn new(beta_star: f64, kappa0: f64) -> Result<Self> {
        check_finite("beta_star", beta_star)?;
        check_finite("kappa0", kappa0)?;
        Ok(Self { beta_star, kappa0 })
    }

    /// Whether both poles are in the open left half plane (β* > 0 and κ0 > 0).
    pub fn is_stable(&self) -> bool {
        self.beta_star > 0.0 && self.kappa0 > 0.0
    }

    /// `H(iω)` at `frequency_hz` (ω = 2π f · 1e-3 rad/ms).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a negative or non-finite frequency;
    /// [`Error::Singular`] at ω = 0 when κ0 = 0 (0/0).
    pub fn transfer(&self, frequency_hz: f64) -> Result<Complex<f64>> {
        if !(frequency_hz.is_finite() && frequency_hz >= 0.0) {
            bail!(invalid "frequency_hz", frequency_hz, "finite and >= 0");
        }
        let w = 2.0 * PI * frequency_hz * 1e-3;
        let den = Complex::new(self.kappa0 - w * w, self.beta_star * w);
        if den.norm() == 0.0 {
            bail!(Singular "eq. 2.59 is 0/0 at f = 0 Hz with kappa0 = 0");
        }
        Ok(Complex::new(self.kappa0, 0.0) / den)
    }
}

// ============================================================================================
// The full nonlinear model: stroboscopic map, shooting, Floquet multipliers
// ============================================================================================

/// Options of [`periodic_orbit`] and [`floquet`].
#[derive(Clone, Debug, PartialEq)]
pub struct ShootingOptions {
    /// Runge-Kutta pair.
    pub method: Method,
    /// Relative tolerance of every period integration.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Step limit per period.
    pub max_steps: usize,
    /// Start of the stroboscopic section within the drive period (ms, in `[0, T)`).
    pub t0: f64,
    /// Cycle-to-cycle simulation from the initial state before Newton (stops early once the
    /// change per cycle is below `warmup_tol`).
    pub warmup_cycles: usize,
    /// Relative change per cycle that ends the warm-up.
    pub warmup_tol: f64,
    /// Newton iterations on `P(y) − y`.
    pub max_newton: usize,
    /// Converged when `‖P(y) − y‖∞ ≤ tol (1 + ‖y‖∞)`.
    pub tol: f64,
    /// Relative finite-difference step (scaled by the size of the coordinates or of the rates).
    /// The monodromy is also computed with 4× this step to estimate its error
    /// ([`NonlinearFloquet::monodromy_uncertainty`]).
    pub fd_step: f64,
    /// Cycles of the fallback simulation when Newton fails.
    pub fallback_cycles: usize,
    /// Initial state (full integrator layout); `None`: rest at the constraints' particular
    /// configuration, as [`crate::simulate()`].
    pub initial: Option<State>,
}

impl Default for ShootingOptions {
    fn default() -> Self {
        Self {
            method: Method::Dop853,
            rtol: 1e-12,
            atol: 1e-14,
            max_steps: 1_000_000,
            t0: 0.0,
            warmup_cycles: 20,
            warmup_tol: 1e-6,
            max_newton: 20,
            tol: 1e-10,
            fd_step: 1e-5,
            fallback_cycles: 2000,
            initial: None,
        }
    }
}

impl ShootingOptions {
    /// The integrator these options describe, validated for a drive `period` (ms).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the bad option.
    pub fn integrator(&self, period: f64) -> Result<RungeKutta> {
        self.validate(period)
    }

    fn validate(&self, period: f64) -> Result<RungeKutta> {
        if !(self.t0.is_finite() && self.t0 >= 0.0 && self.t0 < period) {
            bail!(invalid "t0", self.t0, format!("in [0, {period}) ms (one drive period)"));
        }
        check_positive("tol", self.tol)?;
        check_positive("warmup_tol", self.warmup_tol)?;
        if !(self.fd_step.is_finite() && self.fd_step > 0.0 && self.fd_step < 0.01) {
            bail!(invalid "fd_step", self.fd_step, "in (0, 0.01)");
        }
        if self.warmup_cycles > 100_000 || self.fallback_cycles > 100_000 {
            bail!(invalid "warmup_cycles, fallback_cycles",
                format!("{}, {}", self.warmup_cycles, self.fallback_cycles), "<= 100000");
        }
        if let Some(y) = &self.initial {
            paritysim_error::check_all_finite("initial", y)?;
        }
        RungeKutta::new(self.method, self.rtol, self.atol, self.max_steps)
    }
}

/// How the periodic orbit was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OrbitMethod {
    /// Newton on the stroboscopic map (stable or not).
    Newton,
    /// Cycle-to-cycle simulation (the fallback; finds stable orbits only).
    Simulation,
}

/// A periodic orbit of a driven device: the state on the section `t ≡ t0 (mod T)`.
#[derive(Clone, Debug, PartialEq)]
pub struct PeriodicOrbit {
    /// Integrator state at `t0` (work integrals zero).
    pub state: State,
    /// Section time (ms).
    pub t0: f64,
    /// Drive period T (ms).
    pub period: f64,
    /// `‖P(y) − y‖∞ / (1 + ‖y‖∞)` at the returned state.
    pub residual: f64,
    /// Newton iterations used.
    pub newton_iterations: usize,
    /// Cycles simulated (warm-up and fallback).
    pub cycles_simulated: usize,
    /// How it was found.
    pub method: OrbitMethod,
}

/// The `2n` integrated entries (coordinates, then rates) of a full state.
pub fn compact_state(n: usize, y: &State) -> DVector<f64> {
    compact(n, y)
}

/// A full state from its `2n` integrated entries (work integrals zero).
pub fn expand_state(n: usize, v: &DVector<f64>) -> State {
    expand(n, v)
}

fn compact(n: usize, y: &State) -> DVector<f64> {
    DVector::from_fn(2 * n, |i, _| if i < n { y[i] } else { y[6 + i - n] })
}

fn expand(n: usize, v: &DVector<f64>) -> State {
    let mut y = [0.0; STATE_LEN];
    for i in 0..n {
        y[i] = v[i];
        y[6 + i] = v[n + i];
    }
    y
}

/// The drive period (ms).
///
/// # Errors
/// [`Error::Constraint`] for a device without an actuator.
pub fn drive_period(device: &Device) -> Result<f64> {
    device.period().ok_or_else(|| {
        Error::Constraint(
            "Floquet analysis needs a periodic drive: the device has no actuator".into(),
        )
    })
}

/// The stroboscopic map: integrates `system` over one `period` from `(t0, y)` with the work
/// integrals reset to zero, and returns the state at `t0 + period` (work integrals zeroed).
///
/// # Errors
/// [`Error::Integration`] when the integration fails.
pub fn stroboscopic_map(
    system: &dyn OdeSystem,
    integrator: &RungeKutta,
    t0: f64,
    period: f64,
    y: &State,
) -> Result<State> {
    let mut start = *y;
    start[12] = 0.0;
    start[13] = 0.0;
    let mut out = integrator.integrate(system, t0, &start, t0 + period, &[t0 + period])?[0];
    out[12] = 0.0;
    out[13] = 0.0;
    Ok(out)
}

fn residual_norm(n: usize, y: &State, py: &State) -> f64 {
    let (mut num, mut den): (f64, f64) = (0.0, 0.0);
    for i in (0..n).chain(6..6 + n) {
        num = num.max((py[i] - y[i]).abs());
        den = den.max(y[i].abs());
    }
    num / (1.0 + den)
}

/// Finite-difference steps: `fd_step ×` the largest |coordinate| (resp. |rate|) of `y`, with a
/// floor so that a coordinate at zero (e.g. `q2` of a symmetric orbit) is still perturbed.
fn fd_steps(n: usize, y: &State, fd_step: f64) -> Vec<f64> {
    let pos = (0..n).map(|i| y[i].abs()).fold(1e-2, f64::max);
    let vel = (0..n).map(|i| y[6 + i].abs()).fold(1e-2, f64::max);
    (0..2 * n)
        .map(|i| fd_step * if i < n { pos } else { vel })
        .collect()
}

/// Jacobian of the stroboscopic map at `y` by central differences over the `2n` integrated
/// entries (columns evaluated in parallel).
///
/// # Errors
/// [`Error::Integration`] when a perturbed integration fails.
pub fn map_jacobian(
    system: &(dyn OdeSystem + Sync),
    n: usize,
    integrator: &RungeKutta,
    t0: f64,
    period: f64,
    y: &State,
    fd_step: f64,
) -> Result<DMatrix<f64>> {
    let steps = fd_steps(n, y, fd_step);
    let base = compact(n, y);
    let columns: Vec<DVector<f64>> = (0..2 * n)
        .into_par_iter()
        .map(|j| {
            let mut plus = base.clone();
            let mut minus = base.clone();
            plus[j] += steps[j];
            minus[j] -= steps[j];
            let fp = stroboscopic_map(system, integrator, t0, period, &expand(n, &plus))?;
            let fm = stroboscopic_map(system, integrator, t0, period, &expand(n, &minus))?;
            Ok((compact(n, &fp) - compact(n, &fm)) / (2.0 * steps[j]))
        })
        .collect::<Result<_>>()?;
    Ok(DMatrix::from_columns(&columns))
}

/// Finds the periodic orbit of a driven device on the section `t ≡ t0 (mod T)`.
///
/// Warm-up: up to `warmup_cycles` cycles of simulation (stopping at the last good state if an
/// integration fails). Then Newton on `F(y) = P(y) − y` with
/// the Jacobian of [`map_jacobian`]; the step solves `(DP − I)Δ = −F` by SVD in the
/// least-squares sense, so a neutral direction (multiplier 1, e.g. K2 = 0 with the linear
/// drivetrain, where every constant `q2` is an orbit) does not break it; steps are halved until
/// the residual decreases. If Newton stalls, cycle-to-cycle simulation continues from the best
/// state (this converges only to a stable orbit).
///
/// # Errors
/// [`Error::Constraint`] without an actuator; [`Error::InvalidParameter`] for bad options;
/// [`Error::Integration`] when an integration fails or no method converges (with the best
/// state and its residual).
pub fn periodic_orbit(device: &Device, options: &ShootingOptions) -> Result<PeriodicOrbit> {
    let period = drive_period(device)?;
    let integrator = options.validate(period)?;
    let n = device.n_dof();
    let t0 = options.t0;
    let mut y = match options.initial {
        Some(y) => y,
        None => device.state_from(device.spec().constraints.particular(), &Vec6::zeros())?,
    };
    y[12] = 0.0;
    y[13] = 0.0;
    let mut cycles = 0;
    let mut py = stroboscopic_map(device, &integrator, t0, period, &y)?;
    let mut res = residual_norm(n, &y, &py);
    while cycles < options.warmup_cycles && res > options.warmup_tol && res > options.tol {
        // A warm-up that runs away (an unstable orbit driven out of the linkage's reach) hands
        // Newton its last good state instead of failing.
        let Ok(next) = stroboscopic_map(device, &integrator, t0, period, &py) else {
            break;
        };
        (y, py) = (py, next);
        res = residual_norm(n, &y, &py);
        cycles += 1;
    }
    let mut iterations = 0;
    while res > options.tol && iterations < options.max_newton {
        iterations += 1;
        let jac = map_jacobian(device, n, &integrator, t0, period, &y, options.fd_step)?;
        let a = jac - DMatrix::<f64>::identity(2 * n, 2 * n);
        let f = compact(n, &py) - compact(n, &y);
        let svd = a.svd(true, true);
        let smax = svd.singular_values.max();
        let delta = svd
            .solve(&(-&f), 1e-10 * smax.max(f64::MIN_POSITIVE))
            .map_err(|e| Error::Singular(format!("Newton step of the shooting method: {e}")))?;
        let mut lambda = 1.0;
        let mut accepted = false;
        for _ in 0..8 {
            let trial = expand(n, &(compact(n, &y) + &delta * lambda));
            // A trial step may leave the linkage's reach: treat it as a failed step.
            if let Ok(pt) = stroboscopic_map(device, &integrator, t0, period, &trial) {
                let rt = residual_norm(n, &trial, &pt);
                if rt < res {
                    (y, py, res) = (trial, pt, rt);
                    accepted = true;
                    break;
                }
            }
            lambda *= 0.5;
        }
        if !accepted {
            break;
        }
    }
    if res <= options.tol {
        return Ok(PeriodicOrbit {
            state: y,
            t0,
            period,
            residual: res,
            newton_iterations: iterations,
            cycles_simulated: cycles,
            method: OrbitMethod::Newton,
        });
    }
    // Fallback: plain cycle-to-cycle simulation.
    for _ in 0..options.fallback_cycles {
        y = py;
        py = stroboscopic_map(device, &integrator, t0, period, &y)?;
        res = residual_norm(n, &y, &py);
        cycles += 1;
        if res <= options.tol {
            return Ok(PeriodicOrbit {
                state: y,
                t0,
                period,
                residual: res,
                newton_iterations: iterations,
                cycles_simulated: cycles,
                method: OrbitMethod::Simulation,
            });
        }
    }
    Err(Error::Integration {
        time: t0,
        state: y.to_vec(),
        reason: format!(
            "no periodic orbit: Newton ({iterations} iterations) and {cycles} simulated cycles \
             left the residual at {res:e} > tol = {:e}",
            options.tol
        ),
    })
}

/// Multipliers whose modulus is within this of 1 (or within the monodromy's estimated error,
/// if larger) are reported as marginal.
pub const MARGINAL_TOL: f64 = 1e-5;

/// Stability of a periodic orbit from its Floquet multipliers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OrbitStability {
    /// Every `|ρ| < 1 − tol`, `tol = max(MARGINAL_TOL, monodromy_uncertainty)`.
    Asymptotic,
    /// The largest `|ρ|` is within `tol` of 1 (e.g. a cyclic coordinate).
    Marginal,
    /// Some `|ρ| > 1 + tol`.
    Unstable,
}

/// Floquet analysis of a device's periodic orbit.
#[derive(Clone, Debug, PartialEq)]
pub struct NonlinearFloquet {
    /// The orbit.
    pub orbit: PeriodicOrbit,
    /// Monodromy matrix: Jacobian of the stroboscopic map over `[x (n), ẋ (n)]`.
    pub monodromy: DMatrix<f64>,
    /// Names of the monodromy's rows/columns (`q1, q2, q1_dot, q2_dot` in drivetrain
    /// coordinates, else `x0.., x0_dot..`).
    pub coordinates: Vec<String>,
    /// Floquet multipliers, largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
    /// Multipliers of the `(q2, q̇2)` block (the whippletree mode) for 2-DOF drivetrain
    /// coordinates; exact when the orbit is left-right symmetric (the blocks then decouple, see
    /// [`Self::whippletree_coupling`]).
    pub whippletree: Option<[Complex<f64>; 2]>,
    /// Largest entry of the off-diagonal `(q1, q̇1)`–`(q2, q̇2)` blocks of the monodromy
    /// (zero for a symmetric orbit).
    pub whippletree_coupling: Option<f64>,
    /// Largest entry of `|M(h) − M(4h)|` between the monodromies at `fd_step` and `4 fd_step`:
    /// an estimate of the finite-difference error (larger for piecewise-smooth models such as
    /// blade-element aerodynamics).
    pub monodromy_uncertainty: f64,
}

impl NonlinearFloquet {
    /// `max |ρ|`.
    pub fn spectral_radius(&self) -> f64 {
        self.multipliers.first().map_or(0.0, |r| r.norm())
    }

    /// Largest Floquet exponent real part `ln(max|ρ|)/T` (1/ms).
    pub fn max_exponent(&self) -> f64 {
        self.spectral_radius().ln() / self.orbit.period
    }

    /// Asymptotically stable, marginal or unstable.
    pub fn stability(&self) -> OrbitStability {
        let r = self.spectral_radius();
        let tol = self.marginal_tol();
        if r < 1.0 - tol {
            OrbitStability::Asymptotic
        } else if r <= 1.0 + tol {
            OrbitStability::Marginal
        } else {
            OrbitStability::Unstable
        }
    }

    /// Half-width of the marginal band around `|ρ| = 1`: `max(MARGINAL_TOL,
    /// monodromy_uncertainty)`.
    pub fn marginal_tol(&self) -> f64 {
        MARGINAL_TOL.max(self.monodromy_uncertainty)
    }

    /// Slowest decay time `T / (−ln|ρ|)` (ms) among the decaying multipliers
    /// (`|ρ| < 1 − marginal_tol`); `None` when none decays.
    pub fn slowest_decay_ms(&self) -> Option<f64> {
        self.multipliers
            .iter()
            .map(|r| r.norm())
            .filter(|&r| r < 1.0 - self.marginal_tol())
            .fold(None, |acc: Option<f64>, r| {
                Some(acc.map_or(r, |a| a.max(r)))
            })
            .map(|r| {
                if r == 0.0 {
                    0.0
                } else {
                    -self.orbit.period / r.ln()
                }
            })
    }

    /// e-folding growth time `T / ln(max|ρ|)` (ms) of an unstable orbit.
    pub fn growth_time_ms(&self) -> Option<f64> {
        let r = self.spectral_radius();
        (r > 1.0 + self.marginal_tol()).then(|| self.orbit.period / r.ln())
    }
}

/// Eigenvalues of a real square matrix, largest modulus first.
///
/// # Errors
/// [`Error::Singular`] when the Schur iteration does not converge or the matrix is not finite.
pub fn eigenvalues(m: &DMatrix<f64>) -> Result<Vec<Complex<f64>>> {
    if m.iter().any(|v| !v.is_finite()) {
        bail!(Singular "monodromy matrix has non-finite entries");
    }
    let schur = nalgebra::Schur::try_new(m.clone(), 1e-15, 100_000).ok_or_else(|| {
        Error::Singular("Schur iteration for the Floquet multipliers did not converge".into())
    })?;
    let mut ev: Vec<Complex<f64>> = schur.complex_eigenvalues().iter().copied().collect();
    ev.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(b.im.total_cmp(&a.im)));
    Ok(ev)
}

fn eig2(m: &Matrix2<f64>) -> [Complex<f64>; 2] {
    multipliers(0.5 * m.trace(), m.determinant())
}

/// Periodic orbit and Floquet multipliers of a driven device (see [`periodic_orbit`]; the
/// monodromy is [`map_jacobian`] at the orbit).
pub fn floquet(device: &Device, options: &ShootingOptions) -> Result<NonlinearFloquet> {
    let orbit = periodic_orbit(device, options)?;
    let integrator = options.validate(orbit.period)?;
    let n = device.n_dof();
    let jacobian = |step: f64| {
        map_jacobian(
            device,
            n,
            &integrator,
            orbit.t0,
            orbit.period,
            &orbit.state,
            step,
        )
    };
    let (monodromy, coarse) = rayon::join(
        || jacobian(options.fd_step),
        || jacobian(4.0 * options.fd_step),
    );
    let (monodromy, coarse) = (monodromy?, coarse?);
    let monodromy_uncertainty = (&monodromy - coarse).amax();
    let multipliers = eigenvalues(&monodromy)?;
    let drivetrain_coords = device.formulation() == Formulation::DrivetrainCoordinates;
    let coordinates: Vec<String> = (0..n)
        .map(|i| {
            if drivetrain_coords {
                format!("q{}", i + 1)
            } else {
                format!("x{i}")
            }
        })
        .chain((0..n).map(|i| {
            if drivetrain_coords {
                format!("q{}_dot", i + 1)
            } else {
                format!("x{i}_dot")
            }
        }))
        .collect();
    let (whippletree, whippletree_coupling) = if drivetrain_coords && n == 2 {
        let block = Matrix2::new(
            monodromy[(1, 1)],
            monodromy[(1, 3)],
            monodromy[(3, 1)],
            monodromy[(3, 3)],
        );
        let coupling = [
            (0, 1),
            (0, 3),
            (2, 1),
            (2, 3),
            (1, 0),
            (1, 2),
            (3, 0),
            (3, 2),
        ]
        .iter()
        .map(|&(i, j)| monodromy[(i, j)].abs())
        .fold(0.0, f64::max);
        (Some(eig2(&block)), Some(coupling))
    } else {
        (None, None)
    };
    Ok(NonlinearFloquet {
        orbit,
        monodromy,
        coordinates,
        multipliers,
        whippletree,
        whippletree_coupling,
        monodromy_uncertainty,
    })
}

/// A device spec with its balance-beam stiffness K2 replaced.
///
/// # Errors
/// [`Error::Constraint`] without a drivetrain; [`Error::InvalidParameter`] for a bad K2.
pub fn with_balance_stiffness(spec: &DeviceSpec, k2: f64) -> Result<DeviceSpec> {
    let Some(tr) = &spec.transmission else {
        bail!(Constraint "a K2 sweep needs a drivetrain");
    };
    let mut out = spec.clone();
    out.transmission = Some(Transmission::new(*tr.kinematics(), k2)?);
    Ok(out)
}

/// [`floquet`] for each balance-beam stiffness K2 in `k2` (mN·mm/rad), in parallel.
///
/// # Errors
/// The first failure, located as `k2[i]`.
pub fn balance_stiffness_sweep(
    spec: &DeviceSpec,
    k2: &[f64],
    options: &ShootingOptions,
) -> Result<Vec<NonlinearFloquet>> {
    k2.par_iter()
        .enumerate()
        .map(|(i, &k)| {
            let run = || -> Result<NonlinearFloquet> {
                let device = Device::new(with_balance_stiffness(spec, k)?)?;
                floquet(&device, options)
            };
            run().map_err(|e| e.at_index(i, Some("k2")))
        })
        .collect()
}

// ============================================================================================
// §2.7: from a device to eq. 2.59, and the nonlinear disturbance response
// ============================================================================================

/// What a stroke-only (fixed-wing) device needs for §2.7.
struct StrokeDevice<'a> {
    device: &'a Device,
    inertia: [f64; 2],
    n_wings: usize,
}

impl<'a> StrokeDevice<'a> {
    fn new(device: &'a Device) -> Result<Self> {
        if device.formulation() != Formulation::DrivetrainCoordinates {
            bail!(Constraint
                "the §2.7 analysis needs a fixed-wing device integrated in drivetrain coordinates \
                 (a *_fixed configuration with a drivetrain; see Formulation::DrivetrainCoordinates)");
        }
        let wings = &device.spec().wings;
        let mut inertia = [0.0; 2];
        for (k, w) in wings.iter().enumerate() {
            inertia[k] = w.inertia()[(0, 0)];
        }
        Ok(Self {
            device,
            inertia,
            n_wings: wings.len(),
        })
    }

    fn transmission(&self) -> &Transmission {
        self.device
            .spec()
            .transmission
            .as_ref()
            .expect("drivetrain-coordinate devices have a drivetrain")
    }
}

/// A sinusoidal roll disturbance torque `d(t) = amplitude · sin(2π f t)` on the wings of a
/// fixed-wing device, split as stroke torques `(−d/2, +d/2)` on `(φL, φR)`: in body roll (the
/// left wing's frame is mirrored, see [`mod@crate::simulate`]) both halves add up to `d`. Wraps the
/// device's right-hand side: `q̈ += M_q⁻¹ Jᵀ τ_d` with `M_q = Σ_k I_k J_kᵀ J_k`.
pub struct RollDisturbance<'a> {
    stroke: StrokeDevice<'a>,
    amplitude: f64,
    omega: f64,
}

impl<'a> RollDisturbance<'a> {
    /// `amplitude` (mN·mm) and `frequency_hz` (> 0).
    ///
    /// # Errors
    /// [`Error::Constraint`] unless the device uses drivetrain coordinates;
    /// [`Error::InvalidParameter`] for a non-finite amplitude or non-positive frequency.
    pub fn new(device: &'a Device, amplitude: f64, frequency_hz: f64) -> Result<Self> {
        check_finite("amplitude", amplitude)?;
        check_positive("frequency_hz", frequency_hz)?;
        Ok(Self {
            stroke: StrokeDevice::new(device)?,
            amplitude,
            omega: 2.0 * PI * frequency_hz * 1e-3,
        })
    }

    /// `d(t)` (mN·mm).
    pub fn torque(&self, t: f64) -> f64 {
        self.amplitude * (self.omega * t).sin()
    }

    /// Disturbance stroke torques on `(φL, φR)` (one wing: the whole torque on it).
    fn stroke_torques(&self, t: f64) -> Vector2<f64> {
        let d = self.torque(t);
        if self.stroke.n_wings == 2 {
            Vector2::new(-0.5 * d, 0.5 * d)
        } else {
            Vector2::new(d, 0.0)
        }
    }

    /// Body roll torque (mN·mm) at an integrator state: `Σ_k m_k (τ_aero,k − I_k φ̈_k + d_k)`
    /// with `m = (−1, +1)` (left mirrored), the wings' momentum balance.
    pub fn body_roll(&self, t: f64, y: &State) -> Result<f64> {
        let mut dydt = [0.0; STATE_LEN];
        self.rhs(t, y, &mut dydt)?;
        let dt = self.stroke.transmission().kinematics();
        let two = self.stroke.device.n_dof() == 2;
        let q_dot = Vector2::new(y[6], if two { y[7] } else { 0.0 });
        let q_ddot = Vector2::new(dydt[6], if two { dydt[7] } else { 0.0 });
        let e = dt.evaluate(y[0], if two { y[1] } else { 0.0 })?;
        let phi_dot = e.jacobian * q_dot;
        let phi_ddot = e.jacobian * q_ddot + e.velocity_product(&q_dot);
        let d = self.stroke_torques(t);
        let wings = &self.stroke.device.spec().wings;
        let mut roll = 0.0;
        for k in 0..self.stroke.n_wings {
            let mirror = if self.stroke.n_wings == 2 && k == 0 {
                -1.0
            } else {
                1.0
            };
            let aero = wings[k].aero().stroke_torque(phi_dot[k]);
            roll += mirror * (aero - self.stroke.inertia[k] * phi_ddot[k] + d[k]);
        }
        Ok(roll)
    }
}

impl OdeSystem for RollDisturbance<'_> {
    fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> Result<()> {
        let device = self.stroke.device;
        device.rhs(t, y, dydt)?;
        let two = device.n_dof() == 2;
        let e = self
            .stroke
            .transmission()
            .kinematics()
            .evaluate(y[0], if two { y[1] } else { 0.0 })?;
        let tau = self.stroke_torques(t);
        let mut mass = Matrix2::zeros();
        let mut force = Vector2::zeros();
        for k in 0..2 {
            let row = e.jacobian.row(k).transpose();
            mass += row * row.transpose() * self.stroke.inertia[k];
            force += row * tau[k];
        }
        if two {
            let extra = mass.lu().solve(&force).ok_or_else(|| {
                Error::Singular(format!(
                    "drivetrain mass matrix is singular at q = ({}, {})",
                    y[0], y[1]
                ))
            })?;
            dydt[6] += extra.x;
            dydt[7] += extra.y;
        } else {
            dydt[6] += force.x / mass[(0, 0)];
        }
        // The disturbance's work is neither actuator nor aerodynamic work: slots 12, 13 as is.
        Ok(())
    }

    fn n_active(&self) -> usize {
        self.stroke.device.n_dof()
    }
}

/// A device placed on the charts of §2.6–2.7, from its periodic orbit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceLinearisation {
    /// Physical parameters read from the device and the orbit (mean of the two wings where
    /// they differ; T and L from the drivetrain Jacobian at rest: `J = [[−T, T hL], [−T, −T hR]]`,
    /// `L = (hL + hR)/2`; drag = `−τ(φ̇ = 1 rad/ms)`, i.e. `Ω1 C` for stroke drag; Φ the mean
    /// stroke amplitude of the orbit).
    pub physical: PhysicalParameters,
    /// (β0, κ1, κ2) of eq. 2.23–2.24 (ERRATA item 7).
    pub hill: HillParameters,
    /// Eq. 2.59 as §2.7 builds it: the cycle averages over the orbit of the whippletree mode's
    /// aerodynamic damping rate and spring stiffness per unit modal inertia,
    /// `β* = ⟨Σ_k J_k2² c_k / m22⟩`, `κ0 = K2 ⟨1/m22⟩`, with `m22 = Σ_k I_k J_k2²` and
    /// `c_k = −∂τ_aero,k/∂φ̇_k`. For stroke drag on the linear map this is `(2/π) β0 ω0`
    /// exactly for any single-hump stroke, since `∮|φ̇| dt = 4Φ`.
    pub lti: LtiModel,
    /// Eq. 2.59 from [`PhysicalParameters::lti`] (sinusoidal flapping assumed).
    pub lti_sinusoidal: LtiModel,
    /// Eq. 2.59 from the cycle average of the whippletree row of the variational equation of
    /// the full model: `κ0 = −⟨∂q̈2/∂q2⟩`, `β* = −⟨∂q̈2/∂q̇2⟩` (central differences of the
    /// right-hand side along the orbit). Unlike [`Self::lti`] it includes the geometric
    /// stiffness of a nonlinear linkage (`2h²g''(q1)` times the crank load; docs/findings.md
    /// item 3), which can make κ0 negative. Equal to [`Self::lti`] for the linear map of eq. 2.15.
    pub lti_averaged: LtiModel,
    /// The geometric stiffness of the whippletree mode, `−⟨∂q̈2/∂q2⟩/⟨1/m22⟩ − K2`
    /// (mN·mm/rad; zero for eq. 2.15).
    pub geometric_stiffness: f64,
}

/// Samples a device along its orbit: `samples` uniform times over one period (endpoint
/// excluded).
fn orbit_samples(
    device: &Device,
    orbit: &PeriodicOrbit,
    integrator: &RungeKutta,
    samples: usize,
) -> Result<(Vec<f64>, Vec<State>)> {
    let times: Vec<f64> = (0..=samples)
        .map(|k| orbit.t0 + orbit.period * k as f64 / samples as f64)
        .collect();
    let mut states = integrator.integrate(
        device,
        orbit.t0,
        &orbit.state,
        orbit.t0 + orbit.period,
        &times,
    )?;
    states.pop();
    let mut times = times;
    times.pop();
    Ok((times, states))
}

/// `sign ×` the extremum (`sign = 1`: maximum, `−1`: minus the minimum) of uniformly sampled
/// periodic data, refined by the parabola through the extreme sample and its neighbours.
fn periodic_extremum(values: &[f64], sign: f64) -> f64 {
    let n = values.len();
    let (i, _) = values
        .iter()
        .enumerate()
        .fold((0, f64::NEG_INFINITY), |best, (i, &v)| {
            if sign * v > best.1 {
                (i, sign * v)
            } else {
                best
            }
        });
    let (ym, y0, yp) = (
        sign * values[(i + n - 1) % n],
        sign * values[i],
        sign * values[(i + 1) % n],
    );
    let curvature = yp - 2.0 * y0 + ym;
    if curvature < 0.0 {
        y0 - (yp - ym).powi(2) / (8.0 * curvature)
    } else {
        y0
    }
}

/// Places a fixed-wing Drag PARITY device (2-DOF drivetrain, drivetrain coordinates) on the
/// charts of §2.6–2.7 from its periodic orbit, sampled at `samples` points per cycle.
///
/// # Errors
/// [`Error::Constraint`] for other devices; [`Error::InvalidParameter`] for `samples < 8`.
pub fn linearise(
    device: &Device,
    orbit: &PeriodicOrbit,
    samples: usize,
) -> Result<DeviceLinearisation> {
    let stroke = StrokeDevice::new(device)?;
    let tr = stroke.transmission();
    if tr.kinematics().dof() != 2 || stroke.n_wings != 2 {
        bail!(Constraint "the §2.6–2.7 linearisation needs a 2-DOF (Drag PARITY) drivetrain and two wings");
    }
    if samples < 8 {
        bail!(invalid "samples", samples, ">= 8");
    }
    let rest = tr.kinematics().evaluate(0.0, 0.0)?.jacobian;
    let t_ratio = -0.5 * (rest[(0, 0)] + rest[(1, 0)]);
    let arm = (rest[(0, 1)] - rest[(1, 1)]) / (2.0 * t_ratio);
    let wings = &device.spec().wings;
    let drag = 0.5 * (-wings[0].aero().stroke_torque(1.0) - wings[1].aero().stroke_torque(1.0));
    let inertia = 0.5 * (stroke.inertia[0] + stroke.inertia[1]);
    let k1 = device
        .spec()
        .actuator
        .as_ref()
        .map_or(0.0, |a| a.stiffness());
    let k2 = tr.balance_stiffness();
    let integrator = RungeKutta::new(Method::Dop853, 1e-10, 1e-12, 1_000_000)?;
    let (times, states) = orbit_samples(device, orbit, &integrator, samples)?;
    let mut strokes = [
        Vec::with_capacity(states.len()),
        Vec::with_capacity(states.len()),
    ];
    let (mut rate, mut inv_m22, mut dq2, mut dq2_dot) = (0.0, 0.0, 0.0, 0.0);
    for (t, y) in times.iter().zip(&states) {
        let e = tr.kinematics().evaluate(y[0], y[1])?;
        let phi_dot = e.jacobian * Vector2::new(y[6], y[7]);
        let (mut c, mut m) = (0.0, 0.0);
        for k in 0..2 {
            strokes[k].push(e.stroke[k]);
            let j2 = e.jacobian[(k, 1)];
            let aero = wings[k].aero();
            let h = 1e-6 * (1.0 + phi_dot[k].abs());
            let slope = (aero.stroke_torque(phi_dot[k] + h) - aero.stroke_torque(phi_dot[k] - h))
                / (2.0 * h);
            c += j2 * j2 * (-slope);
            m += j2 * j2 * stroke.inertia[k];
        }
        rate += c / m;
        inv_m22 += 1.0 / m;
        // Whippletree row of the variational equation (central differences of the RHS).
        for (slot, acc) in [(1, &mut dq2), (7, &mut dq2_dot)] {
            let h = 1e-6 * (1.0 + y[slot].abs());
            let (mut plus, mut minus) = (*y, *y);
            plus[slot] += h;
            minus[slot] -= h;
            let (mut fp, mut fm) = ([0.0; STATE_LEN], [0.0; STATE_LEN]);
            device.rhs(*t, &plus, &mut fp)?;
            device.rhs(*t, &minus, &mut fm)?;
            *acc += (fp[7] - fm[7]) / (2.0 * h);
        }
    }
    let count = states.len() as f64;
    let stroke_amplitude = 0.25
        * strokes
            .iter()
            .map(|phi| periodic_extremum(phi, 1.0) + periodic_extremum(phi, -1.0))
            .sum::<f64>();
    let physical = PhysicalParameters {
        inertia,
        drag,
        transmission_ratio: t_ratio,
        arm_length: arm,
        k1,
        k2,
        stroke_amplitude,
        frequency_hz: 1e3 / orbit.period,
    };
    Ok(DeviceLinearisation {
        physical,
        hill: physical.hill()?,
        lti: LtiModel::new(rate / count, k2 * inv_m22 / count)?,
        lti_sinusoidal: physical.lti()?,
        lti_averaged: LtiModel::new(-dq2_dot / count, -dq2 / count)?,
        geometric_stiffness: -dq2 / inv_m22 - k2,
    })
}

/// Options of [`disturbance_response`].
#[derive(Clone, Debug, PartialEq)]
pub struct DisturbanceOptions {
    /// Drive cycles simulated with the disturbance before measuring (transient decay).
    pub settle_cycles: usize,
    /// The window is the number of drive cycles `k ≤ max_window_cycles` that holds the closest
    /// to an integer number of disturbance periods.
    pub max_window_cycles: usize,
    /// Samples per drive cycle in the window.
    pub samples_per_cycle: usize,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
}

impl Default for DisturbanceOptions {
    fn default() -> Self {
        Self {
            settle_cycles: 40,
            max_window_cycles: 12,
            samples_per_cycle: 400,
            rtol: 1e-11,
            atol: 1e-13,
        }
    }
}

/// The body roll response of the nonlinear model to a sinusoidal wing roll disturbance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisturbanceResponse {
    /// Disturbance frequency (Hz).
    pub frequency_hz: f64,
    /// Disturbance amplitude (mN·mm).
    pub amplitude: f64,
    /// Measured transfer `τ̂/d̂` at the disturbance frequency (complex amplitude ratio).
    pub transfer: Complex<f64>,
    /// Measurement window (ms, an integer number of drive cycles).
    pub window_ms: f64,
    /// Distance of the window from an integer number of disturbance periods (in periods).
    pub commensurability_error: f64,
    /// `|H1 − H2| / |H2|` between the transfer measured on the window and on the window that
    /// follows it: large when the transient has not decayed or the orbit is unstable.
    pub drift: f64,
}

/// Measures the body roll response of the nonlinear model to `d(t) = ±amplitude · sin(2πft)`
/// ([`RollDisturbance`]) started on the periodic orbit: after `settle_cycles` and one more
/// window (compared for [`DisturbanceResponse::drift`]), the complex amplitude at `f` of the
/// body roll torque over the window, from the antisymmetric difference
/// of the `+amplitude` and `−amplitude` runs (which cancels the undisturbed orbit and the even
/// nonlinear terms), divided by that of `d`.
///
/// # Errors
/// [`Error::Constraint`] unless the device uses drivetrain coordinates;
/// [`Error::InvalidParameter`] for bad arguments; [`Error::Integration`].
pub fn disturbance_response(
    device: &Device,
    orbit: &PeriodicOrbit,
    frequency_hz: f64,
    amplitude: f64,
    options: &DisturbanceOptions,
) -> Result<DisturbanceResponse> {
    check_positive("frequency_hz", frequency_hz)?;
    check_positive("amplitude", amplitude)?;
    if options.samples_per_cycle < 16 {
        bail!(invalid "samples_per_cycle", options.samples_per_cycle, ">= 16");
    }
    if options.max_window_cycles == 0 || options.max_window_cycles > 10_000 {
        bail!(invalid "max_window_cycles", options.max_window_cycles, "in [1, 10000]");
    }
    if options.settle_cycles > 100_000 {
        bail!(invalid "settle_cycles", options.settle_cycles, "<= 100000");
    }
    let integrator = RungeKutta::new(Method::Dop853, options.rtol, options.atol, 10_000_000)?;
    let period = orbit.period;
    let f_per_ms = frequency_hz * 1e-3;
    let (mut best_k, mut best_err) = (1, f64::INFINITY);
    for k in 1..=options.max_window_cycles {
        let periods = k as f64 * period * f_per_ms;
        let err = (periods - periods.round()).abs();
        if err < best_err - 1e-12 {
            (best_k, best_err) = (k, err);
        }
    }
    let window = best_k as f64 * period;
    let t_start = orbit.t0 + options.settle_cycles as f64 * period;
    // Two consecutive windows: the second one is the measurement, their difference the drift.
    let n = best_k * options.samples_per_cycle;
    let times: Vec<f64> = (0..2 * n)
        .map(|j| t_start + window * j as f64 / n as f64)
        .collect();
    let omega = 2.0 * PI * f_per_ms;
    let run = |sign: f64| -> Result<[Complex<f64>; 2]> {
        let system = RollDisturbance::new(device, sign * amplitude, frequency_hz)?;
        let y0 = if t_start > orbit.t0 {
            integrator.integrate(&system, orbit.t0, &orbit.state, t_start, &[t_start])?[0]
        } else {
            orbit.state
        };
        let states = integrator.integrate(&system, t_start, &y0, t_start + 2.0 * window, &times)?;
        let mut acc = [Complex::new(0.0, 0.0); 2];
        for (j, (t, y)) in times.iter().zip(&states).enumerate() {
            let roll = system.body_roll(*t, y)?;
            acc[j / n] += Complex::from_polar(roll, -omega * t);
        }
        Ok(acc.map(|a| a * (2.0 / n as f64)))
    };
    let (plus, minus) = rayon::join(|| run(1.0), || run(-1.0));
    let (plus, minus) = (plus?, minus?);
    // d(t) = A sin(ωt) has complex amplitude −iA under the same projection.
    let [first, transfer] =
        [0, 1].map(|w| (plus[w] - minus[w]) * 0.5 / Complex::new(0.0, -amplitude));
    if !(transfer.re.is_finite() && transfer.im.is_finite() && first.norm().is_finite()) {
        return Err(Error::Integration {
            time: t_start + 2.0 * window,
            state: vec![],
            reason: "non-finite disturbance response (is the orbit unstable?)".into(),
        });
    }
    Ok(DisturbanceResponse {
        frequency_hz,
        amplitude,
        transfer,
        window_ms: window,
        commensurability_error: best_err,
        drift: (transfer - first).norm() / transfer.norm().max(f64::MIN_POSITIVE),
    })
}

/// [`disturbance_response`] at each of `frequencies_hz`, in parallel.
///
/// # Errors
/// The first failure, located as `frequency_hz[i]`.
pub fn disturbance_responses(
    device: &Device,
    orbit: &PeriodicOrbit,
    frequencies_hz: &[f64],
    amplitude: f64,
    options: &DisturbanceOptions,
) -> Result<Vec<DisturbanceResponse>> {
    frequencies_hz
        .par_iter()
        .enumerate()
        .map(|(i, &f)| {
            disturbance_response(device, orbit, f, amplitude, options)
                .map_err(|e| e.at_index(i, Some("frequency_hz")))
        })
        .collect()
}
