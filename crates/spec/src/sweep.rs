//! sweeps (todo)
