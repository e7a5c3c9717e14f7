//! Bindings for the stability functions (prefix `stability_`): eq. 2.25 Floquet analysis,
//! Brockett's criterion, the §2.6.1 parameter map, eq. 2.59, and the Floquet analysis and
//! disturbance response of the full nonlinear model (`paritysim_dynamics::floquet`). Results
//! are the `floquet::records` types through [`to_py`] (complex numbers as `[re, im]` pairs);
//! options are JSON records of `ShootingOptions` / `DisturbanceOptions`.

use nalgebra::Complex;
use numpy::{Complex64, PyArray1, PyReadonlyArray1};
use paritysim_dynamics::floquet::records::{
    BalanceSweepRecord, DisturbanceRecord, FloquetRecord, HillFloquetRecord, HillParametersRecord,
    regions, rows2,
};
use paritysim_dynamics::floquet::{self, DisturbanceOptions, PhysicalParameters, ShootingOptions};
use paritysim_dynamics::{Formulation, State};
use paritysim_error::Result;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{Floats, bindings, from_json, to_vec};
use crate::errors::IntoPyResult;
use crate::spec::{cancellable, cancellable_on, device as parse_device, within};
use paritysim_dynamics::integrate::budget;

fn c64(z: Complex<f64>) -> Complex64 {
    Complex64::new(z.re, z.im)
}

/// Options from JSON (`None`: the defaults); unknown keys name the nearest valid one.
fn options<T: serde::de::DeserializeOwned + Default>(json: Option<&str>, field: &str) -> Result<T> {
    json.map_or_else(|| Ok(T::default()), |j| from_json(field, j))
}

bindings! {
    run cancellable;
    extra stability_chart;
    extra stability_region;
    extra stability_lti_transfer;
    extra sensitivity;

    /// The continuous spec paths `params` of a JSON spec resolved: their names, units and
    /// values (`paritysim_spec::sensitivity::parameters`).
    fn sensitivity_parameters(json: &str, params: Vec<String>) {
        let spec = crate::spec::parse(json)?;
        paritysim_spec::sensitivity::parameters(&spec, &params)
            .map(|(p, units, values)| {
                let names: Vec<String> = p.into_iter().map(|p| p.name).collect();
                (names, units, values)
            })
    }

    /// `sensitivity` at each point `rows[i]` (a JSON object of spec paths and values) of a
    /// JSON spec, on `threads` of the sweep engine (default: as a sweep resolves them;
    /// `paritysim_spec::sensitivity::sensitivities`).
    #[pyo3(signature = (json, rows, params, metrics = None, threads = None))]
    fn sensitivity_rows(json: &str, rows: Vec<String>, params: Vec<String>, metrics: Option<Vec<String>>, threads: Option<usize>) {
        let spec = crate::spec::parse(json)?;
        paritysim_spec::sensitivity::sensitivities(&spec, &rows, &params, metrics.as_deref(), threads)
    }

    /// Monodromy matrix `M(t0)` of eq. 2.25 (`x'' + β0|cos t| x' + κ x = 0`, period π), 2×2.
    fn stability_hill_monodromy(beta0: f64, kappa: f64, t0: f64) {
        Ok(rows2(&floquet::hill_monodromy(beta0, kappa, t0)?))
    }

    /// Solution matrices `Π(t_i, t0)` of eq. 2.25 at each `t_i >= t0`, shape `(n, 2, 2)`.
    /// The budget (Ctrl-C, `max_wall_ms`) is checked between the `t_i`: each is an
    /// integration of up to 1e4 time units.
    #[pyo3(signature = (beta0, kappa, t0, t, max_wall_ms = None))]
    fn stability_hill_solution(beta0: f64, kappa: f64, t0: f64, t: Floats, max_wall_ms: Option<f64>) {
        within(max_wall_ms, || {
            let mut out = Vec::with_capacity(t.len());
            for (i, ti) in t.iter().enumerate() {
                budget::check(0.0)?;
                let m = floquet::hill_solution_matrix(beta0, kappa, t0, *ti)
                    .map_err(|e| e.at_index(i, Some("t")))?;
                out.push(rows2(&m));
            }
            Ok(out)
        })
    }

    /// Floquet analysis of eq. 2.25 (`floquet::records::HillFloquetRecord`).
    fn stability_hill_floquet(beta0: f64, kappa: f64) {
        Ok(HillFloquetRecord::from(&floquet::hill_floquet(beta0, kappa)?))
    }

    /// Brockett's criterion (eqs. 2.57-2.58) for `|g| <= 2 delta`, period T and `∫g dt`.
    fn stability_brockett(delta: f64, period: f64, damping_integral: f64) {
        floquet::brockett(delta, period, damping_integral)
    }

    /// Brockett's criterion for eq. 2.25 after rescaling time by √κ (κ > 0).
    fn stability_brockett_hill(beta0: f64, kappa: f64) {
        floquet::brockett_hill(beta0, kappa)
    }

    /// (β0, κ1, κ2) of §2.6.1 with docs/errata.md#7's factors, and eq. 2.59's `beta_star`
    /// (1/ms), `kappa0` (1/ms²) for sinusoidal flapping.
    #[allow(clippy::too_many_arguments)]
    fn stability_hill_parameters(
        inertia: f64,
        drag: f64,
        transmission_ratio: f64,
        arm_length_mm: f64,
        k1: f64,
        k2: f64,
        stroke_amplitude: f64,
        frequency_hz: f64,
    ) {
        HillParametersRecord::of(&PhysicalParameters {
            inertia,
            drag,
            transmission_ratio,
            arm_length: arm_length_mm,
            k1,
            k2,
            stroke_amplitude,
            frequency_hz,
        })
    }

    /// Periodic orbit (shooting) and Floquet multipliers of a device spec (`FloquetRecord`).
    /// `options_json`: a `ShootingOptions` record.
    #[pyo3(signature = (spec, options_json = None))]
    fn stability_floquet(spec: &str, options_json: Option<&str>) {
        let device = parse_device(spec)?;
        let opts: ShootingOptions = options(options_json, "options")?;
        Ok(FloquetRecord::from(&floquet::floquet(&device, &opts)?))
    }

    /// The wing coordinates' derivative by a device's integrated ones: column `i` is
    /// `∂p/∂x_i` (`p = p_part + N x`, `(φ, θ, ψ)` per wing), so a Floquet mode over `x` reads
    /// in wing angles; `None` in drivetrain coordinates, which are already physical (`q`).
    fn stability_coordinate_basis(spec: &str) -> Option<Vec<Vec<f64>>> {
        let device = parse_device(spec)?;
        if device.formulation() == Formulation::DrivetrainCoordinates {
            return Ok(None);
        }
        let origin = device.coordinates(&State::default())?.0;
        let column = |i: usize| {
            let mut unit = State::default();
            unit.coords[i] = 1.0;
            device
                .coordinates(&unit)
                .map(|(p, _)| (p - origin).iter().copied().collect::<Vec<f64>>())
        };
        Ok(Some((0..device.n_dof()).map(column).collect::<Result<Vec<_>>>()?))
    }

    /// Floquet analysis over balance-beam stiffnesses `k2` (mN·mm/rad), in parallel
    /// (`BalanceSweepRecord`).
    #[pyo3(signature = (spec, k2, options_json = None))]
    fn stability_k2_sweep(spec: &str, k2: Floats, options_json: Option<&str>) {
        let device = parse_device(spec)?;
        let opts: ShootingOptions = options(options_json, "options")?;
        let runs = floquet::balance_spring_sweep(device.spec(), &k2, &opts)?;
        Ok(BalanceSweepRecord::of(&k2, &runs))
    }

    /// Places a fixed-wing Drag PARITY device spec on the charts of §2.6-2.7 from its
    /// periodic orbit (`floquet::DeviceLinearisation`).
    #[pyo3(signature = (spec, options_json, samples))]
    fn stability_linearise(spec: &str, options_json: Option<&str>, samples: usize) {
        let device = parse_device(spec)?;
        let opts: ShootingOptions = options(options_json, "options")?;
        floquet::linearise(&device, &floquet::periodic_orbit(&device, &opts)?, samples)
    }

    /// The body roll response of the nonlinear model to a sinusoidal wing roll disturbance
    /// torque of `amplitude` (mN·mm) at each of `frequency_hz`, started on the periodic orbit
    /// (`DisturbanceRecord`). `disturbance_json`: a `DisturbanceOptions` record.
    #[pyo3(signature = (spec, frequency_hz, amplitude, options_json = None, disturbance_json = None))]
    fn stability_disturbance_response(
        spec: &str,
        frequency_hz: Floats,
        amplitude: f64,
        options_json: Option<&str>,
        disturbance_json: Option<&str>,
    ) {
        let device = parse_device(spec)?;
        let opts: ShootingOptions = options(options_json, "options")?;
        let dist: DisturbanceOptions = options(disturbance_json, "disturbance")?;
        let orbit = floquet::periodic_orbit(&device, &opts)?;
        let runs = floquet::disturbance_responses(&device, &orbit, &frequency_hz, amplitude, &dist)?;
        Ok(DisturbanceRecord::of(&frequency_hz, amplitude, &runs))
    }
}

/// Derivatives of a JSON spec's steady-state metrics (`metrics`, or all) by the continuous
/// spec paths `params` (`paritysim_spec::sensitivity`), as plain columns. On this thread
/// (`cancellable_on`): the worker thread of `cancellable` cost 0.2-0.3 ms a call, a fifth
/// of a short sensitivity's wall time. Ctrl-C is polled from this thread's budget checks (the
/// orbit's solve, the variational period); while the parameter groups run on the pool it
/// waits for them.
#[pyfunction]
#[pyo3(signature = (json, params, metrics = None))]
fn sensitivity<'py>(
    py: Python<'py>,
    json: &str,
    params: Vec<String>,
    metrics: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyAny>> {
    let record = cancellable_on(py, true, || {
        let spec = crate::spec::parse(json)?;
        paritysim_spec::sensitivity::sensitivity(&spec, &params, metrics.as_deref())
            .map(|s| s.record())
    })?;
    crate::convert::to_py(py, &record)
}

/// The (β0, κ) grid `beta0 × kappa` (row-major, β0 outer) computed in parallel: flat arrays
/// `beta0, kappa, a, b, spectral_radius, region` (int 1-4; 0 for a failed point, whose numbers
/// are NaN), `multiplier_error`, `marginal` and `stable` (Region I and not marginal), and the
/// failed points as `error_index` (flat indices) with their messages `error`.
/// With `brockett`, also `brockett_bounded` (`floquet::brockett_hill` at every computed point
/// with κ > 0; false elsewhere), inside the same budget.
/// `max_wall_ms` bounds the whole chart (None: no budget of its own).
#[pyfunction]
#[pyo3(signature = (beta0, kappa, max_wall_ms = None, brockett = false))]
fn stability_chart<'py>(
    py: Python<'py>,
    beta0: PyReadonlyArray1<'py, f64>,
    kappa: PyReadonlyArray1<'py, f64>,
    max_wall_ms: Option<f64>,
    brockett: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (beta0, kappa) = (to_vec(&beta0), to_vec(&kappa));
    let (c, bounded) = cancellable(py, || {
        within(max_wall_ms, || {
            let c = floquet::stability_chart(&beta0, &kappa)?;
            if !brockett {
                return Ok((c, None));
            }
            let mut bounded = vec![false; c.beta0.len()];
            for (i, (slot, r)) in bounded.iter_mut().zip(&c.region).enumerate() {
                if i % 4096 == 0 {
                    budget::check(f64::NAN)?;
                }
                let (b, k) = (c.beta0[i], c.kappa[i]);
                if k > 0.0 && r.is_some() {
                    *slot = floquet::brockett_hill(b, k)?.bounded;
                }
            }
            Ok((c, Some(bounded)))
        })
    })?;
    // Up to 4M points: numpy columns straight from the vectors, not the generic converter.
    let (stable, region) = (c.stable(), c.region_numbers());
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
    let (index, messages): (Vec<i64>, Vec<String>) = c
        .errors
        .iter()
        .map(|(i, e)| (*i as i64, e.to_string()))
        .unzip();
    out.set_item("error_index", PyArray1::from_vec(py, index))?;
    out.set_item("error", messages)?;
    if let Some(bounded) = bounded {
        out.set_item("brockett_bounded", PyArray1::from_vec(py, bounded))?;
    }
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
    paritysim_error::check_same_len(("a", a.len()), ("b", b.len())).py_err()?;
    let r = regions(&a, &b).py_err()?;
    Ok(PyArray1::from_vec(
        py,
        r.into_iter().map(i64::from).collect(),
    ))
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
