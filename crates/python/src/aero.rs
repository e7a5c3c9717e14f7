//! Bindings of paritysim-aero (functions prefixed `aero_`).
//!
//! Planforms cross the boundary as `(n, 2)` float arrays of `[z, x]` vertices (mm); every call
//! re-validates them (cheap next to Python overhead for the usual < 1000 vertices). Results are
//! the `paritysim_aero::records` types through [`to_py`](crate::convert::to_py).

use paritysim_aero::records::{
    ChordTable, CoefficientTable, InertiaReport, MomentRequest, PlanformReport, vertices,
};
use paritysim_aero::{CoefficientModel, CoefficientSet, CutEdge, NormalForceLaw, Planform};
use paritysim_error::Result;
use pyo3::prelude::*;

use crate::convert::{Floats, Table, bindings};

fn planform(points: &Table, closure_tolerance: Option<f64>) -> Result<Planform> {
    let pts = points.rows::<2>("points")?;
    match closure_tolerance {
        Some(tol) => Planform::from_traced_outline(&pts, tol),
        None => Planform::from_points(&pts),
    }
}

bindings! {
    const "AERO_AIR_DENSITY" = paritysim_aero::DEFAULT_AIR_DENSITY;
    const "AERO_DEFAULT_ROTATIONAL_DAMPING" = paritysim_aero::DEFAULT_ROTATIONAL_DAMPING;
    const "AERO_DEFAULT_MODEL" = CoefficientSet::default().name();
    const "AERO_DEFAULT_NORMAL_FORCE_LAW" = NormalForceLaw::default().name();

    /// Geometry and Ω1..Ω4 of an outline (`(n, 2)` `[z, x]` mm, closing edge implicit; with
    /// `closure_tolerance` mm a traced curve returning to its start) in air of `density` mg/mm³.
    #[pyo3(signature = (points, density, closure_tolerance=None))]
    fn aero_planform_properties(points: Table, density: f64, closure_tolerance: Option<f64>) {
        PlanformReport::of(&planform(&points, closure_tolerance)?, density)
    }

    /// Vertices of a rectangle `z ∈ [root_offset, root_offset + span]`,
    /// `x ∈ [le_offset − chord, le_offset]`.
    fn aero_planform_rectangle(span: f64, chord: f64, root_offset: f64, le_offset: f64) {
        Ok(vertices(&Planform::rectangle(span, chord, root_offset, le_offset)?))
    }

    /// Vertices of a semi-elliptic planform (straight leading edge) with `segments` steps.
    fn aero_planform_semi_ellipse(
        span: f64,
        max_chord: f64,
        root_offset: f64,
        le_offset: f64,
        segments: usize,
    ) {
        let p = Planform::semi_ellipse(span, max_chord, root_offset, le_offset, segments)?;
        Ok(vertices(&p))
    }

    /// Vertices of the HMF-like wing scaled to `tip_radius` mm.
    fn aero_planform_hmf_like(tip_radius: f64, segments: usize) {
        Ok(vertices(&Planform::hmf_like(tip_radius, segments)?))
    }

    /// The membrane left after cutting `fraction` of the span at the tip (`edge = "tip"`) or of
    /// the chordwise extent at the trailing edge (`"trailing"`).
    fn aero_planform_cut(points: Table, fraction: f64, edge: &str) {
        let edge = CutEdge::from_name(edge)?;
        Ok(vertices(&planform(&points, None)?.cut(fraction, edge)?))
    }

    /// Chord `c(z)` and leading edge `l(z)` (mm); outside the span 0 and NaN (documented mask).
    fn aero_planform_chord(points: Table, z: Floats) {
        ChordTable::of(&planform(&points, None)?, &z)
    }

    /// Mass properties about the spherical centre: membrane `areal_density` (mg/mm²), line
    /// masses `[z0, x0, z1, x1, linear_density]` (mg/mm), point masses `[z, x, mass]`.
    fn aero_planform_inertia(
        points: Table,
        areal_density: f64,
        line_masses: Table,
        point_masses: Table,
    ) {
        let lines = line_masses.rows::<5>("line_masses")?;
        let pts = point_masses.rows::<3>("point_masses")?;
        InertiaReport::of(&planform(&points, None)?, areal_density, &lines, &pts)
    }

    /// Coefficients of `model` at angles of attack `alpha` (rad, each in [0, π]).
    fn aero_coefficients(alpha: Floats, model: &str) {
        CoefficientTable::of(&CoefficientSet::from_name(model)?, &alpha)
    }

    /// Blade-element moments (eqs. 3.8–3.11) over paired state arrays (`MomentRequest`).
    #[pyo3(signature = (omegas, phi, theta, psi, phi_dot, theta_dot, psi_dot, model, rotational_damping, normal_force_law, force=None))]
    #[allow(clippy::too_many_arguments)]
    fn aero_moments(
        omegas: [f64; 4],
        phi: Floats,
        theta: Floats,
        psi: Floats,
        phi_dot: Floats,
        theta_dot: Floats,
        psi_dot: Floats,
        model: &str,
        rotational_damping: f64,
        normal_force_law: &str,
        force: Option<f64>,
    ) {
        MomentRequest {
            omegas,
            force,
            model,
            rotational_damping,
            normal_force_law,
            columns: [&phi, &theta, &psi, &phi_dot, &theta_dot, &psi_dot],
        }
        .evaluate()
    }

    /// Built-in coefficient model names.
    fn aero_model_names() -> Vec<&'static str> {
        Ok(CoefficientSet::NAMES.to_vec())
    }
}
