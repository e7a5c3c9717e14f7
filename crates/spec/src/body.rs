//! The airframe of a free-flying device (issue 17, beyond the thesis: every thesis trial holds
//! the body fixed). Absent, or `mode = "fixed"`: the torque-stand device, results unchanged.
//!
//! Defaults: an HMF-class airframe. Mass 60 mg, the Harvard Microrobotic Fly of the thesis'
//! introduction ("the 60mg HMF", §1); inertia of a uniform 18 × 2.4 × 5 mm box of that mass
//! (Mabee's length 18 mm and height 2.4 mm, §4.1; the 5 mm width is our assumption): about
//! the centre of mass `Ixx = m(2.4² + 5²)/12`, `Iyy = m(18² + 5²)/12`, `Izz = m(18² + 2.4²)/12`
//! with `x̂` the body's long axis (the stroke axis). Shoulders 6 mm above the centre of mass,
//! ±1.5 mm to the sides (assumed). Force radius 12 mm: the `∫z³c/∫z²c` radius of a
//! rectangular 16 mm wing (§3.3.1: the wings extend 16.0 mm beyond the pivot). Wing masses
//! 0 (the wing inertia about the shoulder is the wing's own tensor; the §3.3.1 wing weighs
//! 0.834 mg, ~1 % of the body).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// How the body may move.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BodyMode {
    /// Held by the torque stand (the thesis' setting; results unchanged).
    #[default]
    Fixed,
    /// Held, but run through the flight model: reports the wrench the stand holds (trim).
    Clamped,
    /// Gimbal about the centre of mass: rotation about the roll axis (x, the stroke axis).
    Roll,
    /// Gimbal: rotation about the yaw axis (y) only.
    Yaw,
    /// Gimbal: rotation about the pitch axis (z, spanwise) only.
    Pitch,
    /// Ball joint at the centre of mass: roll, pitch and yaw, no translation.
    RollPitchYaw,
    /// Six degrees of freedom under gravity.
    Free,
}

/// Drivetrain coordinate a mechanism or control acts on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DriveCoordinate {
    /// Actuator coordinate q1 (force, mN).
    Q1,
    /// Whippletree angle q2 (torque, mN·mm): the Drag PARITY pivot.
    #[default]
    Q2,
}

/// A pendulum hanging from a drivetrain coordinate: `τ = moment (d × R_bᵀ g)·a`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct GravityPendulum {
    /// Coordinate it biases.
    pub coordinate: DriveCoordinate,
    /// Mass times arm (mg·mm), in [-1e4, 1e4].
    #[schemars(range(min = -1e4, max = 1e4), extend("x-unit" = "mg mm"))]
    pub moment_mg_mm: f64,
    /// Rest direction of the arm (body frame; normalised).
    #[schemars(extend("x-unit" = "1"))]
    pub direction: [f64; 3],
    /// Rotation axis of the coordinate (body frame; normalised).
    #[schemars(extend("x-unit" = "1"))]
    pub axis: [f64; 3],
}

impl Default for GravityPendulum {
    fn default() -> Self {
        Self {
            coordinate: DriveCoordinate::Q2,
            moment_mg_mm: 10.0,
            direction: [-1.0, 0.0, 0.0],
            axis: [0.0, 1.0, 0.0],
        }
    }
}

/// A haltere-like rate element: `τ = −gain (Ω · axis)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct RateElement {
    /// Coordinate it acts on.
    pub coordinate: DriveCoordinate,
    /// Gain (mN·mm per rad/ms on q2, mN per rad/ms on q1), in [-1e6, 1e6].
    #[schemars(range(min = -1e6, max = 1e6), extend("x-unit" = "mN mm ms/rad"))]
    pub gain: f64,
    /// Sensing axis (body frame; normalised).
    #[schemars(extend("x-unit" = "1"))]
    pub axis: [f64; 3],
}

impl Default for RateElement {
    fn default() -> Self {
        Self {
            coordinate: DriveCoordinate::Q2,
            gain: 1.0,
            axis: [1.0, 0.0, 0.0],
        }
    }
}

/// A body-referenced mechanism, tagged by `kind`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Mechanism {
    /// Ground-referenced: gravity pendulum.
    GravityPendulum(GravityPendulum),
    /// Rate-referenced: gyroscopic element.
    RateElement(RateElement),
}

/// What a set point or controller drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ControlInput {
    /// Bias torque on the whippletree q2 (mN·mm): the q3 of eq. 5.1.
    #[default]
    Q2Bias,
    /// Added actuator force on q1 (mN): DC offset.
    ActuatorOffset,
    /// Relative actuator amplitude change (1 = +100 %).
    ActuatorGain,
    /// `ln q3` of eq. 5.1 (1): the whippletree holds the torque ratio `τL/τR = q3` (a
    /// "virtual moving pivot"; a 2-DOF differential drivetrain).
    LogQ3,
    /// `dual_four_bar`, `dual_linear`: relative change of the left drive's force (1 = +100 %).
    SideGainLeft,
    /// `dual_four_bar`, `dual_linear`: relative change of the right drive's force.
    SideGainRight,
    /// `dual_four_bar`, `dual_linear`: added force on the left drive (mN).
    SideOffsetLeft,
    /// `dual_four_bar`, `dual_linear`: added force on the right drive (mN).
    SideOffsetRight,
    /// `dual_four_bar`, `dual_linear`: +u on the left drive's relative force, −u on the right's.
    SideGainDifference,
    /// `dual_four_bar`, `dual_linear`: +u mN on the left drive, −u on the right.
    SideOffsetDifference,
}

/// How a set point fills the time between its nodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Interpolation {
    /// Piecewise linear.
    #[default]
    Linear,
    /// Piecewise constant: the value of the last node at or before t (steps at the nodes).
    Previous,
}

/// A piecewise-linear schedule, held outside its times.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct SetPoint {
    /// What it drives.
    pub input: ControlInput,
    /// Times (ms) from the release, increasing.
    #[schemars(inner(range(min = 0.0, max = 1e7)), extend("x-unit" = "ms"))]
    pub times_ms: Vec<f64>,
    /// Values at those times (unit of the input).
    pub values: Vec<f64>,
    /// Between the nodes: `linear` or `previous` (steps).
    pub interpolation: Interpolation,
    /// Repeat the schedule with this period (ms; times then in [0, period_ms)), e.g. the
    /// drive period for a stroke-synchronous schedule. Absent: held outside its times.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(range(max = 1e7), extend("exclusiveMinimum" = 0.0, "x-unit" = "ms"))]
    pub period_ms: Option<f64>,
}

/// A schedule without an input: what a controller's output multiplies.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Shape {
    /// Times (ms) from the release, increasing.
    #[schemars(inner(range(min = 0.0, max = 1e7)), extend("x-unit" = "ms"))]
    pub times_ms: Vec<f64>,
    /// Values at those times (1).
    pub values: Vec<f64>,
    /// Between the nodes: `linear` or `previous` (steps).
    pub interpolation: Interpolation,
    /// Repeat period (ms; times then in [0, period_ms)).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(range(max = 1e7), extend("exclusiveMinimum" = 0.0, "x-unit" = "ms"))]
    pub period_ms: Option<f64>,
}

/// Body axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    /// x (stroke axis).
    #[default]
    Roll,
    /// y.
    Yaw,
    /// z (spanwise).
    Pitch,
}

/// A PD controller on one attitude angle, run at `rate_hz` with zero-order hold:
/// `u = −kp (angle − target_rad) − kd (rate − target_rate_rad_per_ms)`, saturated at `±limit`
/// (`kp = 0`: a rate controller).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Control {
    /// What it drives.
    pub input: ControlInput,
    /// Controlled axis.
    pub axis: Axis,
    /// Target angle (rad), in [-pi, pi].
    #[schemars(range(min = -std::f64::consts::PI, max = std::f64::consts::PI), extend("x-unit" = "rad"))]
    pub target_rad: f64,
    /// Proportional gain (input unit per rad), in [-1e6, 1e6].
    #[schemars(range(min = -1e6, max = 1e6))]
    pub kp: f64,
    /// Derivative gain (input unit per rad/ms), in [-1e6, 1e6].
    #[schemars(range(min = -1e6, max = 1e6))]
    pub kd: f64,
    /// Target rate about the axis (rad/ms), in [-100, 100].
    #[schemars(range(min = -100.0, max = 100.0), extend("x-unit" = "rad/ms"))]
    pub target_rate_rad_per_ms: f64,
    /// Control rate (Hz), in (0, 1e5].
    #[schemars(range(max = 1e5), extend("exclusiveMinimum" = 0.0, "x-unit" = "Hz"))]
    pub rate_hz: f64,
    /// Output saturation (input unit), in (0, 1e6].
    #[schemars(range(max = 1e6), extend("exclusiveMinimum" = 0.0))]
    pub limit: f64,
    /// Optional schedule the output multiplies (the controller sets its amplitude), e.g.
    /// a stroke-synchronous ±1 with `input = "log_q3"`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shape: Option<Shape>,
}

impl Default for Control {
    fn default() -> Self {
        Self {
            input: ControlInput::Q2Bias,
            axis: Axis::Roll,
            target_rad: 0.0,
            kp: 0.0,
            kd: 0.0,
            target_rate_rad_per_ms: 0.0,
            rate_hz: 1000.0,
            limit: 1.0,
            shape: None,
        }
    }
}

/// The airframe (body frame: x the stroke axis, "up" in hover; y the wing normal at rest; z
/// spanwise toward the right wing; origin anywhere, lengths in mm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Body {
    /// How the body may move.
    pub mode: BodyMode,
    /// Body mass without the wings (mg), in (0, 1e5].
    #[schemars(range(max = 1e5), extend("exclusiveMinimum" = 0.0, "x-unit" = "mg"))]
    pub mass_mg: f64,
    /// Inertia tensor about the body's centre of mass, body frame (mg·mm², symmetric positive
    /// definite), entries in [-1e7, 1e7].
    #[schemars(extend("x-unit" = "mg mm^2"))]
    pub inertia: [[f64; 3]; 3],
    /// Centre of mass of the body (mm), entries in [-1e3, 1e3].
    #[schemars(inner(range(min = -1e3, max = 1e3)), extend("x-unit" = "mm"))]
    pub center_of_mass_mm: [f64; 3],
    /// Shoulder (spherical centre) of each wing, left first (mm).
    #[schemars(extend("x-unit" = "mm"))]
    pub shoulders_mm: [[f64; 3]; 2],
    /// Gravity in the world frame (mm/ms²; 9.81 m/s² = 9.81e-3 mm/ms²).
    #[schemars(inner(range(min = -1.0, max = 1.0)), extend("x-unit" = "mm/ms^2"))]
    pub gravity_mm_per_ms2: [f64; 3],
    /// Radius where the shoulder's translation enters the blade-element velocity, and
    /// `Ω1 / r` the lift/drag force parameter (mm), in (0, 1e3].
    #[schemars(range(max = 1e3), extend("exclusiveMinimum" = 0.0, "x-unit" = "mm"))]
    pub force_radius_mm: f64,
    /// Wing masses, left first (mg), each in [0, 1e3].
    #[schemars(inner(range(min = 0.0, max = 1e3)), extend("x-unit" = "mg"))]
    pub wing_mass_mg: [f64; 2],
    /// Wing centres of mass in each wing's frame 6 (mm).
    #[schemars(extend("x-unit" = "mm"))]
    pub wing_center_of_mass_mm: [[f64; 3]; 2],
    /// Attitude at release: roll, yaw, pitch (rad; `R = R_x(roll) R_y(yaw) R_z(pitch)`).
    #[schemars(inner(range(min = -7.0, max = 7.0)), extend("x-unit" = "rad"))]
    pub initial_attitude_rad: [f64; 3],
    /// Body angular velocity at release (body frame, rad/ms).
    #[schemars(inner(range(min = -100.0, max = 100.0)), extend("x-unit" = "rad/ms"))]
    pub initial_rates_rad_per_ms: [f64; 3],
    /// Velocity at release (world, mm/ms).
    #[schemars(inner(range(min = -1e3, max = 1e3)), extend("x-unit" = "mm/ms"))]
    pub initial_velocity_mm_per_ms: [f64; 3],
    /// Body-referenced mechanisms on the drivetrain.
    pub mechanisms: Vec<Mechanism>,
    /// Time-varying set points (eq. 5.1 in flight).
    pub set_points: Vec<SetPoint>,
    /// A PD attitude controller.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub control: Option<Control>,
}

impl Default for Body {
    fn default() -> Self {
        // 60 mg box (module docs): m(2.4² + 5²)/12 = 153.8, m(18² + 5²)/12 = 1745,
        // m(18² + 2.4²)/12 = 1648.8 mg·mm².
        Self {
            mode: BodyMode::Fixed,
            mass_mg: 60.0,
            inertia: [[153.8, 0.0, 0.0], [0.0, 1745.0, 0.0], [0.0, 0.0, 1648.8]],
            center_of_mass_mm: [0.0; 3],
            shoulders_mm: [[6.0, 0.0, -1.5], [6.0, 0.0, 1.5]],
            gravity_mm_per_ms2: [-9.81e-3, 0.0, 0.0],
            force_radius_mm: 12.0,
            wing_mass_mg: [0.0; 2],
            wing_center_of_mass_mm: [[0.0; 3]; 2],
            initial_attitude_rad: [0.0; 3],
            initial_rates_rad_per_ms: [0.0; 3],
            initial_velocity_mm_per_ms: [0.0; 3],
            mechanisms: Vec::new(),
            set_points: Vec::new(),
            control: None,
        }
    }
}
