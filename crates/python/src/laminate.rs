//! Bindings of paritysim-laminate (functions prefixed `laminate_`).
//!
//! Layups cross the boundary as JSON lists of [`LayerRecord`], materials as JSON
//! [`MaterialRecord`]; results are the `paritysim_laminate::records` types through
//! [`to_py`]. Units: mm, mN, mg, V, K; moduli mN/mm².

use numpy::PyReadonlyArray1;
use paritysim_error::Error;
use paritysim_laminate::flexure::{CastellatedJoint, Flexure};
use paritysim_laminate::records::{
    self, BimorphReport, CastellatedReport, FlexureReport, LayerRecord, LayupSummary,
    MaterialRecord, PlyStressColumns, ResponseRecord,
};
use paritysim_laminate::{
    ActuatorConstants, Bimorph, BimorphGeometry, Layer, Layup, Loads, Material, library,
};
use pyo3::prelude::*;

use crate::convert::{from_json, to_py, to_vec};
use crate::errors::IntoPyResult;

fn layup(layers: &str) -> PyResult<Layup> {
    LayerRecord::build_layup(from_json("layers", layers).py_err()?).py_err()
}

fn material(json: &str, ctx: &str) -> PyResult<Material> {
    from_json::<MaterialRecord>("material", json)
        .and_then(|m| m.build(ctx))
        .py_err()
}

fn vec3(name: &'static str, a: &PyReadonlyArray1<'_, f64>) -> PyResult<nalgebra::Vector3<f64>> {
    let v = to_vec(a);
    let [x, y, z] = v[..] else {
        let msg = format!("`{name}` must have 3 elements, got {}", v.len());
        return Err(Error::Shape(msg)).py_err();
    };
    paritysim_error::check_all_finite(name, &v).py_err()?;
    Ok(nalgebra::Vector3::new(x, y, z))
}

fn loads(
    n: &PyReadonlyArray1<'_, f64>,
    m: &PyReadonlyArray1<'_, f64>,
    delta_t: f64,
    voltages: &PyReadonlyArray1<'_, f64>,
) -> PyResult<Loads> {
    let (n, m, voltages) = (vec3("n", n)?, vec3("m", m)?, to_vec(voltages));
    Ok(Loads {
        n,
        m,
        delta_t,
        voltages,
    })
}

/// Keys of the material library.
#[pyfunction]
fn laminate_material_names() -> Vec<&'static str> {
    library::NAMES.to_vec()
}

/// A library material as a material dict.
#[pyfunction]
fn laminate_material<'py>(py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
    to_py(py, &MaterialRecord::of(&library::by_name(key).py_err()?))
}

/// Validates a material (JSON) and returns the normalised dict.
#[pyfunction]
fn laminate_check_material<'py>(
    py: Python<'py>,
    material_json: &str,
) -> PyResult<Bound<'py, PyAny>> {
    to_py(py, &MaterialRecord::of(&material(material_json, "")?))
}

/// A preset layup (see `records::preset`) as layer dicts.
#[pyfunction]
fn laminate_preset<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    to_py(py, &LayerRecord::all(&records::preset(name).py_err()?))
}

/// PZT–CF–PZT layup of Wood et al. 2005 (thicknesses mm) as layer dicts.
#[pyfunction]
fn laminate_wood_layup<'py>(py: Python<'py>, t_pzt: f64, t_cf: f64) -> PyResult<Bound<'py, PyAny>> {
    to_py(
        py,
        &LayerRecord::all(&Bimorph::wood_layup(t_pzt, t_cf).py_err()?),
    )
}

/// The cured 0-90-0 carbon-fibre layer (§4.4.2) of `thickness` mm at `angle` rad, as a layer dict.
#[pyfunction]
#[pyo3(signature = (name, thickness=0.1, angle=0.0))]
fn laminate_cf_0_90_0<'py>(
    py: Python<'py>,
    name: &str,
    thickness: f64,
    angle: f64,
) -> PyResult<Bound<'py, PyAny>> {
    to_py(
        py,
        &LayerRecord::of(&Layer::cf_0_90_0(name, thickness, angle).py_err()?),
    )
}

/// Named constants (`records::Constants`).
#[pyfunction]
fn laminate_constants(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    to_py(py, &records::constants())
}

/// The 6×6 `[A B; B D]` matrix (A mN/mm, B mN, D mN·mm) of a layup.
#[pyfunction]
fn laminate_abd<'py>(py: Python<'py>, layers_json: &str) -> PyResult<Bound<'py, PyAny>> {
    let layup = layup(layers_json)?;
    let m = py.detach(|| layup.abd().matrix());
    let rows: Vec<[f64; 6]> = (0..6).map(|i| std::array::from_fn(|j| m[(i, j)])).collect();
    to_py(py, &rows)
}

/// Mid-plane `strain` (3,) and `curvature` (3,) (1/mm) under `n` (mN/mm), `m` (mN),
/// `delta_t` (K) and per-layer `voltages` (V; empty for none).
#[pyfunction]
fn laminate_response<'py>(
    py: Python<'py>,
    layers_json: &str,
    n: PyReadonlyArray1<'py, f64>,
    m: PyReadonlyArray1<'py, f64>,
    delta_t: f64,
    voltages: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let (layup, loads) = (layup(layers_json)?, loads(&n, &m, delta_t, &voltages)?);
    let r = py.detach(|| layup.response(&loads)).py_err()?;
    to_py(py, &ResponseRecord::from(r))
}

/// Ply face stresses (`records::PlyStressColumns`), same arguments as `laminate_response`.
#[pyfunction]
fn laminate_ply_stresses<'py>(
    py: Python<'py>,
    layers_json: &str,
    n: PyReadonlyArray1<'py, f64>,
    m: PyReadonlyArray1<'py, f64>,
    delta_t: f64,
    voltages: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let (layup, loads) = (layup(layers_json)?, loads(&n, &m, delta_t, &voltages)?);
    let s = py.detach(|| layup.ply_stresses(&loads)).py_err()?;
    to_py(py, &s.into_iter().collect::<PlyStressColumns>())
}

/// Summary of a layup (`records::LayupSummary`).
#[pyfunction]
fn laminate_summary<'py>(py: Python<'py>, layers_json: &str) -> PyResult<Bound<'py, PyAny>> {
    let layup = layup(layers_json)?;
    to_py(py, &py.detach(|| LayupSummary::of(&layup)).py_err()?)
}

/// A bending actuator of the layup and planform (mm): `records::BimorphReport` at each drive
/// amplitude in `voltages` (V).
#[pyfunction]
fn laminate_bimorph<'py>(
    py: Python<'py>,
    layers_json: &str,
    length: f64,
    extension: f64,
    base_width: f64,
    width_ratio: f64,
    voltages: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let layup = layup(layers_json)?;
    let g = BimorphGeometry::new(length, extension, base_width, width_ratio).py_err()?;
    let b = py.detach(|| Bimorph::new(layup, g)).py_err()?;
    to_py(py, &BimorphReport::of(&b, &to_vec(&voltages)).py_err()?)
}

/// Solves for the planform giving `stiffness` (mN/mm) and `force_per_volt` (mN/V) with the
/// layup, taper `width_ratio` and `extension_ratio`; returns the `laminate_bimorph` dict.
#[pyfunction]
fn laminate_bimorph_design<'py>(
    py: Python<'py>,
    layers_json: &str,
    stiffness: f64,
    force_per_volt: f64,
    width_ratio: f64,
    extension_ratio: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let layup = layup(layers_json)?;
    let target = ActuatorConstants::new(stiffness, force_per_volt).py_err()?;
    let b = py
        .detach(|| Bimorph::design_for(layup, target, width_ratio, extension_ratio))
        .py_err()?;
    to_py(py, &BimorphReport::of(&b, &[]).py_err()?)
}

/// Flexure of `material_json`, `width`, `thickness`, `length` (mm): `records::FlexureReport`.
#[pyfunction]
fn laminate_flexure<'py>(
    py: Python<'py>,
    material_json: &str,
    width: f64,
    thickness: f64,
    length: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let f = Flexure::new(
        material(material_json, "material")?,
        width,
        thickness,
        length,
    );
    to_py(py, &FlexureReport::of(&f.py_err()?).py_err()?)
}

/// Castellated joint (§4.4.3): `records::CastellatedReport`.
#[pyfunction]
fn laminate_castellated_joint<'py>(
    py: Python<'py>,
    material_json: &str,
    joint_width: f64,
    n_segments: usize,
    flexure_fraction: f64,
    thickness: f64,
    flexure_length: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let m = material(material_json, "material")?;
    let j = CastellatedJoint::new(
        m,
        joint_width,
        n_segments,
        flexure_fraction,
        thickness,
        flexure_length,
    );
    to_py(py, &CastellatedReport::of(&j.py_err()?).py_err()?)
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
