//! The lean right-hand side of the §2.5 free-deviation devices (Lift and Dual PARITY: two wings
//! with θ free on α2 = 90°, α3 = 0 shoulders, on the linear map of eq. 2.15): eq. 3.20 in
//! null-space coordinates with each wing's closed-form terms ([`crate::Wing`]'s
//! `free_deviation_dynamics`), assembled directly on the `n` integrated coordinates.
//!
//! The general path (`null_space.rs`) computes the same equations through the 6-vector
//! `p̈ = N (Nᵀ M N)⁻¹ Nᵀ f` and then `ẍ = Nᵀ p̈`; here `ẍ = (Nᵀ M N)⁻¹ Nᵀ f` (the two agree
//! because `N` has orthonormal columns), the coordinates use only the basis' `n` columns, the
//! drivetrain's inverse kinematics are the constant `J⁻¹` of the linear map (`q = J⁻¹ φ`,
//! `τ_φ = J⁻ᵀ Q`, as `stroke_plane/` does) instead of an LU solve and a Newton correction per
//! call, and the terms that only recordings read (the wing deviation's `atan2`, the kinetic
//! energy, the full `Evaluation`) are not formed. Tested against the general path to 1e-12
//! (`device/free_deviation/tests.rs`); the variational equations differentiate it.

use nalgebra::{Matrix2, SMatrix, SVector, Vector2, Vector3};
use paritysim_aero::Branch;
use paritysim_error::{Error, Result};

use super::equations::Equations;
use super::{Device, Formulation};
use crate::integrate::State;

pub(crate) mod generic;
#[cfg(test)]
mod tests;

/// The constants of [`generic::step`] on `N` coordinates: the device's own, the same in every
/// lane (batches of one device's states) and its wings' blade elements.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Held<const N: usize> {
    pub(crate) constants: generic::Constants<f64, N>,
    pub(crate) splat: generic::Constants<paritysim_simd::f64x4, N>,
    pub(crate) aero: [paritysim_aero::BladeElementModel<paritysim_aero::CoefficientSet>; 2],
}

impl<const N: usize> Held<N> {
    fn of(device: &Device, lean: &FreeDeviation) -> Option<Self> {
        let constants = generic::Constants::of(device, lean)?;
        Some(Self {
            constants,
            splat: generic::Constants::lanes([&constants; 4]),
            aero: generic::blade_models(device)?,
        })
    }
}

/// [`Held`] for the devices' coordinate counts: four (Lift PARITY) or five (Dual PARITY).
#[derive(Clone, Debug)]
pub(crate) enum HeldConstants {
    Four(Box<Held<4>>),
    Five(Box<Held<5>>),
}

// Derived from the spec, which `Device`'s equality compares.
impl PartialEq for HeldConstants {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl HeldConstants {
    /// Those of `device`, or `None` unless it has the lean free-deviation model on four or
    /// five coordinates with blade elements on both wings.
    fn of(device: &Device, lean: &FreeDeviation) -> Option<Self> {
        match device.n_dof {
            4 => Held::of(device, lean).map(|h| Self::Four(Box::new(h))),
            5 => Held::of(device, lean).map(|h| Self::Five(Box::new(h))),
            _ => None,
        }
    }
}

/// The constants of [`Device::rhs_free_deviation`].
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct FreeDeviation {
    /// `J⁻¹` and `J⁻ᵀ` of the linear map.
    pub(crate) inverse: Matrix2<f64>,
    pub(crate) inverse_transpose: Matrix2<f64>,
    /// The held-branch equations over `Real` ([`generic::step`]), where they apply.
    held: Option<HeldConstants>,
}

impl FreeDeviation {
    /// The lean model when `device` applies: null-space coordinates, two wings with the
    /// closed-form free deviation, the 2-DOF linear map.
    pub(super) fn of(device: &Device) -> Option<Self> {
        // No actuator mass (it couples the wings' blocks) and no hinge damping: the general
        // form runs those.
        let applies = device.formulation == Formulation::NullSpace
            && device.n_wings() == 2
            && device.free_deviation == [true, true]
            && device.drive.mass == 0.0
            && device.spec.wings.iter().all(|w| w.hinge_damping() == 0.0);
        let jacobian = device.linear_jacobian.filter(|_| applies)?;
        let inverse = jacobian.try_inverse()?;
        let mut lean = Self {
            inverse,
            inverse_transpose: inverse.transpose(),
            held: None,
        };
        lean.held = HeldConstants::of(device, &lean);
        Some(lean)
    }
}

impl Device {
    /// The right-hand side of a free-deviation device ([`FreeDeviation`]); the blade elements
    /// on `branches` when given (event location), else on the state's own sides.
    ///
    /// # Errors
    /// As the general path, which takes over (and names the cause) for a drivetrain
    /// coordinate beyond the linkage's plausible range or a pose where the closed form does
    /// not apply; a reduced mass matrix that is not positive definite.
    #[inline]
    pub(super) fn rhs_free_deviation(
        &self,
        lean: &FreeDeviation,
        t: f64,
        y: &State,
        branches: Option<[Branch; 2]>,
        dydt: &mut State,
    ) -> Result<()> {
        match (&lean.held, branches) {
            (Some(HeldConstants::Four(held)), Some(branches)) => {
                return self.rhs_free_deviation_held(held, t, y, branches, dydt);
            }
            (Some(HeldConstants::Five(held)), Some(branches)) => {
                return self.rhs_free_deviation_held(held, t, y, branches, dydt);
            }
            _ => {}
        }
        let lean_rhs = match self.n_dof {
            1 => self.free_deviation_step::<1>(lean, t, y, branches),
            2 => self.free_deviation_step::<2>(lean, t, y, branches),
            3 => self.free_deviation_step::<3>(lean, t, y, branches),
            4 => self.free_deviation_step::<4>(lean, t, y, branches),
            5 => self.free_deviation_step::<5>(lean, t, y, branches),
            _ => self.free_deviation_step::<6>(lean, t, y, branches),
        }?;
        match lean_rhs {
            Some(derivative) => {
                *dydt = derivative;
                Ok(())
            }
            None => self.rhs_null_space_on(t, y, branches, dydt),
        }
    }

    /// [`Self::rhs_free_deviation`] on held `branches` through [`generic::step`] (the code the
    /// SIMD lanes share).
    ///
    /// # Errors
    /// As [`Self::rhs_free_deviation`].
    #[inline]
    fn rhs_free_deviation_held<const N: usize>(
        &self,
        held: &Held<N>,
        t: f64,
        y: &State,
        branches: [Branch; 2],
        dydt: &mut State,
    ) -> Result<()> {
        let forces = self.drive_forces(t);
        let x: [f64; N] = std::array::from_fn(|i| y.coords[i]);
        let x_dot: [f64; N] = std::array::from_fn(|i| y.rates[i]);
        let on = branches.map(paritysim_aero::HeldBranch::of);
        let step = generic::step(&held.constants, &held.aero, forces, (&x, &x_dot), &on);
        if step.general {
            // The general path names the implausible coordinate or takes the pose.
            return self.rhs_null_space_on(t, y, Some(branches), dydt);
        }
        if step.singular {
            return Err(Error::Singular(format!(
                "reduced mass matrix is not positive definite at x = {:?}",
                &y.coords[..N]
            )));
        }
        *dydt = State::default();
        for i in 0..N {
            dydt.coords[i] = y.rates[i];
            dydt.rates[i] = step.x_ddot[i];
        }
        let q_dot = Vector2::new(step.q_dot[0], step.q_dot[1]);
        dydt.work_actuator = self.actuator_power(t, forces[0], &q_dot);
        dydt.work_aero = step.aero_power;
        Ok(())
    }

    /// [`Self::rhs_free_deviation`] of several states at `t` on held `branches`, four at a
    /// time in SIMD lanes ([`generic::step`]: each the scalar result bit for bit; lanes off
    /// the closed form one by one on the scalar path).
    ///
    /// # Errors
    /// The first failing state's index and error.
    #[allow(clippy::needless_range_loop)] // coordinates index the state and the lanes alike
    pub(super) fn free_deviation_batch<const N: usize>(
        &self,
        (held, lean): (&Held<N>, &FreeDeviation),
        t: f64,
        branches: [Branch; 2],
        ys: &[State],
        out: &mut [State],
    ) -> std::result::Result<(), (usize, Error)> {
        use paritysim_simd::{Real, f64x4};
        let forces = self.drive_forces(t);
        let drive = forces.map(f64x4::splat);
        let on = branches.map(|b| paritysim_aero::HeldBranch::lanes([b; 4]));
        for start in (0..ys.len()).step_by(4) {
            let count = (ys.len() - start).min(4);
            let lane = |l: usize| &ys[start + l.min(count - 1)];
            let x: [f64x4; N] =
                std::array::from_fn(|i| f64x4::new(std::array::from_fn(|l| lane(l).coords[i])));
            let x_dot: [f64x4; N] =
                std::array::from_fn(|i| f64x4::new(std::array::from_fn(|l| lane(l).rates[i])));
            let step = generic::step(&held.splat, &held.aero, drive, (&x, &x_dot), &on);
            let scalar = f64x4::bits(step.general | step.singular);
            let x_ddot = step.x_ddot.map(|v| v.to_array());
            let (q_dot, aero_power) =
                (step.q_dot.map(|v| v.to_array()), step.aero_power.to_array());
            for l in 0..count {
                let k = start + l;
                if scalar & (1 << l) != 0 {
                    self.rhs_free_deviation(lean, t, &ys[k], Some(branches), &mut out[k])
                        .map_err(|e| (k, e))?;
                    continue;
                }
                let mut d = State::default();
                for i in 0..N {
                    d.coords[i] = ys[k].rates[i];
                    d.rates[i] = x_ddot[i][l];
                }
                let q_dot = Vector2::new(q_dot[0][l], q_dot[1][l]);
                d.work_actuator = self.actuator_power(t, forces[0], &q_dot);
                d.work_aero = aero_power[l];
                out[k] = d;
            }
        }
        Ok(())
    }

    /// The derivative of [`Self::rhs_free_deviation`] on `N` coordinates; `Ok(None)` where
    /// the general path must take over (see there).
    #[inline(always)]
    fn free_deviation_step<const N: usize>(
        &self,
        lean: &FreeDeviation,
        t: f64,
        y: &State,
        branches: Option<[Branch; 2]>,
    ) -> Result<Option<State>> {
        // p = offset + N x, ṗ = N ẋ on the basis' first N columns.
        let mut p = [0.0; 6];
        let mut p_dot = [0.0; 6];
        for i in 0..6 {
            let (mut v, mut r) = (self.offset[i], 0.0);
            for k in 0..N {
                v += self.basis[(i, k)] * y.coords[k];
                r += self.basis[(i, k)] * y.rates[k];
            }
            p[i] = v;
            p_dot[i] = r;
        }
        let q = lean.inverse * Vector2::new(p[0], p[3]);
        if !(q.x.abs() <= paritysim_error::plausible::OFFSET_MM
            && q.y.abs() <= paritysim_error::plausible::ANGLE_RAD)
        {
            return Ok(None);
        }
        let q_dot = lean.inverse * Vector2::new(p_dot[0], p_dot[3]);
        let (force, load, _) = self.drive_load(t, &q, &q_dot);
        let drive_torque = lean.inverse_transpose * load;

        let mut reduced_mass = SMatrix::<f64, N, N>::zeros();
        let mut reduced_force = SVector::<f64, N>::zeros();
        let mut aero_power = 0.0;
        for (w, wing) in self.spec.wings.iter().enumerate() {
            let k = 3 * w;
            let pw = Vector3::new(p[k], p[k + 1], p[k + 2]);
            let vw = Vector3::new(p_dot[k], p_dot[k + 1], p_dot[k + 2]);
            let Some(kinematics) = wing.free_deviation_kinematics(&pw, &vw) else {
                return Ok(None);
            };
            let terms = wing.free_deviation_dynamics(&pw, &vw, &kinematics, branches.map(|b| b[w]));
            let mut f = terms.aero - terms.coriolis - terms.spring;
            f.x += drive_torque[w];
            aero_power += terms.aero.dot(&vw);
            let basis_w: SMatrix<f64, 3, N> = self.basis.fixed_view::<3, N>(k, 0).into_owned();
            reduced_mass += basis_w.transpose() * (terms.mass * basis_w);
            reduced_force += basis_w.transpose() * f;
        }
        let Some(cholesky) = reduced_mass.cholesky() else {
            return Err(Error::Singular(format!(
                "reduced mass matrix is not positive definite at x = {:?}",
                &y.coords[..N]
            )));
        };
        let x_ddot = cholesky.solve(&reduced_force);
        let mut dydt = State::default();
        for i in 0..N {
            dydt.coords[i] = y.rates[i];
            dydt.rates[i] = x_ddot[i];
        }
        dydt.work_actuator = self.actuator_power(t, force, &q_dot);
        dydt.work_aero = aero_power;
        Ok(Some(dydt))
    }
}

impl Equations for FreeDeviation {
    #[inline]
    fn rhs(
        &self,
        device: &Device,
        t: f64,
        y: &State,
        branches: Option<[Branch; 2]>,
        dydt: &mut State,
    ) -> Result<()> {
        device.rhs_free_deviation(self, t, y, branches, dydt)
    }

    fn rhs_batch(
        &self,
        device: &Device,
        t: f64,
        branches: [Branch; 2],
        ys: &[State],
        out: &mut [State],
    ) -> Option<std::result::Result<(), (usize, Error)>> {
        Some(match self.held.as_ref()? {
            HeldConstants::Four(held) => {
                device.free_deviation_batch((held, self), t, branches, ys, out)
            }
            HeldConstants::Five(held) => {
                device.free_deviation_batch((held, self), t, branches, ys, out)
            }
        })
    }
}
