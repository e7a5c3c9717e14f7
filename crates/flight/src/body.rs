//! The airframe: how the body may move, its mass properties and where the wings attach.
//!
//! Frames. The body frame is the device's shoulder ground frame 1 of the right wing (§3.2.3):
//! `x̂` the stroke axis, `ŷ` the wing normal at rest, `ẑ` spanwise toward the right wing. The
//! axes are named as in Fig. 2.10 (and [`paritysim_aero::AeroLoads`]): **roll** about `x̂`,
//! **yaw** about `ŷ`, **pitch** about `ẑ`. The left wing's frame 1 is the mirror image of the
//! right's through the sagittal plane (`z → −z`, as in `paritysim_dynamics::trajectory`). The
//! world frame coincides with the body frame at zero attitude; lift points along `+x̂` in
//! hover, so gravity defaults to `−x̂`.

use nalgebra::{Matrix3, Vector3};
use paritysim_error::{Error, Result, check_all_finite, check_non_negative, check_positive};

/// Standard gravity in mm/ms² (9.81 m/s²).
pub const GRAVITY: f64 = 9.81e-3;

/// How the body may move.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BodyMode {
    /// Held by the torque stand: the engine's fixed-body device, results unchanged.
    #[default]
    Fixed,
    /// Held, but run through the coupled flight model (reports the wrench the stand holds).
    Clamped,
    /// A gimbal about the centre of mass: rotation about the roll axis `x̂` only.
    Roll,
    /// Rotation about the yaw axis `ŷ` only.
    Yaw,
    /// Rotation about the pitch axis `ẑ` only.
    Pitch,
    /// A ball joint at the centre of mass: roll, pitch and yaw (no translation).
    RollPitchYaw,
    /// Six degrees of freedom under gravity.
    Free,
}

impl BodyMode {
    /// Which of `(V_x, V_y, V_z, Ω_x, Ω_y, Ω_z)` move.
    pub fn active(self) -> [bool; 6] {
        match self {
            BodyMode::Fixed | BodyMode::Clamped => [false; 6],
            BodyMode::Roll => [false, false, false, true, false, false],
            BodyMode::Yaw => [false, false, false, false, true, false],
            BodyMode::Pitch => [false, false, false, false, false, true],
            BodyMode::RollPitchYaw => [false, false, false, true, true, true],
            BodyMode::Free => [true; 6],
        }
    }

    /// By name (`fixed`, `clamped`, `roll`, `yaw`, `pitch`, `roll_pitch_yaw`, `free`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`body.mode`) for another name.
    pub fn from_name(name: &str) -> Result<Self> {
        Ok(match name {
            "fixed" => BodyMode::Fixed,
            "clamped" => BodyMode::Clamped,
            "roll" => BodyMode::Roll,
            "yaw" => BodyMode::Yaw,
            "pitch" => BodyMode::Pitch,
            "roll_pitch_yaw" => BodyMode::RollPitchYaw,
            "free" => BodyMode::Free,
            other => {
                return Err(Error::invalid(
                    "body.mode",
                    format!("{other:?}"),
                    "one of fixed, clamped, roll, yaw, pitch, roll_pitch_yaw, free",
                ));
            }
        })
    }
}

/// The airframe (all lengths in the body frame, mm).
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// How the body may move.
    pub mode: BodyMode,
    /// Body mass without the wings (mg).
    pub mass: f64,
    /// Inertia tensor about the body's centre of mass (mg·mm², body frame).
    pub inertia: Matrix3<f64>,
    /// Centre of mass of the body (mm); gimbals pivot about it.
    pub center_of_mass: Vector3<f64>,
    /// Spherical centre of each wing's shoulder (left first) (mm).
    pub shoulders: [Vector3<f64>; 2],
    /// Gravity in the world frame (mm/ms²).
    pub gravity: Vector3<f64>,
    /// Radius at which the shoulder's translation enters the blade-element velocity, and the
    /// force parameter `Ω1 / r` when a wing's model has none (mm).
    pub force_radius: f64,
    /// Wing masses (mg; their inertia about the shoulder is the wing's own tensor).
    pub wing_mass: [f64; 2],
    /// Wing centres of mass in the wing frame 6 (mm).
    pub wing_center_of_mass: [Vector3<f64>; 2],
}

impl Body {
    /// Checks ranges: mass > 0, inertia symmetric positive definite, finite vectors,
    /// `force_radius > 0`, wing masses >= 0.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the `body.` field.
    pub fn validate(&self) -> Result<()> {
        let at = |e: Error| e.in_field("body");
        check_positive("mass_mg", self.mass).map_err(at)?;
        check_all_finite("inertia", self.inertia.as_slice()).map_err(at)?;
        if (self.inertia - self.inertia.transpose()).amax() > 1e-12 * self.inertia.amax()
            || self.inertia.cholesky().is_none()
        {
            return Err(Error::invalid(
                "body.inertia",
                format!("{:?}", self.inertia.symmetric_eigenvalues().as_slice()),
                "a symmetric positive definite tensor (mg mm^2)",
            ));
        }
        check_all_finite("center_of_mass_mm", self.center_of_mass.as_slice()).map_err(at)?;
        for s in &self.shoulders {
            check_all_finite("shoulders_mm", s.as_slice()).map_err(at)?;
        }
        check_all_finite("gravity_mm_per_ms2", self.gravity.as_slice()).map_err(at)?;
        check_positive("force_radius_mm", self.force_radius).map_err(at)?;
        for (m, c) in self.wing_mass.iter().zip(&self.wing_center_of_mass) {
            check_non_negative("wing_mass_mg", *m).map_err(at)?;
            check_all_finite("wing_center_of_mass_mm", c.as_slice()).map_err(at)?;
        }
        Ok(())
    }

    /// The body scaled by `factor` in mass and inertia (the heavy-body limit).
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            mass: self.mass * factor,
            inertia: self.inertia * factor,
            ..self.clone()
        }
    }
}
