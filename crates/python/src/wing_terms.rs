//! Binding for Appendix A's per-wing dynamics terms (`Wing::terms`): `M`, `c`, `∇V`, `J6`.

use paritysim_dynamics::wing::WingTermsRecord;
use pyo3::prelude::*;

use crate::convert::bindings;

bindings! {
    /// `WingTermsRecord::at` for wing `wing` of a JSON spec at `p = (φ, θ, ψ)`, `ṗ`: mass
    /// matrix (A.36), Coriolis, spring gradient (A.6), aero, J6 (A.9), energies. Always the
    /// general terms (never the stroke-plane closed form).
    fn dynamics_wing_terms(spec: &str, wing: usize, p: [f64; 3], p_dot: [f64; 3]) {
        WingTermsRecord::at(&crate::spec::device(spec)?, wing, p, p_dot)
    }
}
