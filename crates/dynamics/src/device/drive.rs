//! The drive load, written once over [`Real`]: what the actuator and the drivetrain's springs
//! apply to the drivetrain coordinates `q = (q1, q2)` (§3.2.2 items 4-5, eq. 3.20's drive term).
//! Every right-hand side (general, drivetrain coordinates, stroke plane, free deviation, the
//! SIMD lanes) and every Jacobian of one takes it from here.

use paritysim_simd::Real;

use super::DeviceSpec;

/// The springs of the drive: the actuator stiffness `K1` (mN/mm) on `q1`, the balance spring
/// `K2` (mN·mm/rad) and a constant preload torque `P` (mN·mm) on the whippletree `q2`, and
/// whether the drivetrain is dual (one actuator per wing: `K1` on both drives, no balance
/// spring). One device, or one device per lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct DriveSprings<R: Real> {
    pub(crate) k1: R,
    pub(crate) k2: R,
    pub(crate) preload: R,
    pub(crate) dual: R::Mask,
}

impl<R: Real> DriveSprings<R> {
    /// A single drive (not dual) with springs `k1`, `k2`.
    pub(crate) fn single(k1: R, k2: R) -> Self {
        let zero = R::splat(0.0);
        Self {
            k1,
            k2,
            preload: zero,
            dual: zero.lt(zero),
        }
    }

    /// The drive load `Q` on `q` from the drive forces `forces` ([`super::Device::drive_forces`]:
    /// the actuator's and 0, or a dual drivetrain's left and right sides'):
    /// `Q = (F − K1 q1, −K2 q2 + P)`, or `(F_L − K1 q1, F_R − K1 q2)` on a dual drivetrain.
    #[inline(always)]
    pub(crate) fn load(&self, forces: [R; 2], q: [R; 2]) -> [R; 2] {
        [
            forces[0] - self.k1 * q[0],
            R::select(
                self.dual,
                forces[1] - self.k1 * q[1],
                -self.k2 * q[1] + self.preload,
            ),
        ]
    }

    /// `∂Q/∂q`, diagonal and constant: `(−K1, −K2)`, or `(−K1, −K1)` on a dual drivetrain.
    #[inline(always)]
    pub(crate) fn slope(&self) -> [R; 2] {
        [-self.k1, R::select(self.dual, -self.k1, -self.k2)]
    }
}

impl DriveSprings<f64> {
    /// The drive springs of `spec` (zero where it has no actuator or transmission).
    pub(crate) fn of(spec: &DeviceSpec, dual: bool) -> Self {
        Self {
            k1: spec.actuator.as_ref().map_or(0.0, |a| a.stiffness()),
            k2: spec
                .transmission
                .as_ref()
                .map_or(0.0, |tr| tr.balance_stiffness()),
            preload: spec.transmission.as_ref().map_or(0.0, |tr| tr.preload()),
            dual,
        }
    }

    /// The energy stored in the drive's springs at `q` (µJ): `½K1q1² + ½K2q2² − P q2`, or
    /// `½K1|q|²` on a dual drivetrain.
    pub(crate) fn energy(&self, q: [f64; 2]) -> f64 {
        if self.dual {
            0.5 * self.k1 * (q[0] * q[0] + q[1] * q[1])
        } else {
            0.5 * self.k1 * q[0] * q[0] + 0.5 * self.k2 * q[1] * q[1] - self.preload * q[1]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The load is the negative gradient of the stored energy plus the drive forces, and its
    /// slope is its derivative, for a single and a dual drive.
    #[test]
    fn the_load_is_the_forces_minus_the_energy_gradient() {
        let preloaded = DriveSprings {
            preload: 0.7,
            ..DriveSprings::single(2.0, 0.3)
        };
        let dual = DriveSprings {
            dual: true,
            ..DriveSprings::single(2.0, 0.3)
        };
        for springs in [DriveSprings::single(2.0, 0.3), preloaded, dual] {
            let forces = if springs.dual {
                [1.5, -0.5]
            } else {
                [1.5, 0.0]
            };
            let q = [0.07, -0.2];
            let load = springs.load(forces, q);
            let h = 1e-6;
            for i in 0..2 {
                let mut up = q;
                let mut down = q;
                up[i] += h;
                down[i] -= h;
                let gradient = (springs.energy(up) - springs.energy(down)) / (2.0 * h);
                assert!(
                    (load[i] - (forces[i] - gradient)).abs() <= 1e-8,
                    "{i}: {load:?}"
                );
                let slope =
                    (springs.load(forces, up)[i] - springs.load(forces, down)[i]) / (2.0 * h);
                assert!((springs.slope()[i] - slope).abs() <= 1e-8);
            }
        }
    }
}
