//! The switched devices in SIMD lanes, the §3.4 stroke-plane ones and the §2.5 free-deviation
//! ones: their right-hand side (`device::stroke_plane::lanes`, `device::free_deviation::lanes`)
//! with each lane's tabulated drive and held branch, as the lane stepper drives it
//! (`integrate::dop853_lanes`).
//!
//! The blade elements switch (stroke reversal, α = π/2, `ω_z = 0`), so each lane holds the
//! branch of its own switching functions as the scalar `drive_on_grid_events` does: taken at
//! the start of its problem, checked at the end of every step, and a step that crosses a
//! switch is replayed on the scalar path (`integrate::replay_grid_step`, the same operations):
//! the root located and the step finished on the new branch, samples included. A lane's step
//! that crosses nothing is the scalar step (the same stages, error estimate and dense
//! output), so a lane's period is bit-identical to the scalar one.

use std::cell::RefCell;
use std::rc::Rc;

use wide::f64x4;

use crate::device::Device;
use crate::device::free_deviation_lanes::FreeDeviationLanes;
use crate::device::stroke_plane_lanes::{self as model, StrokePlaneLanes};
use crate::device::switched_lanes::{SwitchedLanes, evaluate_scalar_lanes};
pub(crate) use crate::device::switched_lanes::{compact, expand};
use crate::integrate::lanes::{LANES, LaneRhs, LaneTolerances, NO_STAGE, stage_times};
use crate::integrate::{
    HeldRun, MAX_SWITCHES, OdeSystem, Sides, State, replay_adaptive_step, replay_grid_step,
};

type V = f64x4;

/// Compact entries of a four-coordinate state (the §3.4 stroke plane, the §2.5 Lift PARITY):
/// `x` (4) then `ẋ` (4), as the scalar integrator holds them.
pub(crate) const M: usize = model::M;

/// Compact entries of a five-coordinate state (the §2.5 Dual PARITY): the scalar integrator
/// holds six coordinates and six rates, the sixth of each zero.
pub(crate) const M12: usize = 12;

/// The branch a lane holds and its switching functions at its step's start.
#[derive(Clone, Copy, Debug, Default)]
struct Held {
    sides: Sides,
    g: [f64; MAX_SWITCHES],
}

/// The compact size of `device`'s lanes when it has a switched lane model: [`M`] (the
/// stroke-plane and the four-coordinate free-deviation ones) or [`M12`] (five coordinates).
pub(crate) fn layout(device: &Device) -> Option<usize> {
    if StrokePlaneLanes::supports(device) || FreeDeviationLanes::<4, M>::supports(device) {
        Some(M)
    } else if FreeDeviationLanes::<5, M12>::supports(device) {
        Some(M12)
    } else {
        None
    }
}

/// Whether `device` has a switched lane model.
pub(crate) fn supports(device: &Device) -> bool {
    layout(device).is_some()
}

/// The lanes' right-hand side of four devices, or `None` for lanes of different kinds (each
/// then evaluated on the scalar path).
pub(crate) type Builder<'a, const M: usize> =
    fn([&'a Device; LANES]) -> Option<Box<dyn SwitchedLanes<M> + 'a>>;

/// [`Builder`] of the four-coordinate devices.
pub(crate) fn build<'a>(devices: [&'a Device; LANES]) -> Option<Box<dyn SwitchedLanes<M> + 'a>> {
    if let Some(lanes) = StrokePlaneLanes::new(devices) {
        return Some(Box::new(lanes));
    }
    FreeDeviationLanes::<4, M>::new(devices).map(|l| Box::new(l) as Box<dyn SwitchedLanes<M>>)
}

/// [`Builder`] of the five-coordinate devices.
pub(crate) fn build12<'a>(
    devices: [&'a Device; LANES],
) -> Option<Box<dyn SwitchedLanes<M12> + 'a>> {
    FreeDeviationLanes::<5, M12>::new(devices).map(|l| Box::new(l) as Box<dyn SwitchedLanes<M12>>)
}

/// [`LANES`] switched devices side by side, on compact states of `M` entries.
pub(crate) struct PlaneLanes<'a, const M: usize> {
    devices: [Option<&'a Device>; LANES],
    build: Builder<'a, M>,
    /// The lanes' constants, rebuilt when a lane takes another device (`None`: mixed kinds).
    model: Option<Box<dyn SwitchedLanes<M> + 'a>>,
    /// Each lane's drive forces at the [`stage_times`] of its grid.
    forcing: [Option<Rc<[[f64; 2]]>>; LANES],
    held: RefCell<[Held; LANES]>,
}

/// The drive forces at every [`stage_times`] of `grid` (`Device::drive_forces`: the drive's
/// `sin` once per grid instead of once per evaluation).
pub(crate) fn forcing(device: &Device, grid: &[f64]) -> Rc<[[f64; 2]]> {
    stage_times(grid)
        .into_iter()
        .map(|t| device.drive_forces(t))
        .collect()
}

impl<'a, const M: usize> PlaneLanes<'a, M> {
    /// No lane loaded; `build` makes the lanes' right-hand side.
    pub(crate) fn new(build: Builder<'a, M>) -> Self {
        Self {
            devices: [None; LANES],
            build,
            model: None,
            forcing: std::array::from_fn(|_| None),
            held: RefCell::new([Held::default(); LANES]),
        }
    }

    /// Puts `device` (one of [`layout`] `M`) into lane `l`.
    pub(crate) fn load(&mut self, l: usize, device: &'a Device) {
        if self.devices[l].is_some_and(|d| std::ptr::eq(d, device)) {
            return;
        }
        self.devices[l] = Some(device);
        // Idle lanes compute with a loaded device's constants (their results are not read).
        let devices = self.devices.map(|d| d.unwrap_or(device));
        self.model = (self.build)(devices);
    }

    /// The drive table lane `l` reads from its next problem on.
    pub(crate) fn load_forcing(&mut self, l: usize, forcing: Rc<[[f64; 2]]>) {
        self.forcing[l] = Some(forcing);
    }
}

impl<const M: usize> LaneRhs<M> for PlaneLanes<'_, M> {
    fn eval(&self, t: [f64; LANES], stage: [usize; LANES], y: &[V; M], dydt: &mut [V; M]) -> u32 {
        let forces: [[f64; 2]; LANES] =
            std::array::from_fn(|l| match (&self.forcing[l], stage[l]) {
                (Some(table), s) if s != NO_STAGE => table[s],
                _ => self.devices[l].map_or([0.0; 2], |d| d.drive_forces(t[l])),
            });
        let held = self.held.borrow();
        let branches = std::array::from_fn(|l| crate::device::blade_branches(held[l].sides));
        match &self.model {
            Some(model) => model.eval(t, forces, y, branches, dydt).failed,
            None => {
                let all = (1 << LANES) - 1;
                evaluate_scalar_lanes(all, y, dydt, |l, state, out| {
                    self.devices[l]
                        .is_some_and(|d| d.rhs_on(t[l], state, held[l].sides, out).is_ok())
                })
                .failed
            }
        }
    }

    fn switched(&self) -> bool {
        true
    }

    fn begin(&self, l: usize, t0: f64, y0: &[f64; M]) -> bool {
        let Some(device) = self.devices[l] else {
            return false;
        };
        let mut g = [0.0; MAX_SWITCHES];
        if device.switches(t0, &expand(y0), &mut g).is_err() {
            return false;
        }
        let n = device.n_switches().min(MAX_SWITCHES);
        self.held.borrow_mut()[l] = Held {
            sides: Sides::of(&g[..n]),
            g,
        };
        true
    }

    fn crossed(&self, l: usize, t_new: f64, y1: &[f64; M]) -> Option<bool> {
        let device = self.devices[l]?;
        let mut g = [0.0; MAX_SWITCHES];
        device.switches(t_new, &expand(y1), &mut g).ok()?;
        let n = device.n_switches().min(MAX_SWITCHES);
        let mut held = self.held.borrow_mut();
        let sides = held[l].sides;
        if (0..n).any(|i| crate::integrate::crossed(sides, i, g[i])) {
            return Some(true);
        }
        held[l].g = g;
        Some(false)
    }

    fn replay(
        &self,
        l: usize,
        tol: LaneTolerances,
        span: (f64, f64),
        (y, f0): (&[f64; M], &[f64; M]),
        times: &[f64],
        next: &mut usize,
        sink: &mut dyn FnMut(usize, f64, &State) -> bool,
    ) -> Option<([f64; M], [f64; M], usize)> {
        let device = self.devices[l]?;
        let start = {
            let held = self.held.borrow();
            (held[l].sides, held[l].g)
        };
        let mut state_sink = |i: usize, t: f64, state: &State| {
            if sink(i, t, state) {
                Ok(())
            } else {
                Err(paritysim_error::Error::OutOfDomain {
                    what: "lane sample".into(),
                    detail: format!("t = {t}"),
                })
            }
        };
        let end = replay_grid_step::<M>(
            device,
            (tol.rtol, tol.atol),
            span,
            (*y, *f0),
            start,
            times,
            next,
            &mut state_sink,
        )
        .ok()?;
        self.held.borrow_mut()[l] = Held {
            sides: end.sides,
            g: end.g,
        };
        Some((end.y, end.f, end.over_tolerance))
    }

    fn replay_adaptive(
        &self,
        l: usize,
        tol: LaneTolerances,
        max_steps: usize,
        span: (f64, f64),
        run: &mut HeldRun<M>,
        steps: &mut Vec<f64>,
    ) -> Option<bool> {
        let device = self.devices[l]?;
        let held = self.held.borrow()[l];
        (run.sides, run.g) = (held.sides, held.g);
        let done =
            replay_adaptive_step::<M>(device, (tol.rtol, tol.atol), max_steps, span, run, steps)
                .ok()?;
        self.held.borrow_mut()[l] = Held {
            sides: run.sides,
            g: run.g,
        };
        Some(done)
    }
}
