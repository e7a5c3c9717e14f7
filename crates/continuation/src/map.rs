//! The stroboscopic (period) map of a periodically forced system: what continuation needs.

use nalgebra::{DMatrix, DVector};
use paritysim_error::Result;

/// `x ↦ P(x; p)`: the state one forcing period after `x`, for parameters `p`.
///
/// Periodic orbits are the fixed points `P(x; p) = x`; the Jacobian `∂P/∂x` at a fixed point is
/// the monodromy matrix, whose eigenvalues are the Floquet multipliers. Implementations are
/// immutable and `Sync`, so a map can be shared by threads.
pub trait PeriodMap: Sync {
    /// Dimension `n` of the state.
    fn dim(&self) -> usize;

    /// `P(x; p)`.
    ///
    /// # Errors
    /// Whatever the underlying integration reports (diverging state, invalid parameter).
    fn image(&self, x: &DVector<f64>, parameters: &[f64]) -> Result<DVector<f64>>;

    /// `P(x; p)` and the monodromy `∂P/∂x` (n × n), e.g. from variational equations.
    ///
    /// # Errors
    /// As [`PeriodMap::image`].
    fn image_and_jacobian(
        &self,
        x: &DVector<f64>,
        parameters: &[f64],
    ) -> Result<(DVector<f64>, DMatrix<f64>)>;
}
