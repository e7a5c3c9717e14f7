//! [`SteadyState::Shooting`](super::SteadyState::Shooting) inside [`simulate`](super::simulate): warm-up, Newton on the frozen
//! grid of the period map, the recorded window from the last Newton period.

use paritysim_error::Result;

use crate::device::Device;
use crate::integrate::{Integrator, RungeKutta, State};
use crate::metrics::StrokeNeeds;
use crate::shooting::grid::{Finished, Guess};
use crate::shooting::newton::{MAX_NEWTON, newton_tolerance};
use crate::trajectory::Trajectory;

use super::{SimulationOptions, record_window, state_change};

/// Shooting results whose largest Floquet multiplier exceeds `1 + UNSTABLE_MARGIN` are
/// unstable orbits, which a run never settles on: [`SteadyState::Shooting`](super::SteadyState::Shooting) then falls back to
/// the transient (the margin covers the error of the Broyden-updated Jacobian; K2 = 0's neutral
/// multiplier 1 stays a steady state).
pub const UNSTABLE_MARGIN: f64 = 1e-2;

/// Below this largest multiplier modulus an "unstable" verdict taken from a Broyden-updated
/// Jacobian (not the variational equations at the orbit) is checked with them before the
/// orbit is rejected: such Jacobians were measured 0.16 off in modulus near a flip (|μ| 1.011
/// against an exact −0.855, docs/findings.md §23); the clearly unstable orbits of the §2.5
/// devices' warm-ups (|μ| 1.86–1.99, exact within 0.004) are not rechecked.
pub(crate) const BROYDEN_VERDICT_CHECKED_BELOW: f64 = 1.5;

/// The tolerances of the switched devices' warm-up and first grid, relative to the run's
/// (see [`shooting_steady_state`]): the start of Newton's iteration, whose accuracy the
/// second grid's Newton does not inherit.
pub(super) const STEPPING_STONE_LOOSENING: f64 = 1e4;

/// What [`shooting_steady_state`] ended with.
pub(crate) enum Shot {
    /// A stable orbit.
    Found(Box<ShotSteadyState>),
    /// An orbit with a multiplier beyond `1 + UNSTABLE_MARGIN`: its state.
    Unstable(State),
    /// Newton did not converge.
    Failed,
}

/// What [`shooting_steady_state`] found.
pub(crate) struct ShotSteadyState {
    pub(super) state: State,
    /// Start of the recorded window.
    pub(super) t: f64,
    pub(super) cycles_run: usize,
    pub(super) residual: f64,
    pub(super) jacobian: nalgebra::DMatrix<f64>,
    pub(super) grid: Vec<f64>,
    pub(super) multipliers: Vec<nalgebra::Complex<f64>>,
    /// The recorded window, when the last Newton period recorded it.
    pub(super) recorded: Option<(Trajectory, Vec<(String, f64)>)>,
    /// That period's variational record ([`SimulationOptions::sampled_orbit`]).
    pub(super) sampled: Option<super::OrbitSamples>,
}

/// [`SteadyState::Shooting`](super::SteadyState::Shooting): warm-up (without a neighbour's Jacobian), then Newton on the
/// frozen grid ([`crate::grid_shooting`]) of the `orbit_cycles`-period map (2: a
/// period-doubled orbit), with a warm-up first unless `settled` (a state the caller's
/// transient settled); the final Newton period records the window when it is one plain orbit.
/// Not [`Shot::Found`]: the caller runs the transient.
#[allow(clippy::too_many_arguments)]
pub(crate) fn shooting_steady_state(
    device: &Device,
    options: &SimulationOptions,
    recording: &RungeKutta,
    transient: &RungeKutta,
    period: f64,
    orbit_cycles: usize,
    settled: bool,
    y0: &State,
    columns: &[crate::trajectory::Column],
    stroke: Option<StrokeNeeds>,
) -> Result<Shot> {
    let mut y = *y0;
    let mut cycles = 0;
    let guess = options.shooting_jacobian.as_ref();
    let map_period = period * orbit_cycles as f64;
    let switched = crate::integrate::OdeSystem::n_switches(device) > 0;
    // The stepping stones need a cheap exact Jacobian at the first orbit (the stroke-plane
    // model's analytic one). The free-θ devices' comes from central differences (two
    // right-hand sides per column and stage): their first pass runs at the run's tolerances and hands
    // its Jacobian to the second (measured on the §2.5 Dual PARITY with stepping stones: the
    // orbit returned within 1.05e-9 instead of 8.8e-11).
    let stepping_stone = switched && device.has_analytic_jacobian();
    if guess.is_none() && !settled {
        // Far from the orbit Newton's model is poor: settle the fast modes first. Only the
        // start of Newton's iteration: for the stepping-stone devices, whose multipliers are
        // taken at the accepted orbit (below), at looser tolerances (the others' warm-up state
        // is where their Jacobian is taken, and the lanes repeat it).
        // The loose warm-up does not locate the blade elements' switches: at its long steps
        // each root's cut step and search cost more than the rejected steps they save
        // (measured on the §3.4 device: 3.9 M → 2.2 M instructions for its three cycles).
        let (warm_up, warm_up_system): (_, &dyn crate::integrate::OdeSystem) = if stepping_stone {
            (
                transient.loosened(STEPPING_STONE_LOOSENING),
                &crate::integrate::WithoutEvents(device),
            )
        } else {
            (*transient, device)
        };
        while cycles < options.min_cycles {
            crate::integrate::budget::check(cycles as f64 * period)?;
            let next = match warm_up.advance(warm_up_system, 0.0, &y, period) {
                Ok(next) => next,
                // A spent budget ends the run; any other failure is left to the fallback.
                Err(e) if crate::shooting::newton::out_of_budget(&e) => return Err(e),
                Err(_) => break,
            };
            let change = state_change(&next, &y);
            y = next.without_work();
            cycles += 1;
            if change < 1e-3 {
                break;
            }
        }
    }
    let tol = newton_tolerance(options.steady_tol, options.rtol);
    let n_samples = options.samples_per_cycle * orbit_cycles;
    let records = options.record_cycles == 1 && options.perturbation.is_none();
    let mut recorded = None;
    let mut sampled = None;
    let mut finish = |grid: &[f64], y: &State| -> Result<Finished> {
        if !records {
            return transient
                .integrate_on_grid(device, grid, y, &[], &mut |_, _, _| Ok(()))
                .map(|end| (end, None));
        }
        if options.sampled_orbit && orbit_cycles == 1 && stroke.is_some_and(|s| !s.work) {
            // The machine gets the end state only: the shooting runs as without the record. A
            // failing variational period (not the budget) leaves the plain record below.
            match super::window::record_window_sampled(
                device,
                transient,
                y,
                n_samples,
                period,
                columns.to_vec(),
                stroke,
                grid,
                options.weight_mn,
            ) {
                Ok(((trajectory, metrics, end), samples)) => {
                    recorded = Some((trajectory, metrics));
                    sampled = Some(samples);
                    return Ok((end, None));
                }
                Err(e) if crate::shooting::newton::out_of_budget(&e) => return Err(e),
                Err(_) => sampled = None,
            }
        }
        // Samples that read no work integral: the lighter state suffices.
        let integrator = match stroke {
            Some(needs) if !needs.work => transient,
            _ => recording,
        };
        let (trajectory, metrics, end) = record_window(
            device,
            integrator,
            grid[0],
            y,
            map_period,
            n_samples,
            Some(period),
            None,
            columns.to_vec(),
            stroke,
            Some(grid),
            options.weight_mn,
        )?;
        recorded = Some((trajectory, metrics));
        Ok((end, None))
    };
    // A right-hand side with switches (event location): the adaptive period cuts the grid at
    // the roots of its start state, which move by the distance to the orbit, and the steps
    // next to them then integrate a continued branch (measured on the §3.4 device: the true
    // map's residual 3e-7 at the frozen grid's orbit). So a first orbit on that grid, then
    // the grid picked again from it (its roots within Newton's last correction); a
    // neighbour's grid is not reused. Lanes never run such devices (no lane model). (One pass
    // on the first grid, whose steps are cut at the trial's own roots, left the §3.4 orbit
    // 1.3e-9 off the true map's; 2.4e-12 with two.)
    // The first grid is a stepping stone: picked and solved at 1e4 × the run's tolerances
    // (its orbit only places the second grid's roots) to a tenth of `steady_tol`, its last
    // Newton trial not integrated (the second grid's Newton starts from that state and checks
    // it). Its Jacobian (taken at the warm-up state, Broyden-updated) and the contraction it
    // achieved start the second grid's Newton, whose first step is then usually the recorded
    // period itself; the multipliers come from the variational equations at the accepted
    // orbit on the first grid (measured on the §3.4 device: 4.9e-9 off an rtol-1e-12
    // reference, where one variational period at the start of the second grid cost 3 × as
    // much; with the loose warm-up below, 25.8 M → 19.8 M instructions per trial).
    let mut first_pass = None;
    let first_rk = if stepping_stone {
        transient.loosened(STEPPING_STONE_LOOSENING)
    } else {
        *transient
    };
    if switched && guess.is_none() {
        let mut plain = |_: &[f64], y: &State| -> Result<Finished> { Ok((*y, None)) };
        // A stepping stone's orbit is only the second grid's start, which that grid's Newton
        // corrects: a tenth of `steady_tol` (its first Newton step from the warm-up suffices).
        let first_tol = if stepping_stone {
            tol.max(0.1 * options.steady_tol)
        } else {
            tol
        };
        if let Some(first) = crate::shooting::grid::shoot(
            device,
            &first_rk,
            map_period,
            0.0,
            &y,
            None,
            first_tol,
            options.steady_tol,
            MAX_NEWTON,
            &mut plain,
        )? {
            y = first.state;
            cycles += first.periods * orbit_cycles;
            first_pass = Some(first);
        }
    }
    let guess = match &first_pass {
        Some(first) => Some(Guess {
            jacobian: &first.jacobian,
            grid: None,
            // The stepping stone's contraction predicts the second grid's first error: its
            // first Newton step is the final period when that is below `tol`.
            contraction: first.contraction.filter(|_| stepping_stone),
        }),
        None => guess.map(|jacobian| Guess {
            jacobian,
            grid: options.shooting_grid.as_deref().filter(|_| !switched),
            contraction: None,
        }),
    };
    let Some(mut orbit) = crate::shooting::grid::shoot(
        device,
        transient,
        map_period,
        0.0,
        &y,
        guess,
        tol,
        options.steady_tol,
        MAX_NEWTON,
        &mut finish,
    )?
    else {
        return Ok(Shot::Failed);
    };
    cycles += orbit.periods * orbit_cycles;
    if let Some(first) = first_pass.filter(|_| stepping_stone && !orbit.jacobian_at_orbit) {
        // The second grid's Newton ran on the stepping stone's Broyden-updated Jacobian
        // (taken off the orbit): the multipliers from the variational equations at the
        // orbit, on the stepping stone's coarser grid (a third of the second grid's steps).
        exact_jacobian_at_orbit(device, &first_rk, &first.grid, &mut orbit)?;
    }
    if options.shooting_jacobian.is_some()
        && !orbit.jacobian_at_orbit
        && device.has_soft_direction()
    {
        // A neighbour's Jacobian says nothing reliable about a soft direction's multiplier
        // (§3.4 1-Cut at K2 = 0 after K2 = 10: 0.974 where it is 1, and chained Newton moved
        // the stroke offset up to 10 rad along the family): the variational equations at the
        // orbit decide whether it is one of a family, which the sweep then runs from the
        // spec's own start (sweep/chain.rs).
        let grid = orbit.grid.clone();
        exact_jacobian_at_orbit(device, transient, &grid, &mut orbit)?;
    }
    let mut multipliers = crate::floquet::eigenvalues(&orbit.jacobian).unwrap_or_default();
    let largest = multipliers.first().map_or(0.0, |m| m.norm());
    if !orbit.jacobian_at_orbit
        && largest > 1.0 + UNSTABLE_MARGIN
        && largest < BROYDEN_VERDICT_CHECKED_BELOW
    {
        // A marginal "unstable" from a Broyden-updated Jacobian: the variational equations
        // at the orbit decide (the free-θ devices' central differences; measured on a §2.5
        // Lift point: Broyden 1.011, exact −0.855, a stable orbit the run then missed).
        let grid = orbit.grid.clone();
        exact_jacobian_at_orbit(device, transient, &grid, &mut orbit)?;
        multipliers = crate::floquet::eigenvalues(&orbit.jacobian).unwrap_or_default();
    }
    if multipliers
        .first()
        .is_some_and(|m| m.norm() > 1.0 + UNSTABLE_MARGIN)
    {
        // An unstable orbit is not a state a run settles on: the transient decides.
        return Ok(Shot::Unstable(orbit.state));
    }
    let t = cycles as f64 * period;
    if let Some((trajectory, _)) = &mut recorded {
        // The window was integrated on the section t = 0; the drive is T-periodic, so it is
        // the window after the cycles run, labelled as such.
        for time in &mut trajectory.time {
            *time += t;
        }
    }
    Ok(Shot::Found(Box::new(ShotSteadyState {
        state: orbit.state,
        t,
        cycles_run: cycles,
        residual: orbit.residual,
        jacobian: orbit.jacobian,
        grid: orbit.grid,
        multipliers,
        recorded,
        sampled,
    })))
}

/// Replaces `orbit`'s Jacobian by the variational equations' on `grid` from its state (the
/// exact monodromy at the orbit, marked so) when they integrate; a failure other than a spent
/// budget keeps the estimate.
///
/// # Errors
/// A spent budget or a cancel.
fn exact_jacobian_at_orbit(
    device: &Device,
    rk: &RungeKutta,
    grid: &[f64],
    orbit: &mut crate::shooting::grid::GridOrbit,
) -> Result<()> {
    match rk.flow_with_sensitivity_on_grid(device, grid, &orbit.state) {
        Ok((_, jacobian)) => {
            orbit.jacobian = jacobian;
            orbit.jacobian_at_orbit = true;
            Ok(())
        }
        Err(e) if crate::shooting::newton::out_of_budget(&e) => Err(e),
        Err(_) => Ok(()),
    }
}
