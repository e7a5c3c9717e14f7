//! Plain serde records of the aero results (what the Python bindings hand over through one
//! generic converter): planform geometry, mass properties, coefficient tables and blade-element
//! moment series. Vectors are `[f64; 3]`, matrices row-major nested arrays.

use nalgebra::Vector3;
use serde::Serialize;

use crate::{
    BladeElementModel, CoefficientModel, CoefficientSet, Error, LineMass, MassDistribution,
    NormalForceLaw, Omegas, Planform, PlanformIntegrals, PointMass, Result, WingState,
    center_of_pressure,
};

fn arr(v: Vector3<f64>) -> [f64; 3] {
    [v[0], v[1], v[2]]
}

/// `[z, x]` vertices of a planform, counter-clockwise.
pub fn vertices(p: &Planform) -> Vec<[f64; 2]> {
    p.vertices().iter().map(|v| [v[0], v[1]]).collect()
}

/// Geometry and Ω1..Ω4 of a planform in air of a density.
#[derive(Clone, Debug, Serialize)]
pub struct PlanformReport {
    /// Validated vertices `[z, x]`, mm.
    pub vertices: Vec<[f64; 2]>,
    /// Area, mm².
    pub area: f64,
    /// Span, mm.
    pub span: f64,
    /// Tip radius, mm.
    pub tip_radius: f64,
    /// Root offset, mm.
    pub root_offset: f64,
    /// Mean chord, mm.
    pub mean_chord: f64,
    /// Centroid `[z, x]`, mm.
    pub centroid: [f64; 2],
    /// `[x_min, x_max]`, mm.
    pub x_range: [f64; 2],
    /// Ω1 (mg·mm²).
    pub omega1: f64,
    /// Ω2.
    pub omega2: f64,
    /// Ω3.
    pub omega3: f64,
    /// Ω4.
    pub omega4: f64,
    /// `½ρ∬z²dA` (mg·mm), 0 when undefined.
    pub force: f64,
    /// Ω5..Ω8 of the Whitney & Wood 2010 model (mg·mm², [`Planform::quasi_steady_omegas`]).
    pub omega5: f64,
    /// Ω6.
    pub omega6: f64,
    /// Ω7.
    pub omega7: f64,
    /// Ω8.
    pub omega8: f64,
    /// The density-free integrals.
    pub integrals: PlanformIntegrals,
}

impl PlanformReport {
    /// The report of `p` for air of `density` (mg/mm³).
    ///
    /// # Errors
    /// As [`Planform::omegas`].
    pub fn of(p: &Planform, density: f64) -> Result<Self> {
        let o = p.omegas(density)?;
        let q = p.quasi_steady_omegas(density)?;
        let (x0, x1) = p.x_range();
        Ok(Self {
            vertices: vertices(p),
            area: p.area(),
            span: p.span(),
            tip_radius: p.tip_radius(),
            root_offset: p.root_offset(),
            mean_chord: p.mean_chord(),
            centroid: p.centroid(),
            x_range: [x0, x1],
            omega1: o.omega1,
            omega2: o.omega2,
            omega3: o.omega3,
            omega4: o.omega4,
            force: o.force.unwrap_or(0.0),
            omega5: q.omega5,
            omega6: q.omega6,
            omega7: q.omega7,
            omega8: q.omega8,
            integrals: *p.integrals(),
        })
    }
}

/// Chord and leading edge at stations (leading edge None outside the span).
#[derive(Clone, Debug, Serialize)]
pub struct ChordTable {
    /// Chord `c(z)`, mm (0 outside the span).
    pub chord: Vec<f64>,
    /// Leading edge `l(z)`, mm.
    pub leading_edge: Vec<Option<f64>>,
}

impl ChordTable {
    /// The table of `p` at the stations `z` (mm).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `z[i]` for a non-finite station.
    pub fn of(p: &Planform, z: &[f64]) -> Result<Self> {
        paritysim_error::check_all_finite("z", z)?;
        let (chord, leading_edge) = z.iter().map(|&z| (p.chord(z), p.leading_edge(z))).unzip();
        Ok(Self {
            chord,
            leading_edge,
        })
    }
}

/// Mass properties about the spherical centre (mg, mm, mg·mm²).
#[derive(Clone, Debug, Serialize)]
pub struct InertiaReport {
    /// Mass, mg.
    pub mass: f64,
    /// Centre of mass `[z, x]`, mm.
    pub center_of_mass: [f64; 2],
    /// `∫ z² dm`.
    pub ixx: f64,
    /// `∫ (x² + z²) dm`.
    pub iyy: f64,
    /// `∫ x² dm`.
    pub izz: f64,
    /// `−∫ x z dm`.
    pub ixz: f64,
    /// The tensor in the wing frame, 3×3.
    pub tensor: [[f64; 3]; 3],
}

impl InertiaReport {
    /// Mass properties of `p` with membrane `areal_density` (mg/mm²), line masses as rows
    /// `[z0, x0, z1, x1, linear_density]` and point masses as rows `[z, x, mass]`.
    ///
    /// # Errors
    /// As [`Planform::inertia`].
    pub fn of(
        p: &Planform,
        areal_density: f64,
        lines: &[[f64; 5]],
        points: &[[f64; 3]],
    ) -> Result<Self> {
        let dist = MassDistribution {
            areal_density,
            line_masses: lines
                .iter()
                .map(|r| LineMass {
                    start: [r[0], r[1]],
                    end: [r[2], r[3]],
                    linear_density: r[4],
                })
                .collect(),
            point_masses: points
                .iter()
                .map(|r| PointMass {
                    position: [r[0], r[1]],
                    mass: r[2],
                })
                .collect(),
        };
        let i = p.inertia(&dist)?;
        let t = i.tensor();
        Ok(Self {
            mass: i.mass,
            center_of_mass: i.center_of_mass,
            ixx: i.ixx,
            iyy: i.iyy,
            izz: i.izz,
            ixz: i.ixz,
            tensor: std::array::from_fn(|r| std::array::from_fn(|c| t[(r, c)])),
        })
    }
}

/// Coefficients over angles of attack.
#[derive(Clone, Debug, Default, Serialize)]
pub struct CoefficientTable {
    /// Lift coefficient.
    pub lift: Vec<f64>,
    /// Drag coefficient.
    pub drag: Vec<f64>,
    /// Normal coefficient.
    pub normal: Vec<f64>,
    /// Tangential coefficient.
    pub tangential: Vec<f64>,
    /// Centre of pressure (fraction of chord).
    pub center_of_pressure: Vec<f64>,
}

impl CoefficientTable {
    /// The coefficients of `set` at each `alpha` (rad).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `alpha[i]` outside [0, π] or non-finite.
    pub fn of(set: &CoefficientSet, alpha: &[f64]) -> Result<Self> {
        let range = 0.0..=std::f64::consts::PI;
        if let Some(i) = alpha.iter().position(|a| !range.contains(a)) {
            let allowed = "in [0, pi] rad (angle between chord and velocity)";
            return Err(Error::invalid(format!("alpha[{i}]"), alpha[i], allowed));
        }
        let mut t = Self::default();
        for &a in alpha {
            let k = set.coefficients(a);
            t.lift.push(k.lift);
            t.drag.push(k.drag);
            t.normal.push(k.normal);
            t.tangential.push(k.tangential);
            t.center_of_pressure.push(center_of_pressure(a));
        }
        Ok(t)
    }
}

/// Blade-element moments (eqs. 3.8–3.11) over a series of states; the loads (body axes
/// `[roll, yaw, pitch]`) only when the model has a force parameter.
#[derive(Clone, Debug, Default, Serialize)]
pub struct MomentSeries {
    /// Normal moment.
    pub normal: Vec<f64>,
    /// Tangential moment.
    pub tangential: Vec<f64>,
    /// Rotational moment.
    pub rotational: Vec<f64>,
    /// Rotational damping moment.
    pub rotational_damping: Vec<f64>,
    /// Angle of attack, rad.
    pub alpha: Vec<f64>,
    /// Wind-relative stroke rate.
    pub phi_dot_rw: Vec<f64>,
    /// Wind-relative rotation.
    pub psi_rw: Vec<f64>,
    /// Wind-relative rotation rate.
    pub psi_dot_rw: Vec<f64>,
    /// Torque in wing axes, (n, 3).
    pub torque_wing: Vec<[f64; 3]>,
    /// Lift, (n, 3).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lift: Option<Vec<[f64; 3]>>,
    /// Drag, (n, 3).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drag: Option<Vec<[f64; 3]>>,
    /// Lift torque, (n, 3).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lift_torque: Option<Vec<[f64; 3]>>,
    /// Drag torque, (n, 3).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drag_torque: Option<Vec<[f64; 3]>>,
    /// Total torque in body axes, (n, 3).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub torque_body: Option<Vec<[f64; 3]>>,
}

impl MomentSeries {
    /// The moments of `m` at each state; with `loads`, the lift/drag outputs too.
    ///
    /// # Errors
    /// As [`BladeElementModel::loads`] (no force parameter).
    pub fn of(m: &BladeElementModel, states: &[WingState], loads: bool) -> Result<Self> {
        let mut s = Self::default();
        let mut l: [Vec<[f64; 3]>; 5] = Default::default();
        for st in states {
            let mo = m.moments(st);
            let w = st.wind_relative();
            s.normal.push(mo.normal);
            s.tangential.push(mo.tangential);
            s.rotational.push(mo.rotational);
            s.rotational_damping.push(mo.rotational_damping);
            s.alpha.push(mo.alpha);
            s.phi_dot_rw.push(w.phi_dot_rw);
            s.psi_rw.push(w.psi_rw);
            s.psi_dot_rw.push(w.psi_dot_rw);
            s.torque_wing.push(arr(mo.torque()));
            if loads {
                let x = m.loads(st)?;
                for (dst, v) in
                    l.iter_mut()
                        .zip([x.lift, x.drag, x.lift_torque, x.drag_torque, x.torque()])
                {
                    dst.push(arr(v));
                }
            }
        }
        if loads {
            let [lift, drag, lift_torque, drag_torque, torque_body] = l;
            (s.lift, s.drag, s.lift_torque, s.drag_torque, s.torque_body) = (
                Some(lift),
                Some(drag),
                Some(lift_torque),
                Some(drag_torque),
                Some(torque_body),
            );
        }
        Ok(s)
    }
}

/// The inputs of a [`MomentSeries`] by name, as the bindings receive them.
#[derive(Clone, Debug)]
pub struct MomentRequest<'a> {
    /// `[Ω1, Ω2, Ω3, Ω4]` (mg·mm²).
    pub omegas: [f64; 4],
    /// `½ρ∬z²dA` (mg·mm); enables the lift/drag outputs.
    pub force: Option<f64>,
    /// Coefficient model name ([`CoefficientSet::from_name`]).
    pub model: &'a str,
    /// Rotational damping coefficient.
    pub rotational_damping: f64,
    /// Normal force law name ([`NormalForceLaw::from_name`]).
    pub normal_force_law: &'a str,
    /// Paired columns `phi, theta, psi, phi_dot, theta_dot, psi_dot`.
    pub columns: [&'a [f64]; 6],
}

impl MomentRequest<'_> {
    /// Column names of [`MomentRequest::columns`], in order.
    pub const COLUMNS: [&'static str; 6] =
        ["phi", "theta", "psi", "phi_dot", "theta_dot", "psi_dot"];

    /// Builds the model and the states and evaluates the series.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for an unknown name, a bad Ω, force or damping, or a
    /// non-finite state; [`Error::Shape`] when the columns' lengths differ (naming both).
    pub fn evaluate(&self) -> Result<MomentSeries> {
        let set = CoefficientSet::from_name(self.model)?;
        let law = NormalForceLaw::from_name(self.normal_force_law)?;
        let [o1, o2, o3, o4] = self.omegas;
        let mut o = Omegas::new(o1, o2, o3, o4)?;
        if let Some(f) = self.force {
            o = o.with_force(f)?;
        }
        let m = BladeElementModel::new(o, set)?
            .with_rotational_damping(self.rotational_damping)?
            .with_normal_force_law(law);
        let n = self.columns[0].len();
        for (name, col) in Self::COLUMNS.iter().zip(self.columns) {
            paritysim_error::check_same_len(("phi", n), (name, col.len()))?;
            paritysim_error::check_all_finite(name, col)?;
        }
        let [phi, theta, psi, phi_dot, theta_dot, psi_dot] = self.columns;
        let states: Vec<WingState> = (0..n)
            .map(|i| WingState {
                phi: phi[i],
                theta: theta[i],
                psi: psi[i],
                phi_dot: phi_dot[i],
                theta_dot: theta_dot[i],
                psi_dot: psi_dot[i],
            })
            .collect();
        MomentSeries::of(&m, &states, self.force.is_some())
    }
}
