//! Plain serde records of the stability results (what the Python bindings hand over through
//! one generic converter). Complex numbers are `[re, im]` pairs; matrices are row-major
//! nested arrays; an undefined value is `None`.

use nalgebra::Complex;
use paritysim_error::Result;
use serde::{Deserialize, Deserializer, Serialize};

use super::*;
use crate::integrate::Method;

/// Reads a [`Method`] by name (`dop853`, `dopri5`).
///
/// # Errors
/// A serde error listing the two names.
pub fn method_by_name<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Method, D::Error> {
    match String::deserialize(d)?.as_str() {
        "dop853" => Ok(Method::Dop853),
        "dopri5" => Ok(Method::Dopri5),
        other => Err(serde::de::Error::unknown_variant(
            other,
            &["dop853", "dopri5"],
        )),
    }
}

fn pair(z: &Complex<f64>) -> [f64; 2] {
    [z.re, z.im]
}

fn pairs<'a>(z: impl IntoIterator<Item = &'a Complex<f64>>) -> Vec<[f64; 2]> {
    z.into_iter().map(pair).collect()
}

fn stability_name(s: OrbitStability) -> &'static str {
    match s {
        OrbitStability::Asymptotic => "asymptotic",
        OrbitStability::Marginal => "marginal",
        OrbitStability::Unstable => "unstable",
    }
}

/// Eq. 2.25 Floquet analysis at one point.
#[derive(Clone, Debug, Serialize)]
pub struct HillFloquetRecord {
    /// β0.
    pub beta0: f64,
    /// κ.
    pub kappa: f64,
    /// Monodromy at t0 = −π/2, 2×2.
    pub monodromy: [[f64; 2]; 2],
    /// Half trace.
    pub a: f64,
    /// Determinant.
    pub b: f64,
    /// Multipliers `[re, im]`.
    pub multipliers: Vec<[f64; 2]>,
    /// Largest modulus.
    pub spectral_radius: f64,
    /// Region 1-4 of Fig. 2.13.
    pub region: u8,
    /// Region I and not marginal.
    pub stable: bool,
    /// `|max|ρ| − 1| <= multiplier_error`.
    pub marginal: bool,
    /// Error estimate of the moduli.
    pub multiplier_error: f64,
}

impl From<&HillFloquet> for HillFloquetRecord {
    fn from(f: &HillFloquet) -> Self {
        let m = &f.monodromy;
        Self {
            beta0: f.beta0,
            kappa: f.kappa,
            monodromy: [[m[(0, 0)], m[(0, 1)]], [m[(1, 0)], m[(1, 1)]]],
            a: f.a,
            b: f.b,
            multipliers: pairs(&f.multipliers),
            spectral_radius: f.spectral_radius(),
            region: f.region.index(),
            stable: f.region.is_stable() && !f.is_marginal(),
            marginal: f.is_marginal(),
            multiplier_error: f.multiplier_error,
        }
    }
}

/// (β0, κ1, κ2) of §2.6.1 with eq. 2.59's `beta_star`, `kappa0` and ω0.
#[derive(Clone, Debug, Serialize)]
pub struct HillParametersRecord {
    /// β0.
    pub beta0: f64,
    /// κ1.
    pub kappa1: f64,
    /// κ2.
    pub kappa2: f64,
    /// Eq. 2.59 damping, 1/ms.
    pub beta_star: f64,
    /// Eq. 2.59 stiffness, 1/ms².
    pub kappa0: f64,
    /// Drive angular frequency, rad/ms.
    pub omega0: f64,
}

impl HillParametersRecord {
    /// The record of `p`.
    ///
    /// # Errors
    /// As [`PhysicalParameters::hill`] and [`PhysicalParameters::lti`].
    pub fn of(p: &PhysicalParameters) -> Result<Self> {
        let (h, lti) = (p.hill()?, p.lti()?);
        Ok(Self {
            beta0: h.beta0,
            kappa1: h.kappa1,
            kappa2: h.kappa2,
            beta_star: lti.beta_star,
            kappa0: lti.kappa0,
            omega0: p.omega0(),
        })
    }
}

/// The nonlinear model's periodic orbit and Floquet analysis.
#[derive(Clone, Debug, Serialize)]
pub struct FloquetRecord {
    /// Names of the integrated coordinates.
    pub coordinates: Vec<String>,
    /// Coordinates then rates at the section.
    pub orbit_state: Vec<f64>,
    /// Period of the orbit, ms (`orbit_cycles` drive periods).
    pub period_ms: f64,
    /// Drive cycles per orbit (2: period-doubled).
    pub orbit_cycles: usize,
    /// Section time, ms.
    pub t0_ms: f64,
    /// Residual of the orbit.
    pub residual: f64,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Cycles simulated.
    pub cycles_simulated: usize,
    /// `newton` or `simulation`.
    pub method: &'static str,
    /// Monodromy, n×n row-major.
    pub monodromy: Vec<Vec<f64>>,
    /// Multipliers `[re, im]`, largest modulus first.
    pub multipliers: Vec<[f64; 2]>,
    /// Largest modulus.
    pub spectral_radius: f64,
    /// Largest Floquet exponent, 1/ms.
    pub max_exponent_per_ms: f64,
    /// `asymptotic`, `marginal` or `unstable`.
    pub stability: &'static str,
    /// Slowest decay time, ms (None when nothing decays).
    pub slowest_decay_ms: Option<f64>,
    /// Growth time, ms (None unless unstable).
    pub growth_time_ms: Option<f64>,
    /// The whippletree block's multipliers, if any.
    pub whippletree_multipliers: Option<Vec<[f64; 2]>>,
    /// Coupling of the whippletree block, if any.
    pub whippletree_coupling: Option<f64>,
    /// Uncertainty of the monodromy.
    pub monodromy_uncertainty: f64,
}

impl From<&NonlinearFloquet> for FloquetRecord {
    fn from(f: &NonlinearFloquet) -> Self {
        let n = f.coordinates.len();
        let s = &f.orbit.state;
        Self {
            coordinates: f.coordinates.clone(),
            orbit_state: (0..n / 2)
                .map(|i| s.coords[i])
                .chain((0..n / 2).map(|i| s.rates[i]))
                .collect(),
            period_ms: f.orbit.period,
            orbit_cycles: f.orbit_cycles,
            t0_ms: f.orbit.t0,
            residual: f.orbit.residual,
            newton_iterations: f.orbit.newton_iterations,
            cycles_simulated: f.orbit.cycles_simulated,
            method: match f.orbit.method {
                OrbitMethod::Newton => "newton",
                OrbitMethod::Simulation => "simulation",
            },
            monodromy: (0..n)
                .map(|i| (0..n).map(|j| f.monodromy[(i, j)]).collect())
                .collect(),
            multipliers: pairs(&f.multipliers),
            spectral_radius: f.spectral_radius(),
            max_exponent_per_ms: f.max_exponent(),
            stability: stability_name(f.stability()),
            slowest_decay_ms: f.slowest_decay_ms(),
            growth_time_ms: f.growth_time_ms(),
            whippletree_multipliers: f.whippletree.as_ref().map(pairs),
            whippletree_coupling: f.whippletree_coupling,
            monodromy_uncertainty: f.monodromy_uncertainty,
        }
    }
}

/// [`FloquetRecord`]'s summary over balance-beam stiffnesses, as columns; a failed stiffness
/// is a row with its `error` (NaN and None elsewhere).
#[derive(Clone, Debug, Serialize)]
pub struct BalanceSweepRecord {
    /// Balance-beam stiffness, mN·mm/rad.
    pub k2: Vec<f64>,
    /// Largest modulus.
    pub spectral_radius: Vec<f64>,
    /// Largest exponent, 1/ms.
    pub max_exponent_per_ms: Vec<f64>,
    /// Largest modulus of the whippletree block (None without one).
    pub whippletree_radius: Vec<Option<f64>>,
    /// Slowest decay time, ms (None when nothing decays).
    pub slowest_decay_ms: Vec<Option<f64>>,
    /// Multipliers `[re, im]` per stiffness (none for a failed one).
    pub multipliers: Vec<Vec<[f64; 2]>>,
    /// Stability name per stiffness (None for a failed one).
    pub stability: Vec<Option<&'static str>>,
    /// The error of a failed stiffness (None when it ran).
    pub error: Vec<Option<String>>,
}

/// `f` of an `Ok` row, `missing` for a failed one.
fn column<T, U>(runs: &[Result<T>], missing: U, f: impl Fn(&T) -> U) -> Vec<U>
where
    U: Clone,
{
    runs.iter()
        .map(|r| r.as_ref().map_or_else(|_| missing.clone(), &f))
        .collect()
}

fn errors<T>(runs: &[Result<T>]) -> Vec<Option<String>> {
    runs.iter()
        .map(|r| r.as_ref().err().map(ToString::to_string))
        .collect()
}

impl BalanceSweepRecord {
    /// Columns of the rows at `k2`.
    pub fn of(k2: &[f64], runs: &[Result<NonlinearFloquet>]) -> Self {
        Self {
            k2: k2.to_vec(),
            spectral_radius: column(runs, f64::NAN, NonlinearFloquet::spectral_radius),
            max_exponent_per_ms: column(runs, f64::NAN, NonlinearFloquet::max_exponent),
            whippletree_radius: column(runs, None, |f| {
                f.whippletree.map(|w| w[0].norm().max(w[1].norm()))
            }),
            slowest_decay_ms: column(runs, None, NonlinearFloquet::slowest_decay_ms),
            multipliers: column(runs, Vec::new(), |f| pairs(&f.multipliers)),
            stability: column(runs, None, |f| Some(stability_name(f.stability()))),
            error: errors(runs),
        }
    }
}

/// Disturbance responses as columns; a failed frequency is a row with its `error` (NaN
/// elsewhere).
#[derive(Clone, Debug, Serialize)]
pub struct DisturbanceRecord {
    /// Disturbance frequency, Hz.
    pub frequency_hz: Vec<f64>,
    /// Transfer `[re, im]`.
    pub transfer: Vec<[f64; 2]>,
    /// Change between two consecutive windows.
    pub drift: Vec<f64>,
    /// Window, ms.
    pub window_ms: Vec<f64>,
    /// Distance from a whole number of disturbance periods.
    pub commensurability_error: Vec<f64>,
    /// Disturbance amplitude, mN·mm.
    pub amplitude: f64,
    /// The error of a failed frequency (None when it ran).
    pub error: Vec<Option<String>>,
}

impl DisturbanceRecord {
    /// Columns of the rows at `frequency_hz`.
    pub fn of(frequency_hz: &[f64], amplitude: f64, runs: &[Result<DisturbanceResponse>]) -> Self {
        Self {
            frequency_hz: frequency_hz.to_vec(),
            transfer: column(runs, [f64::NAN; 2], |r| pair(&r.transfer)),
            drift: column(runs, f64::NAN, |r| r.drift),
            window_ms: column(runs, f64::NAN, |r| r.window_ms),
            commensurability_error: column(runs, f64::NAN, |r| r.commensurability_error),
            amplitude,
            error: errors(runs),
        }
    }
}

/// A 2×2 matrix as rows.
pub fn rows2(m: &nalgebra::Matrix2<f64>) -> [[f64; 2]; 2] {
    [[m[(0, 0)], m[(0, 1)]], [m[(1, 0)], m[(1, 1)]]]
}

/// Regions (1-4) of Fig. 2.13 for paired half traces `a` and determinants `b`.
///
/// # Errors
/// As [`region`], naming the index.
pub fn regions(a: &[f64], b: &[f64]) -> Result<Vec<u8>> {
    let at = |(i, (&x, &y)): (usize, (&f64, &f64))| {
        region(x, y)
            .map(Region::index)
            .map_err(|e| e.at_index(i, None))
    };
    a.iter().zip(b).enumerate().map(at).collect()
}
