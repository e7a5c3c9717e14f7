//! The RoboBee-standard quasi-steady model of Whitney & Wood (2010): the translational
//! blade element of §3.2.4 ([`BladeElementModel`]: `M_N`, `M_T`, `M_r`, rotational damping
//! `M_rd`) plus **rotational (circulatory) lift** and **added mass**, translational and
//! rotational.
//!
//! J. P. Whitney & R. J. Wood, "Aeromechanics of passive rotation in flapping flight",
//! J. Fluid Mech. 660 (2010) 197–220, §2.2 (the blade-element terms they sum: translational,
//! rotational, added mass, rotational damping). Strips of chord `c(z)` and leading edge `l(z)`
//! (frame of Fig. 3.1: `x` chordwise toward the leading edge, hinge line `x = 0`) at span `z`.
//!
//! # Rotational lift
//! A strip translating at `U = z W` (`W² = ω_x² + ω_y²`) while pitching about the hinge at
//! `ω_z` sheds the quasi-steady circulation of thin-airfoil theory that enforces the Kutta
//! condition at the ¾-chord: `Γ = π ω_z c² (¾ − x̂₀)` with `x̂₀ = l/c` the hinge's distance
//! from the leading edge in chords (Fung 1969; Sane & Dickinson 2002, eq. 8;
//! `C_R = π(¾ − x̂₀)` in Whitney & Wood 2010 §2.2). Its force `ρ U Γ` acts normal to the wing
//! (`ŷ`), at the quarter chord `x_q = l − c/4`, times the spec's multiplier `k_R` (default 1,
//! the theoretical value the paper uses):
//!
//! ```text
//! dF_y = k_R ρ π z W ω_z c (¾c − l) dz
//! τ_x  = −∫ z dF_y   = −2π k_R (¾Ω3 − Ω4) W ω_z
//! τ_z  =  ∫ x_q dF_y =  2π k_R Ω8 W ω_z,      Ω8 = ½ρ ∫ z c (l − c/4)(¾c − l) dz
//! ```
//!
//! (`Ω3 = ½ρ∫z²c²dz`, `Ω4 = ½ρ∫z²lc dz`, eqs. 3.14–3.15.) The force itself is `−τ_x / r_f`
//! along `ŷ` with the force radius `r_f = Ω1 / force` of the blade element (the same
//! moment-to-force rule as its translational force). The sign does not depend on the stroke
//! direction: the pitch-up rate is `α̇ = σ ω_z` and the normal force direction is `σ ŷ`. As in
//! the paper the leading edge is the physical one on both half-strokes.
//!
//! # Added mass: an added inertia tensor
//! A rigid wing turning about a fixed point in still ideal fluid carries the fluid kinetic
//! energy `½ ωᵀ I_a ω` with `I_a` constant in the wing frame (Kirchhoff). In strip theory a
//! flat-plate strip has the 2-D added mass `ρπc²/4` per span for motion normal to it, at
//! mid-chord `x_m = l − c/2`, and `ρπc⁴/128` for pitch about mid-chord, none chordwise
//! (Sedov 1965; Newman, *Marine Hydrodynamics*, §4.13). The strip's normal velocity at
//! mid-chord is `x_m ω_z − z ω_x`, so
//!
//! ```text
//! I_a,xx = k_t π/2 Ω3
//! I_a,xz = −k_t π/2 Ω5,             Ω5 = ½ρ ∫ z c² x_m dz
//! I_a,zz = k_t π/2 Ω6 + k_r π/64 Ω7,  Ω6 = ½ρ ∫ c² x_m² dz,  Ω7 = ½ρ ∫ c⁴ dz
//! ```
//!
//! with multipliers `k_t` (translational added mass) and `k_r` (rotational added mass), both 1
//! by default (the flat-plate values Whitney & Wood 2010 use). The engine adds `I_a` to the
//! wing's inertia tensor ([`WhitneyWoodModel::added_inertia`]): the fluid's reaction
//! `−(I_a ω̇ + ω × I_a ω)` then enters every form and flight exactly, and its energy is stored
//! (kinetic), not dissipated. Whitney & Wood's added-mass expressions (the normal force from
//! stroke and pitch accelerations, `∝ ∫c²r dr φ̈`, `∫c³ … ψ̈`, and the pitch moment
//! `∝ ∫c⁴ ψ̈`) are the acceleration terms of this tensor; the tensor also keeps the
//! velocity-product terms `ω × I_a ω` that make the exchange with the fluid conservative.

use std::f64::consts::PI;

use nalgebra::{Matrix3, Vector3};
use paritysim_error::{Error, Result, check_finite, check_non_negative};

use crate::{AeroMoments, BladeElementModel, Branch, CoefficientSet};

/// Default rotational-lift multiplier `k_R` (1: `C_R = π(¾ − x̂₀)`, Whitney & Wood 2010 §2.2).
pub const DEFAULT_ROTATIONAL_LIFT: f64 = 1.0;
/// Default translational added-mass multiplier `k_t` (1: the flat plate's `ρπc²/4`).
pub const DEFAULT_TRANSLATIONAL_ADDED_MASS: f64 = 1.0;
/// Default rotational added-mass multiplier `k_r` (1: the flat plate's `ρπc⁴/128`).
pub const DEFAULT_ROTATIONAL_ADDED_MASS: f64 = 1.0;

/// The planform parameters the added terms need, beyond Ω1..Ω4 (mg·mm², `½ρ` folded in like
/// eqs. 3.12–3.15); `x_m = l − c/2` is the mid-chord. Build with
/// [`crate::Planform::quasi_steady_omegas`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct QuasiSteadyOmegas {
    /// Ω5 = ½ρ∫ z c² x_m dz: the stroke–pitch product of the added inertia.
    pub omega5: f64,
    /// Ω6 = ½ρ∫ c² x_m² dz (>= 0): the normal added mass' pitch inertia about the hinge.
    pub omega6: f64,
    /// Ω7 = ½ρ∫ c⁴ dz (>= 0): the pitch added inertia about mid-chord (÷ 64/π).
    pub omega7: f64,
    /// Ω8 = ½ρ∫ z c (l − c/4)(¾c − l) dz: the rotational lift's moment about the hinge.
    pub omega8: f64,
}

/// Multipliers of the added terms (each 1 by default, 0 switches its term off).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuasiSteadyTerms {
    /// Rotational lift `k_R`, in [0, 10].
    pub rotational_lift: f64,
    /// Translational (normal, `ρπc²/4`) added mass `k_t`, in [0, 10].
    pub translational_added_mass: f64,
    /// Rotational (pitch, `ρπc⁴/128`) added mass `k_r`, in [0, 10].
    pub rotational_added_mass: f64,
}

impl Default for QuasiSteadyTerms {
    fn default() -> Self {
        Self {
            rotational_lift: DEFAULT_ROTATIONAL_LIFT,
            translational_added_mass: DEFAULT_TRANSLATIONAL_ADDED_MASS,
            rotational_added_mass: DEFAULT_ROTATIONAL_ADDED_MASS,
        }
    }
}

/// The Whitney & Wood 2010 model of a wing (module docs). Immutable; the torques allocate
/// nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WhitneyWoodModel {
    blade: BladeElementModel<CoefficientSet>,
    omegas: QuasiSteadyOmegas,
    terms: QuasiSteadyTerms,
    added_inertia: Matrix3<f64>,
    /// `τ_rot = (lift_x, 0, lift_z) W ω_z`.
    lift_x: f64,
    lift_z: f64,
}

fn check_multiplier(name: &'static str, v: f64) -> Result<f64> {
    check_non_negative(name, v)?;
    if v > 10.0 {
        return Err(Error::invalid(name, v, "in [0, 10]"));
    }
    Ok(v)
}

impl WhitneyWoodModel {
    /// The model from its translational blade element, Ω5..Ω8 and the multipliers.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `omegaK` (non-finite; `omega6`, `omega7` negative;
    /// `|omega5| > √(Ω3 Ω6)`, which no planform has: the added inertia would not be positive
    /// semi-definite) or a multiplier outside [0, 10].
    pub fn new(
        blade: BladeElementModel<CoefficientSet>,
        omegas: QuasiSteadyOmegas,
        terms: QuasiSteadyTerms,
    ) -> Result<Self> {
        check_finite("omega5", omegas.omega5)?;
        check_non_negative("omega6", omegas.omega6)?;
        check_non_negative("omega7", omegas.omega7)?;
        check_finite("omega8", omegas.omega8)?;
        let o = blade.omegas();
        let bound = (o.omega3 * omegas.omega6).sqrt();
        if omegas.omega5.abs() > bound * (1.0 + 1e-9) + 1e-12 {
            return Err(Error::invalid(
                "omega5",
                omegas.omega5,
                format!("|omega5| <= sqrt(omega3 omega6) = {bound} (Cauchy-Schwarz on a planform)"),
            ));
        }
        check_multiplier("rotational_lift", terms.rotational_lift)?;
        check_multiplier("translational_added_mass", terms.translational_added_mass)?;
        check_multiplier("rotational_added_mass", terms.rotational_added_mass)?;
        let (kt, kr) = (terms.translational_added_mass, terms.rotational_added_mass);
        let ixx = kt * PI / 2.0 * o.omega3;
        let ixz = -kt * PI / 2.0 * omegas.omega5;
        let izz = kt * PI / 2.0 * omegas.omega6 + kr * PI / 64.0 * omegas.omega7;
        let added_inertia = Matrix3::new(ixx, 0.0, ixz, 0.0, 0.0, 0.0, ixz, 0.0, izz);
        let k = terms.rotational_lift;
        Ok(Self {
            blade,
            omegas,
            terms,
            added_inertia,
            lift_x: -2.0 * PI * k * (0.75 * o.omega3 - o.omega4),
            lift_z: 2.0 * PI * k * omegas.omega8,
        })
    }

    /// The translational blade element (with its rotational damping).
    pub fn blade(&self) -> &BladeElementModel<CoefficientSet> {
        &self.blade
    }

    /// Ω5..Ω8.
    pub fn omegas(&self) -> &QuasiSteadyOmegas {
        &self.omegas
    }

    /// The multipliers.
    pub fn terms(&self) -> &QuasiSteadyTerms {
        &self.terms
    }

    /// The added inertia `I_a` (mg·mm², frame 6, about the shoulder; module docs).
    pub fn added_inertia(&self) -> Matrix3<f64> {
        self.added_inertia
    }

    /// `W = √(ω_x² + ω_y²)`, on a branch continued through the stroke reversal with the sign
    /// of the held `σ` (so `W = σ φ̇` on a stroke plane, analytic across `ω_x = 0`).
    #[inline]
    fn speed(omega: &Vector3<f64>, branch: Option<Branch>) -> f64 {
        let w = omega.x.hypot(omega.y);
        match branch {
            Some(b) if b.chordwise_positive != (omega.x >= 0.0) => -w,
            _ => w,
        }
    }

    /// The rotational-lift torque (frame 6, mN·mm) at `ω` (module docs).
    #[inline]
    pub fn rotational_lift_torque(
        &self,
        omega: &Vector3<f64>,
        branch: Option<Branch>,
    ) -> Vector3<f64> {
        let s = Self::speed(omega, branch) * omega.z;
        Vector3::new(self.lift_x * s, 0.0, self.lift_z * s)
    }

    /// The partial derivatives of [`Self::rotational_lift_torque`] on a stroke plane
    /// (`ω = φ̇ (cos ψ, −sin ψ, 0) + ψ̇ ẑ`, so `W = |φ̇|`, `σ φ̇` on a branch) by `φ̇`, `ψ` and
    /// `ψ̇`: `L ψ̇ dW/dφ̇`, `0`, `L W` with `L = (lift_x, 0, lift_z)`. For the stroke-plane
    /// variational equations.
    #[inline]
    pub fn rotational_lift_stroke_plane_slopes(
        &self,
        phi_dot: f64,
        omega: &Vector3<f64>,
        branch: Option<Branch>,
    ) -> [Vector3<f64>; 3] {
        let w = Self::speed(omega, branch);
        let dw = if phi_dot != 0.0 {
            (w / phi_dot).signum()
        } else {
            match branch {
                Some(b) if !b.chordwise_positive => -1.0,
                _ => 1.0,
            }
        };
        let lever = Vector3::new(self.lift_x, 0.0, self.lift_z);
        [lever * (dw * omega.z), Vector3::zeros(), lever * w]
    }

    /// The rotational-lift force (frame 6, mN) at `ω`: `−τ_x / r_f` along `ŷ` (module docs);
    /// zero without a force parameter.
    #[inline]
    pub fn rotational_lift_force(
        &self,
        omega: &Vector3<f64>,
        branch: Option<Branch>,
    ) -> Vector3<f64> {
        let o = self.blade.omegas();
        match o.force {
            Some(f) if o.omega1 > 0.0 => Vector3::new(
                0.0,
                -self.rotational_lift_torque(omega, branch).x * f / o.omega1,
                0.0,
            ),
            _ => Vector3::zeros(),
        }
    }

    /// The velocity-dependent torque (frame 6): the blade element's `(M_N, M_T, M_r + M_rd)`
    /// plus the rotational lift; on `branch` when given. Added mass is not in it (it is
    /// inertia, [`Self::added_inertia`]).
    #[inline]
    pub fn torque(&self, omega: &Vector3<f64>, branch: Option<Branch>) -> Vector3<f64> {
        let m: AeroMoments = match branch {
            None => self.blade.moments_omega(omega),
            Some(b) => self.blade.moments_omega_branch(omega, b),
        };
        m.torque() + self.rotational_lift_torque(omega, branch)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Omegas, Planform};

    fn model(terms: QuasiSteadyTerms) -> (Planform, WhitneyWoodModel) {
        // A rectangle: span 10..20 mm, chord 4 mm, leading edge 1 mm ahead of the hinge.
        let p = Planform::rectangle(10.0, 4.0, 10.0, 1.0).unwrap();
        let rho = crate::DEFAULT_AIR_DENSITY;
        let blade =
            BladeElementModel::new(p.omegas(rho).unwrap(), CoefficientSet::default()).unwrap();
        let m = WhitneyWoodModel::new(blade, p.quasi_steady_omegas(rho).unwrap(), terms).unwrap();
        (p, m)
    }

    #[test]
    fn rectangle_added_inertia_and_rotational_lift_match_hand_integrals() {
        let (_, m) = model(QuasiSteadyTerms::default());
        let rho = crate::DEFAULT_AIR_DENSITY;
        let (c, l, z0, z1) = (4.0_f64, 1.0_f64, 10.0_f64, 20.0_f64);
        let xm = l - c / 2.0;
        let xq = l - c / 4.0;
        let m_strip = rho * PI * c * c / 4.0;
        let i_strip = rho * PI * c.powi(4) / 128.0;
        let span = z1 - z0;
        let z1m = (z1 * z1 - z0 * z0) / 2.0;
        let z2m = (z1.powi(3) - z0.powi(3)) / 3.0;
        let ia = m.added_inertia();
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1e-9);
        assert!(close(ia[(0, 0)], m_strip * z2m));
        assert!(close(ia[(0, 2)], -m_strip * xm * z1m));
        assert!(close(ia[(2, 2)], (m_strip * xm * xm + i_strip) * span));
        // Rotational lift at W = 2, ω_z = 0.5: Γ = π ω_z c² (¾ − l/c), dF = ρ z W Γ dz.
        let omega = Vector3::new(2.0, 0.0, 0.5);
        let gamma = PI * 0.5 * c * c * (0.75 - l / c);
        let t = m.rotational_lift_torque(&omega, None);
        assert!(close(t.x, -rho * 2.0 * gamma * z2m));
        assert!(close(t.z, rho * 2.0 * gamma * xq * z1m));
        assert_eq!(t.y, 0.0);
    }

    #[test]
    fn zero_terms_reduce_to_the_blade_element_and_branches_continue_the_speed() {
        let terms = QuasiSteadyTerms {
            rotational_lift: 0.0,
            translational_added_mass: 0.0,
            rotational_added_mass: 0.0,
        };
        let (_, m) = model(terms);
        assert_eq!(m.added_inertia(), Matrix3::zeros());
        let omega = Vector3::new(-1.3, 0.4, 0.7);
        assert_eq!(
            m.torque(&omega, None),
            m.blade().moments_omega(&omega).torque()
        );
        // On a branch past ω_x = 0, W changes sign with the held σ.
        let (_, full) = model(QuasiSteadyTerms::default());
        let b = Branch::of(&Vector3::new(1.0, 0.0, 1.0));
        let own = full.rotational_lift_torque(&Vector3::new(1.0, 0.0, 0.7), Some(b));
        let past = full.rotational_lift_torque(&Vector3::new(-1.0, 0.0, 0.7), Some(b));
        assert!((own + past).norm() < 1e-15 * own.norm());
    }

    #[test]
    fn bad_parameters_name_their_field() {
        let blade = BladeElementModel::new(
            Omegas::new(30.0, 0.5, 10.0, 1.0).unwrap(),
            CoefficientSet::default(),
        )
        .unwrap();
        let ok = QuasiSteadyOmegas {
            omega5: 1.0,
            omega6: 1.0,
            omega7: 1.0,
            omega8: 0.1,
        };
        let err = |o, t| WhitneyWoodModel::new(blade, o, t).unwrap_err().to_string();
        assert!(
            err(
                QuasiSteadyOmegas { omega6: -1.0, ..ok },
                QuasiSteadyTerms::default()
            )
            .contains("omega6")
        );
        assert!(
            err(
                QuasiSteadyOmegas { omega5: 10.0, ..ok },
                QuasiSteadyTerms::default()
            )
            .contains("omega5")
        );
        let t = QuasiSteadyTerms {
            rotational_lift: 11.0,
            ..QuasiSteadyTerms::default()
        };
        let e = err(ok, t);
        assert!(
            e.contains("rotational_lift") && e.contains("[0, 10]"),
            "{e}"
        );
    }
}
