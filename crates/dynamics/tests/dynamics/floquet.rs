//! floquet tests (submodule of the one dynamics integration binary).

#[allow(unused_imports)]
use super::*;
