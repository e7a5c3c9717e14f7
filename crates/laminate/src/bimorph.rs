//! Piezoelectric bending actuator (bimorph) after Wood, Steltz & Fearing 2005, "Optimal energy
//! density piezoelectric bending actuators" (thesis ref. \[42\]).
//!
//! # Model
//!
//! A cantilever of active (piezo) length `L` clamped at its base, followed by a rigid, massless
//! extension of length `L_ext` whose end is the output point. The width tapers linearly from
//! `w0` at the base to `w0 · width_ratio` at the end of the active part.
//!
//! * The laminate (CLPT, [`crate::clpt`]) gives the free curvature per volt `κ_V` (narrow-beam
//!   assumption: no applied `N`, `My`, `Mxy`), which does not depend on the width. Integrating
//!   twice, the free deflection at the extension end is
//!   `δ = κ_V V L (L/2 + L_ext)` (the extension adds the rotation at `x = L` times `L_ext`).
//! * A force `F` at the output gives the moment `F (L + L_ext − x)` and the curvature
//!   `d11 F (L + L_ext − x) / w(x)`, with `d11` the (1,1) entry of `D*`, the bending block of
//!   `ABD⁻¹` (mm/(mN·mm)·mm). By the unit-load method the output compliance is
//!   `1/k = d11 ∫₀ᴸ (L + L_ext − x)² / w(x) dx`, integrated in closed form (series for a nearly
//!   rectangular planform).
//! * Blocked force `F_b = k δ`, hence `F_b/V = k κ_V L (L/2 + L_ext)`.
//!
//! For a rectangular actuator without extension this reduces to `δ = κ L²/2`,
//! `k = 3 w / (d11 L³)` (= `3EI/L³`), `F_b = 3 κ w / (2 d11 L)`. The geometry factor of a tapered
//! actuator with extension matches the closed form published by Wood et al. 2005 (checked in the
//! tests).
//!
//! **Drive**: every piezo layer whose centre lies above the mid-plane receives `+V`, every one
//! below receives `−V` across its own thickness (poling along +z). For the usual parallel/bias
//! drive of HMF-type bimorphs, `V` is the drive amplitude about the half-bias point. With
//! `d31 < 0` a positive `V` deflects the output towards +z.
//!
//! Units: lengths mm, voltage V, force mN, stiffness mN/mm, mass mg.

use paritysim_error::{Error, Result, check_finite, check_non_negative, check_positive};

use crate::clpt::{Layer, Layup, Loads};
use crate::material::library;

/// The zeroth-order actuator model of thesis §3.2.2 (assumption 4): a voltage-proportional force
/// in parallel with a linear spring, `F = force_per_volt · V − stiffness · x`.
///
/// This is what the dynamics engine consumes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActuatorConstants {
    /// Output stiffness `k`, mN/mm.
    pub stiffness_mn_per_mm: f64,
    /// Blocked force per drive volt `F_b / V`, mN/V.
    pub force_per_volt_mn_per_v: f64,
}

impl ActuatorConstants {
    /// The thesis' actuator (§3.3.1): 467 mN/mm and 120 mN amplitude at 100 V amplitude
    /// (1.2 mN/V), "from a laminate plate theory analysis" \[42\].
    pub const THESIS: ActuatorConstants = ActuatorConstants {
        stiffness_mn_per_mm: 467.0,
        force_per_volt_mn_per_v: 1.2,
    };

    /// Validated constructor: both finite and `> 0` (mN/mm, mN/V).
    pub fn new(stiffness_mn_per_mm: f64, force_per_volt_mn_per_v: f64) -> Result<Self> {
        check_positive("stiffness_mn_per_mm", stiffness_mn_per_mm)?;
        check_positive("force_per_volt_mn_per_v", force_per_volt_mn_per_v)?;
        Ok(ActuatorConstants {
            stiffness_mn_per_mm,
            force_per_volt_mn_per_v,
        })
    }

    /// Free (unloaded) deflection per volt `F_b / (V k)`, mm/V (thesis: 2.57 µm/V).
    pub fn free_deflection_per_volt(&self) -> f64 {
        self.force_per_volt_mn_per_v / self.stiffness_mn_per_mm
    }
}

/// Planform of a bending actuator. Lengths mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BimorphGeometry {
    /// Active (piezo) length `L`, mm (> 0).
    pub length: f64,
    /// Rigid extension length `L_ext` beyond the active part, mm (≥ 0).
    pub extension: f64,
    /// Width at the clamped base `w0`, mm (> 0).
    pub base_width: f64,
    /// Taper: width at the end of the active part divided by `w0` (> 0; 1 = rectangular).
    pub width_ratio: f64,
}

impl BimorphGeometry {
    /// Validated constructor (see the field docs for the ranges).
    pub fn new(length: f64, extension: f64, base_width: f64, width_ratio: f64) -> Result<Self> {
        let g = BimorphGeometry {
            length,
            extension,
            base_width,
            width_ratio,
        };
        g.validate()?;
        Ok(g)
    }

    /// From the parameters of Wood et al. 2005: active length `L` (mm), extension ratio
    /// `l_r = L_ext / L` (≥ 0), nominal (mean) width `w_nom` (mm) and their width ratio
    /// `w_r = w0 / w_nom` in (0, 2) (1 = rectangular, → 2 = pointed tip).
    pub fn from_wood(
        length: f64,
        extension_ratio: f64,
        nominal_width: f64,
        wood_width_ratio: f64,
    ) -> Result<Self> {
        check_positive("length", length)?;
        check_non_negative("extension_ratio", extension_ratio)?;
        check_positive("nominal_width", nominal_width)?;
        check_finite("wood_width_ratio", wood_width_ratio)?;
        if !(wood_width_ratio > 0.0 && wood_width_ratio < 2.0) {
            return Err(Error::invalid(
                "wood_width_ratio",
                wood_width_ratio,
                "in (0, 2)",
            ));
        }
        BimorphGeometry::new(
            length,
            extension_ratio * length,
            wood_width_ratio * nominal_width,
            (2.0 - wood_width_ratio) / wood_width_ratio,
        )
    }

    fn validate(&self) -> Result<()> {
        check_positive("length", self.length)?;
        check_non_negative("extension", self.extension)?;
        check_positive("base_width", self.base_width)?;
        check_positive("width_ratio", self.width_ratio)?;
        Ok(())
    }

    /// Width at the end of the active part, mm.
    pub fn tip_width(&self) -> f64 {
        self.base_width * self.width_ratio
    }
    /// Mean width of the active part `w_nom`, mm.
    pub fn nominal_width(&self) -> f64 {
        0.5 * self.base_width * (1.0 + self.width_ratio)
    }
    /// `L_ext / L`.
    pub fn extension_ratio(&self) -> f64 {
        self.extension / self.length
    }
    /// Planform area of the active part, mm².
    pub fn active_area(&self) -> f64 {
        self.length * self.nominal_width()
    }
}

/// `∫₀ᴸ (L + L_ext − x)² / s(x) dx` with `s(x) = 1 − c x / L`, `c = 1 − ratio` (mm³).
fn taper_integral(l: f64, ext: f64, ratio: f64) -> f64 {
    let a = l + ext;
    let c = 1.0 - ratio;
    if c.abs() < 0.2 {
        // 1/s = Σ (c x/L)^n; ∫₀ᴸ (a − x)² (x/L)^n dx = L (a²/(n+1) − 2aL/(n+2) + L²/(n+3)).
        let mut sum = 0.0;
        let mut cn = 1.0;
        for n in 0..80 {
            let nf = n as f64;
            let term = l * (a * a / (nf + 1.0) - 2.0 * a * l / (nf + 2.0) + l * l / (nf + 3.0));
            sum += cn * term;
            cn *= c;
            if cn.abs() < 1e-30 {
                break;
            }
        }
        sum
    } else {
        // s = 1 − c x/L, a − x = (L/c)(s + β), β = a c / L − 1.
        let s0 = ratio;
        let beta = a * c / l - 1.0;
        let bracket = 0.5 * (1.0 - s0 * s0) + 2.0 * beta * (1.0 - s0) - beta * beta * s0.ln();
        (l / c).powi(3) * bracket
    }
}

/// A piezoelectric bending actuator: a layup with at least one piezo layer and a planform.
#[derive(Clone, Debug, PartialEq)]
pub struct Bimorph {
    layup: Layup,
    geometry: BimorphGeometry,
    /// Per-layer drive sign (+1 above the mid-plane, −1 below, 0 for passive layers).
    drive: Vec<f64>,
    /// `w''` per volt, 1/(mm·V).
    curvature_per_volt: f64,
    /// Bending compliance `d11` of the laminate, 1/(mN·mm).
    d11: f64,
}

impl Bimorph {
    /// Builds the actuator; `Error::Geometry` if the layup has no piezo layer or a piezo layer
    /// straddles the mid-plane, `Error::Singular` if the laminate has no bending stiffness.
    pub fn new(layup: Layup, geometry: BimorphGeometry) -> Result<Bimorph> {
        geometry.validate()?;
        let bounds = layup.layer_bounds();
        let mut drive = Vec::with_capacity(layup.len());
        for (layer, (z0, z1)) in layup.layers().iter().zip(bounds) {
            if !layer.is_piezo() {
                drive.push(0.0);
                continue;
            }
            let zc = 0.5 * (z0 + z1);
            let tol = 1e-12 * (z1 - z0);
            if zc.abs() <= tol {
                return Err(Error::Geometry(format!(
                    "piezo layer `{}` is centred on the mid-plane: it cannot bend the actuator",
                    layer.name()
                )));
            }
            drive.push(zc.signum());
        }
        if drive.iter().all(|&s| s == 0.0) {
            return Err(Error::Geometry(
                "a bending actuator needs at least one piezoelectric layer".into(),
            ));
        }
        let compliance = layup.abd().compliance()?;
        let d11 = compliance[(3, 3)];
        let kappa = layup
            .response(&Loads {
                voltages: drive.clone(),
                ..Loads::default()
            })?
            .curvature[0];
        Ok(Bimorph {
            layup,
            geometry,
            drive,
            curvature_per_volt: -kappa,
            d11,
        })
    }

    /// The PZT–CF–PZT layup of Wood et al. 2005: two [`library::pzt_5h`] plates of `t_pzt` mm
    /// around a unidirectional carbon-fibre core ([`library::cf_prepreg_ud`] at 0°, fibres
    /// along the actuator) of `t_cf` mm.
    pub fn wood_layup(t_pzt: f64, t_cf: f64) -> Result<Layup> {
        let pzt = library::pzt_5h();
        Layup::new(vec![
            Layer::single("PZT (bottom)", pzt.clone(), t_pzt, 0.0)?,
            Layer::single("CF", library::cf_prepreg_ud(), t_cf, 0.0)?,
            Layer::single("PZT (top)", pzt, t_pzt, 0.0)?,
        ])
    }

    /// The Mobee actuator layup of §4.4.2: two 127 µm PSI-5H4E plates bonded with 12.5 µm
    /// Pyralux to a central 100 µm 0-90-0 CF layer ("similar to those created by \[42\], differing
    /// only in that Pyralux acrylic replaces a cyanate ester").
    pub fn mobee_layup() -> Result<Layup> {
        let pzt = library::pzt_5h();
        let a = library::pyralux_adhesive();
        Layup::new(vec![
            Layer::single("PZT (bottom)", pzt.clone(), 0.127, 0.0)?,
            Layer::single("A", a.clone(), 0.0125, 0.0)?,
            Layer::cf_0_90_0("CF 0-90-0", 0.100, 0.0)?,
            Layer::single("A", a, 0.0125, 0.0)?,
            Layer::single("PZT (top)", pzt, 0.127, 0.0)?,
        ])
    }

    /// Solves for the planform that gives `target` constants with the given `layup`, taper
    /// `width_ratio` (tip/base, > 0) and `extension_ratio` (`L_ext / L`, ≥ 0).
    ///
    /// The free deflection per volt `F_b/(V k)` fixes `L` (it does not depend on the width):
    /// `L = sqrt(δ_V / (κ_V (1/2 + l_r)))`; the stiffness is proportional to `w0`, which fixes
    /// the base width. `Error::OutOfDomain` if the target deflection has the opposite sign of
    /// the laminate's curvature.
    pub fn design_for(
        layup: Layup,
        target: ActuatorConstants,
        width_ratio: f64,
        extension_ratio: f64,
    ) -> Result<Bimorph> {
        let target =
            ActuatorConstants::new(target.stiffness_mn_per_mm, target.force_per_volt_mn_per_v)?;
        check_positive("width_ratio", width_ratio)?;
        check_non_negative("extension_ratio", extension_ratio)?;
        let unit = BimorphGeometry::new(1.0, extension_ratio, 1.0, width_ratio)?;
        let probe = Bimorph::new(layup, unit)?;
        let kv = probe.curvature_per_volt.abs();
        if kv == 0.0 {
            return Err(Error::OutOfDomain {
                what: "bimorph design".into(),
                detail: "the laminate does not bend under voltage".into(),
            });
        }
        let dv = target.free_deflection_per_volt();
        let length = (dv / (kv * (0.5 + extension_ratio))).sqrt();
        let mut geometry =
            BimorphGeometry::new(length, extension_ratio * length, 1.0, width_ratio)?;
        let k1 = 1.0 / (probe.d11 * taper_integral(length, geometry.extension, width_ratio));
        geometry.base_width = target.stiffness_mn_per_mm / k1;
        let Bimorph { layup, .. } = probe;
        Bimorph::new(layup, geometry)
    }

    /// The laminate.
    pub fn layup(&self) -> &Layup {
        &self.layup
    }
    /// The planform.
    pub fn geometry(&self) -> &BimorphGeometry {
        &self.geometry
    }
    /// The same laminate with another planform.
    pub fn with_geometry(&self, geometry: BimorphGeometry) -> Result<Bimorph> {
        geometry.validate()?;
        let mut b = self.clone();
        b.geometry = geometry;
        Ok(b)
    }

    /// Per-layer drive voltages for a drive amplitude `voltage` (V): `+V` above the mid-plane,
    /// `−V` below, 0 on passive layers (usable as [`Loads::voltages`]).
    pub fn layer_voltages(&self, voltage: f64) -> Vec<f64> {
        self.drive.iter().map(|s| s * voltage).collect()
    }

    /// Free curvature per drive volt, `w''/V` (1/(mm·V)); positive means the output moves
    /// towards +z for positive voltage.
    pub fn curvature_per_volt(&self) -> f64 {
        self.curvature_per_volt
    }

    /// Beam bending stiffness per unit width `1/d11`, mN·mm.
    pub fn bending_stiffness_per_width(&self) -> f64 {
        1.0 / self.d11
    }

    /// Largest drive amplitude allowed by the piezo plies' `max_field`, V.
    pub fn max_voltage(&self) -> f64 {
        self.layup
            .layers()
            .iter()
            .flat_map(|l| l.plies())
            .filter_map(|p| p.material().piezo().map(|pz| pz.max_field * p.thickness()))
            .fold(f64::INFINITY, f64::min)
    }

    fn check_voltage(&self, voltage: f64) -> Result<()> {
        check_finite("voltage", voltage)?;
        let vmax = self.max_voltage();
        if voltage.abs() > vmax {
            return Err(Error::OutOfDomain {
                what: "bimorph drive voltage".into(),
                detail: format!(
                    "|V| = {} V exceeds {vmax:.1} V, the max_field of the thinnest piezo ply",
                    voltage.abs()
                ),
            });
        }
        Ok(())
    }

    /// Free deflection per volt at the output, mm/V.
    pub fn free_deflection_per_volt(&self) -> f64 {
        let g = &self.geometry;
        self.curvature_per_volt * g.length * (0.5 * g.length + g.extension)
    }

    /// Free (unloaded) output deflection at drive amplitude `voltage` (V), mm;
    /// `Error::OutOfDomain` beyond [`Bimorph::max_voltage`].
    pub fn free_deflection(&self, voltage: f64) -> Result<f64> {
        self.check_voltage(voltage)?;
        Ok(self.free_deflection_per_volt() * voltage)
    }

    /// Output stiffness `k`, mN/mm.
    pub fn stiffness(&self) -> f64 {
        let g = &self.geometry;
        g.base_width / (self.d11 * taper_integral(g.length, g.extension, g.width_ratio))
    }

    /// Blocked force per volt `k δ / V`, mN/V (signed like the deflection).
    pub fn force_per_volt(&self) -> f64 {
        self.stiffness() * self.free_deflection_per_volt()
    }

    /// Blocked force at drive amplitude `voltage` (V), mN; `Error::OutOfDomain` beyond
    /// [`Bimorph::max_voltage`].
    pub fn blocked_force(&self, voltage: f64) -> Result<f64> {
        self.check_voltage(voltage)?;
        Ok(self.force_per_volt() * voltage)
    }

    /// The constants of the zeroth-order model (§3.2.2) for the dynamics engine. The force per
    /// volt is reported as a magnitude (the drive sign is a wiring convention).
    pub fn constants(&self) -> ActuatorConstants {
        ActuatorConstants {
            stiffness_mn_per_mm: self.stiffness(),
            force_per_volt_mn_per_v: self.force_per_volt().abs(),
        }
    }

    /// Mass of the active part (laminate areal mass × planform area), mg. The extension,
    /// electrodes and base clamp are not included.
    pub fn active_mass(&self) -> f64 {
        self.layup.areal_mass() * self.geometry.active_area()
    }
}

#[cfg(test)]
mod tests {
    use super::taper_integral;

    fn quad(l: f64, ext: f64, ratio: f64) -> f64 {
        // composite Simpson with many panels
        let n = 20_000;
        let h = l / n as f64;
        let f = |x: f64| (l + ext - x).powi(2) / (1.0 - (1.0 - ratio) * x / l);
        let mut s = f(0.0) + f(l);
        for i in 1..n {
            let x = i as f64 * h;
            s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(x);
        }
        s * h / 3.0
    }

    #[test]
    fn taper_integral_matches_quadrature_on_both_branches() {
        for &r in &[0.1, 0.5, 0.79, 0.81, 0.95, 1.0, 1.05, 1.19, 1.21, 2.0] {
            for &ext in &[0.0, 1.5, 6.0] {
                let a = taper_integral(3.0, ext, r);
                let b = quad(3.0, ext, r);
                assert!((a - b).abs() <= 1e-9 * b, "r={r} ext={ext}: {a} vs {b}");
            }
        }
    }
}
