//! Bindings of paritysim-kinematics; results are `paritysim_kinematics::records` through
//! [`to_py`].

use numpy::PyReadonlyArray1;
use paritysim_kinematics::records::{DrivetrainMap, PartialsRecord, PoseRecord, ShoulderMap};
use paritysim_kinematics::{Drivetrain, SphericalShoulder};
use pyo3::prelude::*;

use crate::convert::{Floats, bindings, to_py, to_vec};
use crate::errors::IntoPyResult;

bindings! {
    class PyDrivetrain;

    /// Vectorised closed-form shoulder map over paired `phi`, `theta` arrays (rad). Where
    /// `reachable` is False (outside the joint limit of eq. 2.10, or a singular pose) the angle
    /// arrays hold NaN: the documented mask, not a silent failure.
    fn shoulder_map(alpha2: f64, alpha3: f64, phi: Floats, theta: Floats) {
        ShoulderMap::checked(&SphericalShoulder::new(alpha2, alpha3)?, &phi, &theta)
    }

    /// One shoulder pose: `joint_angles (6,)`, `link_rotations (6, 3, 3)`, `wing_angles (3,)`.
    fn shoulder_pose(alpha2: f64, alpha3: f64, phi: f64, theta: f64, psi: f64) {
        PoseRecord::of(&SphericalShoulder::new(alpha2, alpha3)?, phi, theta, psi)
    }

    /// Partials of γ2, γ3, γ5 w.r.t. (φ, θ) and the Jacobian J6 (A.9) at `(phi, theta, psi)`.
    fn shoulder_partials(alpha2: f64, alpha3: f64, phi: f64, theta: f64, psi: f64) {
        PartialsRecord::of(&SphericalShoulder::new(alpha2, alpha3)?, phi, theta, psi)
    }
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
            inner: spec
                .kinematics()
                .map_err(|e| e.in_field("drivetrain"))
                .py_err()?,
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

    /// Evaluates over paired arrays `q1` (mm), `q2` (rad): `records::DrivetrainMap`.
    /// Raises `OutOfDomainError` naming the first unreachable index.
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        q1: PyReadonlyArray1<'py, f64>,
        q2: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q1, q2, d) = (to_vec(&q1), to_vec(&q2), self.inner);
        to_py(py, &py.detach(|| DrivetrainMap::of(&d, &q1, &q2)).py_err()?)
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
