//! Mechanisms referenced to the body state (§2.1.3, §5.1 "ground-referenced mechanisms"):
//! elements whose generalized force on a drivetrain coordinate depends on the body's attitude
//! or angular rate. They act between the body and the drivetrain (internal forces: the body
//! takes the reaction through the coupled equations, momentum is unaffected), except the
//! pendulum's weight, which is neglected (its moment `m l` is the parameter).

use nalgebra::{Matrix3, Vector3};
use paritysim_error::{Result, check_all_finite, check_finite};

/// Which drivetrain coordinate a mechanism pushes on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DriveCoordinate {
    /// The actuator coordinate `q1` (force, mN).
    Q1,
    /// The whippletree angle `q2` of a 2-DOF drivetrain (torque, mN·mm): the Drag PARITY
    /// pivot.
    Q2,
}

/// A body-referenced mechanism.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mechanism {
    /// A pendulum of moment `m l` (mg·mm) hanging from the drivetrain coordinate: its gravity
    /// torque `τ = m l (d̂ × R_bᵀ g) · â` biases the coordinate while the body is tilted
    /// (`d̂` the pendulum's rest direction, `â` the coordinate's rotation axis, both body frame;
    /// the pendulum turns with `q2`: `d̂(q2) = Rot(â, q2) d̂`).
    GravityPendulum {
        /// Coordinate it acts on.
        coordinate: DriveCoordinate,
        /// Mass times arm length (mg·mm).
        moment: f64,
        /// Rest direction `d̂` (body frame, normalised).
        direction: Vector3<f64>,
        /// Rotation axis `â` (body frame, normalised).
        axis: Vector3<f64>,
    },
    /// A haltere-like rate element: `τ = −gain (Ω · â)`, a gyroscopic sensor coupled to the
    /// coordinate (`gain` in mN·mm per rad/ms, or mN per rad/ms on `q1`).
    RateElement {
        /// Coordinate it acts on.
        coordinate: DriveCoordinate,
        /// Gain.
        gain: f64,
        /// Sensing axis `â` (body frame, normalised).
        axis: Vector3<f64>,
    },
}

fn unit(field: &'static str, v: Vector3<f64>) -> Result<Vector3<f64>> {
    check_all_finite(field, v.as_slice())?;
    let n = v.norm();
    if n == 0.0 {
        return Err(paritysim_error::Error::invalid(
            field,
            format!("{:?}", v.as_slice()),
            "a non-zero vector",
        ));
    }
    Ok(v / n)
}

impl Mechanism {
    /// A validated pendulum.
    ///
    /// # Errors
    /// [`paritysim_error::Error::InvalidParameter`] for a non-finite moment or a zero vector.
    pub fn pendulum(
        coordinate: DriveCoordinate,
        moment: f64,
        direction: Vector3<f64>,
        axis: Vector3<f64>,
    ) -> Result<Self> {
        Ok(Mechanism::GravityPendulum {
            coordinate,
            moment: check_finite("moment_mg_mm", moment)?,
            direction: unit("direction", direction)?,
            axis: unit("axis", axis)?,
        })
    }

    /// A validated rate element.
    ///
    /// # Errors
    /// [`paritysim_error::Error::InvalidParameter`] for a non-finite gain or a zero axis.
    pub fn rate(coordinate: DriveCoordinate, gain: f64, axis: Vector3<f64>) -> Result<Self> {
        Ok(Mechanism::RateElement {
            coordinate,
            gain: check_finite("gain", gain)?,
            axis: unit("axis", axis)?,
        })
    }

    /// Coordinate it acts on.
    pub fn coordinate(&self) -> DriveCoordinate {
        match self {
            Mechanism::GravityPendulum { coordinate, .. }
            | Mechanism::RateElement { coordinate, .. } => *coordinate,
        }
    }

    /// The generalized force at body attitude `r_b` (body to world), body rate `omega` (body
    /// frame), gravity `g` (world) and coordinate value `q`.
    #[inline]
    pub fn force(&self, r_b: &Matrix3<f64>, omega: &Vector3<f64>, g: &Vector3<f64>, q: f64) -> f64 {
        match self {
            Mechanism::GravityPendulum {
                moment,
                direction,
                axis,
                coordinate,
            } => {
                let d = if *coordinate == DriveCoordinate::Q2 {
                    nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_unchecked(*axis), q)
                        * direction
                } else {
                    *direction
                };
                moment * d.cross(&(r_b.transpose() * g)).dot(axis)
            }
            Mechanism::RateElement { gain, axis, .. } => -gain * omega.dot(axis),
        }
    }
}
