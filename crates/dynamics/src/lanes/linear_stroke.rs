//! The drivetrain-coordinate right-hand side of [`Formulation::DrivetrainCoordinates`] for the
//! linear differential map (eq. 2.15) in SIMD lanes, one device per lane: the scalar form's own
//! equations ([`linear_map::accelerations`] and [`linear_map::variational`], generic over the
//! number type), so a lane's derivative is bit-identical to the scalar one; the force is the
//! scalar [`Actuator::force`] of each lane's time (any waveform).

use wide::f64x4;

use crate::actuator::{Actuator, Waveform};
use crate::device::{Device, Formulation};
use std::rc::Rc;

use crate::device::DriveSprings;
use crate::device::linear_map::{self, LinearMapTerms};
use crate::integrate::lanes::{LANES, LaneRhs, stage_times};
use crate::wing::WingAero;

type V = f64x4;

/// Per-device constants of the lane right-hand side.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LinearStroke<'a> {
    actuator: &'a Actuator,
    /// The constants of the equations and of their Jacobian, the device's own.
    terms: LinearMapTerms<f64>,
    /// Wings without aerodynamics (their torque is exactly 0).
    vacuum: [bool; 2],
}

impl<'a> LinearStroke<'a> {
    /// The constants of `device`, or `None` unless it integrates drivetrain coordinates of a
    /// two-DOF linear differential with an actuator and stroke drag (or no aerodynamics) on
    /// both wings: the devices whose scalar right-hand side this model reproduces exactly.
    pub(crate) fn of(device: &'a Device) -> Option<Self> {
        if device.formulation() != Formulation::DrivetrainCoordinates || device.n_dof() != 2 {
            return None;
        }
        let terms = *device.linear_map_terms()?;
        // Polynomial transmissions and dual drives run scalar (their state-dependent mass matrix
        // and per-side forces are not in the lane gathers).
        if terms.polynomial || terms.drive.dual {
            return None;
        }
        if terms.det == 0.0 || !terms.det.is_finite() {
            return None; // the scalar path reports the singular drivetrain
        }
        let spec = device.spec();
        let actuator = spec.actuator.as_ref()?;
        let vacuum = [0, 1].map(|k| matches!(spec.wings[k].aero(), WingAero::None));
        Some(Self {
            actuator,
            terms,
            vacuum,
        })
    }
}

impl<'a> LinearStroke<'a> {
    /// The actuator force at `t` (mN).
    pub(crate) fn force(&self, t: f64) -> f64 {
        self.actuator.force(t)
    }

    /// The actuator.
    pub(crate) fn actuator(&self) -> &'a Actuator {
        self.actuator
    }

    /// What `StrokeSample::of_stroke_device` computes at up to four states of this device
    /// (one per vector lane, compact `[q1, q2, q̇1, q̇2]`), with its operations: the mask of
    /// states inside the drivetrain's domain, the strokes `(φL, φR)` and the roll torques
    /// (left mirrored).
    pub(crate) fn stroke_samples(&self, y: &[V; 4]) -> (u32, [V; 2], [V; 2]) {
        let [q1, q2, q1_dot, q2_dot] = *y;
        let inside = (q1
            .abs()
            .simd_le(V::splat(paritysim_error::plausible::OFFSET_MM))
            & q2.abs()
                .simd_le(V::splat(paritysim_error::plausible::ANGLE_RAD)))
        .to_bitmask();
        let j = self.terms.jacobian.map(V::splat);
        let stroke = [j[0] * q1 + j[1] * q2, j[2] * q1 + j[3] * q2];
        let rate = [j[0] * q1_dot + j[1] * q2_dot, j[2] * q1_dot + j[3] * q2_dot];
        let torque = |k: usize| {
            if self.vacuum[k] {
                V::splat(0.0)
            } else {
                paritysim_aero::stroke_drag_torque(V::splat(self.terms.drag[k]), rate[k])
            }
        };
        (inside, stroke, [-torque(0), torque(1)])
    }
}

/// A table on a grid (its stage times) of what `K` (a drive) gives there.
type Table<K> = (Rc<[f64]>, K, Rc<[f64]>);

/// Tables of actuator forces at the [`stage_times`] of grids: the drive's `sin` once per grid
/// instead of once per evaluation (a grid is shared by a point's Newton periods, usually by
/// its chain neighbours, and by a sensitivity's perturbed periods). Drives with the same force
/// ([`Actuator::same_force`]) share a table; sine drives that differ only in amplitude,
/// offset, DC treatment or force per volt share the sines ([`Waveform::same_sine`]), each
/// force computed from them by [`Actuator::force_of_sine`], the force's own operations, so a
/// table holds [`Actuator::force`]'s bits.
#[derive(Clone, Default)]
pub(crate) struct DriveTables {
    forces: Vec<Table<Actuator>>,
    sines: Vec<Table<Waveform>>,
    /// Keep only the newest table of each kind (a sweep lane's, whose neighbours share it).
    newest_only: bool,
}

impl DriveTables {
    /// Tables that keep only the newest force and sine tables.
    pub(crate) fn newest_only() -> Self {
        Self {
            newest_only: true,
            ..Self::default()
        }
    }

    /// `actuator`'s forces at the stage times of `grid`, from a table when one fits.
    pub(crate) fn forces(&mut self, grid: &Rc<[f64]>, actuator: &Actuator) -> Rc<[f64]> {
        if let Some((_, _, table)) = self
            .forces
            .iter()
            .find(|(g, a, _)| **g == **grid && a.same_force(actuator))
        {
            return table.clone();
        }
        let waveform = actuator.waveform();
        let from_sines = self.sines(grid, waveform).and_then(|sines| {
            sines
                .iter()
                .map(|&s| actuator.force_of_sine(s))
                .collect::<Option<Rc<[f64]>>>()
        });
        let table = from_sines.unwrap_or_else(|| {
            stage_times(grid)
                .into_iter()
                .map(|t| actuator.force(t))
                .collect()
        });
        if self.newest_only {
            self.forces.clear();
        }
        self.forces
            .push((grid.clone(), actuator.clone(), table.clone()));
        table
    }

    /// The sines of `waveform` at the stage times of `grid` (`None`: not a sine drive).
    fn sines(&mut self, grid: &Rc<[f64]>, waveform: &Waveform) -> Option<Rc<[f64]>> {
        if let Some((_, _, table)) = self
            .sines
            .iter()
            .find(|(g, w, _)| **g == **grid && w.same_sine(waveform))
        {
            return Some(table.clone());
        }
        let table: Rc<[f64]> = stage_times(grid)
            .into_iter()
            .map(|t| waveform.sine_at(t))
            .collect::<Option<_>>()?;
        if self.newest_only {
            self.sines.clear();
        }
        self.sines
            .push((grid.clone(), waveform.clone(), table.clone()));
        Some(table)
    }
}

/// A [`DriveTables`]'s tables of one drive on one grid as vectors, to seed the tables of
/// other threads ([`DriveTables::seeded`]; the tables themselves share by `Rc`).
pub(crate) struct DriveSeed {
    grid: Vec<f64>,
    actuator: Actuator,
    forces: Vec<f64>,
    sines: Option<Vec<f64>>,
}

impl DriveTables {
    /// `actuator`'s tables on `grid`, computed here to seed other threads' ([`Self::seeded`]).
    pub(crate) fn seed(grid: &[f64], actuator: &Actuator) -> DriveSeed {
        let mut tables = Self::default();
        let forces = tables.forces(&Rc::from(grid), actuator);
        DriveSeed {
            grid: grid.to_vec(),
            actuator: actuator.clone(),
            forces: forces.to_vec(),
            sines: tables.sines.first().map(|(_, _, sines)| sines.to_vec()),
        }
    }

    /// Tables holding `seed`'s.
    pub(crate) fn seeded(seed: &DriveSeed) -> Self {
        let grid: Rc<[f64]> = Rc::from(seed.grid.as_slice());
        let waveform = seed.actuator.waveform();
        Self {
            forces: vec![(
                grid.clone(),
                seed.actuator.clone(),
                Rc::from(seed.forces.as_slice()),
            )],
            sines: (seed.sines.iter())
                .map(|sines| (grid.clone(), waveform.clone(), Rc::from(sines.as_slice())))
                .collect(),
            newest_only: false,
        }
    }
}

/// [`LANES`] devices side by side (vectors of their constants).
pub(crate) struct LinearStrokeLanes<'a> {
    actuators: [Option<&'a Actuator>; LANES],
    /// Each lane's drive has no cubic or damping term ([`DriveSprings::lossless`]).
    lossless: [bool; LANES],
    /// Each lane's [`LinearStroke::forcing`] of its current grid.
    forcing: [Option<Rc<[f64]>>; LANES],
    /// Each lane's device constants.
    terms: LinearMapTerms<V>,
}

fn set(v: &mut V, l: usize, x: f64) {
    let mut a = v.to_array();
    a[l] = x;
    *v = V::new(a);
}

impl<'a> LinearStrokeLanes<'a> {
    /// No device in any lane (idle lanes evaluate a unit-mass system).
    pub(crate) fn new() -> Self {
        let (z, one) = (V::splat(0.0), V::splat(1.0));
        Self {
            actuators: [None; LANES],
            lossless: [true; LANES],
            forcing: std::array::from_fn(|_| None),
            terms: LinearMapTerms {
                jacobian: [one, z, z, one],
                mass: [one, z, one],
                det: one,
                drag: [z; 2],
                analytic: true,
                stiffness: [z; 2],
                cubic: [z; 2],
                rest: [z; 2],
                drive: DriveSprings::single(z, z),
                polynomial: false,
                poly: [z; 4],
                inertia: [one; 2],
            },
        }
    }

    /// The forcing table lane `l` reads (`None`: the actuator is evaluated).
    pub(crate) fn load_forcing(&mut self, l: usize, forcing: Option<Rc<[f64]>>) {
        self.forcing[l] = forcing;
    }

    /// Puts `model` into lane `l`.
    pub(crate) fn load(&mut self, l: usize, model: &LinearStroke<'a>) {
        self.actuators[l] = Some(model.actuator);
        let (lane, device) = (&mut self.terms, &model.terms);
        for i in 0..4 {
            set(&mut lane.jacobian[i], l, device.jacobian[i]);
        }
        for i in 0..3 {
            set(&mut lane.mass[i], l, device.mass[i]);
        }
        set(&mut lane.det, l, device.det);
        for k in 0..2 {
            set(&mut lane.drag[k], l, device.drag[k]);
            set(&mut lane.stiffness[k], l, device.stiffness[k]);
            set(&mut lane.cubic[k], l, device.cubic[k]);
            set(&mut lane.rest[k], l, device.rest[k]);
        }
        set(&mut lane.drive.k1, l, device.drive.k1);
        set(&mut lane.drive.k2, l, device.drive.k2);
        set(&mut lane.drive.preload, l, device.drive.preload);
        set(&mut lane.drive.k1_cubic, l, device.drive.k1_cubic);
        set(&mut lane.drive.k2_cubic, l, device.drive.k2_cubic);
        set(&mut lane.drive.b1, l, device.drive.b1);
        set(&mut lane.drive.b2, l, device.drive.b2);
        set(&mut lane.drive.mass, l, device.drive.mass);
        self.lossless[l] = device.drive.lossless;
        lane.drive.lossless = self.lossless.iter().all(|&x| x);
    }
}

impl LinearStrokeLanes<'_> {
    /// The actuator force of every lane at its time (from its forcing table at `stage`).
    #[inline(always)]
    fn force(&self, t: [f64; LANES], stage: [usize; LANES]) -> V {
        V::new(std::array::from_fn(|l| {
            match (&self.forcing[l], self.actuators[l]) {
                (Some(table), _) if stage[l] < table.len() => table[stage[l]],
                (_, Some(a)) => a.force(t[l]),
                _ => 0.0,
            }
        }))
    }

    /// The right-hand side at the actuator force `force` (see [`LaneRhs::eval`]).
    #[inline(always)]
    fn eval_with(&self, force: V, y: &[V; 4], dydt: &mut [V; 4]) -> u32 {
        let [q1, q2, q1_dot, q2_dot] = *y;
        // `Drivetrain::evaluate`'s plausibility check (the scalar path errs outside it).
        let inside = q1
            .abs()
            .simd_le(V::splat(paritysim_error::plausible::OFFSET_MM))
            & q2.abs()
                .simd_le(V::splat(paritysim_error::plausible::ANGLE_RAD));
        let failed = !inside.to_bitmask() & ((1 << LANES) - 1);
        let drag = self.terms.drag;
        let ([q1_ddot, q2_ddot], _) =
            linear_map::accelerations(&self.terms, [force, V::splat(0.0)], y, |k, rate| {
                paritysim_aero::stroke_drag_torque(drag[k], rate)
            });
        *dydt = [q1_dot, q2_dot, q1_ddot, q2_ddot];
        failed
    }
}

impl LaneRhs<4> for LinearStrokeLanes<'_> {
    // Inlined into the stages of the lane stepper (it is generic over the right-hand side).
    #[inline(always)]
    fn eval(&self, t: [f64; LANES], stage: [usize; LANES], y: &[V; 4], dydt: &mut [V; 4]) -> u32 {
        self.eval_with(self.force(t, stage), y, dydt)
    }
}

/// The variational equations of [`LinearStrokeLanes`] on `[y (4), Φ (4 × 4, by columns)]`,
/// as integrate/variational.rs forms them for the scalar device: the right-hand side, then
/// `J Φ` from the analytic Jacobian ([`crate::device::linear_map::variational`], the same
/// function, so the same operations), one device per lane.
pub(crate) struct VariationalLanes<'m, 'a>(pub(crate) &'m LinearStrokeLanes<'a>);

impl LaneRhs<20> for VariationalLanes<'_, '_> {
    fn eval(&self, t: [f64; LANES], stage: [usize; LANES], c: &[V; 20], dc: &mut [V; 20]) -> u32 {
        let rhs = self.0;
        let y: [V; 4] = std::array::from_fn(|i| c[i]);
        let mut f = [V::splat(0.0); 4];
        let force = rhs.force(t, stage);
        let failed = rhs.eval_with(force, &y, &mut f);
        dc[..4].copy_from_slice(&f);
        let forces = [force, V::splat(0.0)];
        linear_map::variational(&rhs.terms, forces, &y, &c[4..], &mut dc[4..]);
        failed
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::actuator::DcOffset;

    /// Drives that differ only in amplitude, offset, DC treatment or force per volt take their
    /// forces from one table of sines, and those are `Actuator::force`'s bits; another
    /// frequency or a sampled drive gets its own.
    #[test]
    fn forces_from_shared_sines_are_the_forces_bit_for_bit() {
        let grid: Rc<[f64]> = Rc::from([0.0, 0.37, 1.1, 2.5, 3.1, 5.0, 8.3].as_slice());
        let drive =
            |amplitude: f64, offset: f64, frequency_hz: f64, dc: DcOffset, per_volt: f64| {
                let waveform = Waveform::sine(amplitude, frequency_hz, offset, 0.3).unwrap();
                Actuator::new(per_volt, 1.0, waveform, dc).unwrap()
            };
        let drives = [
            drive(100.0, 0.0, 120.0, DcOffset::AsForce, 0.03),
            drive(100.0 * (1.0 + 1e-5), 0.0, 120.0, DcOffset::AsForce, 0.03),
            drive(100.0, 7.0, 120.0, DcOffset::Ignore, 0.03),
            drive(100.0, 7.0, 120.0, DcOffset::AsForce, 0.03 * (1.0 - 1e-5)),
            drive(100.0, 0.0, 121.0, DcOffset::AsForce, 0.03),
        ];
        let mut tables = DriveTables::default();
        for actuator in &drives {
            let table = tables.forces(&grid, actuator);
            let direct: Vec<f64> = stage_times(&grid)
                .iter()
                .map(|&t| actuator.force(t))
                .collect();
            assert_eq!(table.len(), direct.len());
            assert!(
                table
                    .iter()
                    .zip(&direct)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            );
        }
        assert_eq!(tables.forces.len(), drives.len());
        assert_eq!(tables.sines.len(), 2, "121 Hz has sines of its own");
        let sampled = Waveform::sampled(vec![0.0, 2.0], vec![0.0, 50.0], 8.3).unwrap();
        let actuator = Actuator::new(0.03, 1.0, sampled, DcOffset::AsForce).unwrap();
        let table = tables.forces(&grid, &actuator);
        let direct: Vec<f64> = stage_times(&grid)
            .iter()
            .map(|&t| actuator.force(t))
            .collect();
        assert!(
            table
                .iter()
                .zip(&direct)
                .all(|(a, b)| a.to_bits() == b.to_bits())
        );
        assert_eq!(tables.sines.len(), 2);
    }
}
