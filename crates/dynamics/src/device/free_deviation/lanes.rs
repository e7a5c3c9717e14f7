//! [`Device::rhs_free_deviation`] on held branches for four free-deviation devices at once, one
//! per SIMD lane: the §2.5 Lift PARITY right-hand side the sweep ensembles need (issue 12
//! item 6; docs/findings.md §24). Every lane runs [`generic::step`], the scalar path's own
//! code, so its derivative is the scalar one bit for bit; a lane the closed form does not
//! cover (an implausible drivetrain coordinate, a pose near a singular one, a reduced mass
//! matrix that is not positive definite) is evaluated on its own by the scalar right-hand side,
//! which also names the error of a lane that fails.

use paritysim_aero::{Branch, HeldBranch};
use paritysim_simd::{Real, f64x4};

use super::generic::{self, Constants};
use super::{Held, HeldConstants};
use crate::device::Device;
use crate::device::switched_lanes::{LaneEval, SwitchedLanes, evaluate_scalar_lanes};

type V = f64x4;

/// Lanes evaluated together.
const LANES: usize = 4;

/// The [`Held`] constants of `device` on `N` coordinates, if it has them.
fn held<const N: usize>(device: &Device) -> Option<&Held<N>> {
    let any: &dyn std::any::Any = match device.free_deviation_held.as_ref()? {
        HeldConstants::Four(h) => &**h,
        HeldConstants::Five(h) => &**h,
    };
    any.downcast_ref::<Held<N>>()
}

/// The constants of four free-deviation devices on `N` coordinates, gathered into vectors;
/// their compact states have `M` entries (`M / 2` coordinates, then as many rates, the ones
/// past `N` zero: the scalar integrator's layout).
pub(crate) struct FreeDeviationLanes<'a, const N: usize, const M: usize> {
    devices: [&'a Device; LANES],
    constants: Constants<V, N>,
    /// The lanes' common blade elements (`None`: the lanes differ, every lane is scalar).
    aero: Option<[paritysim_aero::BladeElementModel<paritysim_aero::CoefficientSet>; 2]>,
}

impl<'a, const N: usize, const M: usize> FreeDeviationLanes<'a, N, M> {
    /// Whether `device` can take a lane: the lean free-deviation model on `N` coordinates
    /// with blade elements on both wings.
    pub(crate) fn supports(device: &Device) -> bool {
        N <= M / 2 && held::<N>(device).is_some()
    }

    /// The lanes of `devices`, or `None` unless every one [`Self::supports`] lanes.
    pub(crate) fn new(devices: [&'a Device; LANES]) -> Option<Self> {
        if N > M / 2 {
            return None;
        }
        let held: [&Held<N>; LANES] = {
            let mut out = [None; LANES];
            for (l, d) in devices.iter().enumerate() {
                out[l] = Some(held::<N>(d)?);
            }
            out.map(|h| h.expect("every lane checked above"))
        };
        let aero = (1..LANES)
            .all(|l| held[l].aero == held[0].aero)
            .then_some(held[0].aero);
        Some(Self {
            devices,
            constants: Constants::lanes(held.map(|h| &h.constants)),
            aero,
        })
    }
}

impl<const N: usize, const M: usize> SwitchedLanes<M> for FreeDeviationLanes<'_, N, M> {
    fn eval(
        &self,
        t: [f64; LANES],
        forces: [[f64; 2]; LANES],
        y: &[V; M],
        branches: [[Branch; 2]; LANES],
        dydt: &mut [V; M],
    ) -> LaneEval {
        let all = (1u32 << LANES) - 1;
        let mut scalar = all;
        if let Some(aero) = &self.aero {
            let x: [V; N] = std::array::from_fn(|i| y[i]);
            let x_dot: [V; N] = std::array::from_fn(|i| y[M / 2 + i]);
            let held = [0, 1].map(|w| HeldBranch::lanes(branches.map(|b| b[w])));
            let drive = [0, 1].map(|k| V::new(forces.map(|f| f[k])));
            let step = generic::step(&self.constants, aero, drive, (&x, &x_dot), &held);
            dydt.fill(V::splat(0.0));
            dydt[..N].copy_from_slice(&x_dot);
            dydt[M / 2..M / 2 + N].copy_from_slice(&step.x_ddot);
            scalar = V::bits(step.general | step.singular) & all;
        }
        evaluate_scalar_lanes(scalar, y, dydt, |l, state, out| {
            let device = self.devices[l];
            device.free_deviation_rhs.as_ref().is_some_and(|lean| {
                device
                    .rhs_free_deviation(lean, t[l], state, Some(branches[l]), out)
                    .is_ok()
            })
        })
    }
}
