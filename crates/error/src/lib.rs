//! The single error enum of paritysim.
//!
//! Every crate returns [`Error`]; the Python bindings map each variant to one exception class
//! (see `python/paritysim/_core.pyi`):
//!
//! | variant              | Python class                                          |
//! |----------------------|-------------------------------------------------------|
//! | `InvalidParameter`   | `InvalidParameterError(ParitysimError, ValueError)`   |
//! | `OutOfDomain`        | `OutOfDomainError(ParitysimError, ValueError)`        |
//! | `Geometry`           | `GeometryError(ParitysimError, ValueError)`           |
//! | `Shape`              | `ShapeError(ParitysimError, ValueError)`              |
//! | `Constraint`         | `ConstraintError(ParitysimError, ValueError)`         |
//! | `Singular`           | `SingularError(ParitysimError, ArithmeticError)`      |
//! | `Integration`        | `IntegrationError(ParitysimError, RuntimeError)`      |
//! | `Cancelled`          | `CancelledError(ParitysimError)`                      |
//! | `InvalidSpec`        | `InvalidParameterError` (with every problem listed)   |
//! | `Attributed`         | the class of the wrapped error, with `.field` set     |
//!
//! Use [`ensure!`] / [`bail!`] and the `check_*` helpers so that every message names the
//! offending field and the allowed range.

use std::borrow::Cow;
use std::fmt;

/// Result alias used across paritysim.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Every failure paritysim can report.
// Not `#[non_exhaustive]`: the bindings map every variant in one exhaustive `match`, so a new
// variant fails to compile until it has a Python class.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A parameter is non-finite or outside its allowed range.
    #[error("invalid `{field}` = {value}: must be {allowed}")]
    InvalidParameter {
        /// Dotted path of the field, e.g. `shoulder.alpha2`.
        field: Cow<'static, str>,
        /// The rejected value, formatted.
        value: String,
        /// Human-readable allowed range, e.g. `in (0, pi]`.
        allowed: String,
    },
    /// Valid parameters, but the requested configuration is unreachable
    /// (e.g. outside the shoulder joint limit of eq. 2.10).
    #[error("{what} is out of its domain: {detail}")]
    OutOfDomain {
        /// What was evaluated.
        what: Cow<'static, str>,
        /// Why it is out of domain, with numbers.
        detail: String,
    },
    /// A geometric description (planform outline, layup) is malformed.
    #[error("invalid geometry: {0}")]
    Geometry(String),
    /// Arrays or matrices with mismatching or wrong dimensions.
    #[error("shape mismatch: {0}")]
    Shape(String),
    /// A constraint matrix is rank deficient or the initial state violates it.
    #[error("constraint error: {0}")]
    Constraint(String),
    /// A linear system that must be solved is singular at this configuration.
    #[error("singular configuration: {0}")]
    Singular(String),
    /// Time integration failed; carries where it failed (diffsol-style).
    #[error("integration failed at t = {time} ms: {reason} (state = {state:?})")]
    Integration {
        /// Time of failure, ms.
        time: f64,
        /// State vector at the failure.
        state: Vec<f64>,
        /// What went wrong (step size underflow, non-finite state, ...).
        reason: String,
    },
    /// Work was cancelled by the caller.
    #[error("cancelled")]
    Cancelled,
    /// Several invalid fields of one spec, every one with its dotted path and allowed range.
    #[error("{} problems in the spec: {}", .0.len(), Problem::list(.0))]
    InvalidSpec(Vec<Problem>),
    /// A model failure that only shows while running (an integration, a pose), attributed to
    /// the field most responsible for it and the range that avoids it. Its kind (and Python
    /// class) is the wrapped error's; only [`Error::field`] differs.
    #[error("{error}; most responsible: `{field}` = {value}: must be {allowed}")]
    Attributed {
        /// Dotted path of the responsible field.
        field: Cow<'static, str>,
        /// Its value, formatted.
        value: String,
        /// The range (computed, with the unit) that avoids the failure.
        allowed: String,
        /// The failure itself.
        error: Box<Error>,
    },
}

/// One invalid field of a spec: its dotted path, the value found and what is allowed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// Dotted path, e.g. `wings[0].aero.omega1`.
    pub field: String,
    /// The rejected value (formatted), `missing` or `<unknown field>`.
    pub value: String,
    /// Allowed values or range, with the unit.
    pub allowed: String,
}

impl Problem {
    /// A problem at `field`.
    pub fn new(
        field: impl Into<String>,
        value: impl fmt::Display,
        allowed: impl Into<String>,
    ) -> Self {
        Self {
            field: field.into(),
            value: value_text(value),
            allowed: allowed.into(),
        }
    }

    fn list(problems: &[Problem]) -> String {
        problems
            .iter()
            .map(|p| format!("`{}` = {}: must be {}", p.field, p.value, p.allowed))
            .collect::<Vec<_>>()
            .join("; ")
    }
}

impl From<Vec<Problem>> for Error {
    /// One problem is an [`Error::InvalidParameter`]; several are an [`Error::InvalidSpec`].
    fn from(mut problems: Vec<Problem>) -> Self {
        if problems.len() == 1 {
            let p = problems.remove(0);
            Error::invalid(p.field, p.value, p.allowed)
        } else {
            Error::InvalidSpec(problems)
        }
    }
}

impl Error {
    /// Stable name of the variant; the Python class is `<kind>Error`.
    pub fn kind(&self) -> &'static str {
        match self {
            Error::InvalidParameter { .. } => "InvalidParameter",
            Error::OutOfDomain { .. } => "OutOfDomain",
            Error::Geometry(_) => "Geometry",
            Error::Shape(_) => "Shape",
            Error::Constraint(_) => "Constraint",
            Error::Singular(_) => "Singular",
            Error::Integration { .. } => "Integration",
            Error::Cancelled => "Cancelled",
            Error::InvalidSpec(_) => "InvalidParameter",
            Error::Attributed { error, .. } => error.kind(),
        }
    }

    /// Attributes this error to `field` (see [`Error::Attributed`]).
    pub fn attributed(
        self,
        field: impl Into<Cow<'static, str>>,
        value: impl fmt::Display,
        allowed: impl Into<String>,
    ) -> Self {
        Error::Attributed {
            field: field.into(),
            value: value_text(value),
            allowed: allowed.into(),
            error: Box::new(self),
        }
    }

    /// The error without its attribution ([`Error::Attributed`] unwrapped).
    pub fn cause(&self) -> &Error {
        match self {
            Error::Attributed { error, .. } => error.cause(),
            other => other,
        }
    }

    /// The field named by an [`Error::InvalidParameter`] (the first of an [`Error::InvalidSpec`],
    /// the attributed one of an [`Error::Attributed`]), if any.
    pub fn field(&self) -> Option<&str> {
        match self {
            Error::InvalidParameter { field, .. } => Some(field),
            Error::InvalidSpec(problems) => problems.first().map(|p| p.field.as_str()),
            Error::Attributed { field, .. } => Some(field),
            _ => None,
        }
    }

    /// Builds an [`Error::InvalidParameter`].
    pub fn invalid(
        field: impl Into<Cow<'static, str>>,
        value: impl fmt::Display,
        allowed: impl Into<String>,
    ) -> Self {
        Error::InvalidParameter {
            field: field.into(),
            value: value_text(value),
            allowed: allowed.into(),
        }
    }

    /// Prefixes the field path of an [`Error::InvalidParameter`] (e.g. `wing.` + `mass`),
    /// so nested specs report full dotted paths. Other variants are returned unchanged.
    pub fn in_field(self, prefix: &str) -> Self {
        match self {
            Error::InvalidParameter {
                field,
                value,
                allowed,
            } => Error::InvalidParameter {
                field: Cow::Owned(format!("{prefix}.{field}")),
                value,
                allowed,
            },
            Error::Attributed {
                field,
                value,
                allowed,
                error,
            } => Error::Attributed {
                field: Cow::Owned(format!("{prefix}.{field}")),
                value,
                allowed,
                error,
            },
            other => other,
        }
    }
}

impl Error {
    /// Locates an error inside an array evaluation: an invalid field becomes
    /// `{array}[{index}]` (`array` defaults to the field's own name) and an out-of-domain detail
    /// is prefixed with the index. Other variants are returned unchanged.
    pub fn at_index(self, index: usize, array: Option<&str>) -> Self {
        match self {
            Error::OutOfDomain { what, detail } => Error::OutOfDomain {
                what,
                detail: format!("at index {index}: {detail}"),
            },
            Error::InvalidParameter {
                field,
                value,
                allowed,
            } => Error::InvalidParameter {
                field: Cow::Owned(format!("{}[{index}]", array.unwrap_or(&field))),
                value,
                allowed,
            },
            Error::Attributed {
                field,
                value,
                allowed,
                error,
            } => Error::Attributed {
                field: Cow::Owned(format!("{}[{index}]", array.unwrap_or(&field))),
                value,
                allowed,
                error,
            },
            other => other,
        }
    }
}

/// Returns early with an error (polars-style).
///
/// `bail!(invalid "field", value, "allowed")` or `bail!(Singular "format {}", args)`.
#[macro_export]
macro_rules! bail {
    (invalid $field:expr, $value:expr, $allowed:expr $(,)?) => {
        return Err($crate::Error::invalid($field, $value, $allowed))
    };
    ($variant:ident $($fmt:tt)+) => {
        return Err($crate::Error::$variant(format!($($fmt)+)))
    };
}

/// Returns early with an error unless `cond` holds.
///
/// `ensure!(x > 0.0, invalid "mass", x, "> 0")` or `ensure!(ok, Shape "len {} != {}", a, b)`.
#[macro_export]
macro_rules! ensure {
    ($cond:expr, $($rest:tt)+) => {
        // Bound first so a NaN comparison counts as failing, without negating a float compare.
        let holds: bool = $cond;
        if !holds {
            $crate::bail!($($rest)+);
        }
    };
}

/// Rejects NaN and infinities.
pub fn check_finite(field: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::invalid(field, value, "a finite number"))
    }
}

/// `value` as an error message shows it: a number whose decimal text is longer than its
/// scientific one (`1e300` displays as 301 digits, `1e-300` as 302) in scientific notation.
fn value_text(value: impl fmt::Display) -> String {
    let text = value.to_string();
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && text.len() > 24 => format!("{x:e}"),
        _ => text,
    }
}

/// Requires a finite `value > 0`.
pub fn check_positive(field: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::invalid(field, value, "finite and > 0"))
    }
}

/// Requires a finite `value >= 0`.
pub fn check_non_negative(field: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::invalid(field, value, "finite and >= 0"))
    }
}

/// Requires `lo <= value <= hi` (closed interval), finite.
pub fn check_in_closed(field: &'static str, value: f64, lo: f64, hi: f64) -> Result<f64> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(value)
    } else {
        Err(Error::invalid(field, value, format!("in [{lo}, {hi}]")))
    }
}

/// Physical plausibility ranges shared by every crate (mg-mm-ms-rad-V). A value outside them is
/// not an insect-scale machine, and letting it through only moves the failure to an overflow or
/// a NaN far from the field that caused it (issue 14).
pub mod plausible {
    /// Lengths of parts: 1 nm to 1 m, in mm.
    pub const LENGTH_MM: (f64, f64) = (1e-6, 1e3);
    /// Positions and offsets (may be signed or zero): |x| up to 1 m, in mm.
    pub const OFFSET_MM: f64 = 1e3;
    /// Joint and drivetrain angles: |q| up to 1000 rad (overflow guard, not a physical limit).
    pub const ANGLE_RAD: f64 = 1e3;
}

/// Requires a finite `value` in `[lo, hi]`; the message names what it is (`a length`) and its unit.
fn check_plausible(
    field: &'static str,
    value: f64,
    (lo, hi): (f64, f64),
    what: &str,
    unit: &str,
) -> Result<f64> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            value,
            format!("{what} in [{lo:e}, {hi:e}] {unit}"),
        ))
    }
}

/// Requires `|value| <= `[`plausible::ANGLE_RAD`] (rad).
pub fn check_angle_rad(field: &'static str, value: f64) -> Result<f64> {
    let hi = plausible::ANGLE_RAD;
    check_plausible(field, value, (-hi, hi), "an angle", "rad")
}

/// Requires a part length in [`plausible::LENGTH_MM`] (mm).
pub fn check_length_mm(field: &'static str, value: f64) -> Result<f64> {
    check_plausible(field, value, plausible::LENGTH_MM, "a length", "mm")
}

/// Requires a signed offset with `|value| <= `[`plausible::OFFSET_MM`] (mm).
pub fn check_offset_mm(field: &'static str, value: f64) -> Result<f64> {
    let hi = plausible::OFFSET_MM;
    check_plausible(field, value, (-hi, hi), "an offset", "mm")
}

/// Requires paired arguments of equal lengths, naming both (`(name, length)` each).
///
/// # Errors
/// [`Error::Shape`] when the lengths differ.
pub fn check_same_len(a: (&str, usize), b: (&str, usize)) -> Result<()> {
    if a.1 != b.1 {
        return Err(Error::Shape(format!(
            "`{}` has {} elements but `{}` has {}; they must match",
            a.0, a.1, b.0, b.1
        )));
    }
    Ok(())
}

/// Requires every element of a slice to be finite; names the first bad index.
pub fn check_all_finite(field: &'static str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::invalid(
            format!("{field}[{i}]"),
            values[i],
            "a finite number",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn needs_positive(x: f64) -> Result<f64> {
        ensure!(x > 0.0, invalid "x", x, "> 0");
        Ok(x)
    }

    #[test]
    fn huge_and_tiny_numbers_show_in_scientific_notation() {
        // `1e300` displayed as 301 digits in the message.
        let e = check_positive("x", -1e300).unwrap_err();
        assert_eq!(
            e.to_string(),
            "invalid `x` = -1e300: must be finite and > 0"
        );
        let e = Error::invalid("x", 1.5e-300, "> 1");
        assert_eq!(e.to_string(), "invalid `x` = 1.5e-300: must be > 1");
        // Ordinary numbers and texts keep their own form.
        assert_eq!(
            Error::invalid("x", 0.125, "> 1").to_string(),
            "invalid `x` = 0.125: must be > 1"
        );
        let long = "a text of more than twenty-four characters";
        assert!(Error::invalid("x", long, "y").to_string().contains(long));
    }

    #[test]
    fn messages_name_field_and_range() {
        let e = needs_positive(-1.0).unwrap_err();
        assert_eq!(e.kind(), "InvalidParameter");
        assert_eq!(e.field(), Some("x"));
        assert_eq!(e.to_string(), "invalid `x` = -1: must be > 0");
        let nested = e.in_field("wing");
        assert_eq!(nested.field(), Some("wing.x"));
    }

    #[test]
    fn at_index_names_the_element() {
        let e = check_finite("q1", f64::NAN).unwrap_err().at_index(3, None);
        assert_eq!(e.field(), Some("q1[3]"));
        let e = check_finite("voltage", f64::NAN)
            .unwrap_err()
            .at_index(1, Some("voltages"));
        assert_eq!(e.field(), Some("voltages[1]"));
    }

    #[test]
    fn nan_is_rejected_everywhere() {
        assert!(check_finite("a", f64::NAN).is_err());
        assert!(check_positive("a", f64::NAN).is_err());
        assert!(check_non_negative("a", f64::INFINITY).is_err());
        assert!(check_in_closed("a", f64::NAN, 0.0, 1.0).is_err());
        let e = check_all_finite("v", &[1.0, f64::NAN]).unwrap_err();
        assert_eq!(e.field(), Some("v[1]"));
    }

    #[test]
    fn bail_with_message_variant() {
        fn f() -> Result<()> {
            bail!(Singular "det = {}", 0.0);
        }
        assert_eq!(
            f().unwrap_err().to_string(),
            "singular configuration: det = 0"
        );
    }
}
