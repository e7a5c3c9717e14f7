//! The lean stroke-plane sample's fields (its own file, as `needs.rs`: the stroke-plane model
//! in `device/` fills it and the accumulator reads it, and neither imports the other for it;
//! it is built in `crate::trajectory`).

use nalgebra::Vector3;

use super::needs::StrokeNeeds;

/// What the metrics read at a sample of a stroke-plane device (§3.4: two wings with θ ≡ 0,
/// φ and ψ free, the linear map), computed as far as the asked metrics need
/// ([`StrokeNeeds`]) from one evaluation of its closed-form equations
/// (`device/stroke_plane/`): the angles, the aerodynamic roll torques (the roll component
/// of `R6 τ⁶ = R_x(φ) R_z(ψ) τ⁶`), `q2`, the actuator force, the body reaction torques
/// (`R6 (τ⁶ − (I ω̇ + ω × Iω))`, `ω̇ = φ̈ a + ψ̈ ẑ + J̇6 ṗ`) and the work integrals. The same
/// numbers as a `Sample` (tested to 1e-12) without the general wing terms, the drivetrain
/// Newton inverse or the 6 × 6 evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneSample {
    /// Time (ms).
    pub time: f64,
    /// What was computed (the other fields are zero).
    pub needs: StrokeNeeds,
    /// Stroke angle `φ` per wing (rad).
    pub phi: [f64; 2],
    /// Hinge angle `ψ` per wing (rad).
    pub psi: [f64; 2],
    /// Aerodynamic body roll torque per wing (mN·mm; the left wing mirrored, as
    /// `Sample::aero``[w].x`).
    pub roll_aero: [f64; 2],
    /// Actuator force (mN; with [`StrokeNeeds::force`]).
    pub actuator_force: f64,
    /// Whippletree angle `q2` (rad).
    pub q2: f64,
    /// Body reaction torque per wing, as `Sample::wing_torque` (with [`StrokeNeeds::torques`]).
    pub torque: [Vector3<f64>; 2],
    /// Their sum, as `Sample::total`.
    pub total: Vector3<f64>,
    /// `(work_actuator, work_aero)` of the state (µJ; with [`StrokeNeeds::work`]).
    pub work: (f64, f64),
}
