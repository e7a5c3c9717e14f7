//! Bindings of paritysim-laminate (functions prefixed `laminate_`).
//!
//! Layups cross the boundary as JSON lists of [`LayerRecord`], materials as JSON
//! [`MaterialRecord`]; results are the `paritysim_laminate::records` types through
//! [`to_py`](crate::convert::to_py). Units: mm, mN, mg, V, K; moduli mN/mm².

use paritysim_error::Result;
use paritysim_laminate::flexure::{CastellatedJoint, Flexure};
use paritysim_laminate::records::{
    self, BimorphReport, CastellatedReport, FlexureReport, LayerRecord, LayupSummary,
    MaterialRecord, PlyStressColumns, ResponseRecord, abd_rows, loads,
};
use paritysim_laminate::{
    ActuatorConstants, Bimorph, BimorphGeometry, Layer, Layup, Material, library,
};
use pyo3::prelude::*;

use crate::convert::{Floats, bindings, from_json};

fn layup(layers: &str) -> Result<Layup> {
    LayerRecord::build_layup(from_json("layers", layers)?)
}

fn material(json: &str, ctx: &str) -> Result<Material> {
    from_json::<MaterialRecord>("material", json)?.build(ctx)
}

bindings! {
    /// Keys of the material library.
    fn laminate_material_names() -> Vec<&'static str> {
        Ok(library::NAMES.to_vec())
    }

    /// A library material as a material dict.
    fn laminate_material(key: &str) {
        Ok(MaterialRecord::of(&library::by_name(key)?))
    }

    /// Validates a material (JSON) and returns the normalised dict.
    fn laminate_check_material(material_json: &str) {
        Ok(MaterialRecord::of(&material(material_json, "")?))
    }

    /// A preset layup (see `records::preset`) as layer dicts.
    fn laminate_preset(name: &str) {
        Ok(LayerRecord::all(&records::preset(name)?))
    }

    /// PZT–CF–PZT layup of Wood et al. 2005 (thicknesses mm) as layer dicts.
    fn laminate_wood_layup(t_pzt: f64, t_cf: f64) {
        Ok(LayerRecord::all(&Bimorph::wood_layup(t_pzt, t_cf)?))
    }

    /// The cured 0-90-0 carbon-fibre layer (§4.4.2) of `thickness` mm at `angle` rad.
    fn laminate_cf_0_90_0(name: &str, thickness: f64, angle: f64) {
        Ok(LayerRecord::of(&Layer::cf_0_90_0(name, thickness, angle)?))
    }

    /// Named constants (`records::Constants`).
    fn laminate_constants() {
        Ok(records::constants())
    }

    /// The 6×6 `[A B; B D]` matrix (A mN/mm, B mN, D mN·mm) of a layup.
    fn laminate_abd(layers_json: &str) {
        Ok(abd_rows(&layup(layers_json)?))
    }

    /// Mid-plane `strain` (3,) and `curvature` (3,) (1/mm) under `n` (mN/mm), `m` (mN),
    /// `delta_t` (K) and per-layer `voltages` (V; empty for none).
    fn laminate_response(layers_json: &str, n: Floats, m: Floats, delta_t: f64, voltages: Floats) {
        let loads = loads(&n, &m, delta_t, &voltages);
        Ok(ResponseRecord::from(layup(layers_json)?.response(&loads?)?))
    }

    /// Ply face stresses (`records::PlyStressColumns`), arguments as `laminate_response`.
    fn laminate_ply_stresses(
        layers_json: &str,
        n: Floats,
        m: Floats,
        delta_t: f64,
        voltages: Floats,
    ) {
        let loads = loads(&n, &m, delta_t, &voltages);
        let stresses = layup(layers_json)?.ply_stresses(&loads?)?;
        Ok(stresses.into_iter().collect::<PlyStressColumns>())
    }

    /// Summary of a layup (`records::LayupSummary`).
    fn laminate_summary(layers_json: &str) {
        LayupSummary::of(&layup(layers_json)?)
    }

    /// A bending actuator of the layup and planform (mm): `records::BimorphReport` at each
    /// drive amplitude in `voltages` (V).
    fn laminate_bimorph(
        layers_json: &str,
        length: f64,
        extension: f64,
        base_width: f64,
        width_ratio: f64,
        voltages: Floats,
    ) {
        let layup = layup(layers_json)?;
        let g = BimorphGeometry::new(length, extension, base_width, width_ratio)?;
        BimorphReport::of(&Bimorph::new(layup, g)?, &voltages)
    }

    /// The planform giving `stiffness` (mN/mm) and `force_per_volt` (mN/V) with the layup,
    /// taper `width_ratio` and `extension_ratio`, as `laminate_bimorph`.
    fn laminate_bimorph_design(
        layers_json: &str,
        stiffness: f64,
        force_per_volt: f64,
        width_ratio: f64,
        extension_ratio: f64,
    ) {
        let layup = layup(layers_json)?;
        let target = ActuatorConstants::new(stiffness, force_per_volt)?;
        let b = Bimorph::design_for(layup, target, width_ratio, extension_ratio)?;
        BimorphReport::of(&b, &[])
    }

    /// Flexure of `material_json`, `width`, `thickness`, `length` (mm).
    fn laminate_flexure(material_json: &str, width: f64, thickness: f64, length: f64) {
        let m = material(material_json, "material")?;
        FlexureReport::of(&Flexure::new(m, width, thickness, length)?)
    }

    /// Castellated joint (§4.4.3): `records::CastellatedReport`.
    fn laminate_castellated_joint(
        material_json: &str,
        joint_width: f64,
        n_segments: usize,
        flexure_fraction: f64,
        thickness: f64,
        flexure_length: f64,
    ) {
        let m = material(material_json, "material")?;
        let j = CastellatedJoint::new(
            m,
            joint_width,
            n_segments,
            flexure_fraction,
            thickness,
            flexure_length,
        )?;
        CastellatedReport::of(&j)
    }
}
