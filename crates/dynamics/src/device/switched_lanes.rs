//! The switched devices' right-hand sides in SIMD lanes (`stroke_plane::lanes`,
//! `free_deviation::lanes`): their common form, and the lanes they leave to the scalar path
//! (states off their closed form), each evaluated on its own. States are compact, as the
//! scalar integrator holds them: `M / 2` coordinates, then as many rates; work integrals zero,
//! as the shooting's states.

use paritysim_aero::Branch;
use wide::f64x4;

use crate::integrate::State;
use crate::integrate::lanes::{LANES, put_lane};

/// Which lanes of a SIMD right-hand side left its vector path (bit masks).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct LaneEval {
    /// Lanes evaluated by the scalar right-hand side.
    pub(crate) scalar: u32,
    /// Lanes whose scalar right-hand side failed.
    pub(crate) failed: u32,
}

/// A right-hand side of four devices' compact states of `M` entries on held branches.
pub(crate) trait SwitchedLanes<const M: usize> {
    /// `f(t, y)` of every lane with the drive forces `forces[l]` at `t[l]` (the actuator's, or
    /// a dual drivetrain's left and right; tabulated by the caller) on `branches[l]`:
    /// `dydt = (ẋ, ẍ)`, and which lanes left the vector path.
    fn eval(
        &self,
        t: [f64; LANES],
        forces: [[f64; 2]; LANES],
        y: &[f64x4; M],
        branches: [[Branch; 2]; LANES],
        dydt: &mut [f64x4; M],
    ) -> LaneEval;
}

/// The state of a compact one.
pub(crate) fn expand<const M: usize>(c: &[f64; M]) -> State {
    let mut y = State::default();
    y.coords[..M / 2].copy_from_slice(&c[..M / 2]);
    y.rates[..M / 2].copy_from_slice(&c[M / 2..]);
    y
}

/// The compact state of `y`.
pub(crate) fn compact<const M: usize>(y: &State) -> [f64; M] {
    std::array::from_fn(|i| {
        if i < M / 2 {
            y.coords[i]
        } else {
            y.rates[i - M / 2]
        }
    })
}

/// Evaluates the lanes of `scalar` one by one with `eval(lane, y, dydt)` (`false`: it failed)
/// and writes their derivatives into `dydt`.
pub(crate) fn evaluate_scalar_lanes<const M: usize>(
    scalar: u32,
    y: &[f64x4; M],
    dydt: &mut [f64x4; M],
    mut eval: impl FnMut(usize, &State, &mut State) -> bool,
) -> LaneEval {
    let mut failed = 0;
    for l in (0..LANES).filter(|l| scalar & (1 << l) != 0) {
        let c: [f64; M] = std::array::from_fn(|i| y[i].to_array()[l]);
        let mut out = State::default();
        if eval(l, &expand(&c), &mut out) {
            put_lane(dydt, l, &compact(&out));
        } else {
            failed |= 1 << l;
        }
    }
    LaneEval { scalar, failed }
}
