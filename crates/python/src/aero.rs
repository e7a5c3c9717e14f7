//! Bindings of paritysim-aero (functions prefixed `aero_`).
//!
//! Planforms cross the boundary as `(n, 2)` float arrays of `[z, x]` vertices (mm); every call
//! re-validates them (cheap next to Python overhead for the usual < 1000 vertices). Results are
//! the `paritysim_aero::records` types through [`to_py`].

use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use paritysim_aero::records::{
    ChordTable, CoefficientTable, InertiaReport, MomentSeries, PlanformReport, vertices,
};
use paritysim_aero::{
    BladeElementModel, CoefficientSet, CutEdge, NormalForceLaw, Omegas, Planform, WingState,
};
use paritysim_error::Error;
use pyo3::prelude::*;

use crate::convert::{same_len, to_py, to_vec};
use crate::errors::IntoPyResult;

/// Rows of an `(n, cols)` array, naming it in the shape error.
fn rows<const N: usize>(name: &str, a: &PyReadonlyArray2<'_, f64>) -> Result<Vec<[f64; N]>, Error> {
    let v = a.as_array();
    if v.ncols() != N {
        let shape = v.shape();
        return Err(Error::Shape(format!(
            "`{name}` must have shape (n, {N}), got {shape:?}"
        )));
    }
    Ok(v.rows()
        .into_iter()
        .map(|r| std::array::from_fn(|j| r[j]))
        .collect())
}

fn planform(
    points: &PyReadonlyArray2<'_, f64>,
    closure_tolerance: Option<f64>,
) -> PyResult<Planform> {
    let pts = rows::<2>("points", points).py_err()?;
    match closure_tolerance {
        Some(tol) => Planform::from_traced_outline(&pts, tol),
        None => Planform::from_points(&pts),
    }
    .py_err()
}

/// Validates an outline (`(n, 2)` `[z, x]` mm, closing edge implicit; with
/// `closure_tolerance` mm a traced curve returning to its start) and returns its geometry and
/// Ω1..Ω4 for air of `density` mg/mm³ (`records::PlanformReport`).
#[pyfunction]
#[pyo3(signature = (points, density, closure_tolerance=None))]
fn aero_planform_properties<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    density: f64,
    closure_tolerance: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let p = planform(&points, closure_tolerance)?;
    to_py(py, &PlanformReport::of(&p, density).py_err()?)
}

/// Vertices `(n, 2)` of a rectangle `z ∈ [root_offset, root_offset + span]`,
/// `x ∈ [le_offset − chord, le_offset]`.
#[pyfunction]
fn aero_planform_rectangle(
    py: Python<'_>,
    span: f64,
    chord: f64,
    root_offset: f64,
    le_offset: f64,
) -> PyResult<Bound<'_, PyAny>> {
    let p = Planform::rectangle(span, chord, root_offset, le_offset).py_err()?;
    to_py(py, &vertices(&p))
}

/// Vertices `(n, 2)` of a semi-elliptic planform (straight leading edge) with `segments` steps.
#[pyfunction]
fn aero_planform_semi_ellipse(
    py: Python<'_>,
    span: f64,
    max_chord: f64,
    root_offset: f64,
    le_offset: f64,
    segments: usize,
) -> PyResult<Bound<'_, PyAny>> {
    let p = Planform::semi_ellipse(span, max_chord, root_offset, le_offset, segments).py_err()?;
    to_py(py, &vertices(&p))
}

/// Vertices `(n, 2)` of the HMF-like wing scaled to `tip_radius` mm.
#[pyfunction]
fn aero_planform_hmf_like(
    py: Python<'_>,
    tip_radius: f64,
    segments: usize,
) -> PyResult<Bound<'_, PyAny>> {
    to_py(
        py,
        &vertices(&Planform::hmf_like(tip_radius, segments).py_err()?),
    )
}

/// Vertices `(m, 2)` of the membrane left after cutting `fraction` of its span at the tip
/// (`edge = "tip"`) or of its chordwise extent at the trailing edge (`"trailing"`).
#[pyfunction]
fn aero_planform_cut<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    fraction: f64,
    edge: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let edge = CutEdge::from_name(edge).py_err()?;
    to_py(
        py,
        &vertices(&planform(&points, None)?.cut(fraction, edge).py_err()?),
    )
}

/// Chord `c(z)` and leading edge `l(z)` (mm) at the stations `z`. Outside the span the chord
/// is 0 and the leading edge NaN (documented mask).
#[pyfunction]
fn aero_planform_chord<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    z: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let (p, z) = (planform(&points, None)?, to_vec(&z));
    to_py(py, &py.detach(|| ChordTable::of(&p, &z)).py_err()?)
}

/// Mass properties about the spherical centre (`records::InertiaReport`): membrane
/// `areal_density` (mg/mm²), line masses as rows `[z0, x0, z1, x1, linear_density]` (mg/mm)
/// and point masses as rows `[z, x, mass]`.
#[pyfunction]
fn aero_planform_inertia<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    areal_density: f64,
    line_masses: PyReadonlyArray2<'py, f64>,
    point_masses: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let p = planform(&points, None)?;
    let lines = rows::<5>("line_masses", &line_masses).py_err()?;
    let pts = rows::<3>("point_masses", &point_masses).py_err()?;
    to_py(
        py,
        &InertiaReport::of(&p, areal_density, &lines, &pts).py_err()?,
    )
}

/// Coefficients of `model` (`"dickinson1999"` or `"whitney_wood2010"`) at angles of attack
/// `alpha` (rad, each in [0, π]): `records::CoefficientTable`.
#[pyfunction]
fn aero_coefficients<'py>(
    py: Python<'py>,
    alpha: PyReadonlyArray1<'py, f64>,
    model: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let (set, alpha) = (CoefficientSet::from_name(model).py_err()?, to_vec(&alpha));
    to_py(
        py,
        &py.detach(|| CoefficientTable::of(&set, &alpha)).py_err()?,
    )
}

/// Blade-element moments (eqs. 3.8–3.11) over paired state arrays (`records::MomentSeries`).
///
/// `omegas` is `[Ω1, Ω2, Ω3, Ω4]` (mg·mm²); `force` (mg·mm, `½ρ∬z²dA`) enables the lift/drag
/// outputs. `normal_force_law` is `"coefficient"` (eq. 3.8) or `"unit"` (eq. 2.16,
/// docs/errata.md#12).
#[pyfunction]
#[pyo3(signature = (omegas, phi, theta, psi, phi_dot, theta_dot, psi_dot, model, rotational_damping, normal_force_law, force=None))]
#[allow(clippy::too_many_arguments)]
fn aero_moments<'py>(
    py: Python<'py>,
    omegas: [f64; 4],
    phi: PyReadonlyArray1<'py, f64>,
    theta: PyReadonlyArray1<'py, f64>,
    psi: PyReadonlyArray1<'py, f64>,
    phi_dot: PyReadonlyArray1<'py, f64>,
    theta_dot: PyReadonlyArray1<'py, f64>,
    psi_dot: PyReadonlyArray1<'py, f64>,
    model: &str,
    rotational_damping: f64,
    normal_force_law: &str,
    force: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let set = CoefficientSet::from_name(model).py_err()?;
    let law = NormalForceLaw::from_name(normal_force_law).py_err()?;
    let mut o = Omegas::new(omegas[0], omegas[1], omegas[2], omegas[3]).py_err()?;
    if let Some(f) = force {
        o = o.with_force(f).py_err()?;
    }
    let m = BladeElementModel::new(o, set)
        .and_then(|m| m.with_rotational_damping(rotational_damping))
        .py_err()?
        .with_normal_force_law(law);
    let names = ["phi", "theta", "psi", "phi_dot", "theta_dot", "psi_dot"];
    let arrays = [&phi, &theta, &psi, &phi_dot, &theta_dot, &psi_dot];
    let cols: Vec<Vec<f64>> = arrays.into_iter().map(to_vec).collect();
    for (name, col) in names.iter().zip(&cols) {
        same_len(("phi", cols[0].len()), (name, col.len())).py_err()?;
        paritysim_error::check_all_finite(name, col).py_err()?;
    }
    let states: Vec<WingState> = (0..cols[0].len())
        .map(|i| WingState {
            phi: cols[0][i],
            theta: cols[1][i],
            psi: cols[2][i],
            phi_dot: cols[3][i],
            theta_dot: cols[4][i],
            psi_dot: cols[5][i],
        })
        .collect();
    let series = py.detach(|| MomentSeries::of(&m, &states, force.is_some()));
    to_py(py, &series.py_err()?)
}

/// Built-in coefficient model names.
#[pyfunction]
fn aero_model_names() -> Vec<&'static str> {
    CoefficientSet::NAMES.to_vec()
}

/// Adds the aero functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(aero_planform_properties, m)?)?;
    m.add_function(wrap_pyfunction!(aero_planform_rectangle, m)?)?;
    m.add_function(wrap_pyfunction!(aero_planform_semi_ellipse, m)?)?;
    m.add_function(wrap_pyfunction!(aero_planform_hmf_like, m)?)?;
    m.add_function(wrap_pyfunction!(aero_planform_chord, m)?)?;
    m.add_function(wrap_pyfunction!(aero_planform_cut, m)?)?;
    m.add_function(wrap_pyfunction!(aero_planform_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(aero_coefficients, m)?)?;
    m.add_function(wrap_pyfunction!(aero_moments, m)?)?;
    m.add_function(wrap_pyfunction!(aero_model_names, m)?)?;
    m.add("AERO_AIR_DENSITY", paritysim_aero::DEFAULT_AIR_DENSITY)?;
    m.add(
        "AERO_DEFAULT_ROTATIONAL_DAMPING",
        paritysim_aero::DEFAULT_ROTATIONAL_DAMPING,
    )?;
    Ok(())
}
