//! The device as an [`OdeSystem`](crate::integrate::OdeSystem) of the integrator: every call
//! goes to the device's one [`Form`](super::form::Form).

use paritysim_error::Result;

use super::Device;
use super::equations::Equations;
use super::switches::branches;
use crate::integrate::{MAX_SWITCHES, Sides, State};

// The device is an ODE system of the integrator (the integrator itself knows no device).
impl crate::integrate::OdeSystem for Device {
    #[inline]
    fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> Result<()> {
        Device::rhs(self, t, y, dydt)
    }

    fn n_active(&self) -> usize {
        self.n_dof()
    }

    fn n_switches(&self) -> usize {
        self.n_switches
    }

    fn switches(&self, _t: f64, y: &State, g: &mut [f64; MAX_SWITCHES]) -> Result<()> {
        self.form.switches(self, y, g)
    }

    #[inline]
    fn rhs_on(&self, t: f64, y: &State, sides: Sides, dydt: &mut State) -> Result<()> {
        self.form.rhs(self, t, y, self.held(sides), dydt)
    }

    fn rhs_on_batch(
        &self,
        t: f64,
        sides: Sides,
        ys: &[State],
        out: &mut [State],
    ) -> Option<std::result::Result<(), (usize, paritysim_error::Error)>> {
        if ys.len() < 2 {
            return None;
        }
        self.form.rhs_batch(self, t, self.held(sides)?, ys, out)
    }

    fn variational(
        &self,
        t: f64,
        y: &State,
        n: usize,
        phi: &[f64],
        dphi: &mut [f64],
    ) -> Option<Result<()>> {
        self.form.variational(self, t, y, None, n, None, phi, dphi)
    }

    fn variational_with_rhs(
        &self,
        t: f64,
        y: &State,
        sides: Option<Sides>,
        n: usize,
        f: &mut [f64],
        phi: &[f64],
        dphi: &mut [f64],
    ) -> Option<Result<()>> {
        let branches = sides.and_then(|s| self.held(s));
        self.form
            .variational(self, t, y, branches, n, Some(f), phi, dphi)
    }
}

impl Device {
    /// The blade-element branches the integrator holds (`None` without switching functions:
    /// the right-hand side is smooth and evaluates each state's own sides).
    #[inline]
    fn held(&self, sides: Sides) -> Option<[paritysim_aero::Branch; 2]> {
        (self.n_switches > 0).then(|| branches(sides))
    }

    /// Whether the variational equations have an analytic Jacobian (the stroke-plane model,
    /// the linear map's drivetrain coordinates) rather than central differences of the
    /// right-hand side.
    pub(crate) fn has_analytic_jacobian(&self) -> bool {
        self.form.has_analytic_jacobian()
    }

    /// The linear map's analytic Jacobian constants (drivetrain coordinates of a two-DOF
    /// linear differential with stroke drag; see [`super::linear_map`]).
    pub(crate) fn linear_map_terms(&self) -> Option<&super::linear_map::LinearMapTerms<f64>> {
        self.form.linear_map_terms()
    }
}
