//! Integration and steady-state options.

use paritysim_dynamics::SimulationOptions;
use paritysim_dynamics::integrate::Method as EngineMethod;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Runge-Kutta pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Dormand-Prince 8(5,3).
    #[default]
    Dop853,
    /// Dormand-Prince 5(4).
    Dopri5,
}

impl From<Method> for EngineMethod {
    fn from(m: Method) -> Self {
        match m {
            Method::Dop853 => EngineMethod::Dop853,
            Method::Dopri5 => EngineMethod::Dopri5,
        }
    }
}

/// How the periodic steady state is reached.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum SteadyState {
    /// Cycle-by-cycle simulation until the change per cycle is below `steady_tol`.
    Transient,
    /// The default: a few cycles, then Newton shooting on the stroboscopic map retraced on a
    /// frozen step grid, with the variational equations; falls back to the transient
    /// automatically (Newton failure, unstable orbit). Reports the residual and the
    /// multipliers.
    #[default]
    Shooting,
}

impl From<SteadyState> for paritysim_dynamics::SteadyState {
    fn from(s: SteadyState) -> Self {
        match s {
            SteadyState::Transient => paritysim_dynamics::SteadyState::Transient,
            SteadyState::Shooting => paritysim_dynamics::SteadyState::Shooting,
        }
    }
}

/// What a perturbation kicks: `"q2"` (the whippletree rate) or a coordinate index of `p`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum PerturbTarget {
    /// A coordinate rate `ṗ_i`, i in [0, 6).
    Coordinate(#[schemars(range(max = 5))] u8),
    /// `"q2"`.
    Named(PerturbName),
}

/// Named perturbation targets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum PerturbName {
    /// The whippletree rate q̇2.
    Q2,
}

impl Default for PerturbTarget {
    fn default() -> Self {
        PerturbTarget::Named(PerturbName::Q2)
    }
}

/// A velocity kick in the recording window.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Perturbation {
    /// What is kicked.
    #[serde(default)]
    pub target: PerturbTarget,
    /// Velocity change (rad/ms), in [-1e3, 1e3].
    #[schemars(range(min = -1e3, max = 1e3), extend("x-unit" = "rad/ms"))]
    pub delta: f64,
    /// Fraction of the first recorded cycle, in [0, 1).
    #[schemars(range(min = 0.0), extend("exclusiveMaximum" = 1.0, "x-unit" = "1"))]
    #[serde(default)]
    pub phase: f64,
}

/// Options of a simulation (defaults: the engine's [`SimulationOptions::default`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Options {
    /// Runge-Kutta pair.
    pub method: Method,
    /// Relative tolerance, in (0, 0.1].
    #[schemars(range(max = 0.1), extend("exclusiveMinimum" = 0.0, "x-unit" = "1"))]
    pub rtol: f64,
    /// Absolute tolerance, in [1e-30, 0.1] (a smaller one makes the error norm of a state at
    /// rest overflow: every step is rejected until the step size underflows).
    #[schemars(range(min = 1e-30, max = 0.1), extend("x-unit" = "1"))]
    pub atol: f64,
    /// Step limit per integration call, in [1, 1e9].
    #[schemars(range(min = 1, max = 1_000_000_000), extend("x-unit" = "steps"))]
    pub max_steps: u64,
    /// Cycles always simulated before checking for steady state, in [0, 100000].
    #[schemars(range(max = 100_000), extend("x-unit" = "cycles"))]
    pub min_cycles: u64,
    /// Give up waiting for steady state after this many cycles, in [1, 100000].
    #[schemars(range(min = 1, max = 100_000), extend("x-unit" = "cycles"))]
    pub max_cycles: u64,
    /// Steady when the cycle-to-cycle change is below this (relative), in (0, 1].
    #[schemars(range(max = 1.0), extend("exclusiveMinimum" = 0.0, "x-unit" = "1"))]
    pub steady_tol: f64,
    /// Samples per recorded cycle, in [8, 1e6].
    #[schemars(range(min = 8, max = 1_000_000), extend("x-unit" = "samples"))]
    pub samples_per_cycle: u64,
    /// Cycles recorded after steady state, in [1, 10000].
    #[schemars(range(min = 1, max = 10_000), extend("x-unit" = "cycles"))]
    pub record_cycles: u64,
    /// Duration (ms) for devices without a periodic drive, in (0, 1e7].
    #[schemars(range(max = 1e7), extend("exclusiveMinimum" = 0.0, "x-unit" = "ms"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub duration_ms: Option<f64>,
    /// Initial configuration `p` (rad), 3 values per wing.
    #[schemars(extend("x-unit" = "rad"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial_p: Option<Vec<f64>>,
    /// Initial rates `ṗ` (rad/ms), 3 values per wing.
    #[schemars(extend("x-unit" = "rad/ms"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial_p_dot: Option<Vec<f64>>,
    /// A velocity kick in the recording window.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub perturbation: Option<Perturbation>,
    /// How the periodic steady state is reached.
    pub steady_state: SteadyState,
    /// Wall-clock budget of one run (ms), in (0, 8.64e7] (a day): a run past it fails with
    /// an error naming this field (a sweep point becomes an error row).
    #[schemars(range(max = 8.64e7), extend("exclusiveMinimum" = 0.0, "x-unit" = "ms"))]
    pub max_wall_ms: f64,
}

impl Default for Options {
    fn default() -> Self {
        // The engine's defaults are the single source.
        let d = SimulationOptions::default();
        Self {
            method: Method::Dop853,
            rtol: d.rtol,
            atol: d.atol,
            max_steps: d.max_steps as u64,
            min_cycles: d.min_cycles as u64,
            max_cycles: d.max_cycles as u64,
            steady_tol: d.steady_tol,
            samples_per_cycle: d.samples_per_cycle as u64,
            record_cycles: d.record_cycles as u64,
            duration_ms: d.duration_ms,
            initial_p: None,
            initial_p_dot: None,
            perturbation: None,
            steady_state: SteadyState::default(),
            max_wall_ms: d
                .max_wall_ms
                .unwrap_or(paritysim_dynamics::simulate::DEFAULT_MAX_WALL_MS),
        }
    }
}
