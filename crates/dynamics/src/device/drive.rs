//! The drive load, written once over [`Real`]: what the actuator and the drivetrain's springs
//! apply to the drivetrain coordinates `q = (q1, q2)` (§3.2.2 items 4-5, eq. 3.20's drive term).
//! Every right-hand side (general, drivetrain coordinates, stroke plane, free deviation, the
//! SIMD lanes) and every Jacobian of one takes it from here.

use paritysim_simd::Real;

use super::DeviceSpec;

/// The springs and losses of the drive: the actuator stiffness `K1` (mN/mm), its cubic
/// stiffness `K1c` (mN/mm³) and damping `b1` (mN·ms/mm) on `q1`; the balance spring `K2`
/// (mN·mm/rad), its cubic stiffness `K2c` (mN·mm/rad³), damping `b2` (mN·mm·ms/rad) and a
/// constant preload torque `P` (mN·mm) on the whippletree `q2`; the actuator's effective mass
/// `m` (mg) on `q1`; and whether the drivetrain is dual (one actuator per wing: `K1`, `K1c`,
/// `b1` and `m` on both drives, no balance spring). One device, or one device per lane.
///
/// Every term beyond `K1`, `K2`, `P` defaults to zero, and then the load takes its previous
/// expression (`lossless`): today's results to the bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct DriveSprings<R: Real> {
    pub(crate) k1: R,
    pub(crate) k2: R,
    pub(crate) preload: R,
    pub(crate) k1_cubic: R,
    pub(crate) k2_cubic: R,
    pub(crate) b1: R,
    pub(crate) b2: R,
    /// The actuator's effective mass on `q1` (mg): not a load, the forms add it to `M_q`.
    pub(crate) mass: R,
    pub(crate) dual: R::Mask,
    /// Whether every cubic and damping term is zero (in every lane): the load skips them (one
    /// predictable branch; the default path then costs what it did before them).
    pub(crate) lossless: bool,
}

impl<R: Real> DriveSprings<R> {
    /// A single drive (not dual) with springs `k1`, `k2`.
    pub(crate) fn single(k1: R, k2: R) -> Self {
        let zero = R::splat(0.0);
        Self {
            k1,
            k2,
            preload: zero,
            k1_cubic: zero,
            k2_cubic: zero,
            b1: zero,
            b2: zero,
            mass: zero,
            dual: zero.lt(zero),
            lossless: true,
        }
    }

    /// The drive load `Q` on `q` at the rates `q_dot` from the drive forces `forces`
    /// ([`super::Device::drive_forces`]: the actuator's and 0, or a dual drivetrain's left and
    /// right sides'): `Q1 = F − K1 q1 − (K1c q1³ + b1 q̇1)`,
    /// `Q2 = −K2 q2 + P − (K2c q2³ + b2 q̇2)`, or `Q2 = F_R − K1 q2 − (K1c q2³ + b1 q̇2)` on a
    /// dual drivetrain.
    #[inline(always)]
    pub(crate) fn load(&self, forces: [R; 2], q: [R; 2], q_dot: [R; 2]) -> [R; 2] {
        if self.lossless {
            return [
                forces[0] - self.k1 * q[0],
                R::select(
                    self.dual,
                    forces[1] - self.k1 * q[1],
                    -self.k2 * q[1] + self.preload,
                ),
            ];
        }
        let extra1 = self.k1_cubic * q[0] * q[0] * q[0] + self.b1 * q_dot[0];
        let cubic2 = R::select(self.dual, self.k1_cubic, self.k2_cubic);
        let b2 = R::select(self.dual, self.b1, self.b2);
        let extra2 = cubic2 * q[1] * q[1] * q[1] + b2 * q_dot[1];
        [
            forces[0] - self.k1 * q[0] - extra1,
            R::select(
                self.dual,
                forces[1] - self.k1 * q[1],
                -self.k2 * q[1] + self.preload,
            ) - extra2,
        ]
    }

    /// `∂Q/∂q` at `q`, diagonal: `(−K1 − 3 K1c q1², −K2 − 3 K2c q2²)`, or with `K1`, `K1c` on
    /// both drives of a dual drivetrain.
    #[inline(always)]
    pub(crate) fn slope(&self, q: [R; 2]) -> [R; 2] {
        if self.lossless {
            return [-self.k1, R::select(self.dual, -self.k1, -self.k2)];
        }
        let three = R::splat(3.0);
        let k2 = R::select(self.dual, self.k1, self.k2);
        let cubic2 = R::select(self.dual, self.k1_cubic, self.k2_cubic);
        [
            -self.k1 - three * self.k1_cubic * q[0] * q[0],
            -k2 - three * cubic2 * q[1] * q[1],
        ]
    }

    /// The actuator mass on each drive coordinate, per lane: `(m, 0)`, or `(m, m)` on a dual
    /// drivetrain.
    #[inline(always)]
    pub(crate) fn lane_masses(&self) -> [R; 2] {
        [self.mass, R::select(self.dual, self.mass, R::splat(0.0))]
    }

    /// `∂Q/∂q̇`, diagonal and constant: `(−b1, −b2)`, or `(−b1, −b1)` on a dual drivetrain.
    #[inline(always)]
    pub(crate) fn damping(&self) -> [R; 2] {
        if self.lossless {
            return [R::splat(0.0); 2];
        }
        [-self.b1, R::select(self.dual, -self.b1, -self.b2)]
    }
}

impl DriveSprings<f64> {
    /// The drive springs of `spec` (zero where it has no actuator or transmission).
    pub(crate) fn of(spec: &DeviceSpec, dual: bool) -> Self {
        let actuator =
            |f: fn(&crate::actuator::Actuator) -> f64| spec.actuator.as_ref().map_or(0.0, f);
        let transmission =
            |f: fn(&super::Transmission) -> f64| spec.transmission.as_ref().map_or(0.0, f);
        Self {
            k1: actuator(|a| a.stiffness()),
            k2: transmission(|tr| tr.balance_spring()),
            preload: transmission(|tr| tr.preload()),
            k1_cubic: actuator(|a| a.cubic_stiffness()),
            k2_cubic: transmission(|tr| tr.balance_cubic()),
            b1: actuator(|a| a.damping()),
            b2: transmission(|tr| tr.balance_damping()),
            mass: actuator(|a| a.mass()),
            dual,
            lossless: true,
        }
        .with_lossless_flag()
    }

    /// `self` with [`Self::lossless`] set from its terms.
    pub(crate) fn with_lossless_flag(mut self) -> Self {
        self.lossless = [self.k1_cubic, self.k2_cubic, self.b1, self.b2] == [0.0; 4];
        self
    }

    /// Whether every term beyond `K1`, `K2`, `P` is zero (today's drive: the closed forms that
    /// take no actuator mass, drive damping or cubic drive stiffness apply).
    pub(crate) fn is_linear_lossless(&self) -> bool {
        self.lossless && self.mass == 0.0
    }

    /// The actuator mass on each drive coordinate: `(m, 0)`, or `(m, m)` on a dual drivetrain.
    pub(crate) fn masses(&self) -> [f64; 2] {
        [self.mass, if self.dual { self.mass } else { 0.0 }]
    }

    /// The energy stored in the drive's springs at `q` (µJ):
    /// `½K1q1² + ¼K1c q1⁴ + ½K2q2² + ¼K2c q2⁴ − P q2`, or `½K1|q|² + ¼K1c Σ q_i⁴` on a dual
    /// drivetrain.
    pub(crate) fn energy(&self, q: [f64; 2]) -> f64 {
        let quartic = |c: f64, x: f64| 0.25 * c * (x * x) * (x * x);
        if self.dual {
            0.5 * self.k1 * (q[0] * q[0] + q[1] * q[1])
                + quartic(self.k1_cubic, q[0])
                + quartic(self.k1_cubic, q[1])
        } else {
            0.5 * self.k1 * q[0] * q[0] + 0.5 * self.k2 * q[1] * q[1] - self.preload * q[1]
                + quartic(self.k1_cubic, q[0])
                + quartic(self.k2_cubic, q[1])
        }
    }

    /// The actuator's kinetic energy `½ m q̇1²` (and `½ m q̇2²` on a dual drivetrain) (µJ).
    pub(crate) fn kinetic(&self, q_dot: [f64; 2]) -> f64 {
        let [m1, m2] = self.masses();
        0.5 * (m1 * q_dot[0] * q_dot[0] + m2 * q_dot[1] * q_dot[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The load is the drive forces minus the energy gradient minus the damping, its slope is
    /// its derivative in `q` and its damping its derivative in `q̇`, for a single and a dual
    /// drive, linear and with cubic springs and dampers; with the new terms zero it is today's
    /// load to the bit.
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
        let lossy = DriveSprings {
            k1_cubic: 40.0,
            k2_cubic: 0.9,
            b1: 0.05,
            b2: 0.02,
            mass: 3.0,
            ..preloaded
        }
        .with_lossless_flag();
        let lossy_dual = DriveSprings {
            dual: true,
            ..lossy
        };
        for springs in [
            DriveSprings::single(2.0, 0.3),
            preloaded,
            dual,
            lossy,
            lossy_dual,
        ] {
            let forces = if springs.dual {
                [1.5, -0.5]
            } else {
                [1.5, 0.0]
            };
            let q = [0.07, -0.2];
            let q_dot = [0.4, -1.3];
            let load = springs.load(forces, q, q_dot);
            let h = 1e-6;
            for i in 0..2 {
                let mut up = q;
                let mut down = q;
                up[i] += h;
                down[i] -= h;
                let gradient = (springs.energy(up) - springs.energy(down)) / (2.0 * h);
                let damping = springs.damping()[i] * q_dot[i];
                assert!(
                    (load[i] - (forces[i] - gradient + damping)).abs() <= 1e-8,
                    "{i}: {load:?}"
                );
                let slope = (springs.load(forces, up, q_dot)[i]
                    - springs.load(forces, down, q_dot)[i])
                    / (2.0 * h);
                assert!((springs.slope(q)[i] - slope).abs() <= 1e-7);
                let (mut fast, mut slow) = (q_dot, q_dot);
                fast[i] += h;
                slow[i] -= h;
                let rate_slope = (springs.load(forces, q, fast)[i]
                    - springs.load(forces, q, slow)[i])
                    / (2.0 * h);
                assert!((springs.damping()[i] - rate_slope).abs() <= 1e-8);
            }
            if springs.is_linear_lossless() {
                // Today's load, written out.
                let today = [
                    forces[0] - springs.k1 * q[0],
                    if springs.dual {
                        forces[1] - springs.k1 * q[1]
                    } else {
                        -springs.k2 * q[1] + springs.preload
                    },
                ];
                assert_eq!(load.map(f64::to_bits), today.map(f64::to_bits));
            }
        }
    }
}
