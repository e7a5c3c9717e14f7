//! A driven device's stroboscopic map as a [`PeriodMap`], so the periodic steady state of any
//! device can be continued in a parameter with its Floquet multipliers and bifurcations
//! ([`paritysim_continuation`], issue 18).

use nalgebra::{DMatrix, DVector};
use paritysim_continuation::{Branch, ContinuationOptions, PeriodMap, continue_orbits};
use paritysim_error::{Error, Result};

use crate::device::{Device, DeviceSpec};
use crate::integrate::RungeKutta;
use crate::stability::{
    ShootingOptions, compact_state, drive_period, expand_state, periodic_orbit, stroboscopic_map,
    with_balance_spring,
};

/// `x ↦ P(x; p)` for the device that `build(p)` makes; the state `x` is the compact
/// `(coordinates, rates)` of the integrated coordinates (2n entries), on the section `t = 0`.
/// The monodromy is the exact derivative of the computed map (forward sensitivities,
/// [`RungeKutta::flow_with_sensitivity`]), as in [`crate::stability::floquet`].
pub struct DevicePeriodMap<F> {
    build: F,
    integrator: RungeKutta,
    coordinates: usize,
}

impl<F: Fn(&[f64]) -> Result<Device> + Sync> DevicePeriodMap<F> {
    /// A map over the devices `build` makes; `parameters` are used once to size the state.
    ///
    /// # Errors
    /// `build`'s error; [`Error::InvalidParameter`] for bad integration options.
    pub fn new(build: F, parameters: &[f64], options: &ShootingOptions) -> Result<Self> {
        let device = build(parameters)?;
        let integrator = options.integrator(drive_period(&device)?)?;
        Ok(DevicePeriodMap {
            coordinates: device.n_dof(),
            build,
            integrator: integrator.with_work(false),
        })
    }

    fn run(&self, x: &DVector<f64>, parameters: &[f64]) -> Result<(Device, f64)> {
        if x.len() != 2 * self.coordinates {
            return Err(Error::Shape(format!(
                "state has {} entries, the device integrates {}",
                x.len(),
                2 * self.coordinates
            )));
        }
        let device = (self.build)(parameters)?;
        if device.n_dof() != self.coordinates {
            return Err(Error::Shape(
                "the parameter changed the device's number of coordinates".into(),
            ));
        }
        let period = drive_period(&device)?;
        Ok((device, period))
    }
}

impl<F: Fn(&[f64]) -> Result<Device> + Sync> PeriodMap for DevicePeriodMap<F> {
    fn dim(&self) -> usize {
        2 * self.coordinates
    }

    fn image(&self, x: &DVector<f64>, parameters: &[f64]) -> Result<DVector<f64>> {
        let (device, period) = self.run(x, parameters)?;
        let n = self.coordinates;
        let out = stroboscopic_map(&device, &self.integrator, 0.0, period, &expand_state(n, x))?;
        Ok(compact_state(n, &out))
    }

    fn image_and_jacobian(
        &self,
        x: &DVector<f64>,
        parameters: &[f64],
    ) -> Result<(DVector<f64>, DMatrix<f64>)> {
        let (device, period) = self.run(x, parameters)?;
        let n = self.coordinates;
        let y = expand_state(n, x);
        let (out, jacobian) = self
            .integrator
            .flow_with_sensitivity(&device, 0.0, &y, period)?;
        Ok((compact_state(n, &out), jacobian))
    }
}

/// Continues the periodic orbit of `spec` in its balance-beam stiffness K2 (mN·mm/rad) from
/// `start` to `options.stop` (`options.parameter` must be 0). The first orbit is found by
/// [`periodic_orbit`] at `start`.
///
/// # Errors
/// As [`with_balance_spring`], [`periodic_orbit`] and [`continue_orbits`].
pub fn continue_balance_spring(
    spec: &DeviceSpec,
    start: f64,
    options: &ContinuationOptions,
    shooting: &ShootingOptions,
) -> Result<Branch> {
    let build = |p: &[f64]| Device::new(with_balance_spring(spec, p[0])?);
    let first = build(&[start])?;
    let orbit = periodic_orbit(&first, shooting)?;
    let map = DevicePeriodMap::new(build, &[start], shooting)?;
    let x0 = compact_state(first.n_dof(), &orbit.state);
    continue_orbits(&map, &x0, &[start], options)
}
