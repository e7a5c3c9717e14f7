//! Orthotropic ply materials and the material library of the thesis (§4.2, §4.4.2) and ref. \[42\].
//!
//! # Units (mg-mm-ms-rad-V)
//!
//! | quantity              | unit                         | conversion                         |
//! |-----------------------|------------------------------|------------------------------------|
//! | moduli `E1, E2, G12`  | mN/mm² (= kPa)               | 1 GPa = 1e6 mN/mm²                 |
//! | density               | mg/mm³                       | 1 g/cm³ = 1 mg/mm³                 |
//! | thermal expansion     | 1/K                          | 1 ppm/K = 1e-6 /K                  |
//! | `d31`                 | mm/V                         | 1 pm/V = 1e-9 mm/V                 |
//! | electric field        | V/mm                         | 1 V/µm = 1e3 V/mm                  |
//!
//! A [`Material`] is validated on construction: moduli and density finite and `> 0`, thermal
//! expansion finite, and the Poisson ratio inside the range that keeps the plane-stress stiffness
//! positive definite (see [`Material::orthotropic`] and [`Material::isotropic`]).
//!
//! # Sources of the library values
//!
//! No datasheet could be consulted while writing this module (no network access). The values
//! below are well-known handbook and manufacturer-datasheet figures quoted from memory and are
//! labelled as such in each function; where sources are known to disagree the spread is given.
//! They are adequate for design studies (a few per cent to tens of per cent, depending on the
//! material), not for certification. The least certain entries are the Pyralux adhesive and the
//! carbon-fibre lamina, whose properties depend on the cure and on the fibre volume fraction.

use paritysim_error::{Error, Result, check_finite, check_positive};

/// 1 GPa expressed in the crate's modulus unit, mN/mm².
pub const GPA: f64 = 1.0e6;
/// 1 pm/V expressed in the crate's `d31` unit, mm/V.
pub const PM_PER_V: f64 = 1.0e-9;
/// 1 V/µm expressed in the crate's field unit, V/mm.
pub const V_PER_UM: f64 = 1.0e3;
/// 1 ppm/K (1e-6 /K), the usual unit of thermal expansion.
pub const PPM_PER_K: f64 = 1.0e-6;

/// Role of a material in a PC-MEMS laminate (§4.2); used for summaries and for drawing stacks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MaterialClass {
    /// Fibre-reinforced composite (carbon fibre, fibreglass): rigid links.
    Composite,
    /// Polymer film (polyimide, polyester): flexures and membranes.
    Polymer,
    /// Interlayer sheet adhesive (Pyralux).
    Adhesive,
    /// Metal foil (brass, titanium, steel).
    Metal,
    /// Piezoelectric ceramic (PZT).
    Piezo,
}

impl MaterialClass {
    /// Stable lower-case name: `composite`, `polymer`, `adhesive`, `metal`, `piezo`.
    pub fn as_str(self) -> &'static str {
        match self {
            MaterialClass::Composite => "composite",
            MaterialClass::Polymer => "polymer",
            MaterialClass::Adhesive => "adhesive",
            MaterialClass::Metal => "metal",
            MaterialClass::Piezo => "piezo",
        }
    }

    /// Parses [`MaterialClass::as_str`] names (case-insensitive).
    pub fn parse(name: &str) -> Result<Self> {
        match name.to_ascii_lowercase().as_str() {
            "composite" => Ok(MaterialClass::Composite),
            "polymer" => Ok(MaterialClass::Polymer),
            "adhesive" => Ok(MaterialClass::Adhesive),
            "metal" => Ok(MaterialClass::Metal),
            "piezo" => Ok(MaterialClass::Piezo),
            _ => Err(Error::invalid(
                "class",
                name,
                "one of composite, polymer, adhesive, metal, piezo",
            )),
        }
    }
}

/// Transverse piezoelectric properties of a poled ceramic ply (poling along the ply normal z).
///
/// Free in-plane strain under a through-thickness field `E3 = V / t` is `d31 · E3` in both
/// in-plane directions (`d31 = d32` for poled ceramics, so the strain is isotropic in-plane and
/// independent of the ply angle).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piezo {
    /// Transverse piezoelectric coefficient `d31`, mm/V (pm/V × 1e-9); negative for PZT.
    pub d31: f64,
    /// Largest field magnitude the model accepts, V/mm; beyond it
    /// [`crate::Bimorph::free_deflection`] reports [`Error::OutOfDomain`].
    pub max_field: f64,
}

/// A validated orthotropic ply material in its principal axes (1 = fibre / roll direction).
///
/// Fields are private so that every `Material` in existence has passed validation; read them
/// with the accessors.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    name: String,
    class: MaterialClass,
    e1: f64,
    e2: f64,
    g12: f64,
    nu12: f64,
    density: f64,
    alpha1: f64,
    alpha2: f64,
    piezo: Option<Piezo>,
}

/// Plain description of an orthotropic material, turned into a [`Material`] by
/// [`MaterialSpec::build`]. Units as in the module table.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialSpec {
    /// Display name.
    pub name: String,
    /// Role in a laminate.
    pub class: MaterialClass,
    /// Young's modulus along axis 1, mN/mm².
    pub e1: f64,
    /// Young's modulus along axis 2, mN/mm².
    pub e2: f64,
    /// In-plane shear modulus, mN/mm².
    pub g12: f64,
    /// Major Poisson ratio ν12 (strain in 2 per strain in 1 under stress along 1), dimensionless.
    pub nu12: f64,
    /// Density, mg/mm³.
    pub density: f64,
    /// Thermal expansion along axis 1, 1/K.
    pub alpha1: f64,
    /// Thermal expansion along axis 2, 1/K.
    pub alpha2: f64,
    /// Piezoelectric properties, if any.
    pub piezo: Option<Piezo>,
}

impl MaterialSpec {
    /// Validates and builds the material. The Poisson ratio must satisfy
    /// `ν12² < E1/E2` (positive-definite plane-stress stiffness); an isotropic spec
    /// (`E1 == E2`) must in addition have `ν12` in (−1, 0.5).
    pub fn build(self) -> Result<Material> {
        Material::from_spec(self)
    }
}

impl Material {
    fn from_spec(s: MaterialSpec) -> Result<Material> {
        if s.name.trim().is_empty() {
            return Err(Error::invalid("name", "\"\"", "a non-empty string"));
        }
        check_positive("e1", s.e1)?;
        check_positive("e2", s.e2)?;
        check_finite("nu12", s.nu12)?;
        if s.e1 == s.e2 {
            if !(s.nu12 > -1.0 && s.nu12 < 0.5) {
                return Err(Error::invalid("nu12", s.nu12, "in (-1, 0.5)"));
            }
        } else {
            let bound = (s.e1 / s.e2).sqrt();
            if s.nu12.abs() >= bound {
                return Err(Error::invalid(
                    "nu12",
                    s.nu12,
                    format!("in (-sqrt(e1/e2), sqrt(e1/e2)) = (-{bound:.4}, {bound:.4})"),
                ));
            }
        }
        check_positive("g12", s.g12)?;
        check_positive("density", s.density)?;
        check_finite("alpha1", s.alpha1)?;
        check_finite("alpha2", s.alpha2)?;
        if let Some(p) = s.piezo {
            check_finite("d31", p.d31)?;
            check_positive("max_field", p.max_field)?;
        }
        Ok(Material {
            name: s.name,
            class: s.class,
            e1: s.e1,
            e2: s.e2,
            g12: s.g12,
            nu12: s.nu12,
            density: s.density,
            alpha1: s.alpha1,
            alpha2: s.alpha2,
            piezo: s.piezo,
        })
    }

    /// An isotropic material: `E1 = E2 = e`, `G12 = e / (2 (1 + ν))`, `α1 = α2 = alpha`.
    ///
    /// `e` mN/mm², `nu` in (−1, 0.5) (reported as field `nu12`), `density` mg/mm³, `alpha` 1/K.
    pub fn isotropic(
        name: impl Into<String>,
        class: MaterialClass,
        e: f64,
        nu: f64,
        density: f64,
        alpha: f64,
    ) -> Result<Material> {
        check_finite("nu12", nu)?;
        if !(nu > -1.0 && nu < 0.5) {
            return Err(Error::invalid("nu12", nu, "in (-1, 0.5)"));
        }
        check_positive("e1", e)?;
        MaterialSpec {
            name: name.into(),
            class,
            e1: e,
            e2: e,
            g12: e / (2.0 * (1.0 + nu)),
            nu12: nu,
            density,
            alpha1: alpha,
            alpha2: alpha,
            piezo: None,
        }
        .build()
    }

    /// A general orthotropic material; see [`MaterialSpec`] for units and the Poisson bound.
    pub fn orthotropic(spec: MaterialSpec) -> Result<Material> {
        spec.build()
    }

    /// The same material with piezoelectric properties: `d31` mm/V (finite, usually negative),
    /// `max_field` V/mm (> 0).
    pub fn with_piezo(self, d31: f64, max_field: f64) -> Result<Material> {
        let mut spec = self.to_spec();
        spec.piezo = Some(Piezo { d31, max_field });
        spec.build()
    }

    /// The same material under another name (validated: non-empty).
    pub fn renamed(self, name: impl Into<String>) -> Result<Material> {
        let mut spec = self.to_spec();
        spec.name = name.into();
        spec.build()
    }

    /// The plain description of this material (round-trips through [`MaterialSpec::build`]).
    pub fn to_spec(&self) -> MaterialSpec {
        MaterialSpec {
            name: self.name.clone(),
            class: self.class,
            e1: self.e1,
            e2: self.e2,
            g12: self.g12,
            nu12: self.nu12,
            density: self.density,
            alpha1: self.alpha1,
            alpha2: self.alpha2,
            piezo: self.piezo,
        }
    }

    /// Display name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Role in a laminate.
    pub fn class(&self) -> MaterialClass {
        self.class
    }
    /// Young's modulus along axis 1, mN/mm².
    pub fn e1(&self) -> f64 {
        self.e1
    }
    /// Young's modulus along axis 2, mN/mm².
    pub fn e2(&self) -> f64 {
        self.e2
    }
    /// In-plane shear modulus, mN/mm².
    pub fn g12(&self) -> f64 {
        self.g12
    }
    /// Major Poisson ratio ν12, dimensionless.
    pub fn nu12(&self) -> f64 {
        self.nu12
    }
    /// Minor Poisson ratio ν21 = ν12 E2 / E1, dimensionless.
    pub fn nu21(&self) -> f64 {
        self.nu12 * self.e2 / self.e1
    }
    /// Density, mg/mm³.
    pub fn density(&self) -> f64 {
        self.density
    }
    /// Thermal expansion along axis 1, 1/K.
    pub fn alpha1(&self) -> f64 {
        self.alpha1
    }
    /// Thermal expansion along axis 2, 1/K.
    pub fn alpha2(&self) -> f64 {
        self.alpha2
    }
    /// Piezoelectric properties, if the material is piezoelectric.
    pub fn piezo(&self) -> Option<Piezo> {
        self.piezo
    }
    /// `true` if [`Material::piezo`] is set.
    pub fn is_piezo(&self) -> bool {
        self.piezo.is_some()
    }
}

/// The material library: the materials named in the thesis (§4.2, §4.4.2, §4.4.4) and ref. \[42\].
///
/// Every function documents where its numbers come from. "Handbook" means the usual values of
/// engineering handbooks (ASM Metals Handbook, MatWeb-style compilations) quoted from memory.
pub mod library {
    use super::{GPA, Material, MaterialClass, MaterialSpec, PM_PER_V, PPM_PER_K, V_PER_UM};
    use paritysim_error::{Error, Result};

    fn ok(m: Result<Material>) -> Material {
        // The library values are compile-time constants checked by the tests; a failure here
        // would be a bug in this file, not bad user input.
        m.expect("library material constants are valid")
    }

    /// PZT-5H piezoceramic, as the Piezo Systems PSI-5H4E plates used by Mobee (§4.4.2:
    /// two 127 µm nickel-plated PSI-5H4E plates).
    ///
    /// * `E = 62 GPa` (short-circuit `Y11^E`, PSI-5H4E datasheet), `ν = 0.31` (typical for
    ///   PZT-5H; the Morgan/Berlincourt compliances `s11^E = 16.5`, `s12^E = −4.78` pm²/N give
    ///   `E = 60.6 GPa`, `ν = 0.29`),
    /// * `d31 = −320 pm/V` (PSI-5H4E datasheet; generic PZT-5H handbooks quote −274 pm/V, so the
    ///   sources disagree by ≈15 %; Wood, Steltz & Fearing 2005 model the same plates),
    /// * density 7.8 mg/mm³ (PSI-5H4E datasheet; generic PZT-5H: 7.5),
    /// * `α ≈ 3.5 ppm/K` (handbook range 2–5 ppm/K, poling dependent),
    /// * `max_field = 2 V/µm`: an engineering limit for the forward (poling-direction) field,
    ///   our assumption; bias-driven bimorphs of the HMF family run at 1.5–2.4 V/µm on the
    ///   forward plate. A reverse field must stay well below the coercive field
    ///   (≈0.5–0.8 V/µm for PZT-5H), which this scalar limit does not distinguish.
    pub fn pzt_5h() -> Material {
        ok(Material::isotropic(
            "PZT-5H",
            MaterialClass::Piezo,
            62.0 * GPA,
            0.31,
            7.8,
            3.5 * PPM_PER_K,
        )
        .and_then(|m| m.with_piezo(-320.0 * PM_PER_V, 2.0 * V_PER_UM)))
    }

    /// Unidirectional high-modulus pitch carbon-fibre/cyanate-ester lamina, as the TenCate
    /// XN-50A-RS3C prepreg of Mobee (§4.4.2), cured ply.
    ///
    /// Estimated, not from a datasheet: the XN-50A fibre (Nippon Graphite) has a tensile modulus
    /// of ≈520 GPa and density ≈2.14 g/cm³; with a fibre volume fraction ≈0.55 in an RS-3C
    /// cyanate ester (≈3 GPa, ≈1.2 g/cm³) the rule of mixtures gives `E1 ≈ 290 GPa` and density
    /// ≈1.7 mg/mm³. Transverse and shear values are typical of high-modulus UD laminae:
    /// `E2 = 6 GPa`, `G12 = 4 GPa`, `ν12 = 0.3`. Thermal expansion: `α1 = −1.0 ppm/K` (pitch
    /// fibres are strongly negative, ≈ −1.4 ppm/K; the lamina value depends on Vf),
    /// `α2 = 30 ppm/K` (matrix dominated). Published Wood-type actuator models use central
    /// CF moduli from 300 to 340 GPa (different fibres), i.e. the sources disagree by ≈15 %.
    pub fn cf_prepreg_ud() -> Material {
        ok(MaterialSpec {
            name: "CF UD (XN-50A/RS-3C)".into(),
            class: MaterialClass::Composite,
            e1: 290.0 * GPA,
            e2: 6.0 * GPA,
            g12: 4.0 * GPA,
            nu12: 0.3,
            density: 1.7,
            alpha1: -PPM_PER_K,
            alpha2: 30.0 * PPM_PER_K,
            piezo: None,
        }
        .build())
    }

    /// Polyimide film, DuPont Kapton HN (the 7.5 µm flexure layers of §4.2/§4.4.2).
    ///
    /// DuPont Kapton HN datasheet (23 °C): tensile modulus 2.5 GPa, Poisson ratio 0.34,
    /// density 1.42 g/cm³, CTE 20 ppm/K (30–100 °C). Yield point ≈3 % strain (69 MPa), see
    /// [`crate::flexure::KAPTON_YIELD_STRAIN`].
    pub fn polyimide() -> Material {
        ok(Material::isotropic(
            "polyimide (Kapton HN)",
            MaterialClass::Polymer,
            2.5 * GPA,
            0.34,
            1.42,
            20.0 * PPM_PER_K,
        ))
    }

    /// DuPont Pyralux FR1500 acrylic sheet adhesive, cured (the 12.5 µm adhesive layers, §4.2.1).
    ///
    /// Order-of-magnitude estimate, **no datasheet value available**: cured modified-acrylic
    /// flex-circuit adhesives have moduli of roughly 0.5–3 GPa, we use 1.0 GPa; `ν = 0.40`;
    /// density 1.3 mg/mm³ (flame-retardant filled acrylic, 1.2–1.4); in-plane CTE 80 ppm/K
    /// (acrylics 50–150 ppm/K). Being thin and compliant, the adhesive affects stack stiffness
    /// and thermal curvature only weakly, but its mass counts (8 × 12.5 µm in Mobee).
    pub fn pyralux_adhesive() -> Material {
        ok(Material::isotropic(
            "Pyralux FR1500 acrylic adhesive",
            MaterialClass::Adhesive,
            1.0 * GPA,
            0.40,
            1.3,
            80.0 * PPM_PER_K,
        ))
    }

    /// Brass, cartridge brass C26000 (70/30), the 12.5 µm solder-pad layers (§4.4.2).
    ///
    /// Handbook (ASM): E = 110 GPa, ν = 0.34 (sources 0.33–0.375), density 8.53 g/cm³,
    /// CTE 19.9 ppm/K (20–300 °C).
    pub fn brass() -> Material {
        ok(Material::isotropic(
            "brass (C26000)",
            MaterialClass::Metal,
            110.0 * GPA,
            0.34,
            8.53,
            19.9 * PPM_PER_K,
        ))
    }

    /// Titanium alloy grade 9 (Ti-3Al-2.5V), the 50.8 µm wing-venation layer (§4.4.2).
    ///
    /// Handbook (ASM): E = 100 GPa (sources 91–107 GPa), ν = 0.30 (0.30–0.34), density
    /// 4.48 g/cm³, CTE 9.5 ppm/K (20–100 °C).
    pub fn titanium() -> Material {
        ok(Material::isotropic(
            "titanium (grade 9)",
            MaterialClass::Metal,
            100.0 * GPA,
            0.30,
            4.48,
            9.5 * PPM_PER_K,
        ))
    }

    /// Spring steel (AISI 1095 class), as the 76.2 µm alignment shim of the second pass (§4.4.4).
    ///
    /// Handbook: E = 205 GPa (plain carbon steels 200–210), ν = 0.29, density 7.85 g/cm³,
    /// CTE 11.0 ppm/K (carbon steels 10.8–12.5).
    pub fn spring_steel() -> Material {
        ok(Material::isotropic(
            "spring steel (1095)",
            MaterialClass::Metal,
            205.0 * GPA,
            0.29,
            7.85,
            11.0 * PPM_PER_K,
        ))
    }

    /// Polyester (PET, DuPont Mylar type), the 1.5 µm wing-membrane film (§4.4.4).
    ///
    /// Datasheet/handbook: density 1.39 g/cm³, CTE 17 ppm/K (Mylar datasheet values);
    /// tensile modulus quoted from 3.5 to 4.9 GPa depending on grade and direction, we use
    /// 4.0 GPa; ν = 0.38 (handbook 0.37–0.44).
    pub fn polyester() -> Material {
        ok(Material::isotropic(
            "polyester (PET)",
            MaterialClass::Polymer,
            4.0 * GPA,
            0.38,
            1.39,
            17.0 * PPM_PER_K,
        ))
    }

    /// Keys accepted by [`by_name`], in library order.
    pub const NAMES: [&str; 8] = [
        "pzt_5h",
        "cf_prepreg_ud",
        "polyimide",
        "pyralux_adhesive",
        "brass",
        "titanium",
        "spring_steel",
        "polyester",
    ];

    /// Looks a library material up by its key (see [`NAMES`]); aliases `pzt`, `cf`, `kapton`,
    /// `pyralux`, `adhesive`, `ti`, `steel`, `pet` are accepted.
    pub fn by_name(key: &str) -> Result<Material> {
        Ok(match key.to_ascii_lowercase().as_str() {
            "pzt_5h" | "pzt" | "pzt-5h" => pzt_5h(),
            "cf_prepreg_ud" | "cf" | "cf_ud" | "carbon_fiber" => cf_prepreg_ud(),
            "polyimide" | "kapton" | "pi" => polyimide(),
            "pyralux_adhesive" | "pyralux" | "adhesive" | "a" => pyralux_adhesive(),
            "brass" | "b" => brass(),
            "titanium" | "ti" => titanium(),
            "spring_steel" | "steel" => spring_steel(),
            "polyester" | "pet" | "mylar" => polyester(),
            _ => {
                return Err(Error::invalid(
                    "material",
                    key,
                    format!("one of {}", NAMES.join(", ")),
                ));
            }
        })
    }

    /// Every library material, in [`NAMES`] order.
    pub fn all() -> Vec<Material> {
        NAMES
            .iter()
            .map(|k| by_name(k).expect("library names resolve"))
            .collect()
    }
}
