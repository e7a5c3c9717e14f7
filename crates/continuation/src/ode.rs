//! A period map for small forced ODEs: classical Runge–Kutta on the state and its variational
//! equations `Φ' = ∂f/∂x · Φ`, so the monodromy is exact to the integrator's order.

use nalgebra::{DMatrix, DVector};
use paritysim_error::{Error, Result};

use crate::map::PeriodMap;

/// `x' = f(t, x; p)`, periodic in `t` with period [`ForcedOde::period`].
pub trait ForcedOde: Sync {
    /// Dimension of the state.
    fn dim(&self) -> usize;
    /// The forcing period for parameters `p` (must be finite and > 0).
    fn period(&self, parameters: &[f64]) -> f64;
    /// Writes `f(t, x; p)` into `dx`.
    fn rhs(&self, t: f64, x: &[f64], parameters: &[f64], dx: &mut [f64]);
    /// Writes `∂f/∂x` at `(t, x; p)` into `jacobian` (n × n).
    fn jacobian(&self, t: f64, x: &[f64], parameters: &[f64], jacobian: &mut DMatrix<f64>);
}

/// The period map of a [`ForcedOde`] by fixed-step RK4 with `steps` steps per period.
#[derive(Clone, Debug)]
pub struct RungeKuttaMap<O> {
    ode: O,
    steps: usize,
}

impl<O: ForcedOde> RungeKuttaMap<O> {
    /// # Errors
    /// [`Error::InvalidParameter`] unless `16 <= steps <= 10_000_000`.
    pub fn new(ode: O, steps: usize) -> Result<Self> {
        if !(16..=10_000_000).contains(&steps) {
            return Err(Error::invalid("steps", steps, "in [16, 10000000]"));
        }
        Ok(RungeKuttaMap { ode, steps })
    }

    /// The system.
    pub fn ode(&self) -> &O {
        &self.ode
    }

    fn step_size(&self, parameters: &[f64]) -> Result<f64> {
        let period = self.ode.period(parameters);
        if !(period.is_finite() && period > 0.0) {
            return Err(Error::invalid(
                "period",
                period,
                "finite and > 0 (check the drive frequency)",
            ));
        }
        Ok(period / self.steps as f64)
    }

    /// Integrates `(x, Φ)` over one period; `with_jacobian = false` skips `Φ`.
    fn flow(
        &self,
        x: &DVector<f64>,
        parameters: &[f64],
        with_jacobian: bool,
    ) -> Result<(DVector<f64>, DMatrix<f64>)> {
        let n = self.ode.dim();
        if x.len() != n {
            return Err(Error::Shape(format!(
                "state has {} entries, the system has {n}",
                x.len()
            )));
        }
        let h = self.step_size(parameters)?;
        let mut y = x.clone();
        let mut phi = if with_jacobian {
            DMatrix::identity(n, n)
        } else {
            DMatrix::zeros(0, 0)
        };
        let (mut k1, mut k2, mut k3, mut k4) = (
            DVector::zeros(n),
            DVector::zeros(n),
            DVector::zeros(n),
            DVector::zeros(n),
        );
        let mut tmp = DVector::zeros(n);
        let mut jac = DMatrix::zeros(n, n);
        for step in 0..self.steps {
            let t = step as f64 * h;
            // Variational stages use the state at the same stage points as the state itself.
            let mut stage =
                |t: f64, y: &DVector<f64>, k: &mut DVector<f64>| -> Option<DMatrix<f64>> {
                    self.ode.rhs(t, y.as_slice(), parameters, k.as_mut_slice());
                    if with_jacobian {
                        self.ode.jacobian(t, y.as_slice(), parameters, &mut jac);
                        Some(jac.clone())
                    } else {
                        None
                    }
                };
            let j1 = stage(t, &y, &mut k1);
            tmp.copy_from(&y);
            tmp.axpy(0.5 * h, &k1, 1.0);
            let j2 = stage(t + 0.5 * h, &tmp, &mut k2);
            tmp.copy_from(&y);
            tmp.axpy(0.5 * h, &k2, 1.0);
            let j3 = stage(t + 0.5 * h, &tmp, &mut k3);
            tmp.copy_from(&y);
            tmp.axpy(h, &k3, 1.0);
            let j4 = stage(t + h, &tmp, &mut k4);
            if let (Some(j1), Some(j2), Some(j3), Some(j4)) = (j1, j2, j3, j4) {
                let p1 = &j1 * &phi;
                let p2 = &j2 * (&phi + &p1 * (0.5 * h));
                let p3 = &j3 * (&phi + &p2 * (0.5 * h));
                let p4 = &j4 * (&phi + &p3 * h);
                phi += (p1 + p2 * 2.0 + p3 * 2.0 + p4) * (h / 6.0);
            }
            y += (&k1 + &k2 * 2.0 + &k3 * 2.0 + &k4) * (h / 6.0);
            if !y.iter().all(|v| v.is_finite()) {
                return Err(Error::Integration {
                    time: t + h,
                    state: y.as_slice().to_vec(),
                    reason: "non-finite state".into(),
                });
            }
        }
        Ok((y, phi))
    }
}

impl<O: ForcedOde> PeriodMap for RungeKuttaMap<O> {
    fn dim(&self) -> usize {
        self.ode.dim()
    }

    fn image(&self, x: &DVector<f64>, parameters: &[f64]) -> Result<DVector<f64>> {
        Ok(self.flow(x, parameters, false)?.0)
    }

    fn image_and_jacobian(
        &self,
        x: &DVector<f64>,
        parameters: &[f64],
    ) -> Result<(DVector<f64>, DMatrix<f64>)> {
        self.flow(x, parameters, true)
    }
}
