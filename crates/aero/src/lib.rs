//! Quasi-steady blade-element aerodynamics and wing planform integrals (thesis §3.2.4).
//!
//! * [`planform`]: a wing outline polygon in the frame of Fig. 3.1 (`z` spanwise along the
//!   hinge from the spherical centre, `x` chordwise, positive toward the leading edge), with
//!   exact area, chord `c(z)`, leading edge `l(z)` and the parameters Ω1..Ω4 of eqs. 3.12–3.15.
//! * [`cut`]: [`Planform::cut`] trims a membrane at the tip or trailing edge (the 1-Cut /
//!   2-Cut wings of §3.3–3.4); the result is a polygon, so its Ω stay exact.
//! * [`inertia`]: the wing inertia tensor about the spherical centre (frame of Fig. 3.10) from a
//!   membrane areal density, line masses (spars) and point masses; exact for polygons.
//! * [`coefficients`]: lift/drag coefficient models behind [`CoefficientModel`]: the Dickinson
//!   et al. 1999 fits (eqs. 3.5–3.6) and the Whitney & Wood 2010 `sin 2α` form; the normal and
//!   tangential coefficients `C_N`, `C_T`; the centre of pressure `d̂_cp(α)` (eq. 3.7).
//! * [`blade`]: the blade-element state (wind-relative coordinates, eq. 3.4) and the four moments
//!   `M_N, M_T, M_rd, M_r` of eqs. 3.8–3.11, plus lift and drag forces and their torques about
//!   the body axes.
//! * [`whitney_wood`]: the Whitney & Wood 2010 model: the blade element plus rotational lift
//!   and added mass (an added inertia tensor), with its planform parameters Ω5..Ω8.
//!
//! # Units
//! mg-mm-ms-rad: lengths mm, mass mg, time ms, density mg/mm³, so the Ω are mg·mm² and
//! `Ω·φ̇²` with `φ̇` in rad/ms is directly mN·mm.
//!
//! **Air density.** 1.2 kg/m³ = 1.2·10⁶ mg / 10⁹ mm³ = **1.2·10⁻³ mg/mm³**
//! ([`DEFAULT_AIR_DENSITY`]). With this value a 16.0 mm × 3.2125 mm rectangle (51.4 mm²) gives
//! Ω1 = ½ρ∬z³dA = 31.6 mg·mm², the figure quoted next to the thesis' 31.3 mg·mm² (§3.3.2);
//! 1.2·10⁻⁶ would be a factor 1000 too small.
//!
//! # Errors
//! Every constructor validates and returns [`paritysim_error::Result`]; malformed outlines are
//! [`Error::Geometry`], bad scalars [`Error::InvalidParameter`] naming the field and range.
//! The hot-path evaluations ([`BladeElementModel::moments`]) are infallible and allocation-free:
//! finite input gives finite output.

pub mod blade;
pub mod coefficients;
pub mod cut;
pub mod inertia;
pub mod planform;
pub mod records;
pub mod stroke_drag;
pub mod whitney_wood;
pub mod wing_aero;

pub use blade::{
    AeroLoads, AeroMoments, BladeElementModel, Branch, HeldBranch, NormalForceLaw, Omegas,
    WindRelative, WingState, drag_torque_eq_2_16,
};
pub use coefficients::{
    CoefficientModel, CoefficientSet, Coefficients, DEFAULT_ROTATIONAL_DAMPING, Dickinson1999,
    WhitneyWood2010, center_of_pressure, checked_coefficients, from_normal_tangential,
    to_normal_tangential,
};
pub use cut::CutEdge;
pub use inertia::{LineMass, MassDistribution, PointMass, WingInertia};
pub use paritysim_error::{Error, Result};
pub use planform::{DEFAULT_AIR_DENSITY, Planform, PlanformIntegrals};
pub use stroke_drag::{stroke_drag, stroke_drag_constant, stroke_drag_slope, stroke_drag_torque};
pub use whitney_wood::{
    DEFAULT_ROTATIONAL_ADDED_MASS, DEFAULT_ROTATIONAL_LIFT, DEFAULT_TRANSLATIONAL_ADDED_MASS,
    QuasiSteadyOmegas, QuasiSteadyTerms, WhitneyWoodModel,
};
pub use wing_aero::WingAero;
