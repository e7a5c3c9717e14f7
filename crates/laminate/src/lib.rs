//! Laminate plate theory for piezoelectric bimorph actuators, flexures and PC-MEMS layups.
//!
//! The thesis derives its actuator constants "from a laminate plate theory analysis" (§3.3.1,
//! ref. \[42\]: Wood, Steltz & Fearing 2005), its joint springs from Euler beam theory (§3.2.2) and
//! builds its devices from multilayer laminates (Chapter 4). This crate is that design layer:
//!
//! * [`material`]: validated orthotropic ply materials and a [`library`] of the thesis' materials
//!   (PZT-5H, carbon-fibre prepreg, polyimide, Pyralux, brass, titanium, spring steel, PET),
//!   each value with its source.
//! * [`clpt`]: classical laminate plate theory — `Q`, `Q̄(θ)`, the `ABD` matrix of a [`Layup`]
//!   of named [`Layer`]s, mid-plane strains and curvatures under mechanical, thermal and
//!   piezoelectric loads, ply stresses.
//! * [`bimorph`]: the bending actuator of ref. \[42\] (length, extension, taper): free deflection,
//!   blocked force, stiffness, a solver for the planform that meets target constants (e.g. the
//!   thesis' 467 mN/mm and 1.2 mN/V), and the [`ActuatorConstants`] the dynamics engine uses.
//! * [`flexure`]: polyimide flexure stiffness `E w t³ / (12 L)` with the large-deflection caveat
//!   of §3.2.2, and the castellated folding joint of §4.4.3.
//! * [`pcmems`]: the Mobee 18-layer stack of Fig. 4.27, the linkage sublaminate, and the
//!   thermal curvature after the 200 °C cure (§4.5.3).
//!
//! # Units (mg-mm-ms-rad-V)
//!
//! Lengths mm, mass mg, force mN, stiffness mN/mm, torsional stiffness mN·mm/rad, moduli
//! **mN/mm² (= kPa; 1 GPa = 1e6 mN/mm²)**, density mg/mm³ (= g/cm³), `d31` mm/V
//! (1 pm/V = 1e-9 mm/V), field V/mm, temperature differences K, thermal expansion 1/K.
//!
//! # Errors
//!
//! Constructors validate and return [`paritysim_error::Result`]: non-physical materials
//! (`E ≤ 0`, Poisson ratio out of range, ...) and non-positive thicknesses are
//! [`Error::InvalidParameter`] naming the field and its allowed range; malformed layups are
//! [`Error::Geometry`]; a laminate without bending stiffness is [`Error::Singular`].

pub mod bimorph;
pub mod clpt;
pub mod flexure;
pub mod material;
pub mod pcmems;
pub mod records;

pub use bimorph::{ActuatorConstants, Bimorph, BimorphGeometry};
pub use clpt::{
    Abd, Layer, Layup, Loads, Ply, PlyStress, Response, reduced_stiffness, transformed_stiffness,
};
pub use flexure::{CastellatedJoint, Flexure};
pub use material::{Material, MaterialClass, MaterialSpec, Piezo, library};
pub use paritysim_error::{Error, Result};
