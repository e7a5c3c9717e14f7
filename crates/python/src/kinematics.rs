//! Bindings of paritysim-kinematics.

use numpy::{PyArray1, PyReadonlyArray1};
use paritysim_error::Error;
use paritysim_kinematics::{Drivetrain, SphericalShoulder};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{same_len, shaped, to_vec};
use crate::errors::IntoPyResult;

/// Vectorised closed-form shoulder map over paired `phi`, `theta` arrays (rad).
///
/// Returns a dict of arrays `gamma2, gamma3, gamma5, theta_w` and boolean `reachable`.
/// Where `reachable` is False (outside the joint limit of eq. 2.10, or a singular pose) the
/// angle arrays hold NaN: that is the documented mask, not a silent failure.
#[pyfunction]
fn shoulder_map<'py>(
    py: Python<'py>,
    alpha2: f64,
    alpha3: f64,
    phi: PyReadonlyArray1<'py, f64>,
    theta: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let sh = SphericalShoulder::new(alpha2, alpha3).py_err()?;
    let (phi, theta) = (to_vec(&phi), to_vec(&theta));
    same_len(("phi", phi.len()), ("theta", theta.len())).py_err()?;
    paritysim_error::check_all_finite("phi", &phi).py_err()?;
    paritysim_error::check_all_finite("theta", &theta).py_err()?;
    let (g2, g3, g5, ok) = py.detach(|| {
        let n = phi.len();
        let (mut g2, mut g3, mut g5, mut ok) = (
            vec![f64::NAN; n],
            vec![f64::NAN; n],
            vec![f64::NAN; n],
            vec![false; n],
        );
        for i in 0..n {
            if let Ok((a, b, c)) = sh.dependent_angles(phi[i], theta[i]) {
                (g2[i], g3[i], g5[i], ok[i]) = (a, b, c, true);
            }
        }
        (g2, g3, g5, ok)
    });
    let out = PyDict::new(py);
    out.set_item("gamma2", PyArray1::from_vec(py, g2))?;
    out.set_item("gamma3", PyArray1::from_vec(py, g3))?;
    out.set_item("theta_w", PyArray1::from_slice(py, &g5))?;
    out.set_item("gamma5", PyArray1::from_vec(py, g5))?;
    out.set_item("reachable", PyArray1::from_vec(py, ok))?;
    Ok(out)
}

/// One shoulder pose: `joint_angles (6,)`, `link_rotations (6, 3, 3)` (R_i^1), `wing_angles (3,)`.
#[pyfunction]
fn shoulder_pose<'py>(
    py: Python<'py>,
    alpha2: f64,
    alpha3: f64,
    phi: f64,
    theta: f64,
    psi: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let sh = SphericalShoulder::new(alpha2, alpha3).py_err()?;
    let pose = sh.pose(phi, theta, psi).py_err()?;
    let out = PyDict::new(py);
    out.set_item("joint_angles", PyArray1::from_slice(py, &pose.joint_angles))?;
    let mut rot = Vec::with_capacity(54);
    for r in &pose.link_rotations {
        for i in 0..3 {
            for j in 0..3 {
                rot.push(r[(i, j)]);
            }
        }
    }
    out.set_item("link_rotations", shaped(py, rot, &[6, 3, 3])?)?;
    out.set_item(
        "wing_angles",
        PyArray1::from_slice(py, pose.wing_angles.as_slice()),
    )?;
    Ok(out)
}

/// Partials of γ2, γ3, γ5 w.r.t. (φ, θ) and the Jacobian J6 (A.9) at `(phi, theta, psi)`.
#[pyfunction]
#[pyo3(signature = (alpha2, alpha3, phi, theta, psi=0.0))]
fn shoulder_partials<'py>(
    py: Python<'py>,
    alpha2: f64,
    alpha3: f64,
    phi: f64,
    theta: f64,
    psi: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let sh = SphericalShoulder::new(alpha2, alpha3).py_err()?;
    let pose = sh.pose(phi, theta, psi).py_err()?;
    let p = sh.partials(phi, theta).py_err()?;
    let j6 = sh.jacobian(&pose, &p);
    let out = PyDict::new(py);
    let m2 = |m: &nalgebra::Matrix2<f64>| vec![m[(0, 0)], m[(0, 1)], m[(1, 0)], m[(1, 1)]];
    for (name, g, h) in [
        ("gamma2", p.gamma2, p.gamma2_hessian),
        ("gamma3", p.gamma3, p.gamma3_hessian),
        ("gamma5", p.gamma5, p.gamma5_hessian),
    ] {
        out.set_item(
            format!("{name}_grad"),
            PyArray1::from_slice(py, g.as_slice()),
        )?;
        out.set_item(format!("{name}_hessian"), shaped(py, m2(&h), &[2, 2])?)?;
    }
    let j: Vec<f64> = (0..9).map(|k| j6[(k / 3, k % 3)]).collect();
    out.set_item("j6", shaped(py, j, &[3, 3])?)?;
    Ok(out)
}

/// A planar drivetrain mapping `(q1, q2)` (mm, rad) to stroke angles `(φL, φR)` (rad), built
/// from a `[drivetrain]` spec (any registered kind).
#[pyclass(name = "Drivetrain", module = "paritysim._core", frozen)]
#[derive(Clone)]
pub struct PyDrivetrain {
    pub inner: Drivetrain,
    spec: paritysim_spec::Drivetrain,
}

#[pymethods]
impl PyDrivetrain {
    /// From a drivetrain spec as JSON text (`{"kind": ..., <fields>}`), validated like a
    /// `[drivetrain]` table.
    #[staticmethod]
    fn from_spec(json: &str) -> PyResult<Self> {
        let spec = paritysim_spec::drivetrain_from_json(json).py_err()?;
        Ok(Self {
            inner: spec.kinematics().py_err()?,
            spec,
        })
    }

    /// The spec as JSON text.
    fn to_spec(&self) -> String {
        serde_json::to_string(&self.spec).expect("a spec serialises")
    }

    /// Kind name.
    #[getter]
    fn name(&self) -> &'static str {
        self.inner.name()
    }

    /// Degrees of freedom (1 or 2).
    #[getter]
    fn dof(&self) -> usize {
        self.inner.dof()
    }

    /// Evaluates over paired arrays `q1` (mm), `q2` (rad). Returns `stroke_left`,
    /// `stroke_right` (n,), `jacobian` (n, 2, 2) and `hessian` (n, 2, 2, 2) with
    /// `hessian[n, k, i, j] = ∂²φ_k/∂q_i∂q_j`. Raises `OutOfDomainError` naming the first
    /// unreachable index.
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        q1: PyReadonlyArray1<'py, f64>,
        q2: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (q1, q2) = (to_vec(&q1), to_vec(&q2));
        same_len(("q1", q1.len()), ("q2", q2.len())).py_err()?;
        let d = self.inner;
        let (left, right, jac, hess) = py
            .detach(|| -> Result<_, Error> {
                let n = q1.len();
                let (mut l, mut r, mut j, mut h) = (
                    Vec::with_capacity(n),
                    Vec::with_capacity(n),
                    Vec::with_capacity(4 * n),
                    Vec::with_capacity(8 * n),
                );
                for i in 0..n {
                    let e = d.evaluate(q1[i], q2[i]).map_err(|e| e.at_index(i, None))?;
                    l.push(e.stroke[0]);
                    r.push(e.stroke[1]);
                    for a in 0..2 {
                        for b in 0..2 {
                            j.push(e.jacobian[(a, b)]);
                        }
                    }
                    for k in 0..2 {
                        for a in 0..2 {
                            for b in 0..2 {
                                h.push(e.hessian[k][(a, b)]);
                            }
                        }
                    }
                }
                Ok((l, r, j, h))
            })
            .py_err()?;
        let n = left.len();
        let out = PyDict::new(py);
        out.set_item("stroke_left", PyArray1::from_vec(py, left))?;
        out.set_item("stroke_right", PyArray1::from_vec(py, right))?;
        out.set_item("jacobian", shaped(py, jac, &[n, 2, 2])?)?;
        out.set_item("hessian", shaped(py, hess, &[n, 2, 2, 2])?)?;
        Ok(out)
    }

    fn __repr__(&self) -> String {
        format!("Drivetrain.from_spec({:?})", self.to_spec())
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.spec == other.spec
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let from_spec = slf.get_type().getattr("from_spec")?;
        Ok((from_spec, (slf.get().to_spec(),)))
    }
}

/// Adds the kinematics functions and classes.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(shoulder_map, m)?)?;
    m.add_function(wrap_pyfunction!(shoulder_pose, m)?)?;
    m.add_function(wrap_pyfunction!(shoulder_partials, m)?)?;
    m.add_class::<PyDrivetrain>()?;
    Ok(())
}
