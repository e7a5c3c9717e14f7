//! PC-MEMS layups (Chapter 4): the Mobee 18-layer stack of Fig. 4.27, the linkage sublaminate
//! and the thermal curvature left by the 200 °C lamination cure (§4.5.3).
//!
//! # Layer order of the Mobee stack (bottom = layer 1)
//!
//! Fig. 4.27 itself is not in the text, but §4.4.2 fixes the order: brass layers 1 and 17;
//! linkage sublaminates CF–A–PI–A–CF on layers 3–7 and 11–15 (adhesive layers 4, 6, 12, 14 are
//! free sheets, 8 and 10 are tacked onto structural layers, 2 is transferred); the CF spacer on
//! layer 9; adhesive layer 16 under brass layer 17; the titanium wing layer 18 on top, without an
//! adhesive layer of its own ("layer sharing": it bonds through an aperture in layer 17 to
//! adhesive 16 and CF 15, Fig. 4.29):
//!
//! | # | layer | µm  |  | # | layer | µm  |  | # | layer | µm   |
//! |---|-------|-----|--|---|-------|-----|--|---|-------|------|
//! | 1 | B     | 12.5|  | 7 | CF    | 100 |  |13 | PI    | 7.5  |
//! | 2 | A     | 12.5|  | 8 | A     | 12.5|  |14 | A     | 12.5 |
//! | 3 | CF    | 100 |  | 9 | CF    | 100 |  |15 | CF    | 100  |
//! | 4 | A     | 12.5|  |10 | A     | 12.5|  |16 | A     | 12.5 |
//! | 5 | PI    | 7.5 |  |11 | CF    | 100 |  |17 | B     | 12.5 |
//! | 6 | A     | 12.5|  |12 | A     | 12.5|  |18 | Ti    | 50.8 |
//!
//! Counts match §4.4.2: five 100 µm CF (0-90-0 each), two 7.5 µm PI, two 12.5 µm brass, one
//! 50.8 µm titanium, eight 12.5 µm Pyralux: 690.8 µm in total. The full through-thickness stack
//! is the design stack; locally (layer sharing, cut-outs, the PZT pockets) fewer layers are
//! present. The stack is asymmetric (titanium on one side), so it curls after the cure.

use nalgebra::Vector3;
use paritysim_error::Result;

use crate::clpt::{Layer, Layup};
use crate::material::{MaterialClass, library};

/// Lamination (cure) temperature of the Pyralux adhesive in the platen press, °C (§4.4.2:
/// "200 °C at 340 kPa for 1 hour").
pub const CURE_TEMPERATURE_C: f64 = 200.0;
/// Room temperature used for the cool-down example, °C.
pub const ROOM_TEMPERATURE_C: f64 = 20.0;
/// Temperature change from the cure to room temperature, K (−180 K).
pub const CURE_DELTA_T: f64 = ROOM_TEMPERATURE_C - CURE_TEMPERATURE_C;

/// Thickness of a CF layer, mm (five 100 µm layers, §4.4.2).
pub const CF_LAYER_MM: f64 = 0.100;
/// Thickness of a polyimide layer, mm.
pub const PI_LAYER_MM: f64 = 0.0075;
/// Thickness of a brass layer, mm.
pub const BRASS_LAYER_MM: f64 = 0.0125;
/// Thickness of the titanium layer, mm (50.8 µm = 0.002 in).
pub const TI_LAYER_MM: f64 = 0.0508;
/// Thickness of a Pyralux FR1500 adhesive layer, mm.
pub const ADHESIVE_LAYER_MM: f64 = 0.0125;

fn adhesive(n: usize) -> Result<Layer> {
    Layer::single(
        format!("{n} A"),
        library::pyralux_adhesive(),
        ADHESIVE_LAYER_MM,
        0.0,
    )
}
fn cf(n: usize) -> Result<Layer> {
    Layer::cf_0_90_0(format!("{n} CF"), CF_LAYER_MM, 0.0)
}
fn pi(n: usize) -> Result<Layer> {
    Layer::single(format!("{n} PI"), library::polyimide(), PI_LAYER_MM, 0.0)
}
fn brass(n: usize) -> Result<Layer> {
    Layer::single(format!("{n} B"), library::brass(), BRASS_LAYER_MM, 0.0)
}

/// The five-layer linkage sublaminate CF–A–PI–A–CF (§4.4.1, Fig. 4.25b); symmetric, so it
/// stays flat after the cure.
pub fn linkage_sublaminate() -> Result<Layup> {
    Layup::new(vec![cf(1)?, adhesive(2)?, pi(3)?, adhesive(4)?, cf(5)?])
}

/// The Mobee 18-layer stack of Fig. 4.27, bottom (layer 1) to top (layer 18); see the module
/// docs for the order and its justification.
pub fn mobee_stack() -> Result<Layup> {
    Layup::new(vec![
        brass(1)?,
        adhesive(2)?,
        cf(3)?,
        adhesive(4)?,
        pi(5)?,
        adhesive(6)?,
        cf(7)?,
        adhesive(8)?,
        cf(9)?,
        adhesive(10)?,
        cf(11)?,
        adhesive(12)?,
        pi(13)?,
        adhesive(14)?,
        cf(15)?,
        adhesive(16)?,
        brass(17)?,
        Layer::single("18 Ti", library::titanium(), TI_LAYER_MM, 0.0)?,
    ])
}

/// The Mobee stack without the titanium layer 18: layers 1–17, mirror-symmetric about the
/// spacer layer 9, hence flat after the cure.
pub fn mobee_stack_without_titanium() -> Result<Layup> {
    let full = mobee_stack()?;
    Layup::new(full.layers()[..17].to_vec())
}

/// Per-class totals and the cure curvature of a layup.
#[derive(Clone, Debug, PartialEq)]
pub struct StackSummary {
    /// Number of named layers.
    pub n_layers: usize,
    /// Total thickness, mm.
    pub total_thickness: f64,
    /// Areal mass, mg/mm².
    pub areal_mass: f64,
    /// `(class, number of layers, thickness mm, areal mass mg/mm²)` per material class present.
    pub by_class: Vec<(MaterialClass, usize, f64, f64)>,
    /// Curvature after cooling from [`CURE_TEMPERATURE_C`] to [`ROOM_TEMPERATURE_C`], 1/mm.
    pub cure_curvature: Vector3<f64>,
}

/// Summarises a layup (see [`StackSummary`]).
pub fn summarize(layup: &Layup) -> Result<StackSummary> {
    let mut by_class: Vec<(MaterialClass, usize, f64, f64)> = Vec::new();
    for l in layup.layers() {
        let c = l.class();
        match by_class.iter_mut().find(|e| e.0 == c) {
            Some(e) => {
                e.1 += 1;
                e.2 += l.thickness();
                e.3 += l.areal_mass();
            }
            None => by_class.push((c, 1, l.thickness(), l.areal_mass())),
        }
    }
    Ok(StackSummary {
        n_layers: layup.len(),
        total_thickness: layup.total_thickness(),
        areal_mass: layup.areal_mass(),
        by_class,
        cure_curvature: layup.thermal_curvature(CURE_DELTA_T)?,
    })
}

/// Out-of-plane rise (sag) at the edge of a free plate of span `span` (mm) curved by `kappa`
/// (1/mm) about its centre: `κ (span/2)² / 2`, mm (shallow-shell approximation).
pub fn edge_rise(kappa: f64, span: f64) -> f64 {
    0.5 * kappa * (0.5 * span).powi(2)
}
