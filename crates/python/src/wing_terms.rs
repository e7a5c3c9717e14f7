//! Binding for Appendix A's per-wing dynamics terms (`Wing::terms`): `M`, `c`, `∇V`, `J6`.

use nalgebra::Vector3;
use paritysim_dynamics::wing::WingTermsRecord;
use paritysim_error::{Error, check_all_finite};
use pyo3::prelude::*;

use crate::convert::to_py;
use crate::errors::IntoPyResult;

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
) -> PyResult<Bound<'py, PyAny>> {
    let device = crate::spec::device(spec).py_err()?;
    let n = device.n_wings();
    let w = device
        .spec()
        .wings
        .get(wing)
        .ok_or_else(|| Error::invalid("wing", wing, format!("in [0, {n})")))
        .py_err()?;
    check_all_finite("p", &p)
        .and_then(|()| check_all_finite("p_dot", &p_dot))
        .py_err()?;
    let t = w.terms(&Vector3::from(p), &Vector3::from(p_dot)).py_err()?;
    to_py(py, &WingTermsRecord::from(&t))
}

/// Registers `dynamics_wing_terms`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(dynamics_wing_terms, m)?)
}
