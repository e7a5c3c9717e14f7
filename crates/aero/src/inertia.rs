//! Wing inertia about the spherical centre in the frame of Fig. 3.10 (Table 3.3).
//!
//! The wing is flat in the `zx` plane (`y = 0`; `z` spanwise, `x` chordwise toward the leading
//! edge, see [`crate::planform`]). For a planar body
//!
//! ```text
//! Ixx = ∫ (y² + z²) dm = ∫ z² dm        (about the chordwise axis = the stroke axis at ψ = 0)
//! Izz = ∫ (x² + y²) dm = ∫ x² dm        (about the hinge)
//! Iyy = ∫ (x² + z²) dm = Ixx + Izz      (about the wing normal)
//! Ixz = −∫ x z dm                        (tensor element; Ixy = Iyz = 0)
//! ```
//!
//! With the sign convention of the tensor element, a wing hanging behind its hinge (`x < 0`,
//! `z > 0`) has `Ixz > 0`, the sign Table 3.3 reports (4.20, 3.87, …) and `Iyy ≈ Ixx + Izz`
//! holds there too (50.5 ≈ 49.0 + 1.56). Membrane terms come from the exact polygon integrals
//! of [`Planform`]; line masses are integrated in closed form along their segments.

use nalgebra::Matrix3;
use paritysim_error::{Error, Result, bail, check_non_negative};

use crate::planform::Planform;

/// A uniform line mass (spar, vein) along the segment `start → end` (`[z, x]`, mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineMass {
    /// Segment start `[z, x]` (mm).
    pub start: [f64; 2],
    /// Segment end `[z, x]` (mm).
    pub end: [f64; 2],
    /// Mass per length (mg/mm), >= 0.
    pub linear_density: f64,
}

/// A point mass at `position` (`[z, x]`, mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointMass {
    /// Position `[z, x]` (mm).
    pub position: [f64; 2],
    /// Mass (mg), >= 0.
    pub mass: f64,
}

/// How the wing's mass is distributed: membrane + line masses + point masses.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MassDistribution {
    /// Membrane mass per area (mg/mm²), >= 0 (e.g. 1.5 µm polyester ≈ 2.1·10⁻³ mg/mm²).
    pub areal_density: f64,
    /// Spars and veins.
    pub line_masses: Vec<LineMass>,
    /// Concentrated masses (glue, hinge parts).
    pub point_masses: Vec<PointMass>,
}

/// Mass properties of a wing about the spherical centre (mg, mm, mg·mm²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WingInertia {
    /// Total mass (mg).
    pub mass: f64,
    /// Centre of mass `[z, x]` (mm).
    pub center_of_mass: [f64; 2],
    /// `∫ z² dm` (mg·mm²).
    pub ixx: f64,
    /// `∫ (x² + z²) dm` (mg·mm²).
    pub iyy: f64,
    /// `∫ x² dm` (mg·mm²).
    pub izz: f64,
    /// Tensor element `−∫ x z dm` (mg·mm²).
    pub ixz: f64,
}

impl WingInertia {
    /// The inertia tensor about the spherical centre in the wing frame `(x, y, z)`:
    /// `[[Ixx, 0, Ixz], [0, Iyy, 0], [Ixz, 0, Izz]]`.
    pub fn tensor(&self) -> Matrix3<f64> {
        Matrix3::new(
            self.ixx, 0.0, self.ixz, 0.0, self.iyy, 0.0, self.ixz, 0.0, self.izz,
        )
    }
}

/// Running sums `m, ∫z, ∫x, ∫z², ∫x², ∫xz` (mass-weighted).
#[derive(Default)]
struct Moments {
    m: f64,
    z: f64,
    x: f64,
    zz: f64,
    xx: f64,
    xz: f64,
}

fn check_point(field: String, p: [f64; 2]) -> Result<()> {
    if p[0].is_finite() && p[1].is_finite() {
        Ok(())
    } else {
        Err(Error::invalid(
            field,
            format!("[{}, {}]", p[0], p[1]),
            "finite [z, x] in mm",
        ))
    }
}

impl MassDistribution {
    /// A bare membrane of `areal_density` mg/mm².
    pub fn membrane(areal_density: f64) -> Self {
        Self {
            areal_density,
            ..Self::default()
        }
    }

    /// Mass properties of this distribution on `planform` (the membrane covers the planform).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a negative or non-finite density or mass (naming
    /// `areal_density`, `line_masses[i].linear_density`, `point_masses[i].mass` or the
    /// position), and if the total mass is zero.
    pub fn inertia(&self, planform: &Planform) -> Result<WingInertia> {
        check_non_negative("areal_density", self.areal_density)?;
        let s = planform.integrals();
        let rho = self.areal_density;
        let mut acc = Moments {
            m: rho * s.area,
            z: rho * s.z1,
            x: rho * s.x1,
            zz: rho * s.z2,
            xx: rho * s.x2,
            xz: rho * s.xz,
        };
        for (i, l) in self.line_masses.iter().enumerate() {
            check_point(format!("line_masses[{i}].start"), l.start)?;
            check_point(format!("line_masses[{i}].end"), l.end)?;
            if !(l.linear_density.is_finite() && l.linear_density >= 0.0) {
                return Err(Error::invalid(
                    format!("line_masses[{i}].linear_density"),
                    l.linear_density,
                    "finite and >= 0 (mg/mm)",
                ));
            }
            // p(t) = a + t d, t ∈ [0, 1]: ∫ p_i p_j dt = a_i a_j + (a_i d_j + a_j d_i)/2 + d_i d_j/3.
            let (a, d) = (l.start, [l.end[0] - l.start[0], l.end[1] - l.start[1]]);
            let m = l.linear_density * d[0].hypot(d[1]);
            let quad = |i: usize, j: usize| {
                a[i] * a[j] + 0.5 * (a[i] * d[j] + a[j] * d[i]) + d[i] * d[j] / 3.0
            };
            acc.m += m;
            acc.z += m * (a[0] + 0.5 * d[0]);
            acc.x += m * (a[1] + 0.5 * d[1]);
            acc.zz += m * quad(0, 0);
            acc.xx += m * quad(1, 1);
            acc.xz += m * quad(0, 1);
        }
        for (i, p) in self.point_masses.iter().enumerate() {
            check_point(format!("point_masses[{i}].position"), p.position)?;
            if !(p.mass.is_finite() && p.mass >= 0.0) {
                return Err(Error::invalid(
                    format!("point_masses[{i}].mass"),
                    p.mass,
                    "finite and >= 0 (mg)",
                ));
            }
            let [z, x] = p.position;
            acc.m += p.mass;
            acc.z += p.mass * z;
            acc.x += p.mass * x;
            acc.zz += p.mass * z * z;
            acc.xx += p.mass * x * x;
            acc.xz += p.mass * x * z;
        }
        if acc.m <= 0.0 {
            bail!(invalid "mass", acc.m, "> 0 in total (set areal_density, line or point masses)");
        }
        Ok(WingInertia {
            mass: acc.m,
            center_of_mass: [acc.z / acc.m, acc.x / acc.m],
            ixx: acc.zz,
            iyy: acc.zz + acc.xx,
            izz: acc.xx,
            ixz: -acc.xz,
        })
    }
}

impl Planform {
    /// Mass properties of this planform carrying `mass` (see [`MassDistribution::inertia`]).
    ///
    /// # Errors
    /// As [`MassDistribution::inertia`].
    pub fn inertia(&self, mass: &MassDistribution) -> Result<WingInertia> {
        mass.inertia(self)
    }
}
