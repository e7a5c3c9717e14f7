//! Event location for piecewise-smooth right-hand sides (Hairer, Nørsett & Wanner, *Solving
//! ODEs I*, §II.6 "discontinuous right-hand sides").
//!
//! A system may declare a few switching functions `g_i(t, y)` whose sign changes mark the
//! places where its right-hand side jumps or kinks (for the blade-element wing: the stroke
//! reversal `ω_x = 0`). Between events the integrator holds the [`Sides`] fixed and the system
//! evaluates the *smooth continuation* of the branch those sides name, also slightly past the
//! switching surface. So no step straddles a jump: an accepted step on which some `g_i` ends on
//! the other side is cut at the first root (found on the step's dense output, Illinois
//! regula falsi to `1e-10 h`; roots within `1e-8 h` after it count as the same event), the
//! sides there are taken over, and the integration restarts from the root with the step size
//! the controller proposed. Without that, an embedded
//! pair's error estimate is `O(h)` across a jump whatever its order, and the controller
//! rejects step after step there.
//!
//! Limitations (as for every sign-change detector): two sign changes of one `g_i` inside one
//! step are not seen (the step is then computed on one branch throughout; its error estimate
//! still controls it), and a switching function that only touches zero is no event.

use super::{OdeSystem, Rhs, State, Stepper};
use paritysim_error::Result;

/// A system integrated without event location: its right-hand side on each state's own sides
/// (for a loose pass, whose long steps make each located root, a cut step and a search on the
/// dense output, cost more than the rejected steps it saves).
pub(crate) struct WithoutEvents<'a>(pub &'a dyn OdeSystem);

impl OdeSystem for WithoutEvents<'_> {
    fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> Result<()> {
        self.0.rhs(t, y, dydt)
    }

    fn n_active(&self) -> usize {
        self.0.n_active()
    }
}

/// Largest number of switching functions of one system.
pub const MAX_SWITCHES: usize = 16;

/// Which side of each switching function the right-hand side evaluates: bit `i` set when the
/// branch of `g_i >= 0` is taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Sides(u32);

impl Sides {
    /// The sides of the values `g` (`g_i >= 0` positive).
    pub fn of(g: &[f64]) -> Self {
        let mut bits = 0;
        for (i, v) in g.iter().enumerate().take(MAX_SWITCHES) {
            if *v >= 0.0 {
                bits |= 1 << i;
            }
        }
        Self(bits)
    }

    /// Whether the branch of `g_i >= 0` is taken.
    #[inline]
    pub fn positive(self, i: usize) -> bool {
        self.0 >> i & 1 == 1
    }

    /// `+1.0` on the positive branch of `g_i`, `−1.0` on the negative one.
    #[inline]
    pub fn sign(self, i: usize) -> f64 {
        if self.positive(i) { 1.0 } else { -1.0 }
    }

    /// The same sides with `g_i`'s set to `positive`.
    #[inline]
    pub fn with(self, i: usize, positive: bool) -> Self {
        if positive {
            Self(self.0 | 1 << i)
        } else {
            Self(self.0 & !(1 << i))
        }
    }
}

/// Whether `g` (a value of switching function `i`) lies strictly on the other side than
/// `sides` names.
#[inline]
pub(crate) fn crossed(sides: Sides, i: usize, g: f64) -> bool {
    if sides.positive(i) { g < 0.0 } else { g > 0.0 }
}

/// The first switch inside an accepted step.
pub(crate) struct Event<const M: usize> {
    /// Where the step ends: the first root (bracketed from the far side).
    pub(crate) t: f64,
    /// The dense output there.
    pub(crate) y: [f64; M],
    /// The switching functions there.
    pub(crate) g: [f64; MAX_SWITCHES],
    /// The sides after the event.
    pub(crate) sides: Sides,
    /// Whether the root is at the step's start (the step was computed on a wrong branch).
    pub(crate) at_start: bool,
}

/// Relative bracket width of the root search (of the step size).
pub(crate) const ROOT_TOLERANCE: f64 = 1e-10;

/// The same on fixed grids, to round-off: there the root's time is part of the frozen map,
/// which Newton solves to `0.1 rtol` (a bracket of `1e-10 h` left the map non-smooth at
/// about `1e-10` of the state and Newton at rtol 1e-12 without descent).
pub(crate) const GRID_ROOT_TOLERANCE: f64 = 1e-15;

/// Roots this close after the first (relative to the step size) are one event: the step ends
/// there with all of them switched. Mirror-symmetric wings cross together up to round-off;
/// switching them one after the other would break the symmetry by `jump × (t₂ − t₁)`.
const CLUSTER: f64 = 1e-8;

/// Locates the first root inside the accepted step `[t, t + h]` (dense output prepared) among
/// the switching functions whose end value `g1` lies across `sides` (`g0` their values at `t`),
/// to a bracket of `root_tolerance × h`.
///
/// # Errors
/// A failing switching function.
#[allow(clippy::too_many_arguments)]
pub(crate) fn locate<const M: usize, S: Stepper<M>>(
    stepper: &S,
    rhs: &mut dyn Rhs<M>,
    n: usize,
    sides: Sides,
    t: f64,
    h: f64,
    g0: &[f64; MAX_SWITCHES],
    g1: &[f64; MAX_SWITCHES],
    root_tolerance: f64,
) -> Result<Event<M>> {
    let t1 = t + h;
    let tol = root_tolerance * h.abs() + 4.0 * f64::EPSILON * t1.abs();
    let mut first = t1;
    let mut y = [0.0; M];
    let mut g = [0.0; MAX_SWITCHES];
    for i in (0..n).filter(|&i| crossed(sides, i, g1[i])) {
        let (mut a, mut ga, mut b, mut gb) = (t, g0[i], first, g1[i]);
        if first < t1 {
            // Only an earlier root matters: bracket [t, first] when g_i already changed there.
            stepper.dense((first - t) / h, &mut y);
            rhs.switches(first, &y, &mut g)?;
            if !crossed(sides, i, g[i]) {
                continue;
            }
            gb = g[i];
        }
        if !(ga != 0.0 && (ga > 0.0) != (gb > 0.0)) {
            // g_i is already on the far side at t (or zero there).
            first = t;
            break;
        }
        // Illinois: regula falsi halving the retained end's value when one end repeats.
        let mut repeated = 0i8;
        while b - a > tol {
            let mut c = (a * gb - b * ga) / (gb - ga);
            if !(c > a && c < b) {
                c = 0.5 * (a + b);
            }
            stepper.dense((c - t) / h, &mut y);
            rhs.switches(c, &y, &mut g)?;
            let gc = g[i];
            if gc == 0.0 {
                b = c;
                break;
            }
            if (gc > 0.0) == (gb > 0.0) {
                b = c;
                gb = gc;
                if repeated == 1 {
                    ga *= 0.5;
                }
                repeated = 1;
            } else {
                a = c;
                ga = gc;
                if repeated == -1 {
                    gb *= 0.5;
                }
                repeated = -1;
            }
        }
        first = b;
    }
    let at_start = first - t <= 2.0 * tol;
    if !at_start && first < t1 {
        first = (first + CLUSTER * h.abs()).min(t1);
    }
    if first >= t1 {
        y = *stepper.y1();
        g = *g1;
    } else {
        stepper.dense((first - t) / h, &mut y);
        rhs.switches(first, &y, &mut g)?;
    }
    let mut after = sides;
    for i in 0..n {
        let positive = if g[i] > 0.0 {
            true
        } else if g[i] < 0.0 {
            false
        } else if crossed(sides, i, g1[i]) {
            g1[i] > 0.0
        } else {
            sides.positive(i)
        };
        if at_start && crossed(sides, i, g1[i]) {
            // The far side at the start: the branch of the step's end.
            after = after.with(i, g1[i] > 0.0);
        } else {
            after = after.with(i, positive);
        }
    }
    Ok(Event {
        t: first,
        y,
        g,
        sides: after,
        at_start,
    })
}
