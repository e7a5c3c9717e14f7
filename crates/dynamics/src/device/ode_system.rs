//! The device as an [`OdeSystem`](crate::integrate::OdeSystem) of the integrator.

use paritysim_error::Result;

use super::free_deviation::HeldConstants;
use super::linear_map_jacobian::{self, LinearMapTerms};
use super::switches::branches;
use super::{Device, stroke_plane};
use crate::integrate::State;

// The device is an ODE system of the integrator (the integrator itself knows no device).
impl crate::integrate::OdeSystem for Device {
    fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> Result<()> {
        Device::rhs(self, t, y, dydt)
    }

    fn n_active(&self) -> usize {
        self.n_dof()
    }

    fn n_switches(&self) -> usize {
        self.n_switches
    }

    fn switches(
        &self,
        _t: f64,
        y: &State,
        g: &mut [f64; crate::integrate::MAX_SWITCHES],
    ) -> Result<()> {
        if self.stroke_plane_rhs.is_some() {
            self.stroke_plane_switching_functions(y, g);
            return Ok(());
        }
        self.blade_switching_functions(y, g)
    }

    fn rhs_on(
        &self,
        t: f64,
        y: &State,
        sides: crate::integrate::Sides,
        dydt: &mut State,
    ) -> Result<()> {
        match &self.stroke_plane_rhs {
            Some(lean) => self.rhs_stroke_plane(lean, t, y, Some(branches(sides)), dydt),
            None if self.n_switches > 0 => match &self.free_deviation_rhs {
                Some(lean) => self.rhs_free_deviation(lean, t, y, Some(branches(sides)), dydt),
                None => self.rhs_null_space_on(t, y, Some(branches(sides)), dydt),
            },
            None => Device::rhs(self, t, y, dydt),
        }
    }

    fn rhs_on_batch(
        &self,
        t: f64,
        sides: crate::integrate::Sides,
        ys: &[State],
        out: &mut [State],
    ) -> Option<std::result::Result<(), (usize, paritysim_error::Error)>> {
        let lean = self.free_deviation_rhs.as_ref()?;
        if self.n_switches == 0 || ys.len() < 2 {
            return None;
        }
        let b = branches(sides);
        Some(match self.free_deviation_held.as_ref()? {
            HeldConstants::Four(held) => self.free_deviation_batch((held, lean), t, b, ys, out),
            HeldConstants::Five(held) => self.free_deviation_batch((held, lean), t, b, ys, out),
        })
    }

    fn variational(
        &self,
        t: f64,
        y: &State,
        n: usize,
        phi: &[f64],
        dphi: &mut [f64],
    ) -> Option<Result<()>> {
        if let Some(lean) = &self.stroke_plane_rhs {
            if n != self.n_dof {
                return None;
            }
            let mut f = [0.0; 2 * stroke_plane::N];
            return self.stroke_plane_variational(lean, t, y, None, &mut f, phi, dphi);
        }
        let terms = self.stroke_only.as_ref()?.jacobian.as_ref()?;
        if n != 2 {
            return None;
        }
        let y = [y.coords[0], y.coords[1], y.rates[0], y.rates[1]];
        linear_map_jacobian::variational(terms, &y, phi, dphi);
        Some(Ok(()))
    }

    fn variational_with_rhs(
        &self,
        t: f64,
        y: &State,
        sides: Option<crate::integrate::Sides>,
        n: usize,
        f: &mut [f64],
        phi: &[f64],
        dphi: &mut [f64],
    ) -> Option<Result<()>> {
        let lean = self.stroke_plane_rhs.as_ref().filter(|_| n == self.n_dof)?;
        self.stroke_plane_variational(lean, t, y, sides.map(branches), f, phi, dphi)
    }
}

impl Device {
    /// Whether the variational equations have an analytic Jacobian (the stroke-plane model,
    /// the linear map's drivetrain coordinates) rather than central differences of the
    /// right-hand side.
    pub(crate) fn has_analytic_jacobian(&self) -> bool {
        self.stroke_plane_rhs.is_some() || self.linear_map_terms().is_some()
    }

    /// The linear map's analytic Jacobian constants (drivetrain coordinates of a two-DOF
    /// linear differential with stroke drag; see [`linear_map_jacobian`]).
    pub(crate) fn linear_map_terms(&self) -> Option<&LinearMapTerms<f64>> {
        self.stroke_only.as_ref()?.jacobian.as_ref()
    }
}
