//! Floquet multipliers of the full nonlinear model's periodic orbit, from the monodromy of
//! [`periodic_orbit`], and the orbit's stability verdict.

use nalgebra::{Complex, DMatrix, Matrix2};
use paritysim_error::{Error, Result, bail};

use crate::device::{Device, Formulation};

use super::*;

/// Multipliers whose modulus is within this of 1 (or within the monodromy's estimated error,
/// if larger) are reported as marginal.
pub const MARGINAL_TOL: f64 = 1e-5;

/// Stability of a periodic orbit from its Floquet multipliers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OrbitStability {
    /// Every `|ρ| < 1 − tol`, `tol = max(MARGINAL_TOL, monodromy_uncertainty)`.
    Asymptotic,
    /// The largest `|ρ|` is within `tol` of 1 (e.g. a cyclic coordinate).
    Marginal,
    /// Some `|ρ| > 1 + tol`.
    Unstable,
}

/// Floquet analysis of a device's periodic orbit.
#[derive(Clone, Debug, PartialEq)]
pub struct NonlinearFloquet {
    /// The orbit.
    pub orbit: PeriodicOrbit,
    /// Drive cycles per orbit (2: a period-doubled orbit; see [`floquet`]).
    pub orbit_cycles: usize,
    /// Monodromy matrix: Jacobian of the stroboscopic map over `[x (n), ẋ (n)]`.
    pub monodromy: DMatrix<f64>,
    /// Names of the monodromy's rows/columns (`q1, q2, q1_dot, q2_dot` in drivetrain
    /// coordinates, else `x0.., x0_dot..`).
    pub coordinates: Vec<String>,
    /// Floquet multipliers, largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
    /// Multipliers of the `(q2, q̇2)` block (the whippletree mode) for 2-DOF drivetrain
    /// coordinates; exact when the orbit is left-right symmetric (the blocks then decouple, see
    /// [`Self::whippletree_coupling`]).
    pub whippletree: Option<[Complex<f64>; 2]>,
    /// Largest entry of the off-diagonal `(q1, q̇1)`–`(q2, q̇2)` blocks of the monodromy
    /// (zero for a symmetric orbit).
    pub whippletree_coupling: Option<f64>,
    /// Largest entry of `|M − M_check|`: the variational equations' monodromy against the
    /// central-difference Jacobian of the map at `fd_step` (two independent formulations), or,
    /// for a switched device without an analytic Jacobian, the differences at `fd_step`
    /// against those at `2 fd_step`. An error estimate, larger for piecewise-smooth models such
    /// as blade-element aerodynamics.
    pub monodromy_uncertainty: f64,
}

impl NonlinearFloquet {
    /// `max |ρ|`.
    pub fn spectral_radius(&self) -> f64 {
        self.multipliers.first().map_or(0.0, |r| r.norm())
    }

    /// Largest Floquet exponent real part `ln(max|ρ|)/T` (1/ms).
    pub fn max_exponent(&self) -> f64 {
        self.spectral_radius().ln() / self.orbit.period
    }

    /// Unstable through a real multiplier below −1 (a flip: period doubling).
    pub fn flip_unstable(&self) -> bool {
        self.stability() == OrbitStability::Unstable
            && self
                .multipliers
                .first()
                .is_some_and(|r| r.re < 0.0 && r.im.abs() <= self.marginal_tol())
    }

    /// Asymptotically stable, marginal or unstable.
    pub fn stability(&self) -> OrbitStability {
        let r = self.spectral_radius();
        let tol = self.marginal_tol();
        if r < 1.0 - tol {
            OrbitStability::Asymptotic
        } else if r <= 1.0 + tol {
            OrbitStability::Marginal
        } else {
            OrbitStability::Unstable
        }
    }

    /// Half-width of the marginal band around `|ρ| = 1`: `max(MARGINAL_TOL,
    /// monodromy_uncertainty)`.
    pub fn marginal_tol(&self) -> f64 {
        MARGINAL_TOL.max(self.monodromy_uncertainty)
    }

    /// Slowest decay time `T / (−ln|ρ|)` (ms) among the decaying multipliers
    /// (`|ρ| < 1 − marginal_tol`); `None` when none decays.
    pub fn slowest_decay_ms(&self) -> Option<f64> {
        self.multipliers
            .iter()
            .map(|r| r.norm())
            .filter(|&r| r < 1.0 - self.marginal_tol())
            .fold(None, |acc: Option<f64>, r| {
                Some(acc.map_or(r, |a| a.max(r)))
            })
            .map(|r| {
                if r == 0.0 {
                    0.0
                } else {
                    -self.orbit.period / r.ln()
                }
            })
    }

    /// e-folding growth time `T / ln(max|ρ|)` (ms) of an unstable orbit.
    pub fn growth_time_ms(&self) -> Option<f64> {
        let r = self.spectral_radius();
        (r > 1.0 + self.marginal_tol()).then(|| self.orbit.period / r.ln())
    }
}

/// Eigenvalues of a real square matrix, largest modulus first.
///
/// # Errors
/// [`Error::Singular`] when the Schur iteration does not converge or the matrix is not finite.
pub fn eigenvalues(m: &DMatrix<f64>) -> Result<Vec<Complex<f64>>> {
    if m.iter().any(|v| !v.is_finite()) {
        bail!(Singular "monodromy matrix has non-finite entries");
    }
    let schur = nalgebra::Schur::try_new(m.clone(), 1e-15, 100_000).ok_or_else(|| {
        Error::Singular("Schur iteration for the Floquet multipliers did not converge".into())
    })?;
    let mut ev: Vec<Complex<f64>> = schur.complex_eigenvalues().iter().copied().collect();
    ev.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(b.im.total_cmp(&a.im)));
    Ok(ev)
}

fn eig2(m: &Matrix2<f64>) -> [Complex<f64>; 2] {
    multipliers(0.5 * m.trace(), m.determinant())
}

/// Periodic orbit and Floquet multipliers of a driven device (see [`periodic_orbit`]; the
/// monodromy is [`map_jacobian`] at the orbit).
///
/// The orbit covers [`ShootingOptions::orbit_cycles`] drive cycles; without it, one, and two
/// when the one-cycle orbit is flip-unstable (a real multiplier below −1: the device settles
/// on a period-doubled orbit, as `simulate`'s two-cycle shot finds) and the two-cycle orbit
/// is not unstable.
///
/// The monodromy is the variational equations' at the orbit, checked against central
/// differences of the map. A device with switches (blade-element branches) whose variational
/// equations run on a numerical Jacobian (the free-deviation Lift and Dual PARITY) misses the
/// jumps at the switches there (docs/findings.md §30), so its monodromy is the central
/// differences of the map (which re-locate the switches), checked against differences at
/// twice the step.
///
/// # Errors
/// Those of [`periodic_orbit`]; [`Error::Singular`] for a non-finite monodromy.
pub fn floquet(device: &Device, options: &ShootingOptions) -> Result<NonlinearFloquet> {
    let cycles = options.orbit_cycles.unwrap_or(1);
    let one = floquet_over(device, options, cycles)?;
    if options.orbit_cycles.is_none() && one.flip_unstable() {
        match floquet_over(device, options, 2) {
            Ok(two) if two.stability() != OrbitStability::Unstable => return Ok(two),
            Err(Error::Cancelled) => return Err(Error::Cancelled),
            _ => {}
        }
    }
    Ok(one)
}

/// [`floquet`] of the orbit of `cycles` drive cycles.
fn floquet_over(
    device: &Device,
    options: &ShootingOptions,
    cycles: usize,
) -> Result<NonlinearFloquet> {
    let options = ShootingOptions {
        orbit_cycles: Some(cycles),
        ..options.clone()
    };
    let orbit = periodic_orbit(device, &options)?;
    let integrator = options.validate(drive_period(device)?)?;
    let n = device.n_dof();
    let switched_without_jacobian =
        crate::integrate::OdeSystem::n_switches(device) > 0 && !device.has_analytic_jacobian();
    // The monodromy from the variational equations (exact derivative of the computed map);
    // its uncertainty from the independent central-difference Jacobian of the map.
    let variational = || -> Result<DMatrix<f64>> {
        if let Some(m) = orbit
            .monodromy
            .as_ref()
            .filter(|_| orbit.monodromy_offset == 0.0)
        {
            return Ok(m.clone());
        }
        integrator
            .with_work(false)
            .flow_with_sensitivity(device, orbit.t0, &orbit.state, orbit.t0 + orbit.period)
            .map(|(_, m)| m)
    };
    let differences = |step: f64| {
        map_jacobian(
            device,
            n,
            &integrator,
            orbit.t0,
            orbit.period,
            &orbit.state,
            step,
        )
    };
    // The monodromy and its check, in parallel on the sweep engine's pool under the caller's
    // budget.
    let mut parts = super::rows::run_parts(2, |i| match (i, switched_without_jacobian) {
        (0, false) => variational(),
        (0, true) | (1, false) => differences(options.fd_step),
        _ => differences(2.0 * options.fd_step),
    })?;
    let coarse = parts.pop().expect("two parts");
    let monodromy = parts.pop().expect("two parts");
    let monodromy_uncertainty = (&monodromy - coarse).amax();
    let multipliers = eigenvalues(&monodromy)?;
    let drivetrain_coords = device.formulation() == Formulation::DrivetrainCoordinates;
    let coordinates: Vec<String> = (0..n)
        .map(|i| {
            if drivetrain_coords {
                format!("q{}", i + 1)
            } else {
                format!("x{i}")
            }
        })
        .chain((0..n).map(|i| {
            if drivetrain_coords {
                format!("q{}_dot", i + 1)
            } else {
                format!("x{i}_dot")
            }
        }))
        .collect();
    let (whippletree, whippletree_coupling) = if drivetrain_coords && n == 2 && !device.is_dual() {
        let block = Matrix2::new(
            monodromy[(1, 1)],
            monodromy[(1, 3)],
            monodromy[(3, 1)],
            monodromy[(3, 3)],
        );
        let coupling = [
            (0, 1),
            (0, 3),
            (2, 1),
            (2, 3),
            (1, 0),
            (1, 2),
            (3, 0),
            (3, 2),
        ]
        .iter()
        .map(|&(i, j)| monodromy[(i, j)].abs())
        .fold(0.0, f64::max);
        (Some(eig2(&block)), Some(coupling))
    } else {
        (None, None)
    };
    Ok(NonlinearFloquet {
        orbit,
        orbit_cycles: cycles,
        monodromy,
        coordinates,
        multipliers,
        whippletree,
        whippletree_coupling,
        monodromy_uncertainty,
    })
}
