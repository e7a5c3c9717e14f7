//! The continuation's equations on the periodic orbits of a period map.

use nalgebra::{DMatrix, DVector};
use paritysim_error::Result;

use crate::map::PeriodMap;
use crate::multipliers::{multipliers, stability};
use crate::points::BranchPoint;
use crate::system::{Corrected, Evaluation, System};

/// `G(x, drift, λ̂) = P(x; λ) − x − drift·e_c` over `u = (x without x_c, [drift], λ̂)`.
pub(crate) struct OrbitSystem<'a, M: PeriodMap> {
    pub map: &'a M,
    pub parameters: Vec<f64>,
    pub index: usize,
    pub scale: f64,
    pub cyclic: Option<(usize, f64)>, // (coordinate, its pinned value)
    pub fd_step: f64,
    pub evaluations: std::cell::Cell<usize>,
}

impl<M: PeriodMap> OrbitSystem<'_, M> {
    pub fn n(&self) -> usize {
        self.map.dim()
    }

    /// `(x, drift, λ)` from `u`.
    pub fn unpack(&self, u: &DVector<f64>) -> (DVector<f64>, f64, f64) {
        let n = self.n();
        let lambda = u[n] * self.scale;
        match self.cyclic {
            None => (u.rows(0, n).into_owned(), 0.0, lambda),
            Some((c, pinned)) => {
                let mut x = DVector::zeros(n);
                let mut k = 0;
                for i in 0..n {
                    if i == c {
                        x[i] = pinned;
                    } else {
                        x[i] = u[k];
                        k += 1;
                    }
                }
                (x, u[n - 1], lambda)
            }
        }
    }

    pub fn pack(&self, x: &DVector<f64>, drift: f64, lambda: f64) -> DVector<f64> {
        let n = self.n();
        let mut u = DVector::zeros(n + 1);
        match self.cyclic {
            None => u.rows_mut(0, n).copy_from(x),
            Some((c, _)) => {
                for (k, i) in (0..n).filter(|&i| i != c).enumerate() {
                    u[k] = x[i];
                }
                u[n - 1] = drift;
            }
        }
        u[n] = lambda / self.scale;
        u
    }

    fn with(&self, lambda: f64) -> Vec<f64> {
        let mut p = self.parameters.clone();
        p[self.index] = lambda;
        p
    }

    pub fn point(&self, corrected: &Corrected, tol: f64, arclength: f64) -> BranchPoint {
        let (state, drift, parameter) = self.unpack(&corrected.u);
        let mu = corrected
            .evaluation
            .monodromy
            .as_ref()
            .map(|m| multipliers(m, self.cyclic.is_some()))
            .unwrap_or_default();
        BranchPoint {
            parameter,
            state,
            drift,
            stability: stability(&mu, tol),
            multipliers: mu,
            iterations: corrected.iterations,
            residual: corrected.evaluation.residual.amax(),
            arclength,
        }
    }
}

impl<M: PeriodMap> System for OrbitSystem<'_, M> {
    fn equations(&self) -> usize {
        self.n()
    }

    fn evaluate(&self, u: &DVector<f64>) -> Result<Evaluation> {
        let n = self.n();
        let (x, drift, lambda) = self.unpack(u);
        let (image, monodromy) = self.map.image_and_jacobian(&x, &self.with(lambda))?;
        let eps = self.fd_step * lambda.abs().max(self.scale);
        let up = self.map.image(&x, &self.with(lambda + eps))?;
        let down = self.map.image(&x, &self.with(lambda - eps))?;
        self.evaluations.set(self.evaluations.get() + 1);
        let mut residual = &image - &x;
        let mut jacobian = DMatrix::zeros(n, n + 1);
        let shifted = &monodromy - DMatrix::identity(n, n);
        match self.cyclic {
            None => jacobian.view_mut((0, 0), (n, n)).copy_from(&shifted),
            Some((c, _)) => {
                residual[c] -= drift;
                for (k, i) in (0..n).filter(|&i| i != c).enumerate() {
                    jacobian.set_column(k, &shifted.column(i));
                }
                jacobian[(c, n - 1)] = -1.0;
            }
        }
        jacobian.set_column(n, &((up - down) * (self.scale / (2.0 * eps))));
        Ok(Evaluation {
            residual,
            jacobian,
            monodromy: Some(monodromy),
        })
    }
}
