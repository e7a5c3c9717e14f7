//! `paritysim._core`: the only crate that knows PyO3.
//!
//! Thin by design: convert numpy/Python values, release the GIL (`Python::detach`), call the
//! pure-Rust crates, convert the result back. Every `paritysim_error::Error` becomes the matching
//! exception of the tree built in `errors`; nothing here panics on user input.

use pyo3::prelude::*;

mod aero;
mod continuation;
mod convert;
mod errors;
mod kinematics;
mod laminate;
mod spec;
mod stability;
mod sweep;
mod wing_terms;

/// The x86-64 SIMD features this build's code may execute (from `.cargo/config.toml` or
/// `RUSTFLAGS`): what `paritysim._cpu` must find on the CPU before it loads this module.
fn compiled_simd_features() -> Vec<&'static str> {
    [
        ("avx", cfg!(target_feature = "avx")),
        ("avx2", cfg!(target_feature = "avx2")),
        ("fma", cfg!(target_feature = "fma")),
        ("avx512f", cfg!(target_feature = "avx512f")),
    ]
    .into_iter()
    .filter_map(|(name, enabled)| enabled.then_some(name))
    .collect()
}

/// The native module.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("__target_features__", compiled_simd_features())?;
    errors::register(m)?;
    kinematics::register(m)?;
    spec::register(m)?;
    continuation::register(m)?;
    aero::register(m)?;
    laminate::register(m)?;
    stability::register(m)?;
    sweep::register(m)?;
    wing_terms::register(m)?;
    Ok(())
}
