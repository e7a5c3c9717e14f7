//! Bindings for the stability functions (prefix `stability_`): eq. 2.25 Floquet analysis,
//! Brockett's criterion, the §2.6.1 parameter map, eq. 2.59, and the Floquet analysis and
//! disturbance response of the full nonlinear model (`paritysim_dynamics::floquet`).

use nalgebra::{Complex, Matrix2};
use numpy::{Complex64, PyArray1, PyArrayMethods, PyReadonlyArray1};
use paritysim_dynamics::floquet::{
    self, Brockett, DisturbanceOptions, HillFloquet, NonlinearFloquet, OrbitMethod, OrbitStability,
    PhysicalParameters, ShootingOptions,
};
use paritysim_dynamics::integrate::Method;
use paritysim_error::{Error, Result};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{same_len, shaped, to_vec};
use crate::errors::IntoPyResult;
use crate::spec::device as parse_device;

fn c64(z: Complex<f64>) -> Complex64 {
    Complex64::new(z.re, z.im)
}

fn matrix2(m: &Matrix2<f64>) -> Vec<f64> {
    vec![m[(0, 0)], m[(0, 1)], m[(1, 0)], m[(1, 1)]]
}

/// Monodromy matrix `M(t0)` of eq. 2.25 (`x'' + β0|cos t| x' + κ x = 0`, period π), 2×2.
#[pyfunction]
#[pyo3(signature = (beta0, kappa, t0 = -std::f64::consts::FRAC_PI_2))]
fn stability_hill_monodromy<'py>(
    py: Python<'py>,
    beta0: f64,
    kappa: f64,
    t0: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let m = floquet::hill_monodromy(beta0, kappa, t0).py_err()?;
    shaped(py, matrix2(&m), &[2, 2])
}

/// Solution matrices `Π(t_i, t0)` of eq. 2.25 at each `t_i >= t0`, shape `(n, 2, 2)`.
#[pyfunction]
fn stability_hill_solution<'py>(
    py: Python<'py>,
    beta0: f64,
    kappa: f64,
    t0: f64,
    t: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let t = to_vec(&t);
    let n = t.len();
    let flat = py
        .detach(|| -> Result<Vec<f64>> {
            let mut out = Vec::with_capacity(4 * n);
            for (i, &ti) in t.iter().enumerate() {
                let m = floquet::hill_solution_matrix(beta0, kappa, t0, ti)
                    .map_err(|e| e.at_index(i, Some("t")))?;
                out.extend(matrix2(&m));
            }
            Ok(out)
        })
        .py_err()?;
    shaped(py, flat, &[n, 2, 2])
}

fn hill_dict<'py>(py: Python<'py>, f: &HillFloquet) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("beta0", f.beta0)?;
    out.set_item("kappa", f.kappa)?;
    out.set_item("monodromy", shaped(py, matrix2(&f.monodromy), &[2, 2])?)?;
    out.set_item("a", f.a)?;
    out.set_item("b", f.b)?;
    out.set_item(
        "multipliers",
        PyArray1::from_vec(py, f.multipliers.iter().map(|z| c64(*z)).collect()),
    )?;
    out.set_item("spectral_radius", f.spectral_radius())?;
    out.set_item("region", f.region.index())?;
    out.set_item("stable", f.region.is_stable() && !f.is_marginal())?;
    out.set_item("marginal", f.is_marginal())?;
    out.set_item("multiplier_error", f.multiplier_error)?;
    Ok(out)
}

/// Floquet analysis of eq. 2.25: `monodromy` (at t0 = -π/2), half trace `a`, determinant `b`,
/// `multipliers` (complex), `spectral_radius`, `region` (1-4 of Fig. 2.13, docs/errata.md#9),
/// `multiplier_error`, `marginal` (`|max|ρ| − 1| <= multiplier_error`) and `stable` (Region I
/// and not marginal).
#[pyfunction]
fn stability_hill_floquet<'py>(
    py: Python<'py>,
    beta0: f64,
    kappa: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let f = floquet::hill_floquet(beta0, kappa).py_err()?;
    hill_dict(py, &f)
}

/// The (β0, κ) grid `beta0 × kappa` (row-major, β0 outer) computed in parallel: flat arrays
/// `beta0, kappa, a, b, spectral_radius, region` (int 1-4), `multiplier_error`, `marginal`
/// and `stable` (Region I and not marginal).
#[pyfunction]
fn stability_chart<'py>(
    py: Python<'py>,
    beta0: PyReadonlyArray1<'py, f64>,
    kappa: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let (beta0, kappa) = (to_vec(&beta0), to_vec(&kappa));
    let chart = py
        .detach(|| floquet::stability_chart(&beta0, &kappa))
        .py_err()?;
    let out = PyDict::new(py);
    let region: Vec<i64> = chart.region.iter().map(|r| i64::from(r.index())).collect();
    let stable: Vec<bool> = chart
        .region
        .iter()
        .zip(&chart.marginal)
        .map(|(r, &marginal)| r.is_stable() && !marginal)
        .collect();
    out.set_item("beta0", PyArray1::from_vec(py, chart.beta0))?;
    out.set_item("kappa", PyArray1::from_vec(py, chart.kappa))?;
    out.set_item("a", PyArray1::from_vec(py, chart.a))?;
    out.set_item("b", PyArray1::from_vec(py, chart.b))?;
    out.set_item(
        "spectral_radius",
        PyArray1::from_vec(py, chart.spectral_radius),
    )?;
    out.set_item("region", PyArray1::from_vec(py, region))?;
    out.set_item("stable", PyArray1::from_vec(py, stable))?;
    out.set_item(
        "multiplier_error",
        PyArray1::from_vec(py, chart.multiplier_error),
    )?;
    out.set_item("marginal", PyArray1::from_vec(py, chart.marginal))?;
    Ok(out)
}

/// Region (1-4) of Fig. 2.13 for paired arrays of half trace `a` and determinant `b`
/// (docs/errata.md#9: Region I is `b <= 1, |a| <= (1 + b)/2`).
#[pyfunction]
fn stability_region<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    b: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<i64>>> {
    let (a, b) = (to_vec(&a), to_vec(&b));
    same_len(("a", a.len()), ("b", b.len())).py_err()?;
    let out = a
        .iter()
        .zip(&b)
        .enumerate()
        .map(|(i, (&x, &y))| {
            floquet::region(x, y)
                .map(|r| i64::from(r.index()))
                .map_err(|e| e.at_index(i, None))
        })
        .collect::<Result<Vec<_>>>()
        .py_err()?;
    Ok(PyArray1::from_vec(py, out))
}

fn brockett_dict<'py>(py: Python<'py>, b: &Brockett) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("delta", b.delta)?;
    out.set_item("period", b.period)?;
    out.set_item("damping_integral", b.damping_integral)?;
    out.set_item("n", b.n)?;
    out.set_item("interval", b.interval)?;
    out.set_item("damping_condition", b.damping_condition)?;
    out.set_item("bounded", b.bounded)?;
    Ok(out)
}

/// Brockett's criterion (eqs. 2.57-2.58) for `|g| <= 2 delta`, period T and `∫g dt`.
#[pyfunction]
#[pyo3(signature = (delta, period, damping_integral = 0.0))]
fn stability_brockett<'py>(
    py: Python<'py>,
    delta: f64,
    period: f64,
    damping_integral: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let b = floquet::brockett(delta, period, damping_integral).py_err()?;
    brockett_dict(py, &b)
}

/// Brockett's criterion for eq. 2.25 after rescaling time by √κ (κ > 0).
#[pyfunction]
fn stability_brockett_hill<'py>(
    py: Python<'py>,
    beta0: f64,
    kappa: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let b = floquet::brockett_hill(beta0, kappa).py_err()?;
    brockett_dict(py, &b)
}

/// (β0, κ1, κ2) of §2.6.1 with docs/errata.md#7's factors, and eq. 2.59's `beta_star` (1/ms),
/// `kappa0` (1/ms²) for sinusoidal flapping.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn stability_hill_parameters<'py>(
    py: Python<'py>,
    inertia: f64,
    drag: f64,
    transmission_ratio: f64,
    arm_length_mm: f64,
    k1: f64,
    k2: f64,
    stroke_amplitude: f64,
    frequency_hz: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let p = PhysicalParameters {
        inertia,
        drag,
        transmission_ratio,
        arm_length: arm_length_mm,
        k1,
        k2,
        stroke_amplitude,
        frequency_hz,
    };
    let h = p.hill().py_err()?;
    let lti = p.lti().py_err()?;
    let out = PyDict::new(py);
    out.set_item("beta0", h.beta0)?;
    out.set_item("kappa1", h.kappa1)?;
    out.set_item("kappa2", h.kappa2)?;
    out.set_item("beta_star", lti.beta_star)?;
    out.set_item("kappa0", lti.kappa0)?;
    out.set_item("omega0", p.omega0())?;
    Ok(out)
}

/// Eq. 2.59 `κ0/(s² + β* s + κ0)` at `s = 2πi f` (f in Hz, s in rad/ms), complex array.
#[pyfunction]
fn stability_lti_transfer<'py>(
    py: Python<'py>,
    beta_star: f64,
    kappa0: f64,
    frequency_hz: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<Complex64>>> {
    let lti = floquet::LtiModel::new(beta_star, kappa0).py_err()?;
    let out = to_vec(&frequency_hz)
        .iter()
        .enumerate()
        .map(|(i, &f)| {
            lti.transfer(f)
                .map(c64)
                .map_err(|e| e.at_index(i, Some("frequency_hz")))
        })
        .collect::<Result<Vec<_>>>()
        .py_err()?;
    Ok(PyArray1::from_vec(py, out))
}

// ------------------------------------------------------------------ the nonlinear model

const SHOOTING_KEYS: [&str; 11] = [
    "method",
    "rtol",
    "atol",
    "max_steps",
    "t0",
    "warmup_cycles",
    "warmup_tol",
    "max_newton",
    "tol",
    "fd_step",
    "fallback_cycles",
];

fn opt_f64(d: &Bound<'_, PyDict>, key: &str, default: f64) -> Result<f64> {
    match d.get_item(key).ok().flatten().filter(|v| !v.is_none()) {
        None => Ok(default),
        Some(v) => v
            .extract::<f64>()
            .map_err(|_| Error::invalid(format!("options.{key}"), v, "a number")),
    }
}

fn opt_usize(d: &Bound<'_, PyDict>, key: &str, default: usize) -> Result<usize> {
    match d.get_item(key).ok().flatten().filter(|v| !v.is_none()) {
        None => Ok(default),
        Some(v) => v
            .extract::<usize>()
            .map_err(|_| Error::invalid(format!("options.{key}"), v, "a non-negative integer")),
    }
}

fn check_keys(d: &Bound<'_, PyDict>, allowed: &[&str]) -> Result<()> {
    for key in d.keys() {
        let name: String = key.extract().unwrap_or_else(|_| key.to_string());
        if !allowed.contains(&name.as_str()) {
            return Err(Error::invalid(
                format!("options.{name}"),
                "<unknown option>",
                paritysim_spec::schema::suggestion(&name, allowed.iter().copied()),
            ));
        }
    }
    Ok(())
}

fn parse_shooting(options: Option<&Bound<'_, PyDict>>) -> Result<ShootingOptions> {
    let d = ShootingOptions::default();
    let Some(o) = options else {
        return Ok(d);
    };
    check_keys(o, &SHOOTING_KEYS)?;
    let method = match o.get_item("method").ok().flatten().filter(|v| !v.is_none()) {
        None => d.method,
        Some(v) => match v.extract::<String>().as_deref() {
            Ok("dop853") => Method::Dop853,
            Ok("dopri5") => Method::Dopri5,
            _ => return Err(Error::invalid("options.method", v, "dop853 or dopri5")),
        },
    };
    Ok(ShootingOptions {
        method,
        rtol: opt_f64(o, "rtol", d.rtol)?,
        atol: opt_f64(o, "atol", d.atol)?,
        max_steps: opt_usize(o, "max_steps", d.max_steps)?,
        t0: opt_f64(o, "t0", d.t0)?,
        warmup_cycles: opt_usize(o, "warmup_cycles", d.warmup_cycles)?,
        warmup_tol: opt_f64(o, "warmup_tol", d.warmup_tol)?,
        max_newton: opt_usize(o, "max_newton", d.max_newton)?,
        tol: opt_f64(o, "tol", d.tol)?,
        fd_step: opt_f64(o, "fd_step", d.fd_step)?,
        fallback_cycles: opt_usize(o, "fallback_cycles", d.fallback_cycles)?,
        initial: None,
    })
}

fn stability_name(s: OrbitStability) -> &'static str {
    match s {
        OrbitStability::Asymptotic => "asymptotic",
        OrbitStability::Marginal => "marginal",
        OrbitStability::Unstable => "unstable",
    }
}

fn floquet_dict<'py>(py: Python<'py>, f: &NonlinearFloquet) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let n = f.coordinates.len();
    let n_dof = n / 2;
    let state: Vec<f64> = (0..n_dof)
        .map(|i| f.orbit.state.coords[i])
        .chain((0..n_dof).map(|i| f.orbit.state.rates[i]))
        .collect();
    out.set_item("coordinates", f.coordinates.clone())?;
    out.set_item("orbit_state", PyArray1::from_vec(py, state))?;
    out.set_item("period_ms", f.orbit.period)?;
    out.set_item("t0_ms", f.orbit.t0)?;
    out.set_item("residual", f.orbit.residual)?;
    out.set_item("newton_iterations", f.orbit.newton_iterations)?;
    out.set_item("cycles_simulated", f.orbit.cycles_simulated)?;
    out.set_item(
        "method",
        match f.orbit.method {
            OrbitMethod::Newton => "newton",
            OrbitMethod::Simulation => "simulation",
        },
    )?;
    let mono: Vec<f64> = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| f.monodromy[(i, j)])
        .collect();
    out.set_item("monodromy", shaped(py, mono, &[n, n])?)?;
    out.set_item(
        "multipliers",
        PyArray1::from_vec(py, f.multipliers.iter().map(|z| c64(*z)).collect()),
    )?;
    out.set_item("spectral_radius", f.spectral_radius())?;
    out.set_item("max_exponent_per_ms", f.max_exponent())?;
    out.set_item("stability", stability_name(f.stability()))?;
    out.set_item("slowest_decay_ms", f.slowest_decay_ms())?;
    out.set_item("growth_time_ms", f.growth_time_ms())?;
    out.set_item(
        "whippletree_multipliers",
        f.whippletree
            .map(|w| PyArray1::from_vec(py, w.iter().map(|z| c64(*z)).collect())),
    )?;
    out.set_item("whippletree_coupling", f.whippletree_coupling)?;
    out.set_item("monodromy_uncertainty", f.monodromy_uncertainty)?;
    Ok(out)
}

/// Periodic orbit (shooting) and Floquet multipliers of a device spec dict. `options`: the
/// shooting options (`rtol, atol, method, max_steps, t0, warmup_cycles, warmup_tol,
/// max_newton, tol, fd_step, fallback_cycles`).
#[pyfunction]
#[pyo3(signature = (spec, options = None))]
fn stability_floquet<'py>(
    py: Python<'py>,
    spec: &str,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let device = parse_device(spec).py_err()?;
    let opts = parse_shooting(options).py_err()?;
    let f = py.detach(|| floquet::floquet(&device, &opts)).py_err()?;
    floquet_dict(py, &f)
}

/// Floquet analysis over balance-beam stiffnesses `k2` (mN·mm/rad), in parallel: arrays
/// `k2, spectral_radius, max_exponent_per_ms, whippletree_radius` (NaN without a whippletree
/// block), `slowest_decay_ms` (NaN when nothing decays), `multipliers` (n_k2 × 2n complex) and
/// the list `stability`.
#[pyfunction]
#[pyo3(signature = (spec, k2, options = None))]
fn stability_k2_sweep<'py>(
    py: Python<'py>,
    spec: &str,
    k2: PyReadonlyArray1<'py, f64>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let device = parse_device(spec).py_err()?;
    let opts = parse_shooting(options).py_err()?;
    let k2 = to_vec(&k2);
    let runs = py
        .detach(|| floquet::balance_stiffness_sweep(device.spec(), &k2, &opts))
        .py_err()?;
    let width = runs.first().map_or(0, |f| f.multipliers.len());
    let out = PyDict::new(py);
    let column =
        |g: &dyn Fn(&NonlinearFloquet) -> f64| -> Vec<f64> { runs.iter().map(g).collect() };
    out.set_item("k2", PyArray1::from_vec(py, k2.clone()))?;
    out.set_item(
        "spectral_radius",
        PyArray1::from_vec(py, column(&|f| f.spectral_radius())),
    )?;
    out.set_item(
        "max_exponent_per_ms",
        PyArray1::from_vec(py, column(&|f| f.max_exponent())),
    )?;
    out.set_item(
        "whippletree_radius",
        PyArray1::from_vec(
            py,
            column(&|f| {
                f.whippletree
                    .map_or(f64::NAN, |w| w[0].norm().max(w[1].norm()))
            }),
        ),
    )?;
    out.set_item(
        "slowest_decay_ms",
        PyArray1::from_vec(py, column(&|f| f.slowest_decay_ms().unwrap_or(f64::NAN))),
    )?;
    let mult: Vec<Complex64> = runs
        .iter()
        .flat_map(|f| f.multipliers.iter().map(|z| c64(*z)))
        .collect();
    out.set_item(
        "multipliers",
        PyArray1::from_vec(py, mult).reshape(vec![runs.len(), width])?,
    )?;
    out.set_item(
        "stability",
        runs.iter()
            .map(|f| stability_name(f.stability()))
            .collect::<Vec<_>>(),
    )?;
    Ok(out)
}

fn lti_dict<'py>(py: Python<'py>, lti: &floquet::LtiModel) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("beta_star", lti.beta_star)?;
    out.set_item("kappa0", lti.kappa0)?;
    Ok(out)
}

/// Places a fixed-wing Drag PARITY device spec on the charts of §2.6-2.7 from its periodic
/// orbit: `physical` (inertia, drag, T, L, K1, K2, stroke amplitude, frequency), `hill`
/// (β0, κ1, κ2), `lti`, `lti_sinusoidal`, `lti_averaged` (each `beta_star` 1/ms, `kappa0`
/// 1/ms²), `geometric_stiffness` (mN·mm/rad).
#[pyfunction]
#[pyo3(signature = (spec, options = None, samples = 2000))]
fn stability_linearise<'py>(
    py: Python<'py>,
    spec: &str,
    options: Option<&Bound<'py, PyDict>>,
    samples: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let device = parse_device(spec).py_err()?;
    let opts = parse_shooting(options).py_err()?;
    let lin = py
        .detach(|| -> Result<floquet::DeviceLinearisation> {
            let orbit = floquet::periodic_orbit(&device, &opts)?;
            floquet::linearise(&device, &orbit, samples)
        })
        .py_err()?;
    let out = PyDict::new(py);
    let p = &lin.physical;
    let physical = PyDict::new(py);
    physical.set_item("inertia", p.inertia)?;
    physical.set_item("drag", p.drag)?;
    physical.set_item("transmission_ratio", p.transmission_ratio)?;
    physical.set_item("arm_length_mm", p.arm_length)?;
    physical.set_item("k1", p.k1)?;
    physical.set_item("k2", p.k2)?;
    physical.set_item("stroke_amplitude", p.stroke_amplitude)?;
    physical.set_item("frequency_hz", p.frequency_hz)?;
    out.set_item("physical", physical)?;
    let hill = PyDict::new(py);
    hill.set_item("beta0", lin.hill.beta0)?;
    hill.set_item("kappa1", lin.hill.kappa1)?;
    hill.set_item("kappa2", lin.hill.kappa2)?;
    out.set_item("hill", hill)?;
    out.set_item("lti", lti_dict(py, &lin.lti)?)?;
    out.set_item("lti_sinusoidal", lti_dict(py, &lin.lti_sinusoidal)?)?;
    out.set_item("lti_averaged", lti_dict(py, &lin.lti_averaged)?)?;
    out.set_item("geometric_stiffness", lin.geometric_stiffness)?;
    Ok(out)
}

const DISTURBANCE_KEYS: [&str; 5] = [
    "settle_cycles",
    "max_window_cycles",
    "samples_per_cycle",
    "rtol",
    "atol",
];

/// The body roll response of the nonlinear model to a sinusoidal wing roll disturbance torque
/// of `amplitude` (mN·mm) at each of `frequency_hz`, started on the periodic orbit: complex
/// `transfer`, `drift` (change between two consecutive windows), `window_ms`,
/// `commensurability_error`. `disturbance`: `settle_cycles, max_window_cycles,
/// samples_per_cycle, rtol, atol`.
#[pyfunction]
#[pyo3(signature = (spec, frequency_hz, amplitude, options = None, disturbance = None))]
fn stability_disturbance_response<'py>(
    py: Python<'py>,
    spec: &str,
    frequency_hz: PyReadonlyArray1<'py, f64>,
    amplitude: f64,
    options: Option<&Bound<'py, PyDict>>,
    disturbance: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let device = parse_device(spec).py_err()?;
    let opts = parse_shooting(options).py_err()?;
    let d = DisturbanceOptions::default();
    let dist = match disturbance {
        None => d,
        Some(o) => {
            check_keys(o, &DISTURBANCE_KEYS).py_err()?;
            DisturbanceOptions {
                settle_cycles: opt_usize(o, "settle_cycles", d.settle_cycles).py_err()?,
                max_window_cycles: opt_usize(o, "max_window_cycles", d.max_window_cycles)
                    .py_err()?,
                samples_per_cycle: opt_usize(o, "samples_per_cycle", d.samples_per_cycle)
                    .py_err()?,
                rtol: opt_f64(o, "rtol", d.rtol).py_err()?,
                atol: opt_f64(o, "atol", d.atol).py_err()?,
            }
        }
    };
    let freqs = to_vec(&frequency_hz);
    let runs = py
        .detach(|| -> Result<Vec<floquet::DisturbanceResponse>> {
            let orbit = floquet::periodic_orbit(&device, &opts)?;
            floquet::disturbance_responses(&device, &orbit, &freqs, amplitude, &dist)
        })
        .py_err()?;
    let out = PyDict::new(py);
    out.set_item("frequency_hz", PyArray1::from_vec(py, freqs))?;
    out.set_item(
        "transfer",
        PyArray1::from_vec(py, runs.iter().map(|r| c64(r.transfer)).collect()),
    )?;
    out.set_item(
        "drift",
        PyArray1::from_vec(py, runs.iter().map(|r| r.drift).collect()),
    )?;
    out.set_item(
        "window_ms",
        PyArray1::from_vec(py, runs.iter().map(|r| r.window_ms).collect()),
    )?;
    out.set_item(
        "commensurability_error",
        PyArray1::from_vec(py, runs.iter().map(|r| r.commensurability_error).collect()),
    )?;
    out.set_item("amplitude", amplitude)?;
    Ok(out)
}

/// Adds the stability functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(stability_hill_monodromy, m)?)?;
    m.add_function(wrap_pyfunction!(stability_hill_solution, m)?)?;
    m.add_function(wrap_pyfunction!(stability_hill_floquet, m)?)?;
    m.add_function(wrap_pyfunction!(stability_chart, m)?)?;
    m.add_function(wrap_pyfunction!(stability_region, m)?)?;
    m.add_function(wrap_pyfunction!(stability_brockett, m)?)?;
    m.add_function(wrap_pyfunction!(stability_brockett_hill, m)?)?;
    m.add_function(wrap_pyfunction!(stability_hill_parameters, m)?)?;
    m.add_function(wrap_pyfunction!(stability_lti_transfer, m)?)?;
    m.add_function(wrap_pyfunction!(stability_floquet, m)?)?;
    m.add_function(wrap_pyfunction!(stability_k2_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(stability_linearise, m)?)?;
    m.add_function(wrap_pyfunction!(stability_disturbance_response, m)?)?;
    Ok(())
}
