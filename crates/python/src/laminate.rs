//! Bindings of paritysim-laminate (functions prefixed `laminate_`).
//!
//! Layups cross the boundary as lists of layer dicts
//! `{"name": str, "plies": [{"material": dict | str, "thickness": float, "angle": float}]}`,
//! materials as dicts `{"name", "class", "e1", "e2", "g12", "nu12", "density", "alpha1",
//! "alpha2", "d31", "max_field"}` (`d31`/`max_field` None for passive materials) or as a
//! library key (`"pzt_5h"`, `"polyimide"`, ...). Units: mm, mN, mg, V, K; moduli mN/mm².

use nalgebra::Vector3;
use numpy::{PyArray1, PyReadonlyArray1};
use paritysim_error::Error;
use paritysim_laminate::flexure::{
    CASTELLATED_FLEXURE_LENGTH_MM, CastellatedJoint, Flexure, KAPTON_YIELD_STRAIN,
};
use paritysim_laminate::pcmems::{self, CURE_DELTA_T, CURE_TEMPERATURE_C, ROOM_TEMPERATURE_C};
use paritysim_laminate::{
    ActuatorConstants, Bimorph, BimorphGeometry, Layer, Layup, Loads, Material, MaterialClass,
    MaterialSpec, Piezo, Ply, library,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};

use crate::convert::{shaped, to_vec};
use crate::errors::{IntoPyResult, to_pyerr};

// ------------------------------------------------------------------ dict <-> Rust

fn missing(field: String) -> PyErr {
    to_pyerr(Error::invalid(field, "missing", "present in the dict"))
}

/// Prefixes an invalid-parameter field with the dotted context (`layers[0].plies[1]`), if any.
fn within(e: Error, ctx: &str) -> Error {
    let ctx = ctx.trim_end_matches('.');
    if ctx.is_empty() { e } else { e.in_field(ctx) }
}

fn get_item<'py>(d: &Bound<'py, PyDict>, key: &str, ctx: &str) -> PyResult<Bound<'py, PyAny>> {
    d.get_item(key)?
        .ok_or_else(|| missing(format!("{ctx}{key}")))
}

/// Extracts `T`, or an `InvalidParameterError` naming `field` (never a bare `TypeError`).
fn typed<'py, T: FromPyObject<'py>>(v: &Bound<'py, PyAny>, field: &str, what: &str) -> PyResult<T> {
    v.extract::<T>().map_err(|_| {
        let shown = v.repr().map(|r| r.to_string()).unwrap_or_default();
        to_pyerr(Error::invalid(field.to_string(), shown, what))
    })
}

/// A dict, or an `InvalidParameterError` naming `field`.
fn table<'a, 'py>(v: &'a Bound<'py, PyAny>, field: &str) -> PyResult<&'a Bound<'py, PyDict>> {
    v.cast::<PyDict>().map_err(|_| {
        to_pyerr(Error::invalid(
            field.trim_end_matches('.').to_string(),
            "not a dict",
            "a dict",
        ))
    })
}

fn get_f64(d: &Bound<'_, PyDict>, key: &str, ctx: &str) -> PyResult<f64> {
    typed(&get_item(d, key, ctx)?, &format!("{ctx}{key}"), "a number")
}

fn get_str(d: &Bound<'_, PyDict>, key: &str, ctx: &str) -> PyResult<String> {
    typed(&get_item(d, key, ctx)?, &format!("{ctx}{key}"), "a string")
}

fn get_opt_f64(d: &Bound<'_, PyDict>, key: &str, ctx: &str) -> PyResult<Option<f64>> {
    match d.get_item(key)? {
        None => Ok(None),
        Some(v) if v.is_none() => Ok(None),
        Some(v) => Ok(Some(typed(&v, &format!("{ctx}{key}"), "a number or None")?)),
    }
}

fn material_from_py(obj: &Bound<'_, PyAny>, ctx: &str) -> PyResult<Material> {
    if obj.is_instance_of::<PyString>() {
        let key: String = typed(obj, ctx.trim_end_matches('.'), "a material key")?;
        return library::by_name(&key).map_err(|e| within(e, ctx)).py_err();
    }
    let d = table(obj, ctx)?;
    let name = get_str(d, "name", ctx)?;
    let class = get_str(d, "class", ctx)?;
    let class = MaterialClass::parse(&class)
        .map_err(|e| within(e, ctx))
        .py_err()?;
    let d31 = get_opt_f64(d, "d31", ctx)?;
    let max_field = get_opt_f64(d, "max_field", ctx)?;
    let piezo = match (d31, max_field) {
        (None, None) => None,
        (Some(d31), Some(max_field)) => Some(Piezo { d31, max_field }),
        (Some(_), None) => return Err(missing(format!("{ctx}max_field"))),
        (None, Some(_)) => return Err(missing(format!("{ctx}d31"))),
    };
    MaterialSpec {
        name,
        class,
        e1: get_f64(d, "e1", ctx)?,
        e2: get_f64(d, "e2", ctx)?,
        g12: get_f64(d, "g12", ctx)?,
        nu12: get_f64(d, "nu12", ctx)?,
        density: get_f64(d, "density", ctx)?,
        alpha1: get_f64(d, "alpha1", ctx)?,
        alpha2: get_f64(d, "alpha2", ctx)?,
        piezo,
    }
    .build()
    .map_err(|e| within(e, ctx))
    .py_err()
}

fn material_to_py<'py>(py: Python<'py>, m: &Material) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", m.name())?;
    d.set_item("class", m.class().as_str())?;
    d.set_item("e1", m.e1())?;
    d.set_item("e2", m.e2())?;
    d.set_item("g12", m.g12())?;
    d.set_item("nu12", m.nu12())?;
    d.set_item("density", m.density())?;
    d.set_item("alpha1", m.alpha1())?;
    d.set_item("alpha2", m.alpha2())?;
    d.set_item("d31", m.piezo().map(|p| p.d31))?;
    d.set_item("max_field", m.piezo().map(|p| p.max_field))?;
    Ok(d)
}

fn layers_from_py(layers: &Bound<'_, PyList>) -> PyResult<Layup> {
    let mut out = Vec::with_capacity(layers.len());
    for (i, item) in layers.iter().enumerate() {
        let ctx = format!("layers[{i}].");
        let d = table(&item, &ctx)?;
        let name = get_str(d, "name", &ctx)?;
        let plies_obj = get_item(d, "plies", &ctx)?;
        let plies_list = plies_obj.cast::<PyList>().map_err(|_| {
            to_pyerr(Error::invalid(
                format!("{ctx}plies"),
                "not a list",
                "a list of ply dicts",
            ))
        })?;
        let mut plies = Vec::with_capacity(plies_list.len());
        for (j, p) in plies_list.iter().enumerate() {
            let pctx = format!("{ctx}plies[{j}].");
            let pd = table(&p, &pctx)?;
            let material = material_from_py(
                &get_item(pd, "material", &pctx)?,
                &format!("{pctx}material."),
            )?;
            let thickness = get_f64(pd, "thickness", &pctx)?;
            let angle = match pd.get_item("angle")? {
                Some(a) => typed(&a, &format!("{pctx}angle"), "a number (rad)")?,
                None => 0.0,
            };
            plies.push(
                Ply::new(material, thickness, angle)
                    .map_err(|e| within(e, &pctx))
                    .py_err()?,
            );
        }
        out.push(
            Layer::from_plies(name, plies)
                .map_err(|e| within(e, &ctx))
                .py_err()?,
        );
    }
    Layup::new(out).py_err()
}

fn layer_to_py<'py>(py: Python<'py>, l: &Layer) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", l.name())?;
    let plies = PyList::empty(py);
    for p in l.plies() {
        let pd = PyDict::new(py);
        pd.set_item("material", material_to_py(py, p.material())?)?;
        pd.set_item("thickness", p.thickness())?;
        pd.set_item("angle", p.angle())?;
        plies.append(pd)?;
    }
    d.set_item("plies", plies)?;
    Ok(d)
}

fn layup_to_py<'py>(py: Python<'py>, l: &Layup) -> PyResult<Bound<'py, PyList>> {
    let out = PyList::empty(py);
    for layer in l.layers() {
        out.append(layer_to_py(py, layer)?)?;
    }
    Ok(out)
}

fn vec3(name: &'static str, a: &PyReadonlyArray1<'_, f64>) -> PyResult<Vector3<f64>> {
    let v = to_vec(a);
    if v.len() != 3 {
        return Err(Error::Shape(format!(
            "`{name}` must have 3 elements, got {}",
            v.len()
        )))
        .py_err();
    }
    paritysim_error::check_all_finite(name, &v).py_err()?;
    Ok(Vector3::new(v[0], v[1], v[2]))
}

fn arr3<'py>(py: Python<'py>, v: &Vector3<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v.as_slice())
}

fn loads_from_py(
    n: &PyReadonlyArray1<'_, f64>,
    m: &PyReadonlyArray1<'_, f64>,
    delta_t: f64,
    voltages: &PyReadonlyArray1<'_, f64>,
) -> PyResult<Loads> {
    Ok(Loads {
        n: vec3("n", n)?,
        m: vec3("m", m)?,
        delta_t,
        voltages: to_vec(voltages),
    })
}

// ------------------------------------------------------------------ materials and presets

/// Keys of the material library.
#[pyfunction]
fn laminate_material_names() -> Vec<&'static str> {
    library::NAMES.to_vec()
}

/// A library material as a dict (units: mN/mm², mg/mm³, 1/K, mm/V, V/mm).
#[pyfunction]
fn laminate_material<'py>(py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyDict>> {
    let m = library::by_name(key).py_err()?;
    material_to_py(py, &m)
}

/// Validates a material dict (or library key) and returns the normalised dict.
#[pyfunction]
fn laminate_check_material<'py>(
    py: Python<'py>,
    spec: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = material_from_py(spec, "")?;
    material_to_py(py, &m)
}

/// A preset layup as a list of layer dicts: `mobee`, `mobee_without_titanium`,
/// `linkage_sublaminate`, `bimorph_mobee`.
#[pyfunction]
fn laminate_preset<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyList>> {
    let l = match name {
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
    .py_err()?;
    layup_to_py(py, &l)
}

/// PZT–CF–PZT layup of Wood et al. 2005 (thicknesses mm) as layer dicts.
#[pyfunction]
fn laminate_wood_layup<'py>(
    py: Python<'py>,
    t_pzt: f64,
    t_cf: f64,
) -> PyResult<Bound<'py, PyList>> {
    let l = Bimorph::wood_layup(t_pzt, t_cf).py_err()?;
    layup_to_py(py, &l)
}

/// The cured 0-90-0 carbon-fibre layer (§4.4.2) of `thickness` mm at `angle` rad, as a layer dict.
#[pyfunction]
#[pyo3(signature = (name, thickness=0.1, angle=0.0))]
fn laminate_cf_0_90_0<'py>(
    py: Python<'py>,
    name: &str,
    thickness: f64,
    angle: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let l = Layer::cf_0_90_0(name, thickness, angle).py_err()?;
    layer_to_py(py, &l)
}

/// Named constants: cure temperatures (°C), cure ΔT (K), Kapton yield strain, castellated
/// flexure length range (mm), thesis actuator constants (mN/mm, mN/V).
#[pyfunction]
fn laminate_constants<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("cure_temperature_c", CURE_TEMPERATURE_C)?;
    d.set_item("room_temperature_c", ROOM_TEMPERATURE_C)?;
    d.set_item("cure_delta_t", CURE_DELTA_T)?;
    d.set_item("kapton_yield_strain", KAPTON_YIELD_STRAIN)?;
    d.set_item(
        "castellated_flexure_length_min",
        CASTELLATED_FLEXURE_LENGTH_MM.0,
    )?;
    d.set_item(
        "castellated_flexure_length_max",
        CASTELLATED_FLEXURE_LENGTH_MM.1,
    )?;
    d.set_item(
        "thesis_stiffness_mn_per_mm",
        ActuatorConstants::THESIS.stiffness_mn_per_mm,
    )?;
    d.set_item(
        "thesis_force_per_volt_mn_per_v",
        ActuatorConstants::THESIS.force_per_volt_mn_per_v,
    )?;
    Ok(d)
}

// ------------------------------------------------------------------ CLPT

/// The 6×6 `[A B; B D]` matrix (A mN/mm, B mN, D mN·mm) of a layup.
#[pyfunction]
fn laminate_abd<'py>(py: Python<'py>, layers: &Bound<'py, PyList>) -> PyResult<Bound<'py, PyAny>> {
    let layup = layers_from_py(layers)?;
    let m = py.detach(|| layup.abd().matrix());
    let flat: Vec<f64> = (0..36).map(|k| m[(k / 6, k % 6)]).collect();
    shaped(py, flat, &[6, 6])
}

/// Mid-plane `strain` (3,) and `curvature` (3,) (1/mm) under `n` (mN/mm), `m` (mN),
/// `delta_t` (K) and per-layer `voltages` (V; empty for none).
#[pyfunction]
fn laminate_response<'py>(
    py: Python<'py>,
    layers: &Bound<'py, PyList>,
    n: PyReadonlyArray1<'py, f64>,
    m: PyReadonlyArray1<'py, f64>,
    delta_t: f64,
    voltages: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let layup = layers_from_py(layers)?;
    let loads = loads_from_py(&n, &m, delta_t, &voltages)?;
    let r = py.detach(|| layup.response(&loads)).py_err()?;
    let out = PyDict::new(py);
    out.set_item("strain", arr3(py, &r.strain))?;
    out.set_item("curvature", arr3(py, &r.curvature))?;
    Ok(out)
}

/// Ply face stresses (mN/mm², laminate axes): `layer`, `ply` (k,), `z_bottom`, `z_top` (k,),
/// `stress_bottom`, `stress_top` (k, 3).
#[pyfunction]
fn laminate_ply_stresses<'py>(
    py: Python<'py>,
    layers: &Bound<'py, PyList>,
    n: PyReadonlyArray1<'py, f64>,
    m: PyReadonlyArray1<'py, f64>,
    delta_t: f64,
    voltages: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let layup = layers_from_py(layers)?;
    let loads = loads_from_py(&n, &m, delta_t, &voltages)?;
    let s = py.detach(|| layup.ply_stresses(&loads)).py_err()?;
    let k = s.len();
    let out = PyDict::new(py);
    out.set_item(
        "layer",
        PyArray1::from_vec(py, s.iter().map(|p| p.layer as i64).collect()),
    )?;
    out.set_item(
        "ply",
        PyArray1::from_vec(py, s.iter().map(|p| p.ply as i64).collect()),
    )?;
    out.set_item(
        "z_bottom",
        PyArray1::from_vec(py, s.iter().map(|p| p.z_bottom).collect()),
    )?;
    out.set_item(
        "z_top",
        PyArray1::from_vec(py, s.iter().map(|p| p.z_top).collect()),
    )?;
    let flat = |f: fn(&paritysim_laminate::PlyStress) -> Vector3<f64>| -> Vec<f64> {
        s.iter().flat_map(|p| f(p).as_slice().to_vec()).collect()
    };
    out.set_item(
        "stress_bottom",
        shaped(py, flat(|p| p.stress_bottom), &[k, 3])?,
    )?;
    out.set_item("stress_top", shaped(py, flat(|p| p.stress_top), &[k, 3])?)?;
    Ok(out)
}

/// Summary of a layup: `n_layers`, `total_thickness` (mm), `areal_mass` (mg/mm²),
/// `layer_bounds` (n, 2) (mm), `layer_thickness`, `layer_areal_mass`, `layer_class`,
/// `layer_is_piezo`, `is_symmetric`, `cure_curvature` (3,) (1/mm, ΔT = −180 K),
/// `beam_bending_stiffness` (mN·mm), `effective_modulus_x` (mN/mm²).
#[pyfunction]
fn laminate_summary<'py>(
    py: Python<'py>,
    layers: &Bound<'py, PyList>,
) -> PyResult<Bound<'py, PyDict>> {
    let layup = layers_from_py(layers)?;
    let (sum, ei, ex) = py
        .detach(|| -> Result<_, Error> {
            Ok((
                pcmems::summarize(&layup)?,
                layup.beam_bending_stiffness()?,
                layup.effective_modulus_x()?,
            ))
        })
        .py_err()?;
    let out = PyDict::new(py);
    out.set_item("n_layers", sum.n_layers)?;
    out.set_item("total_thickness", sum.total_thickness)?;
    out.set_item("areal_mass", sum.areal_mass)?;
    let bounds: Vec<f64> = layup
        .layer_bounds()
        .iter()
        .flat_map(|&(a, b)| [a, b])
        .collect();
    out.set_item("layer_bounds", shaped(py, bounds, &[layup.len(), 2])?)?;
    let ls = layup.layers();
    out.set_item(
        "layer_thickness",
        PyArray1::from_vec(py, ls.iter().map(Layer::thickness).collect()),
    )?;
    out.set_item(
        "layer_areal_mass",
        PyArray1::from_vec(py, ls.iter().map(Layer::areal_mass).collect()),
    )?;
    out.set_item(
        "layer_class",
        ls.iter().map(|l| l.class().as_str()).collect::<Vec<_>>(),
    )?;
    out.set_item(
        "layer_is_piezo",
        ls.iter().map(Layer::is_piezo).collect::<Vec<_>>(),
    )?;
    out.set_item("is_symmetric", layup.is_symmetric())?;
    out.set_item("cure_curvature", arr3(py, &sum.cure_curvature))?;
    out.set_item("beam_bending_stiffness", ei)?;
    out.set_item("effective_modulus_x", ex)?;
    Ok(out)
}

// ------------------------------------------------------------------ bimorph

fn bimorph_to_py<'py>(
    py: Python<'py>,
    b: &Bimorph,
    voltages: &[f64],
) -> PyResult<Bound<'py, PyDict>> {
    let mut defl = Vec::with_capacity(voltages.len());
    let mut force = Vec::with_capacity(voltages.len());
    for (i, &v) in voltages.iter().enumerate() {
        let at = |e: Error| {
            let array = format!("{}s", e.field().unwrap_or("voltage"));
            e.at_index(i, Some(&array))
        };
        defl.push(b.free_deflection(v).map_err(at).py_err()?);
        force.push(b.blocked_force(v).map_err(at).py_err()?);
    }
    let g = b.geometry();
    let out = PyDict::new(py);
    out.set_item("length", g.length)?;
    out.set_item("extension", g.extension)?;
    out.set_item("base_width", g.base_width)?;
    out.set_item("width_ratio", g.width_ratio)?;
    out.set_item("tip_width", g.tip_width())?;
    out.set_item("nominal_width", g.nominal_width())?;
    out.set_item("curvature_per_volt", b.curvature_per_volt())?;
    out.set_item(
        "bending_stiffness_per_width",
        b.bending_stiffness_per_width(),
    )?;
    out.set_item("free_deflection_per_volt", b.free_deflection_per_volt())?;
    out.set_item("stiffness", b.stiffness())?;
    out.set_item("force_per_volt", b.force_per_volt())?;
    out.set_item("max_voltage", b.max_voltage())?;
    out.set_item("active_mass", b.active_mass())?;
    out.set_item("layer_voltages_per_volt", b.layer_voltages(1.0))?;
    out.set_item("free_deflection", PyArray1::from_vec(py, defl))?;
    out.set_item("blocked_force", PyArray1::from_vec(py, force))?;
    Ok(out)
}

/// A bending actuator of the layup and planform (mm): its constants and, for each drive
/// amplitude in `voltages` (V), `free_deflection` (mm) and `blocked_force` (mN).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn laminate_bimorph<'py>(
    py: Python<'py>,
    layers: &Bound<'py, PyList>,
    length: f64,
    extension: f64,
    base_width: f64,
    width_ratio: f64,
    voltages: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let layup = layers_from_py(layers)?;
    let g = BimorphGeometry::new(length, extension, base_width, width_ratio).py_err()?;
    let b = py.detach(|| Bimorph::new(layup, g)).py_err()?;
    bimorph_to_py(py, &b, &to_vec(&voltages))
}

/// Solves for the planform giving `stiffness` (mN/mm) and `force_per_volt` (mN/V) with the
/// layup, taper `width_ratio` and `extension_ratio`; returns the `laminate_bimorph` dict.
#[pyfunction]
fn laminate_bimorph_design<'py>(
    py: Python<'py>,
    layers: &Bound<'py, PyList>,
    stiffness: f64,
    force_per_volt: f64,
    width_ratio: f64,
    extension_ratio: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let layup = layers_from_py(layers)?;
    let target = ActuatorConstants::new(stiffness, force_per_volt).py_err()?;
    let b = py
        .detach(|| Bimorph::design_for(layup, target, width_ratio, extension_ratio))
        .py_err()?;
    bimorph_to_py(py, &b, &[])
}

// ------------------------------------------------------------------ flexures

/// Flexure of `material` (dict or key), `width`, `thickness`, `length` (mm): `stiffness`,
/// `plate_stiffness` (mN·mm/rad) and `strain_per_rad` (`t / (2 L)`).
#[pyfunction]
fn laminate_flexure<'py>(
    py: Python<'py>,
    material: &Bound<'py, PyAny>,
    width: f64,
    thickness: f64,
    length: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let m = material_from_py(material, "material.")?;
    let f = Flexure::new(m, width, thickness, length).py_err()?;
    let out = PyDict::new(py);
    out.set_item("stiffness", f.stiffness())?;
    out.set_item("plate_stiffness", f.plate_stiffness())?;
    out.set_item("strain_per_rad", f.max_strain(1.0).py_err()?)?;
    Ok(out)
}

/// Castellated joint (§4.4.3): `stiffness` (mN·mm/rad), `flexure_width`, `segment_width` (mm),
/// `within_thesis_range` (flexure length in 20–40 µm), `strain_per_rad`.
#[pyfunction]
fn laminate_castellated_joint<'py>(
    py: Python<'py>,
    material: &Bound<'py, PyAny>,
    joint_width: f64,
    n_segments: usize,
    flexure_fraction: f64,
    thickness: f64,
    flexure_length: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let m = material_from_py(material, "material.")?;
    let j = CastellatedJoint::new(
        m,
        joint_width,
        n_segments,
        flexure_fraction,
        thickness,
        flexure_length,
    )
    .py_err()?;
    let out = PyDict::new(py);
    out.set_item("stiffness", j.stiffness())?;
    out.set_item("flexure_width", j.flexure().width())?;
    out.set_item("segment_width", j.segment_width())?;
    out.set_item("within_thesis_range", j.within_thesis_range())?;
    out.set_item("strain_per_rad", j.flexure().max_strain(1.0).py_err()?)?;
    Ok(out)
}

/// Adds the laminate functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(laminate_material_names, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_material, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_check_material, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_preset, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_wood_layup, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_cf_0_90_0, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_constants, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_abd, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_response, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_ply_stresses, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_summary, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_bimorph, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_bimorph_design, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_flexure, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_castellated_joint, m)?)?;
    Ok(())
}
