//! Forward sensitivities: the flow map and its Jacobian `Φ = ∂y(t1)/∂y(t0)` (over one drive
//! period: the monodromy matrix) by integrating the variational equations `Φ̇ = J(t, y) Φ`
//! alongside the state, on the same steps.
//!
//! `J Φ` comes from the system's analytic Jacobian when it has one
//! ([`OdeSystem::variational`]: the linear-map drivetrain coordinates); otherwise it is formed
//! column by column by central differences of the right-hand side along each column
//! (`J v ≈ (f(y + δv) − f(y − δv)) / 2δ`, `δ` scaled to `y` and `v`: two more evaluations per
//! column and stage). The step size is chosen by the state alone (the sensitivities do not
//! take part in the error control).

use nalgebra::DMatrix;
use paritysim_error::Result;

use super::{
    MAX_SWITCHES, OdeSystem, Rhs, RungeKutta, Sides, Sink, State, Tolerances, check_grid,
    drive_method, drive_method_on_grid, integration_error,
};

/// Relative size of the directional difference step.
pub(crate) const DIRECTIONAL_STEP: f64 = 1e-6;

struct Variational<'a> {
    system: &'a dyn OdeSystem,
    n: usize,
    calls: usize,
    /// The branch held by event location (switches of the state part; None on fixed grids).
    sides: Option<Sides>,
    /// The active coordinates (the first `n_real` of the `n` coordinates and of the rates).
    n_real: usize,
    /// `Φ`'s active block (column-major, `2 n_real` square) at each sample handed to the sink,
    /// when recorded.
    sampled_phi: Option<Vec<f64>>,
}

fn to_state(n: usize, c: &[f64]) -> State {
    let mut y = State::default();
    y.coords[..n].copy_from_slice(&c[..n]);
    y.rates[..n].copy_from_slice(&c[n..2 * n]);
    y
}

impl Variational<'_> {
    fn f(&mut self, t: f64, y: &State, out: &mut [f64]) -> Result<()> {
        self.calls += 1;
        let mut d = State::default();
        let evaluated = match self.sides {
            None => self.system.rhs(t, y, &mut d),
            Some(sides) => self.system.rhs_on(t, y, sides, &mut d),
        };
        if let Err(e) = evaluated {
            return Err(integration_error(t, y, format!("the model failed: {e}")));
        }
        let n = self.n;
        out[..n].copy_from_slice(&d.coords[..n]);
        out[n..2 * n].copy_from_slice(&d.rates[..n]);
        Ok(())
    }
}

/// The central differences' step along column `j` of `Φ` (in `c` after the `m` state
/// entries) and the two perturbed states `y ± δ v`; `None` for a zero column.
fn perturbation<const M: usize>(
    c: &[f64; M],
    m: usize,
    j: usize,
    scale: f64,
) -> Option<(f64, [f64; 12], [f64; 12])> {
    let col = m + j * m;
    let v = &c[col..col + m];
    let size = v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    if size == 0.0 {
        return None;
    }
    let delta = DIRECTIONAL_STEP * scale / size;
    let (mut yp, mut ym) = ([0.0; 12], [0.0; 12]);
    for i in 0..m {
        yp[i] = c[i] + delta * v[i];
        ym[i] = c[i] - delta * v[i];
    }
    Some((delta, yp, ym))
}

impl Variational<'_> {
    /// The central differences of [`Rhs::eval`] with the `2n` perturbed right-hand sides of
    /// each column evaluated together ([`OdeSystem::rhs_on_batch`]: the same bits, so the
    /// same sensitivities); `false` when the system has no batch form (nothing written).
    fn batched_differences<const M: usize>(
        &mut self,
        t: f64,
        sides: Sides,
        c: &[f64; M],
        dc: &mut [f64; M],
        scale: f64,
    ) -> Result<bool> {
        let m = 2 * self.n;
        let mut states = [State::default(); 24];
        let mut deltas = [0.0; 12];
        let mut columns = [0usize; 12];
        let mut count = 0;
        for j in 0..m {
            let Some((delta, yp, ym)) = perturbation(c, m, j, scale) else {
                continue;
            };
            states[2 * count] = to_state(self.n, &yp[..m]);
            states[2 * count + 1] = to_state(self.n, &ym[..m]);
            (deltas[count], columns[count]) = (delta, j);
            count += 1;
        }
        let mut out = [State::default(); 24];
        let Some(done) =
            self.system
                .rhs_on_batch(t, sides, &states[..2 * count], &mut out[..2 * count])
        else {
            return Ok(false);
        };
        self.calls += 2 * count;
        if let Err((k, e)) = done {
            return Err(integration_error(
                t,
                &states[k],
                format!("the model failed: {e}"),
            ));
        }
        for j in 0..m {
            let col = m + j * m;
            dc[col..col + m].fill(0.0);
        }
        for k in 0..count {
            let (col, delta) = (m + columns[k] * m, deltas[k]);
            let (fp, fm) = (&out[2 * k], &out[2 * k + 1]);
            let n = self.n;
            for i in 0..m {
                let (p, q) = if i < n {
                    (fp.coords[i], fm.coords[i])
                } else {
                    (fp.rates[i - n], fm.rates[i - n])
                };
                dc[col + i] = (p - q) / (2.0 * delta);
            }
        }
        Ok(true)
    }
}

impl<const M: usize> Rhs<M> for Variational<'_> {
    fn observe_sample(&mut self, c: &[f64; M]) {
        let m = 2 * self.n;
        if let Some(sampled) = &mut self.sampled_phi {
            push_active_block(&c[m..m + m * m], self.n, self.n_real, sampled);
        }
    }

    fn eval(&mut self, t: f64, c: &[f64; M], dc: &mut [f64; M]) -> Result<()> {
        let m = 2 * self.n;
        let y = to_state(self.n, &c[..m]);
        let (f, rest) = dc.split_at_mut(m);
        let (phi, dphi) = (&c[m..m + m * m], &mut rest[..m * m]);
        if let Some(done) = self
            .system
            .variational_with_rhs(t, &y, self.sides, self.n, f, phi, dphi)
        {
            self.calls += 1;
            return done.map_err(|e| integration_error(t, &y, format!("the model failed: {e}")));
        }
        self.f(t, &y, &mut dc[..m])?;
        let (phi, dphi) = (&c[m..m + m * m], &mut dc[m..m + m * m]);
        if let Some(done) = self.system.variational(t, &y, self.n, phi, dphi) {
            return done.map_err(|e| integration_error(t, &y, format!("the model failed: {e}")));
        }
        let scale = 1.0 + c[..m].iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if let Some(sides) = self.sides {
            if self.batched_differences(t, sides, c, dc, scale)? {
                return Ok(());
            }
        }
        let (mut fp, mut fm) = ([0.0; 12], [0.0; 12]);
        for j in 0..m {
            let col = m + j * m;
            let Some((delta, yp, ym)) = perturbation(c, m, j, scale) else {
                dc[col..col + m].fill(0.0);
                continue;
            };
            self.f(t, &to_state(self.n, &yp[..m]), &mut fp[..m])?;
            self.f(t, &to_state(self.n, &ym[..m]), &mut fm[..m])?;
            for i in 0..m {
                dc[col + i] = (fp[i] - fm[i]) / (2.0 * delta);
            }
        }
        Ok(())
    }

    fn expand(&self, c: &[f64; M]) -> State {
        to_state(self.n, &c[..2 * self.n])
    }

    fn n_switches(&self) -> usize {
        self.system.n_switches().min(MAX_SWITCHES)
    }

    fn switches(&mut self, t: f64, c: &[f64; M], g: &mut [f64; MAX_SWITCHES]) -> Result<()> {
        let y = to_state(self.n, &c[..2 * self.n]);
        self.system
            .switches(t, &y, g)
            .map_err(|e| integration_error(t, &y, format!("the model failed: {e}")))
    }

    fn set_sides(&mut self, sides: Sides) {
        self.sides = Some(sides);
    }
}

impl RungeKutta {
    /// The state at `t1` from `(t0, y0)` (work integrals left at zero) and the sensitivity
    /// matrix `∂y(t1)/∂y(t0)` over the `2n` integrated entries `[coords (n), rates (n)]`,
    /// `n = system.n_active()`.
    ///
    /// # Errors
    /// As [`super::Integrator::integrate_with`].
    pub fn flow_with_sensitivity(
        &self,
        system: &dyn OdeSystem,
        t0: f64,
        y0: &State,
        t1: f64,
    ) -> Result<(State, DMatrix<f64>)> {
        if t1.is_nan() || t1 <= t0 {
            return Err(paritysim_error::Error::invalid(
                "t_end",
                t1,
                format!("> t0 = {t0}"),
            ));
        }
        let sink = &mut |_: usize, _: f64, _: &State| Ok(());
        self.sensitivity_any(system, t0, y0, t1, None, Along { times: &[], sink })
            .map(|(y, phi, _, _)| (y, phi))
    }

    /// [`Self::flow_with_sensitivity`] that also returns the accepted step times (from `t0`
    /// to `t1`): the grid on which [`RungeKutta::integrate_on_grid`] retraces the same map.
    ///
    /// # Errors
    /// As [`Self::flow_with_sensitivity`].
    pub fn flow_with_sensitivity_and_steps(
        &self,
        system: &dyn OdeSystem,
        t0: f64,
        y0: &State,
        t1: f64,
    ) -> Result<(State, DMatrix<f64>, Vec<f64>)> {
        if t1.is_nan() || t1 <= t0 {
            return Err(paritysim_error::Error::invalid(
                "t_end",
                t1,
                format!("> t0 = {t0}"),
            ));
        }
        let sink = &mut |_: usize, _: f64, _: &State| Ok(());
        self.sensitivity_any(system, t0, y0, t1, None, Along { times: &[], sink })
            .map(|(y, phi, steps, _)| (y, phi, steps))
    }

    /// The flow and its sensitivity on the fixed steps of `grid` (see
    /// [`RungeKutta::integrate_on_grid`]): the exact derivative of that map.
    ///
    /// # Errors
    /// [`paritysim_error::Error::InvalidParameter`] for a bad grid; integration errors.
    pub fn flow_with_sensitivity_on_grid(
        &self,
        system: &dyn OdeSystem,
        grid: &[f64],
        y0: &State,
    ) -> Result<(State, DMatrix<f64>)> {
        self.flow_with_sensitivity_on_grid_sampled(system, grid, y0, &[], &mut |_, _, _| Ok(()))
            .map(|(y, phi, _)| (y, phi))
    }

    /// [`Self::flow_with_sensitivity_on_grid`] sampled at `times` (within the grid): each
    /// sample's state goes to `sink`, and its `Φ(t, grid[0])` (the active rows and columns, as
    /// the monodromy; column-major) is returned, one block after another.
    ///
    /// # Errors
    /// As [`Self::flow_with_sensitivity_on_grid`]; whatever `sink` returns.
    pub(crate) fn flow_with_sensitivity_on_grid_sampled(
        &self,
        system: &dyn OdeSystem,
        grid: &[f64],
        y0: &State,
        times: &[f64],
        sink: &mut Sink<'_>,
    ) -> Result<(State, DMatrix<f64>, Vec<f64>)> {
        check_grid(grid)?;
        let (t0, t1) = (grid[0], grid[grid.len() - 1]);
        let along = Along { times, sink };
        self.sensitivity_any(system, t0, y0, t1, Some(grid), along)
            .map(|(y, phi, _, sampled)| (y, phi, sampled))
    }

    fn sensitivity_any(
        &self,
        system: &dyn OdeSystem,
        t0: f64,
        y0: &State,
        t1: f64,
        grid: Option<&[f64]>,
        along: Along<'_, '_>,
    ) -> Result<Sensitivities> {
        let n_real = system.n_active().clamp(1, 6);
        match n_real {
            1..=2 => self.sensitivity::<20>(system, 2, n_real, (t0, y0, t1), grid, along),
            3..=4 => self.sensitivity::<72>(system, 4, n_real, (t0, y0, t1), grid, along),
            _ => self.sensitivity::<156>(system, 6, n_real, (t0, y0, t1), grid, along),
        }
    }

    fn sensitivity<const M: usize>(
        &self,
        system: &dyn OdeSystem,
        n: usize,
        n_real: usize,
        (t0, y0, t1): (f64, &State, f64),
        grid: Option<&[f64]>,
        along: Along<'_, '_>,
    ) -> Result<Sensitivities> {
        let m = 2 * n;
        debug_assert_eq!(M, m + m * m);
        let mut c0 = [0.0; M];
        c0[..n].copy_from_slice(&y0.coords[..n]);
        c0[n..m].copy_from_slice(&y0.rates[..n]);
        for j in 0..m {
            c0[m + j * m + j] = 1.0;
        }
        let mut rhs = Variational {
            system,
            n,
            calls: 0,
            sides: None,
            n_real,
            sampled_phi: (!along.times.is_empty())
                .then(|| Vec::with_capacity(along.times.len() * 4 * n_real * n_real)),
        };
        let tol = Tolerances {
            rtol: self.rtol,
            atol: self.atol,
            controlled: m,
        };
        let mut steps = vec![t0];
        let (c, _) = match grid {
            None => drive_method(
                self.method,
                &mut rhs,
                &tol,
                self.max_steps,
                t0,
                c0,
                t1,
                along.times,
                along.sink,
                &mut |t, _| steps.push(t),
            )?,
            Some(grid) => drive_method_on_grid(
                self.method,
                &mut rhs,
                &tol,
                grid,
                c0,
                along.times,
                along.sink,
            )?,
        };
        let mut monodromy = Vec::with_capacity(4 * n_real * n_real);
        push_active_block(&c[m..m + m * m], n, n_real, &mut monodromy);
        let monodromy = DMatrix::from_vec(2 * n_real, 2 * n_real, monodromy);
        let sampled = rhs.sampled_phi.unwrap_or_default();
        Ok((to_state(n, &c[..m]), monodromy, steps, sampled))
    }
}

/// Appends the active block of `full` (a `2n`-square `Φ`, column-major) to `out`, column-major:
/// the rows and columns of the coordinates `0..n_real` and of the rates `n..n + n_real`.
fn push_active_block(full: &[f64], n: usize, n_real: usize, out: &mut Vec<f64>) {
    let m = 2 * n;
    if n_real == n {
        out.extend_from_slice(&full[..m * m]);
        return;
    }
    let index = |k: usize| if k < n_real { k } else { n + k - n_real };
    for j in 0..2 * n_real {
        let column = &full[index(j) * m..];
        out.extend((0..2 * n_real).map(|i| column[index(i)]));
    }
}

/// The flow, its sensitivity, the accepted step times and `Φ` at the samples (the active
/// blocks, column-major, one after another).
type Sensitivities = (State, DMatrix<f64>, Vec<f64>, Vec<f64>);

/// The samples a sensitivity run hands out: their times and the sink of their states.
struct Along<'a, 's> {
    times: &'a [f64],
    sink: &'a mut Sink<'s>,
}

#[cfg(test)]
mod tests {
    use super::super::Method;
    use super::*;

    /// Damped Mathieu-like oscillator `ẍ + c ẋ + (a + b cos t) x = 0` (linear: the flow *is*
    /// the sensitivity applied to y0).
    struct Mathieu(f64, f64, f64);

    impl OdeSystem for Mathieu {
        fn rhs(&self, t: f64, y: &State, d: &mut State) -> Result<()> {
            d.coords[0] = y.rates[0];
            d.rates[0] = -self.0 * y.rates[0] - (self.1 + self.2 * t.cos()) * y.coords[0];
            Ok(())
        }
        fn n_active(&self) -> usize {
            1
        }
    }

    #[test]
    fn linear_flow_equals_its_sensitivity_and_liouville_holds() {
        let (c, a, b) = (0.3, 1.7, 0.8);
        let rk = RungeKutta::new(Method::Dop853, 1e-11, 1e-13, 100_000).unwrap();
        let mut y0 = State::default();
        y0.coords[0] = 0.4;
        y0.rates[0] = -1.1;
        let period = std::f64::consts::TAU;
        let (y1, phi) = rk
            .flow_with_sensitivity(&Mathieu(c, a, b), 0.0, &y0, period)
            .unwrap();
        assert_eq!(phi.shape(), (2, 2));
        let lin = &phi * nalgebra::DVector::from_vec(vec![0.4, -1.1]);
        assert!((lin[0] - y1.coords[0]).abs() < 1e-9);
        assert!((lin[1] - y1.rates[0]).abs() < 1e-9);
        // Liouville: det Φ(T) = exp(−c T).
        assert!((phi.determinant() - (-c * period).exp()).abs() < 1e-9);
    }

    /// Sampled on a grid, a linear flow's states are `Φ(t) y0` at every sample, the states are
    /// the plain run's, and the first and last `Φ` are the identity and the monodromy.
    #[test]
    fn sampled_sensitivities_carry_each_samples_phi() {
        let system = Mathieu(0.3, 1.7, 0.8);
        let rk = RungeKutta::new(Method::Dop853, 1e-10, 1e-12, 100_000).unwrap();
        let period = std::f64::consts::TAU;
        let (_, _, grid) = rk
            .flow_with_sensitivity_and_steps(&system, 0.0, &State::default(), period)
            .unwrap();
        let mut y0 = State::default();
        y0.coords[0] = 0.4;
        y0.rates[0] = -1.1;
        let times: Vec<f64> = (0..=40).map(|k| period * f64::from(k) / 40.0).collect();
        let mut states = Vec::new();
        let (_, monodromy, phis) = rk
            .flow_with_sensitivity_on_grid_sampled(&system, &grid, &y0, &times, &mut |_, _, y| {
                states.push(*y);
                Ok(())
            })
            .unwrap();
        let mut plain = Vec::new();
        rk.integrate_on_grid(&system, &grid, &y0, &times, &mut |_, _, y| {
            plain.push(*y);
            Ok(())
        })
        .unwrap();
        let phis: Vec<DMatrix<f64>> = phis
            .chunks_exact(4)
            .map(|phi| DMatrix::from_column_slice(2, 2, phi))
            .collect();
        assert_eq!((phis.len(), states.len(), plain.len()), (41, 41, 41));
        let start = nalgebra::DVector::from_vec(vec![0.4, -1.1]);
        for ((phi, y), p) in phis.iter().zip(&states).zip(&plain) {
            let lin = phi * &start;
            // Φ from central differences of the right-hand side: exact for a linear one up to
            // rounding over the difference step (measured: up to 1.2e-8 here).
            let off = (lin[0] - y.coords[0])
                .abs()
                .max((lin[1] - y.rates[0]).abs());
            assert!(off < 1e-7, "{off:e}");
            assert!((y.coords[0] - p.coords[0]).abs() < 1e-12);
        }
        assert_eq!(phis[0], DMatrix::identity(2, 2));
        assert_eq!(phis[40], monodromy);
    }
}
