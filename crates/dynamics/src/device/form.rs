//! The equations a device integrates, chosen once when the model is built.
//!
//! A device has exactly one [`Form`]; each form is one implementation of [`Equations`]
//! (`equations.rs`). The integrator, shooting, sweeps and recordings ask the form; nothing else decides which
//! equations apply. Adding a form: a variant, an [`Equations`] impl, and its condition in
//! [`Form::choose`].

use paritysim_aero::Branch;
use paritysim_error::{Error, Result};

use super::Device;
use super::drivetrain_coordinates::StrokeOnly;
use super::equations::Equations;
use super::free_deviation::FreeDeviation;
use super::linear_map::LinearMapTerms;
use super::null_space::General;
use super::stroke_plane::StrokePlane;
use crate::integrate::{MAX_SWITCHES, State};

/// The form of a device, chosen by [`Form::choose`].
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Form {
    /// Fixed wings only stroking, in drivetrain coordinates `q`
    /// ([`super::Formulation::DrivetrainCoordinates`]).
    DrivetrainCoordinates(StrokeOnly),
    /// §3.4 rotating wings with the deviation held on α2 = 90° shoulders (`stroke_plane/`).
    StrokePlane(StrokePlane),
    /// §2.5 wings with a free deviation on α2 = 90°, α3 = 0 shoulders (`free_deviation.rs`).
    FreeDeviation(FreeDeviation),
    /// Anything else (`null_space.rs`).
    General(General),
}

/// Runs `$body` with `$eq` bound to the form's [`Equations`] (static dispatch, inlined).
macro_rules! with_equations {
    ($form:expr, $eq:ident => $body:expr) => {
        match $form {
            Form::DrivetrainCoordinates($eq) => $body,
            Form::StrokePlane($eq) => $body,
            Form::FreeDeviation($eq) => $body,
            Form::General($eq) => $body,
        }
    };
}

impl Form {
    /// The form of `device` (built with [`Form::General`]): drivetrain coordinates when the
    /// formulation chose them, else the first closed form that applies.
    pub(super) fn choose(device: &Device, stroke_only: Option<StrokeOnly>) -> Self {
        if let Some(fast) = stroke_only {
            return Self::DrivetrainCoordinates(fast);
        }
        if let Some(plane) = StrokePlane::of(device) {
            return Self::StrokePlane(plane);
        }
        if let Some(free) = FreeDeviation::of(device) {
            return Self::FreeDeviation(free);
        }
        Self::General(General)
    }

    /// The stroke-plane constants, if this is that form.
    pub(super) fn stroke_plane(&self) -> Option<&StrokePlane> {
        match self {
            Self::StrokePlane(plane) => Some(plane),
            _ => None,
        }
    }

    /// The free-deviation constants, if this is that form.
    pub(super) fn free_deviation(&self) -> Option<&FreeDeviation> {
        match self {
            Self::FreeDeviation(free) => Some(free),
            _ => None,
        }
    }

    /// The drivetrain-coordinate constants, if this is that form.
    pub(super) fn stroke_only(&self) -> Option<&StrokeOnly> {
        match self {
            Self::DrivetrainCoordinates(fast) => Some(fast),
            _ => None,
        }
    }

    /// The linear map's analytic Jacobian constants (drivetrain coordinates of a two-DOF linear
    /// differential with stroke drag or no aerodynamics).
    pub(crate) fn linear_map_terms(&self) -> Option<&LinearMapTerms<f64>> {
        (self.stroke_only()?.linear.as_ref()).filter(|terms| terms.analytic)
    }

    /// Whether [`Equations::variational`] is analytic rather than central differences.
    pub(crate) fn has_analytic_jacobian(&self) -> bool {
        self.stroke_plane().is_some() || self.linear_map_terms().is_some()
    }
}

impl Equations for Form {
    #[inline(always)]
    fn rhs(
        &self,
        device: &Device,
        t: f64,
        y: &State,
        branches: Option<[Branch; 2]>,
        dydt: &mut State,
    ) -> Result<()> {
        with_equations!(self, eq => eq.rhs(device, t, y, branches, dydt))
    }

    fn switches(&self, device: &Device, y: &State, g: &mut [f64; MAX_SWITCHES]) -> Result<()> {
        with_equations!(self, eq => eq.switches(device, y, g))
    }

    #[inline]
    fn variational(
        &self,
        device: &Device,
        t: f64,
        y: &State,
        branches: Option<[Branch; 2]>,
        n: usize,
        rhs: Option<&mut [f64]>,
        phi: &[f64],
        dphi: &mut [f64],
    ) -> Option<Result<()>> {
        with_equations!(self, eq => eq.variational(device, t, y, branches, n, rhs, phi, dphi))
    }

    fn rhs_batch(
        &self,
        device: &Device,
        t: f64,
        branches: [Branch; 2],
        ys: &[State],
        out: &mut [State],
    ) -> Option<std::result::Result<(), (usize, Error)>> {
        with_equations!(self, eq => eq.rhs_batch(device, t, branches, ys, out))
    }
}
