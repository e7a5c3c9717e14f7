//! What a continuation returns: its points, the bifurcations located on it, why it ended.

use nalgebra::{Complex, DVector};

use crate::multipliers::Stability;

/// One periodic orbit of the branch.
#[derive(Clone, Debug, PartialEq)]
pub struct BranchPoint {
    /// The continued parameter.
    pub parameter: f64,
    /// The orbit's state at phase 0 (a fixed point of the period map).
    pub state: DVector<f64>,
    /// Shift of the cyclic coordinate per period (0 without one).
    pub drift: f64,
    /// Non-trivial Floquet multipliers, largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
    /// From the multipliers.
    pub stability: Stability,
    /// Newton iterations the point took.
    pub iterations: usize,
    /// `|P(x) − x − drift|∞` at the point.
    pub residual: f64,
    /// Scaled arclength from the first point.
    pub arclength: f64,
}

/// What changes at a bifurcation of a forced periodic orbit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BifurcationKind {
    /// A multiplier through +1 where the branch turns back (saddle-node of orbits).
    Fold,
    /// A multiplier through −1: an orbit of twice the period is born.
    PeriodDoubling,
    /// A complex pair through the unit circle: a torus (quasi-periodic motion) is born.
    NeimarkSacker,
    /// A multiplier through +1 where the branch does not turn: another branch crosses this one
    /// (symmetry breaking or transcritical). Detected with pseudo-arclength only.
    BranchPoint,
}

impl BifurcationKind {
    /// `fold`, `period_doubling` or `neimark_sacker`.
    pub fn name(self) -> &'static str {
        match self {
            BifurcationKind::Fold => "fold",
            BifurcationKind::PeriodDoubling => "period_doubling",
            BifurcationKind::NeimarkSacker => "neimark_sacker",
            BifurcationKind::BranchPoint => "branch_point",
        }
    }
}

/// A located bifurcation.
#[derive(Clone, Debug, PartialEq)]
pub struct Bifurcation {
    /// Which one.
    pub kind: BifurcationKind,
    /// The orbit at it.
    pub point: BranchPoint,
    /// Index of the branch point after which it lies.
    pub after: usize,
    /// Whether bisection converged (else `point` is the nearer bracketing point).
    pub located: bool,
}

/// Why the continuation ended.
#[derive(Clone, Debug, PartialEq)]
pub enum StopReason {
    /// The branch reached `stop`.
    ReachedStop,
    /// The branch turned and left the interval on the side of the starting parameter.
    LeftInterval,
    /// `max_points` were computed.
    MaxPoints,
    /// Newton failed even at `min_step`; with natural continuation this is usually a fold.
    StepTooSmall(String),
}

/// A branch of periodic orbits.
#[derive(Clone, Debug, PartialEq)]
pub struct Branch {
    /// The orbits in order along the branch.
    pub points: Vec<BranchPoint>,
    /// Bifurcations in order along the branch.
    pub bifurcations: Vec<Bifurcation>,
    /// Why it ended.
    pub stop_reason: StopReason,
    /// Period-map evaluations with the monodromy (the cost).
    pub map_evaluations: usize,
}
