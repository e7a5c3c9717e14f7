//! Binding for Appendix A's per-wing dynamics terms (`Wing::terms`): `M`, `c`, `∇V`, `J6`.

use nalgebra::{Matrix3, Vector3};
use numpy::PyArray1;
use paritysim_error::Error;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::shaped;
use crate::errors::IntoPyResult;

fn row_major(m: &Matrix3<f64>) -> Vec<f64> {
    (0..3)
        .flat_map(|i| (0..3).map(move |j| m[(i, j)]))
        .collect()
}

fn vector<'py>(py: Python<'py>, v: &Vector3<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, v.as_slice().to_vec())
}

/// `Wing::terms` of wing `wing` of a JSON spec at `p = (φ, θ, ψ)`, `ṗ`: a dict of
/// `mass` (M, A.36, 3×3, mg·mm²), `coriolis` (c, mN·mm), `spring_gradient` (∇V of the joint
/// springs and tunable hinge, A.6, mN·mm), `aero` (J6ᵀτ⁶, mN·mm), `j6` (A.9, 3×3), `omega`
/// (J6 ṗ, rad/ms), `jdot_pdot` (J̇6 ṗ, rad/ms²), `rotation` (R_6^1), `theta_w`, `kinetic`
/// and `potential` (µJ). Always the general terms (never the stroke-plane closed form).
///
/// # Errors
/// `InvalidParameterError` for a bad device or wing index; `OutOfDomainError` outside the
/// shoulder's joint limit; `SingularError` at a singular shoulder pose.
#[pyfunction]
fn dynamics_wing_terms<'py>(
    py: Python<'py>,
    spec: &str,
    wing: usize,
    p: [f64; 3],
    p_dot: [f64; 3],
) -> PyResult<Bound<'py, PyDict>> {
    let device = crate::spec::device(spec).py_err()?;
    let n = device.n_wings();
    let w = device
        .spec()
        .wings
        .get(wing)
        .ok_or_else(|| Error::invalid("wing", wing, format!("in [0, {n})")))
        .py_err()?;
    for (name, v) in [("p", &p), ("p_dot", &p_dot)] {
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(Error::invalid(
                format!("{name}[{i}]"),
                v[i],
                "a finite number",
            ))
            .py_err();
        }
    }
    let t = w.terms(&Vector3::from(p), &Vector3::from(p_dot)).py_err()?;
    let out = PyDict::new(py);
    out.set_item("mass", shaped(py, row_major(&t.mass), &[3, 3])?)?;
    out.set_item("coriolis", vector(py, &t.coriolis))?;
    out.set_item("spring_gradient", vector(py, &t.spring))?;
    out.set_item("aero", vector(py, &t.aero))?;
    out.set_item("j6", shaped(py, row_major(&t.j6), &[3, 3])?)?;
    out.set_item("omega", vector(py, &t.omega))?;
    out.set_item("jdot_pdot", vector(py, &t.jdot_pdot))?;
    out.set_item("rotation", shaped(py, row_major(&t.rotation), &[3, 3])?)?;
    out.set_item("theta_w", t.theta_w)?;
    out.set_item("kinetic", t.kinetic)?;
    out.set_item("potential", t.potential)?;
    Ok(out)
}

/// Registers `dynamics_wing_terms`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(dynamics_wing_terms, m)?)
}
