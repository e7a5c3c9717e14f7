//! The one equations trait: what every form of a device's equations of motion provides (the
//! right-hand side on the state's own sides or on held blade-element branches, the switching
//! functions, the analytic variational equations where it has them, batches of states).
//! `form.rs` chooses a device's form; each form implements this trait in its own file.

use paritysim_aero::Branch;
use paritysim_error::{Error, Result};

use super::Device;
use crate::integrate::{MAX_SWITCHES, State};

/// One form of the equations of motion (eq. 3.20 and its closed-form reductions).
pub(crate) trait Equations {
    /// `ẏ = f(t, y)`, with the blade elements on `branches` when given (event location), else
    /// on the state's own sides; the last two entries integrate the actuator and aerodynamic
    /// work.
    ///
    /// # Errors
    /// A pose or drivetrain coordinate outside the model's domain; a singular mass matrix.
    fn rhs(
        &self,
        device: &Device,
        t: f64,
        y: &State,
        branches: Option<[Branch; 2]>,
        dydt: &mut State,
    ) -> Result<()>;

    /// The switching functions at `y` (one per blade-element switch, `1` where none).
    ///
    /// # Errors
    /// As the general wing terms.
    fn switches(&self, device: &Device, y: &State, g: &mut [f64; MAX_SWITCHES]) -> Result<()> {
        device.blade_switching_functions(y, g)
    }

    /// The variational equations `Φ̇ = (∂f/∂y) Φ` on `n` coordinates from an analytic Jacobian,
    /// also writing `f` when `rhs` is given; `None`: the caller differentiates numerically.
    #[allow(clippy::too_many_arguments)]
    fn variational(
        &self,
        _device: &Device,
        _t: f64,
        _y: &State,
        _branches: Option<[Branch; 2]>,
        _n: usize,
        _rhs: Option<&mut [f64]>,
        _phi: &[f64],
        _dphi: &mut [f64],
    ) -> Option<Result<()>> {
        None
    }

    /// The right-hand sides of several states at `t` on held `branches`, four at a time in SIMD
    /// lanes; `None` when the form has no batch (the caller loops).
    fn rhs_batch(
        &self,
        _device: &Device,
        _t: f64,
        _branches: [Branch; 2],
        _ys: &[State],
        _out: &mut [State],
    ) -> Option<std::result::Result<(), (usize, Error)>> {
        None
    }
}
