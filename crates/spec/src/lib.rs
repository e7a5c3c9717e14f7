//! The device spec of paritysim, owned by the Rust core.
//!
//! One set of serde types ([`Simulation`] and its parts) describes a runnable device: TOML
//! files, JSON and Python dicts all deserialise into it, the defaults are written once (the
//! `Default` impls here, or the engine's own for [`Options`]), and the JSON Schema
//! ([`schema::schema`]) is generated from the same types. Validation
//! ([`from_value`]) walks a spec against the schema and reports **every** problem with its
//! dotted path and allowed range (unknown keys name the nearest valid key), then builds the
//! dynamics model ([`Simulation::model`]) whose constructors check the cross-field
//! conditions.
//!
//! Dependency direction: this crate depends on `paritysim-dynamics` (and the kinematics,
//! aero and constraints crates), never the reverse, so the engine never parses a file or knows
//! a format (it derives serde traits on its options and result records only).

pub mod actuator;
pub mod attribute;
pub mod body;
mod build;
pub mod continuation;
pub mod drivetrain;
pub mod flight;
pub mod migrate;
pub mod options;
pub mod paths;
pub mod schema;
pub mod sensitivity;
pub mod spec;
pub mod sweep;
pub mod watch;
pub mod wing;

pub use actuator::{Actuator, DcOffset, Sampled, Sine, Waveform};
pub use body::{Body, BodyMode};
pub use build::options as engine_options;
pub use drivetrain::{Drivetrain, DrivetrainConfig};
pub use options::{Options, Perturbation};
pub use paritysim_error::{Error, Problem, Result};
pub use spec::{Configuration, Formulation, Simulation};
pub use wing::{Aero, Shoulder, Spring, Springs, TunableHinge, Wing};

use serde_json::Value;

/// Validates and deserialises a spec value; returns the spec and the deprecation notes of
/// any old spellings it contained.
///
/// # Errors
/// [`Error::InvalidParameter`] (one problem) or [`Error::InvalidSpec`] (several), each with
/// the dotted field path and what is allowed.
pub fn from_value(mut value: Value) -> Result<(Simulation, Vec<String>)> {
    let notes = migrate::migrate(&mut value);
    Ok((from_current(&value)?, notes))
}

/// [`from_value`] of a value in today's spellings (a spec's own serialisation, or one with
/// numbers set in it: no migration), read without consuming it.
///
/// # Errors
/// As [`from_value`].
pub fn from_current(value: &Value) -> Result<Simulation> {
    let mut problems = Vec::new();
    schema::check(value, &mut problems);
    read_checked(value, problems)
}

/// [`from_current`] of a valid spec's value in which only the fields at the canonical
/// `changed` paths were set, `base` the spec it held before: the schema is checked along those
/// paths only, and when they are all under one top-level field, that field alone is read into
/// a copy of `base`.
///
/// # Errors
/// As [`from_value`].
pub(crate) fn from_changed(
    base: &Simulation,
    value: &Value,
    changed: &[&str],
) -> Result<Simulation> {
    let mut problems = Vec::new();
    schema::check_along(value, changed, &mut problems);
    fn top(path: &str) -> &str {
        path.split(['.', '[']).next().unwrap_or_default()
    }
    if let Some(first) = changed.first().map(|path| top(path))
        && problems.is_empty()
        && changed.iter().all(|path| top(path) == first)
        && let Some(spec) = base.with_field(first, &value[first])
    {
        return spec
            .map_err(|e| Error::invalid("spec", e.to_string(), "a spec matching the schema"));
    }
    read_checked(value, problems)
}

/// The spec in `value` when its schema check found no `problems`.
fn read_checked(value: &Value, problems: Vec<paritysim_error::Problem>) -> Result<Simulation> {
    if !problems.is_empty() {
        return Err(problems.into());
    }
    <Simulation as serde::Deserialize>::deserialize(value)
        .map_err(|e| Error::invalid("spec", e.to_string(), "a spec matching the schema"))
}

/// Parses a JSON spec.
///
/// # Errors
/// [`Error::InvalidParameter`] for malformed JSON; otherwise see [`from_value`].
pub fn from_json(text: &str) -> Result<(Simulation, Vec<String>)> {
    let value: Value = serde_json::from_str(text)
        .map_err(|e| Error::invalid("spec", e.to_string(), "valid JSON"))?;
    from_value(value)
}

/// Parses a TOML spec.
///
/// # Errors
/// [`Error::InvalidParameter`] for malformed TOML; otherwise see [`from_value`].
pub fn from_toml(text: &str) -> Result<(Simulation, Vec<String>)> {
    let value: Value = toml::from_str(text)
        .map_err(|e| Error::invalid("spec", e.to_string().trim().to_string(), "valid TOML"))?;
    from_value(value)
}

/// A drivetrain spec alone (a `[drivetrain]` table as JSON), validated like one.
///
/// # Errors
/// As [`from_value`], with paths under `drivetrain`.
pub fn drivetrain_from_json(text: &str) -> Result<Drivetrain> {
    let value: Value = serde_json::from_str(text)
        .map_err(|e| Error::invalid("drivetrain", e.to_string(), "valid JSON"))?;
    let mut problems = Vec::new();
    schema::check_definition(&value, "Drivetrain", "drivetrain", &mut problems);
    if !problems.is_empty() {
        return Err(problems.into());
    }
    serde_json::from_value(value)
        .map_err(|e| Error::invalid("drivetrain", e.to_string(), "a drivetrain spec"))
}

impl Simulation {
    /// The spec as JSON (defaults filled in, current names).
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("a spec serialises")
    }

    /// The spec as TOML.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a spec serialises to TOML")
    }
}
