//! Plain serde records of the laminate inputs and results: what crosses a language boundary
//! (the Python bindings read and write these as JSON; no binding builds a dict by hand).
//!
//! Inputs deny unknown fields; building a record validates it and prefixes every invalid field
//! with its dotted path (`layers[1].plies[0].thickness`).

use nalgebra::Vector3;
use serde::{Deserialize, Deserializer, Serialize};

use crate::flexure::{
    CASTELLATED_FLEXURE_LENGTH_MM, CastellatedJoint, Flexure, KAPTON_YIELD_STRAIN,
};
use crate::pcmems::{self, CURE_DELTA_T, CURE_TEMPERATURE_C, ROOM_TEMPERATURE_C};
use crate::{
    ActuatorConstants, Bimorph, Error, Layer, Layup, Loads, Material, MaterialClass, MaterialSpec,
    Piezo, Ply, PlyStress, Response, Result,
};

/// A number where JSON `null` stands for a non-finite value (JSON has no NaN; serde_json
/// writes NaN as `null`), so the range check below names the field instead of the parser.
fn real<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// Prefixes an invalid field with the dotted context, if any.
fn within(e: Error, ctx: &str) -> Error {
    if ctx.is_empty() { e } else { e.in_field(ctx) }
}

/// A material: units mN/mm², mg/mm³, 1/K, mm/V, V/mm; `d31`/`max_field` null for passive ones.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialRecord {
    /// Display name.
    pub name: String,
    /// [`MaterialClass::as_str`] name.
    pub class: String,
    /// Young's modulus along axis 1.
    #[serde(deserialize_with = "real")]
    pub e1: f64,
    /// Young's modulus along axis 2.
    #[serde(deserialize_with = "real")]
    pub e2: f64,
    /// In-plane shear modulus.
    #[serde(deserialize_with = "real")]
    pub g12: f64,
    /// Major Poisson ratio.
    #[serde(deserialize_with = "real")]
    pub nu12: f64,
    /// Density.
    #[serde(deserialize_with = "real")]
    pub density: f64,
    /// Thermal expansion along axis 1.
    #[serde(deserialize_with = "real")]
    pub alpha1: f64,
    /// Thermal expansion along axis 2.
    #[serde(deserialize_with = "real")]
    pub alpha2: f64,
    /// Piezoelectric coefficient, if piezoelectric.
    #[serde(default)]
    pub d31: Option<f64>,
    /// Depoling field limit, if piezoelectric.
    #[serde(default)]
    pub max_field: Option<f64>,
}

impl MaterialRecord {
    /// The record of a material.
    pub fn of(m: &Material) -> Self {
        Self {
            name: m.name().to_string(),
            class: m.class().as_str().to_string(),
            e1: m.e1(),
            e2: m.e2(),
            g12: m.g12(),
            nu12: m.nu12(),
            density: m.density(),
            alpha1: m.alpha1(),
            alpha2: m.alpha2(),
            d31: m.piezo().map(|p| p.d31),
            max_field: m.piezo().map(|p| p.max_field),
        }
    }

    /// Validates and builds the material; fields are prefixed with `ctx`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the field (an unknown `class`, only one of
    /// `d31`/`max_field`, or a non-physical value, see [`MaterialSpec::build`]).
    pub fn build(self, ctx: &str) -> Result<Material> {
        let piezo = match (self.d31, self.max_field) {
            (None, None) => Ok(None),
            (Some(d31), Some(max_field)) => Ok(Some(Piezo { d31, max_field })),
            (Some(_), None) => Err(Error::invalid("max_field", "missing", "present with d31")),
            (None, Some(_)) => Err(Error::invalid("d31", "missing", "present with max_field")),
        };
        piezo
            .and_then(|piezo| Ok((piezo, MaterialClass::parse(&self.class)?)))
            .and_then(|(piezo, class)| {
                MaterialSpec {
                    name: self.name,
                    class,
                    e1: self.e1,
                    e2: self.e2,
                    g12: self.g12,
                    nu12: self.nu12,
                    density: self.density,
                    alpha1: self.alpha1,
                    alpha2: self.alpha2,
                    piezo,
                }
                .build()
            })
            .map_err(|e| within(e, ctx))
    }
}

/// One ply: material, thickness (mm), angle (rad, default 0).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlyRecord {
    /// The material.
    pub material: MaterialRecord,
    /// Thickness, mm.
    #[serde(deserialize_with = "real")]
    pub thickness: f64,
    /// Angle of axis 1 from the laminate x axis, rad.
    #[serde(default, deserialize_with = "real")]
    pub angle: f64,
}

/// A named layer of plies (bottom to top).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerRecord {
    /// Layer name.
    pub name: String,
    /// Plies, bottom to top.
    pub plies: Vec<PlyRecord>,
}

impl LayerRecord {
    /// The record of a layer.
    pub fn of(l: &Layer) -> Self {
        Self {
            name: l.name().to_string(),
            plies: l
                .plies()
                .iter()
                .map(|p| PlyRecord {
                    material: MaterialRecord::of(p.material()),
                    thickness: p.thickness(),
                    angle: p.angle(),
                })
                .collect(),
        }
    }

    /// Records of every layer of a layup.
    pub fn all(layup: &Layup) -> Vec<Self> {
        layup.layers().iter().map(Self::of).collect()
    }

    /// Validates and builds the layup, naming fields `layers[i].plies[j].<field>`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a bad ply or material, [`Error::Geometry`] for an empty
    /// stack.
    pub fn build_layup(layers: Vec<LayerRecord>) -> Result<Layup> {
        let mut out = Vec::with_capacity(layers.len());
        for (i, layer) in layers.into_iter().enumerate() {
            let ctx = format!("layers[{i}]");
            let mut plies = Vec::with_capacity(layer.plies.len());
            for (j, p) in layer.plies.into_iter().enumerate() {
                let pctx = format!("{ctx}.plies[{j}]");
                let material = p.material.build(&format!("{pctx}.material"))?;
                plies.push(Ply::new(material, p.thickness, p.angle).map_err(|e| within(e, &pctx))?);
            }
            out.push(Layer::from_plies(layer.name, plies).map_err(|e| within(e, &ctx))?);
        }
        Layup::new(out)
    }
}

/// A preset layup by name: `mobee`, `mobee_without_titanium`, `linkage_sublaminate`,
/// `bimorph_mobee`.
///
/// # Errors
/// [`Error::InvalidParameter`] (field `name`) for another name.
pub fn preset(name: &str) -> Result<Layup> {
    match name {
        "mobee" => pcmems::mobee_stack(),
        "mobee_without_titanium" => pcmems::mobee_stack_without_titanium(),
        "linkage_sublaminate" => pcmems::linkage_sublaminate(),
        "bimorph_mobee" => Bimorph::mobee_layup(),
        _ => Err(Error::invalid(
            "name",
            name,
            "one of mobee, mobee_without_titanium, linkage_sublaminate, bimorph_mobee",
        )),
    }
}

/// Named constants of the laminate crate.
#[derive(Clone, Debug, Serialize)]
pub struct Constants {
    /// Cure temperature, °C.
    pub cure_temperature_c: f64,
    /// Room temperature, °C.
    pub room_temperature_c: f64,
    /// Cure temperature change, K.
    pub cure_delta_t: f64,
    /// Kapton yield strain.
    pub kapton_yield_strain: f64,
    /// Shortest castellated flexure of §4.4.3, mm.
    pub castellated_flexure_length_min: f64,
    /// Longest castellated flexure of §4.4.3, mm.
    pub castellated_flexure_length_max: f64,
    /// Thesis actuator stiffness, mN/mm.
    pub thesis_stiffness_mn_per_mm: f64,
    /// Thesis actuator force per volt, mN/V.
    pub thesis_force_per_volt_mn_per_v: f64,
}

/// The named constants.
pub fn constants() -> Constants {
    Constants {
        cure_temperature_c: CURE_TEMPERATURE_C,
        room_temperature_c: ROOM_TEMPERATURE_C,
        cure_delta_t: CURE_DELTA_T,
        kapton_yield_strain: KAPTON_YIELD_STRAIN,
        castellated_flexure_length_min: CASTELLATED_FLEXURE_LENGTH_MM.0,
        castellated_flexure_length_max: CASTELLATED_FLEXURE_LENGTH_MM.1,
        thesis_stiffness_mn_per_mm: ActuatorConstants::THESIS.stiffness_mn_per_mm,
        thesis_force_per_volt_mn_per_v: ActuatorConstants::THESIS.force_per_volt_mn_per_v,
    }
}

fn arr(v: &Vector3<f64>) -> [f64; 3] {
    [v[0], v[1], v[2]]
}

/// Mid-plane strain and curvature (1/mm).
#[derive(Clone, Debug, Serialize)]
pub struct ResponseRecord {
    /// Mid-plane strain (εx, εy, γxy).
    pub strain: [f64; 3],
    /// Curvature (κx, κy, κxy), 1/mm.
    pub curvature: [f64; 3],
}

impl From<Response> for ResponseRecord {
    fn from(r: Response) -> Self {
        Self {
            strain: arr(&r.strain),
            curvature: arr(&r.curvature),
        }
    }
}

/// Ply face stresses (mN/mm², laminate axes) as columns over the plies.
#[derive(Clone, Debug, Default, Serialize)]
pub struct PlyStressColumns {
    /// Layer index.
    pub layer: Vec<usize>,
    /// Ply index within the layer.
    pub ply: Vec<usize>,
    /// Bottom face z, mm.
    pub z_bottom: Vec<f64>,
    /// Top face z, mm.
    pub z_top: Vec<f64>,
    /// Stress at the bottom face, (k, 3).
    pub stress_bottom: Vec<[f64; 3]>,
    /// Stress at the top face, (k, 3).
    pub stress_top: Vec<[f64; 3]>,
}

impl FromIterator<PlyStress> for PlyStressColumns {
    fn from_iter<I: IntoIterator<Item = PlyStress>>(iter: I) -> Self {
        let mut c = Self::default();
        for p in iter {
            c.layer.push(p.layer);
            c.ply.push(p.ply);
            c.z_bottom.push(p.z_bottom);
            c.z_top.push(p.z_top);
            c.stress_bottom.push(arr(&p.stress_bottom));
            c.stress_top.push(arr(&p.stress_top));
        }
        c
    }
}

/// Totals and per-layer data of a layup.
#[derive(Clone, Debug, Serialize)]
pub struct LayupSummary {
    /// Number of layers.
    pub n_layers: usize,
    /// Total thickness, mm.
    pub total_thickness: f64,
    /// Areal mass, mg/mm².
    pub areal_mass: f64,
    /// `(z_bottom, z_top)` of each layer, mm.
    pub layer_bounds: Vec<[f64; 2]>,
    /// Thickness of each layer, mm.
    pub layer_thickness: Vec<f64>,
    /// Areal mass of each layer, mg/mm².
    pub layer_areal_mass: Vec<f64>,
    /// Material class of each layer.
    pub layer_class: Vec<&'static str>,
    /// Whether each layer is piezoelectric.
    pub layer_is_piezo: Vec<bool>,
    /// Whether the stack is mirror-symmetric.
    pub is_symmetric: bool,
    /// Curvature after the cure (ΔT = −180 K), 1/mm.
    pub cure_curvature: [f64; 3],
    /// Beam bending stiffness per width, mN·mm.
    pub beam_bending_stiffness: f64,
    /// Effective x modulus, mN/mm².
    pub effective_modulus_x: f64,
}

impl LayupSummary {
    /// Summarises a layup.
    ///
    /// # Errors
    /// As [`pcmems::summarize`], [`Layup::beam_bending_stiffness`] and
    /// [`Layup::effective_modulus_x`] (a singular stack).
    pub fn of(layup: &Layup) -> Result<Self> {
        let sum = pcmems::summarize(layup)?;
        let ls = layup.layers();
        Ok(Self {
            n_layers: sum.n_layers,
            total_thickness: sum.total_thickness,
            areal_mass: sum.areal_mass,
            layer_bounds: layup.layer_bounds().iter().map(|&(a, b)| [a, b]).collect(),
            layer_thickness: ls.iter().map(Layer::thickness).collect(),
            layer_areal_mass: ls.iter().map(Layer::areal_mass).collect(),
            layer_class: ls.iter().map(|l| l.class().as_str()).collect(),
            layer_is_piezo: ls.iter().map(Layer::is_piezo).collect(),
            is_symmetric: layup.is_symmetric(),
            cure_curvature: arr(&sum.cure_curvature),
            beam_bending_stiffness: layup.beam_bending_stiffness()?,
            effective_modulus_x: layup.effective_modulus_x()?,
        })
    }
}

/// A bending actuator's geometry, constants and drive responses.
#[derive(Clone, Debug, Serialize)]
pub struct BimorphReport {
    /// Length, mm.
    pub length: f64,
    /// Rigid extension, mm.
    pub extension: f64,
    /// Base width, mm.
    pub base_width: f64,
    /// Tip-to-base width ratio.
    pub width_ratio: f64,
    /// Tip width, mm.
    pub tip_width: f64,
    /// Nominal width, mm.
    pub nominal_width: f64,
    /// Curvature per volt, 1/(mm·V).
    pub curvature_per_volt: f64,
    /// Bending stiffness per width, mN·mm.
    pub bending_stiffness_per_width: f64,
    /// Free tip deflection per volt, mm/V.
    pub free_deflection_per_volt: f64,
    /// Tip stiffness, mN/mm.
    pub stiffness: f64,
    /// Blocked force per volt, mN/V.
    pub force_per_volt: f64,
    /// Largest drive amplitude before depoling, V.
    pub max_voltage: f64,
    /// Mass of the active plate, mg.
    pub active_mass: f64,
    /// Voltage across each layer per volt of drive.
    pub layer_voltages_per_volt: Vec<f64>,
    /// Free deflection at each drive amplitude, mm.
    pub free_deflection: Vec<f64>,
    /// Blocked force at each drive amplitude, mN.
    pub blocked_force: Vec<f64>,
}

impl BimorphReport {
    /// The report of `b` driven at each amplitude of `voltages` (V).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `voltages[i]` for an amplitude beyond
    /// [`Bimorph::max_voltage`] or non-finite.
    pub fn of(b: &Bimorph, voltages: &[f64]) -> Result<Self> {
        let mut free_deflection = Vec::with_capacity(voltages.len());
        let mut blocked_force = Vec::with_capacity(voltages.len());
        for (i, &v) in voltages.iter().enumerate() {
            let at = |e: Error| {
                let array = format!("{}s", e.field().unwrap_or("voltage"));
                e.at_index(i, Some(&array))
            };
            free_deflection.push(b.free_deflection(v).map_err(at)?);
            blocked_force.push(b.blocked_force(v).map_err(at)?);
        }
        let g = b.geometry();
        Ok(Self {
            length: g.length,
            extension: g.extension,
            base_width: g.base_width,
            width_ratio: g.width_ratio,
            tip_width: g.tip_width(),
            nominal_width: g.nominal_width(),
            curvature_per_volt: b.curvature_per_volt(),
            bending_stiffness_per_width: b.bending_stiffness_per_width(),
            free_deflection_per_volt: b.free_deflection_per_volt(),
            stiffness: b.stiffness(),
            force_per_volt: b.force_per_volt(),
            max_voltage: b.max_voltage(),
            active_mass: b.active_mass(),
            layer_voltages_per_volt: b.layer_voltages(1.0),
            free_deflection,
            blocked_force,
        })
    }
}

/// A flexure's stiffnesses and strain per radian.
#[derive(Clone, Debug, Serialize)]
pub struct FlexureReport {
    /// Rotational stiffness (beam), mN·mm/rad.
    pub stiffness: f64,
    /// Rotational stiffness (plate), mN·mm/rad.
    pub plate_stiffness: f64,
    /// Peak surface strain per radian, `t / (2 L)`.
    pub strain_per_rad: f64,
}

impl FlexureReport {
    /// The report of `f`.
    ///
    /// # Errors
    /// As [`Flexure::max_strain`].
    pub fn of(f: &Flexure) -> Result<Self> {
        Ok(Self {
            stiffness: f.stiffness(),
            plate_stiffness: f.plate_stiffness(),
            strain_per_rad: f.max_strain(1.0)?,
        })
    }
}

/// A castellated joint's stiffness and widths (§4.4.3).
#[derive(Clone, Debug, Serialize)]
pub struct CastellatedReport {
    /// Rotational stiffness, mN·mm/rad.
    pub stiffness: f64,
    /// Total flexure width, mm.
    pub flexure_width: f64,
    /// Width of one segment, mm.
    pub segment_width: f64,
    /// Flexure length within 20–40 µm.
    pub within_thesis_range: bool,
    /// Peak surface strain per radian.
    pub strain_per_rad: f64,
}

impl CastellatedReport {
    /// The report of `j`.
    ///
    /// # Errors
    /// As [`Flexure::max_strain`].
    pub fn of(j: &CastellatedJoint) -> Result<Self> {
        Ok(Self {
            stiffness: j.stiffness(),
            flexure_width: j.flexure().width(),
            segment_width: j.segment_width(),
            within_thesis_range: j.within_thesis_range(),
            strain_per_rad: j.flexure().max_strain(1.0)?,
        })
    }
}

/// A 3-vector argument named `name`: exactly 3 finite numbers.
///
/// # Errors
/// [`Error::Shape`] for another length, [`Error::InvalidParameter`] for a non-finite entry.
pub fn vector3(name: &'static str, v: &[f64]) -> Result<Vector3<f64>> {
    let [x, y, z] = v[..] else {
        return Err(Error::Shape(format!(
            "`{name}` must have 3 elements, got {}",
            v.len()
        )));
    };
    paritysim_error::check_all_finite(name, v)?;
    Ok(Vector3::new(x, y, z))
}

/// [`Loads`] from plain arguments: `n` (mN/mm) and `m` (mN) 3-vectors, `delta_t` (K) and per-layer
/// `voltages` (V; empty for none).
///
/// # Errors
/// As [`vector3`] for `n` and `m`.
pub fn loads(n: &[f64], m: &[f64], delta_t: f64, voltages: &[f64]) -> Result<Loads> {
    Ok(Loads {
        n: vector3("n", n)?,
        m: vector3("m", m)?,
        delta_t,
        voltages: voltages.to_vec(),
    })
}

/// The 6×6 `[A B; B D]` matrix (A mN/mm, B mN, D mN·mm) of a layup, row-major.
pub fn abd_rows(layup: &Layup) -> Vec<[f64; 6]> {
    let m = layup.abd().matrix();
    (0..6).map(|i| std::array::from_fn(|j| m[(i, j)])).collect()
}
