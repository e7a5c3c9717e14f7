//! Bindings for the stability functions (prefix `stability_`): eq. 2.25 Floquet analysis,
//! Brockett's criterion, the §2.6.1 parameter map, eq. 2.59, and the Floquet analysis and
//! disturbance response of the full nonlinear model (`paritysim_dynamics::floquet`). Results
//! are the `floquet::records` types through [`to_py`] (complex numbers as `[re, im]` pairs);
//! options are JSON records of `ShootingOptions` / `DisturbanceOptions`.

use nalgebra::Complex;
use numpy::{Complex64, PyArray1, PyReadonlyArray1};
use paritysim_dynamics::floquet::records::{
    BalanceSweepRecord, DisturbanceRecord, FloquetRecord, HillFloquetRecord, HillParametersRecord,
    hill_solutions, regions, rows2,
};
use paritysim_dynamics::floquet::{self, DisturbanceOptions, PhysicalParameters, ShootingOptions};
use paritysim_error::Result;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{from_json, same_len, to_py, to_vec};
use crate::errors::IntoPyResult;
use crate::spec::{cancellable, device as parse_device};

fn c64(z: Complex<f64>) -> Complex64 {
    Complex64::new(z.re, z.im)
}

/// Options from JSON (`None`: the defaults); unknown keys name the nearest valid one.
fn options<T: serde::de::DeserializeOwned + Default>(json: Option<&str>, field: &str) -> Result<T> {
    json.map_or_else(|| Ok(T::default()), |j| from_json(field, j))
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
    to_py(
        py,
        &rows2(&floquet::hill_monodromy(beta0, kappa, t0).py_err()?),
    )
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
    let m = cancellable(py, || hill_solutions(beta0, kappa, t0, &t))?;
    to_py(py, &m)
}

/// Floquet analysis of eq. 2.25 (`floquet::records::HillFloquetRecord`).
#[pyfunction]
fn stability_hill_floquet(py: Python<'_>, beta0: f64, kappa: f64) -> PyResult<Bound<'_, PyAny>> {
    let f = floquet::hill_floquet(beta0, kappa).py_err()?;
    to_py(py, &HillFloquetRecord::from(&f))
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
    let c = cancellable(py, || floquet::stability_chart(&beta0, &kappa))?;
    // Up to 4M points: numpy columns straight from the vectors, not the generic converter.
    let stable = c.region.iter().zip(&c.marginal);
    let stable: Vec<bool> = stable.map(|(r, &m)| r.is_stable() && !m).collect();
    let region: Vec<i64> = c.region.iter().map(|r| i64::from(r.index())).collect();
    let out = PyDict::new(py);
    for (name, column) in [
        ("beta0", c.beta0),
        ("kappa", c.kappa),
        ("a", c.a),
        ("b", c.b),
        ("spectral_radius", c.spectral_radius),
    ] {
        out.set_item(name, PyArray1::from_vec(py, column))?;
    }
    out.set_item("region", PyArray1::from_vec(py, region))?;
    out.set_item("stable", PyArray1::from_vec(py, stable))?;
    out.set_item(
        "multiplier_error",
        PyArray1::from_vec(py, c.multiplier_error),
    )?;
    out.set_item("marginal", PyArray1::from_vec(py, c.marginal))?;
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
    let r = regions(&a, &b).py_err()?;
    Ok(PyArray1::from_vec(
        py,
        r.into_iter().map(i64::from).collect(),
    ))
}

/// Brockett's criterion (eqs. 2.57-2.58) for `|g| <= 2 delta`, period T and `∫g dt`.
#[pyfunction]
#[pyo3(signature = (delta, period, damping_integral = 0.0))]
fn stability_brockett(
    py: Python<'_>,
    delta: f64,
    period: f64,
    damping_integral: f64,
) -> PyResult<Bound<'_, PyAny>> {
    to_py(
        py,
        &floquet::brockett(delta, period, damping_integral).py_err()?,
    )
}

/// Brockett's criterion for eq. 2.25 after rescaling time by √κ (κ > 0).
#[pyfunction]
fn stability_brockett_hill(py: Python<'_>, beta0: f64, kappa: f64) -> PyResult<Bound<'_, PyAny>> {
    to_py(py, &floquet::brockett_hill(beta0, kappa).py_err()?)
}

/// (β0, κ1, κ2) of §2.6.1 with docs/errata.md#7's factors, and eq. 2.59's `beta_star` (1/ms),
/// `kappa0` (1/ms²) for sinusoidal flapping.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn stability_hill_parameters(
    py: Python<'_>,
    inertia: f64,
    drag: f64,
    transmission_ratio: f64,
    arm_length_mm: f64,
    k1: f64,
    k2: f64,
    stroke_amplitude: f64,
    frequency_hz: f64,
) -> PyResult<Bound<'_, PyAny>> {
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
    to_py(py, &HillParametersRecord::of(&p).py_err()?)
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

/// Periodic orbit (shooting) and Floquet multipliers of a device spec (`FloquetRecord`).
/// `options_json`: a `ShootingOptions` record.
#[pyfunction]
#[pyo3(signature = (spec, options_json = None))]
fn stability_floquet<'py>(
    py: Python<'py>,
    spec: &str,
    options_json: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let device = parse_device(spec).py_err()?;
    let opts: ShootingOptions = options(options_json, "options").py_err()?;
    let f = cancellable(py, || floquet::floquet(&device, &opts))?;
    to_py(py, &FloquetRecord::from(&f))
}

/// Floquet analysis over balance-beam stiffnesses `k2` (mN·mm/rad), in parallel
/// (`BalanceSweepRecord`).
#[pyfunction]
#[pyo3(signature = (spec, k2, options_json = None))]
fn stability_k2_sweep<'py>(
    py: Python<'py>,
    spec: &str,
    k2: PyReadonlyArray1<'py, f64>,
    options_json: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let device = parse_device(spec).py_err()?;
    let opts: ShootingOptions = options(options_json, "options").py_err()?;
    let k2 = to_vec(&k2);
    let runs = cancellable(py, || {
        floquet::balance_stiffness_sweep(device.spec(), &k2, &opts)
    })?;
    to_py(py, &BalanceSweepRecord::of(&k2, &runs))
}

/// Places a fixed-wing Drag PARITY device spec on the charts of §2.6-2.7 from its periodic
/// orbit (`floquet::DeviceLinearisation`).
#[pyfunction]
#[pyo3(signature = (spec, options_json = None, samples = 2000))]
fn stability_linearise<'py>(
    py: Python<'py>,
    spec: &str,
    options_json: Option<&str>,
    samples: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let device = parse_device(spec).py_err()?;
    let opts: ShootingOptions = options(options_json, "options").py_err()?;
    let lin = cancellable(py, || -> Result<floquet::DeviceLinearisation> {
        let orbit = floquet::periodic_orbit(&device, &opts)?;
        floquet::linearise(&device, &orbit, samples)
    })?;
    to_py(py, &lin)
}

/// The body roll response of the nonlinear model to a sinusoidal wing roll disturbance torque
/// of `amplitude` (mN·mm) at each of `frequency_hz`, started on the periodic orbit
/// (`DisturbanceRecord`). `disturbance_json`: a `DisturbanceOptions` record.
#[pyfunction]
#[pyo3(signature = (spec, frequency_hz, amplitude, options_json = None, disturbance_json = None))]
fn stability_disturbance_response<'py>(
    py: Python<'py>,
    spec: &str,
    frequency_hz: PyReadonlyArray1<'py, f64>,
    amplitude: f64,
    options_json: Option<&str>,
    disturbance_json: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let device = parse_device(spec).py_err()?;
    let opts: ShootingOptions = options(options_json, "options").py_err()?;
    let dist: DisturbanceOptions = options(disturbance_json, "disturbance").py_err()?;
    let freqs = to_vec(&frequency_hz);
    let runs = cancellable(py, || -> Result<Vec<floquet::DisturbanceResponse>> {
        let orbit = floquet::periodic_orbit(&device, &opts)?;
        floquet::disturbance_responses(&device, &orbit, &freqs, amplitude, &dist)
    })?;
    to_py(py, &DisturbanceRecord::of(&freqs, amplitude, &runs))
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
