//! Bindings of paritysim-aero (functions prefixed `aero_`).
//!
//! Planforms cross the boundary as `(n, 2)` float arrays of `[z, x]` vertices (mm); every call
//! re-validates them (cheap next to Python overhead for the usual < 1000 vertices).

use nalgebra::Vector3;
use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use paritysim_aero::{
    BladeElementModel, CoefficientModel, CoefficientSet, CutEdge, LineMass, MassDistribution,
    NormalForceLaw, Omegas, Planform, PointMass, WingState, center_of_pressure,
};
use paritysim_error::Error;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{same_len, shaped, to_vec};
use crate::errors::IntoPyResult;

/// Rows of an `(n, cols)` array, naming it in the shape error.
fn rows<const N: usize>(name: &str, a: &PyReadonlyArray2<'_, f64>) -> Result<Vec<[f64; N]>, Error> {
    let v = a.as_array();
    if v.ncols() != N {
        return Err(Error::Shape(format!(
            "`{name}` must have shape (n, {N}), got {:?}",
            v.shape()
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
) -> Result<Planform, Error> {
    let pts = rows::<2>("points", points)?;
    match closure_tolerance {
        Some(tol) => Planform::from_traced_outline(&pts, tol),
        None => Planform::from_points(&pts),
    }
}

fn vertices<'py>(py: Python<'py>, p: &Planform) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = p.vertices().iter().flat_map(|v| [v[0], v[1]]).collect();
    let n = p.vertices().len();
    shaped(py, flat, &[n, 2])
}

/// Validates an outline and returns its geometry and Ω1..Ω4 for air of `density` mg/mm³.
///
/// `points` is `(n, 2)` `[z, x]` in mm (closing edge implicit). With `closure_tolerance`
/// (mm) the outline is a traced curve whose last point must return to the first.
/// Returns `vertices (m, 2)` (validated, counter-clockwise), `area`, `span`, `tip_radius`,
/// `root_offset`, `mean_chord`, `centroid (2,)`, `x_range (2,)`, `omega1..omega4`, `force`
/// and the density-free `integrals` dict.
#[pyfunction]
#[pyo3(signature = (points, density, closure_tolerance=None))]
fn aero_planform_properties<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    density: f64,
    closure_tolerance: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let p = planform(&points, closure_tolerance).py_err()?;
    let o = p.omegas(density).py_err()?;
    let out = PyDict::new(py);
    out.set_item("vertices", vertices(py, &p)?)?;
    out.set_item("area", p.area())?;
    out.set_item("span", p.span())?;
    out.set_item("tip_radius", p.tip_radius())?;
    out.set_item("root_offset", p.root_offset())?;
    out.set_item("mean_chord", p.mean_chord())?;
    out.set_item("centroid", PyArray1::from_slice(py, &p.centroid()))?;
    let (x0, x1) = p.x_range();
    out.set_item("x_range", PyArray1::from_slice(py, &[x0, x1]))?;
    out.set_item("omega1", o.omega1)?;
    out.set_item("omega2", o.omega2)?;
    out.set_item("omega3", o.omega3)?;
    out.set_item("omega4", o.omega4)?;
    out.set_item("force", o.force.unwrap_or(0.0))?;
    let s = p.integrals();
    let ints = PyDict::new(py);
    for (k, v) in [
        ("area", s.area),
        ("z1", s.z1),
        ("x1", s.x1),
        ("z2", s.z2),
        ("x2", s.x2),
        ("xz", s.xz),
        ("z3", s.z3),
        ("x3_abs", s.x3_abs),
        ("z2_c2", s.z2_c2),
        ("z2_lc", s.z2_lc),
    ] {
        ints.set_item(k, v)?;
    }
    out.set_item("integrals", ints)?;
    Ok(out)
}

/// Vertices `(n, 2)` of a rectangle `z ∈ [root_offset, root_offset + span]`,
/// `x ∈ [le_offset − chord, le_offset]`.
#[pyfunction]
fn aero_planform_rectangle<'py>(
    py: Python<'py>,
    span: f64,
    chord: f64,
    root_offset: f64,
    le_offset: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let p = Planform::rectangle(span, chord, root_offset, le_offset).py_err()?;
    vertices(py, &p)
}

/// Vertices `(n, 2)` of a semi-elliptic planform (straight leading edge) with `segments` steps.
#[pyfunction]
fn aero_planform_semi_ellipse<'py>(
    py: Python<'py>,
    span: f64,
    max_chord: f64,
    root_offset: f64,
    le_offset: f64,
    segments: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let p = Planform::semi_ellipse(span, max_chord, root_offset, le_offset, segments).py_err()?;
    vertices(py, &p)
}

/// Vertices `(n, 2)` of the HMF-like wing scaled to `tip_radius` mm.
#[pyfunction]
fn aero_planform_hmf_like<'py>(
    py: Python<'py>,
    tip_radius: f64,
    segments: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let p = Planform::hmf_like(tip_radius, segments).py_err()?;
    vertices(py, &p)
}

/// Vertices `(m, 2)` of the membrane left after cutting `fraction` of its span at the tip
/// (`where = "tip"`) or of its chordwise extent at the trailing edge (`"trailing"`).
#[pyfunction]
fn aero_planform_cut<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    fraction: f64,
    edge: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let edge = CutEdge::from_name(edge).py_err()?;
    let p = planform(&points, None)
        .and_then(|p| p.cut(fraction, edge))
        .py_err()?;
    vertices(py, &p)
}

/// Chord `c(z)` and leading edge `l(z)` (mm) at the stations `z`. Outside the span the chord
/// is 0 and the leading edge NaN (documented mask).
#[pyfunction]
fn aero_planform_chord<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    z: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let p = planform(&points, None).py_err()?;
    let z = to_vec(&z);
    paritysim_error::check_all_finite("z", &z).py_err()?;
    let (c, l): (Vec<f64>, Vec<f64>) = py.detach(|| {
        z.iter()
            .map(|&z| (p.chord(z), p.leading_edge(z).unwrap_or(f64::NAN)))
            .unzip()
    });
    let out = PyDict::new(py);
    out.set_item("chord", PyArray1::from_vec(py, c))?;
    out.set_item("leading_edge", PyArray1::from_vec(py, l))?;
    Ok(out)
}

/// Mass properties about the spherical centre: membrane `areal_density` (mg/mm²), line masses
/// as rows `[z0, x0, z1, x1, linear_density]` (mg/mm) and point masses as rows `[z, x, mass]`.
/// Returns `mass`, `center_of_mass (2,)`, `ixx`, `iyy`, `izz`, `ixz` (= −∫xz dm) and
/// `tensor (3, 3)`.
#[pyfunction]
fn aero_planform_inertia<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    areal_density: f64,
    line_masses: PyReadonlyArray2<'py, f64>,
    point_masses: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let p = planform(&points, None).py_err()?;
    let lines = rows::<5>("line_masses", &line_masses).py_err()?;
    let pts = rows::<3>("point_masses", &point_masses).py_err()?;
    let dist = MassDistribution {
        areal_density,
        line_masses: lines
            .iter()
            .map(|r| LineMass {
                start: [r[0], r[1]],
                end: [r[2], r[3]],
                linear_density: r[4],
            })
            .collect(),
        point_masses: pts
            .iter()
            .map(|r| PointMass {
                position: [r[0], r[1]],
                mass: r[2],
            })
            .collect(),
    };
    let i = p.inertia(&dist).py_err()?;
    let out = PyDict::new(py);
    out.set_item("mass", i.mass)?;
    out.set_item(
        "center_of_mass",
        PyArray1::from_slice(py, &i.center_of_mass),
    )?;
    out.set_item("ixx", i.ixx)?;
    out.set_item("iyy", i.iyy)?;
    out.set_item("izz", i.izz)?;
    out.set_item("ixz", i.ixz)?;
    let t = i.tensor();
    let flat: Vec<f64> = (0..9).map(|k| t[(k / 3, k % 3)]).collect();
    out.set_item("tensor", shaped(py, flat, &[3, 3])?)?;
    Ok(out)
}

/// Coefficients of `model` (`"dickinson1999"` or `"whitney_wood2010"`) at angles of attack
/// `alpha` (rad, each in [0, π]): `lift`, `drag`, `normal`, `tangential`, `center_of_pressure`.
#[pyfunction]
fn aero_coefficients<'py>(
    py: Python<'py>,
    alpha: PyReadonlyArray1<'py, f64>,
    model: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let set = CoefficientSet::from_name(model).py_err()?;
    let alpha = to_vec(&alpha);
    if let Some(i) = alpha
        .iter()
        .position(|a| !(a.is_finite() && (0.0..=std::f64::consts::PI).contains(a)))
    {
        return Err(Error::invalid(
            format!("alpha[{i}]"),
            alpha[i],
            "in [0, pi] rad (angle between chord and velocity)",
        ))
        .py_err();
    }
    let cols = py.detach(|| {
        let n = alpha.len();
        let mut c: [Vec<f64>; 5] = std::array::from_fn(|_| Vec::with_capacity(n));
        for &a in &alpha {
            let k = set.coefficients(a);
            c[0].push(k.lift);
            c[1].push(k.drag);
            c[2].push(k.normal);
            c[3].push(k.tangential);
            c[4].push(center_of_pressure(a));
        }
        c
    });
    let out = PyDict::new(py);
    let names = ["lift", "drag", "normal", "tangential", "center_of_pressure"];
    for (name, col) in names.into_iter().zip(cols) {
        out.set_item(name, PyArray1::from_vec(py, col))?;
    }
    Ok(out)
}

/// Blade-element moments (eqs. 3.8–3.11) over paired state arrays.
///
/// `omegas` is `[Ω1, Ω2, Ω3, Ω4]` (mg·mm²); `force` (mg·mm, `½ρ∬z²dA`) enables the lift/drag
/// outputs. `normal_force_law` is `"coefficient"` (eq. 3.8) or `"unit"` (eq. 2.16, docs/errata.md#12).
/// Returns `normal`, `tangential`, `rotational`, `rotational_damping`, `alpha`, `phi_dot_rw`,
/// `psi_rw`, `psi_dot_rw` (n,), `torque_wing (n, 3)`, and with `force`: `lift`, `drag`,
/// `lift_torque`, `drag_torque`, `torque_body` (n, 3) in body axes `[roll, yaw, pitch]`.
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
) -> PyResult<Bound<'py, PyDict>> {
    let set = CoefficientSet::from_name(model).py_err()?;
    let law = match normal_force_law {
        "coefficient" => NormalForceLaw::Coefficient,
        "unit" => NormalForceLaw::Unit,
        other => {
            return Err(Error::invalid(
                "normal_force_law",
                format!("{other:?}"),
                "one of \"coefficient\", \"unit\"",
            ))
            .py_err();
        }
    };
    let mut o = Omegas::new(omegas[0], omegas[1], omegas[2], omegas[3]).py_err()?;
    if let Some(f) = force {
        o = o.with_force(f).py_err()?;
    }
    let m = BladeElementModel::new(o, set)
        .and_then(|m| m.with_rotational_damping(rotational_damping))
        .py_err()?
        .with_normal_force_law(law);
    let names = ["phi", "theta", "psi", "phi_dot", "theta_dot", "psi_dot"];
    let cols = [
        to_vec(&phi),
        to_vec(&theta),
        to_vec(&psi),
        to_vec(&phi_dot),
        to_vec(&theta_dot),
        to_vec(&psi_dot),
    ];
    for (name, col) in names.iter().zip(&cols).skip(1) {
        same_len(("phi", cols[0].len()), (name, col.len())).py_err()?;
    }
    for (name, col) in names.iter().zip(&cols) {
        paritysim_error::check_all_finite(name, col).py_err()?;
    }
    let n = cols[0].len();
    let with_loads = force.is_some();
    let (scalars, vectors) = py
        .detach(|| -> Result<_, Error> {
            let col = |k: usize, i: usize| cols[k][i];
            let mut s: [Vec<f64>; 8] = std::array::from_fn(|_| Vec::with_capacity(n));
            let mut v: [Vec<f64>; 6] = std::array::from_fn(|_| Vec::with_capacity(3 * n));
            let push3 = |dst: &mut Vec<f64>, x: Vector3<f64>| dst.extend_from_slice(x.as_slice());
            for i in 0..n {
                let st = WingState {
                    phi: col(0, i),
                    theta: col(1, i),
                    psi: col(2, i),
                    phi_dot: col(3, i),
                    theta_dot: col(4, i),
                    psi_dot: col(5, i),
                };
                let mo = m.moments(&st);
                let w = st.wind_relative();
                for (dst, x) in s.iter_mut().zip([
                    mo.normal,
                    mo.tangential,
                    mo.rotational,
                    mo.rotational_damping,
                    mo.alpha,
                    w.phi_dot_rw,
                    w.psi_rw,
                    w.psi_dot_rw,
                ]) {
                    dst.push(x);
                }
                push3(&mut v[0], mo.torque());
                if with_loads {
                    let l = m.loads(&st)?;
                    push3(&mut v[1], l.lift);
                    push3(&mut v[2], l.drag);
                    push3(&mut v[3], l.lift_torque);
                    push3(&mut v[4], l.drag_torque);
                    push3(&mut v[5], l.torque());
                }
            }
            Ok((s, v))
        })
        .py_err()?;
    let out = PyDict::new(py);
    let snames = [
        "normal",
        "tangential",
        "rotational",
        "rotational_damping",
        "alpha",
        "phi_dot_rw",
        "psi_rw",
        "psi_dot_rw",
    ];
    for (name, col) in snames.into_iter().zip(scalars) {
        out.set_item(name, PyArray1::from_vec(py, col))?;
    }
    let vnames = [
        "torque_wing",
        "lift",
        "drag",
        "lift_torque",
        "drag_torque",
        "torque_body",
    ];
    for (k, (name, col)) in vnames.into_iter().zip(vectors).enumerate() {
        if k == 0 || with_loads {
            out.set_item(name, shaped(py, col, &[n, 3])?)?;
        }
    }
    Ok(out)
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
