//! Disturbance sweeps and §2.7 on the full model: K2 sweeps of the Floquet analysis, the
//! device's linearisation onto eq. 2.59, and the nonlinear disturbance response (a roll torque
//! injected on the wings).

use std::f64::consts::PI;

use nalgebra::{Complex, Matrix2, Vector2};
use paritysim_error::{Error, Result, bail, check_finite, check_positive};

use crate::device::{Device, DeviceSpec, Formulation, Transmission};
use crate::integrate::{Integrator, Method, OdeSystem, RungeKutta, State};

use super::*;

/// A device spec with its balance-beam stiffness K2 replaced.
///
/// # Errors
/// [`Error::Constraint`] without a drivetrain; [`Error::InvalidParameter`] for a bad K2.
pub fn with_balance_spring(spec: &DeviceSpec, k2: f64) -> Result<DeviceSpec> {
    let Some(tr) = &spec.transmission else {
        bail!(Constraint "a K2 sweep needs a drivetrain");
    };
    let mut out = spec.clone();
    out.transmission = Some(Transmission::new(*tr.kinematics(), k2)?);
    Ok(out)
}

/// [`floquet`] for each balance-beam stiffness K2 in `k2` (mN·mm/rad), one row each, on the
/// sweep engine's pool ([`super::rows`]).
///
/// # Errors
/// A failing stiffness (an invalid K2, no orbit) is its row's error, located as `k2[i]`; the
/// call itself fails only when cancelled ([`Error::Cancelled`]) or for a bad thread count.
pub fn balance_spring_sweep(
    spec: &DeviceSpec,
    k2: &[f64],
    options: &ShootingOptions,
) -> Result<Rows<NonlinearFloquet>> {
    super::rows::run_rows(k2.len(), None, Some("k2"), |i| {
        let device = Device::new(with_balance_spring(spec, k2[i])?)?;
        floquet(&device, options)
    })
}

/// What a stroke-only (fixed-wing) device needs for §2.7.
struct StrokeDevice<'a> {
    device: &'a Device,
    inertia: [f64; 2],
    n_wings: usize,
}

impl<'a> StrokeDevice<'a> {
    fn new(device: &'a Device) -> Result<Self> {
        if device.formulation() != Formulation::DrivetrainCoordinates {
            bail!(Constraint
                "the §2.7 analysis needs a fixed-wing device integrated in drivetrain coordinates \
                 (a *_fixed configuration with a drivetrain; see Formulation::DrivetrainCoordinates)");
        }
        let wings = &device.spec().wings;
        let mut inertia = [0.0; 2];
        for (k, w) in wings.iter().enumerate() {
            inertia[k] = w.inertia()[(0, 0)];
        }
        Ok(Self {
            device,
            inertia,
            n_wings: wings.len(),
        })
    }

    fn transmission(&self) -> &Transmission {
        self.device
            .spec()
            .transmission
            .as_ref()
            .expect("drivetrain-coordinate devices have a drivetrain")
    }
}

/// A sinusoidal roll disturbance torque `d(t) = amplitude · sin(2π f t)` on the wings of a
/// fixed-wing device, split as stroke torques `(−d/2, +d/2)` on `(φL, φR)`: in body roll (the
/// left wing's frame is mirrored, see [`mod@crate::simulate`]) both halves add up to `d`. Wraps the
/// device's right-hand side: `q̈ += M_q⁻¹ Jᵀ τ_d` with `M_q = Σ_k I_k J_kᵀ J_k`.
pub struct RollDisturbance<'a> {
    stroke: StrokeDevice<'a>,
    amplitude: f64,
    omega: f64,
}

impl<'a> RollDisturbance<'a> {
    /// `amplitude` (mN·mm) and `frequency_hz` (> 0).
    ///
    /// # Errors
    /// [`Error::Constraint`] unless the device uses drivetrain coordinates;
    /// [`Error::InvalidParameter`] for a non-finite amplitude or non-positive frequency.
    pub fn new(device: &'a Device, amplitude: f64, frequency_hz: f64) -> Result<Self> {
        check_finite("amplitude", amplitude)?;
        check_positive("frequency_hz", frequency_hz)?;
        Ok(Self {
            stroke: StrokeDevice::new(device)?,
            amplitude,
            omega: 2.0 * PI * frequency_hz * 1e-3,
        })
    }

    /// `d(t)` (mN·mm).
    pub fn torque(&self, t: f64) -> f64 {
        self.amplitude * (self.omega * t).sin()
    }

    /// Disturbance stroke torques on `(φL, φR)` (one wing: the whole torque on it).
    fn stroke_torques(&self, t: f64) -> Vector2<f64> {
        let d = self.torque(t);
        if self.stroke.n_wings == 2 {
            Vector2::new(-0.5 * d, 0.5 * d)
        } else {
            Vector2::new(d, 0.0)
        }
    }

    /// Body roll torque (mN·mm) at an integrator state: `Σ_k m_k (τ_aero,k − I_k φ̈_k + d_k)`
    /// with `m = (−1, +1)` (left mirrored), the wings' momentum balance.
    pub fn body_roll(&self, t: f64, y: &State) -> Result<f64> {
        let mut dydt = State::default();
        self.rhs(t, y, &mut dydt)?;
        let dt = self.stroke.transmission().kinematics();
        let two = self.stroke.device.n_dof() == 2;
        let q_dot = Vector2::new(y.rates[0], if two { y.rates[1] } else { 0.0 });
        let q_ddot = Vector2::new(dydt.rates[0], if two { dydt.rates[1] } else { 0.0 });
        let e = dt.evaluate(y.coords[0], if two { y.coords[1] } else { 0.0 })?;
        let phi_dot = e.jacobian * q_dot;
        let phi_ddot = e.jacobian * q_ddot + e.velocity_product(&q_dot);
        let d = self.stroke_torques(t);
        let wings = &self.stroke.device.spec().wings;
        let mut roll = 0.0;
        for k in 0..self.stroke.n_wings {
            let mirror = if self.stroke.n_wings == 2 && k == 0 {
                -1.0
            } else {
                1.0
            };
            let aero = wings[k].aero().stroke_torque(phi_dot[k]);
            roll += mirror * (aero - self.stroke.inertia[k] * phi_ddot[k] + d[k]);
        }
        Ok(roll)
    }
}

impl OdeSystem for RollDisturbance<'_> {
    fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> Result<()> {
        let device = self.stroke.device;
        device.rhs(t, y, dydt)?;
        let two = device.n_dof() == 2;
        let e = self
            .stroke
            .transmission()
            .kinematics()
            .evaluate(y.coords[0], if two { y.coords[1] } else { 0.0 })?;
        let tau = self.stroke_torques(t);
        let mut mass = Matrix2::zeros();
        let mut force = Vector2::zeros();
        for k in 0..2 {
            let row = e.jacobian.row(k).transpose();
            mass += row * row.transpose() * self.stroke.inertia[k];
            force += row * tau[k];
        }
        if two {
            let extra = mass.lu().solve(&force).ok_or_else(|| {
                Error::Singular(format!(
                    "drivetrain mass matrix is singular at q = ({}, {})",
                    y.coords[0], y.coords[1]
                ))
            })?;
            dydt.rates[0] += extra.x;
            dydt.rates[1] += extra.y;
        } else {
            dydt.rates[0] += force.x / mass[(0, 0)];
        }
        // The disturbance's work is neither actuator nor aerodynamic work: powers as is.
        Ok(())
    }

    fn n_active(&self) -> usize {
        self.stroke.device.n_dof()
    }
}

/// A device placed on the charts of §2.6–2.7, from its periodic orbit.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct DeviceLinearisation {
    /// Physical parameters read from the device and the orbit (mean of the two wings where
    /// they differ; T and L from the drivetrain Jacobian at rest: `J = [[−T, T hL], [−T, −T hR]]`,
    /// `L = (hL + hR)/2`; drag = `−τ(φ̇ = 1 rad/ms)`, i.e. `Ω1 C` for stroke drag; Φ the mean
    /// stroke amplitude of the orbit).
    pub physical: PhysicalParameters,
    /// (β0, κ1, κ2) of eq. 2.23–2.24 (docs/errata.md#7).
    pub hill: HillParameters,
    /// Eq. 2.59 as §2.7 builds it: the cycle averages over the orbit of the whippletree mode's
    /// aerodynamic damping rate and spring stiffness per unit modal inertia,
    /// `β* = ⟨Σ_k J_k2² c_k / m22⟩`, `κ0 = K2 ⟨1/m22⟩`, with `m22 = Σ_k I_k J_k2²` and
    /// `c_k = −∂τ_aero,k/∂φ̇_k`. For stroke drag on the linear map this is `(2/π) β0 ω0`
    /// exactly for any single-hump stroke, since `∮|φ̇| dt = 4Φ`.
    pub lti: LtiModel,
    /// Eq. 2.59 from [`PhysicalParameters::lti`] (sinusoidal flapping assumed).
    pub lti_sinusoidal: LtiModel,
    /// Eq. 2.59 from the cycle average of the whippletree row of the variational equation of
    /// the full model: `κ0 = −⟨∂q̈2/∂q2⟩`, `β* = −⟨∂q̈2/∂q̇2⟩` (central differences of the
    /// right-hand side along the orbit). Unlike [`Self::lti`] it includes the geometric
    /// stiffness of a nonlinear linkage (`2h²g''(q1)` times the crank load; docs/findings.md
    /// item 3), which can make κ0 negative. Equal to [`Self::lti`] for the linear map of eq. 2.15.
    pub lti_averaged: LtiModel,
    /// The geometric stiffness of the whippletree mode, `−⟨∂q̈2/∂q2⟩/⟨1/m22⟩ − K2`
    /// (mN·mm/rad; zero for eq. 2.15).
    pub geometric_stiffness: f64,
}

/// Samples a device along its orbit: `samples` uniform times over one period (endpoint
/// excluded).
fn orbit_samples(
    device: &Device,
    orbit: &PeriodicOrbit,
    integrator: &RungeKutta,
    samples: usize,
) -> Result<(Vec<f64>, Vec<State>)> {
    let times: Vec<f64> = (0..=samples)
        .map(|k| orbit.t0 + orbit.period * k as f64 / samples as f64)
        .collect();
    let mut states = integrator.integrate(
        device,
        orbit.t0,
        &orbit.state,
        orbit.t0 + orbit.period,
        &times,
    )?;
    states.pop();
    let mut times = times;
    times.pop();
    Ok((times, states))
}

/// `sign ×` the extremum (`sign = 1`: maximum, `−1`: minus the minimum) of uniformly sampled
/// periodic data, refined by the parabola through the extreme sample and its neighbours.
fn periodic_extremum(values: &[f64], sign: f64) -> f64 {
    let n = values.len();
    let (i, _) = values
        .iter()
        .enumerate()
        .fold((0, f64::NEG_INFINITY), |best, (i, &v)| {
            if sign * v > best.1 {
                (i, sign * v)
            } else {
                best
            }
        });
    let (ym, y0, yp) = (
        sign * values[(i + n - 1) % n],
        sign * values[i],
        sign * values[(i + 1) % n],
    );
    let curvature = yp - 2.0 * y0 + ym;
    if curvature < 0.0 {
        y0 - (yp - ym).powi(2) / (8.0 * curvature)
    } else {
        y0
    }
}

/// Places a fixed-wing Drag PARITY device (2-DOF drivetrain, drivetrain coordinates) on the
/// charts of §2.6–2.7 from its periodic orbit, sampled at `samples` points per cycle.
///
/// # Errors
/// [`Error::Constraint`] for other devices; [`Error::InvalidParameter`] for `samples < 8`.
pub fn linearise(
    device: &Device,
    orbit: &PeriodicOrbit,
    samples: usize,
) -> Result<DeviceLinearisation> {
    let stroke = StrokeDevice::new(device)?;
    let tr = stroke.transmission();
    if tr.kinematics().dof() != 2 || stroke.n_wings != 2 || tr.kinematics().is_dual() {
        bail!(Constraint "the §2.6–2.7 linearisation needs a 2-DOF (Drag PARITY) drivetrain with a whippletree and two wings (not a drive per wing: {})", tr.kinematics().name());
    }
    if samples < 8 {
        bail!(invalid "samples", samples, ">= 8");
    }
    let rest = tr.kinematics().evaluate(0.0, 0.0)?.jacobian;
    let t_ratio = -0.5 * (rest[(0, 0)] + rest[(1, 0)]);
    let arm = (rest[(0, 1)] - rest[(1, 1)]) / (2.0 * t_ratio);
    let wings = &device.spec().wings;
    let drag = 0.5 * (-wings[0].aero().stroke_torque(1.0) - wings[1].aero().stroke_torque(1.0));
    let inertia = 0.5 * (stroke.inertia[0] + stroke.inertia[1]);
    let k1 = device
        .spec()
        .actuator
        .as_ref()
        .map_or(0.0, |a| a.stiffness());
    let k2 = tr.balance_spring();
    let integrator = RungeKutta::new(Method::Dop853, 1e-10, 1e-12, 1_000_000)?;
    let (times, states) = orbit_samples(device, orbit, &integrator, samples)?;
    let mut strokes = [
        Vec::with_capacity(states.len()),
        Vec::with_capacity(states.len()),
    ];
    let (mut rate, mut inv_m22, mut dq2, mut dq2_dot) = (0.0, 0.0, 0.0, 0.0);
    for (t, y) in times.iter().zip(&states) {
        let e = tr.kinematics().evaluate(y.coords[0], y.coords[1])?;
        let phi_dot = e.jacobian * Vector2::new(y.rates[0], y.rates[1]);
        let (mut c, mut m) = (0.0, 0.0);
        for k in 0..2 {
            strokes[k].push(e.stroke[k]);
            let j2 = e.jacobian[(k, 1)];
            let aero = wings[k].aero();
            let h = 1e-6 * (1.0 + phi_dot[k].abs());
            let slope = (aero.stroke_torque(phi_dot[k] + h) - aero.stroke_torque(phi_dot[k] - h))
                / (2.0 * h);
            c += j2 * j2 * (-slope);
            m += j2 * j2 * stroke.inertia[k];
        }
        rate += c / m;
        inv_m22 += 1.0 / m;
        // Whippletree row of the variational equation (central differences of the RHS).
        for (rate, acc) in [(false, &mut dq2), (true, &mut dq2_dot)] {
            let value = if rate { y.rates[1] } else { y.coords[1] };
            let h = 1e-6 * (1.0 + value.abs());
            let (mut plus, mut minus) = (*y, *y);
            if rate {
                plus.rates[1] += h;
                minus.rates[1] -= h;
            } else {
                plus.coords[1] += h;
                minus.coords[1] -= h;
            }
            let (mut fp, mut fm) = (State::default(), State::default());
            device.rhs(*t, &plus, &mut fp)?;
            device.rhs(*t, &minus, &mut fm)?;
            *acc += (fp.rates[1] - fm.rates[1]) / (2.0 * h);
        }
    }
    let count = states.len() as f64;
    let stroke_amplitude = 0.25
        * strokes
            .iter()
            .map(|phi| periodic_extremum(phi, 1.0) + periodic_extremum(phi, -1.0))
            .sum::<f64>();
    let physical = PhysicalParameters {
        inertia,
        drag,
        transmission_ratio: t_ratio,
        arm_length: arm,
        k1,
        k2,
        stroke_amplitude,
        frequency_hz: 1e3 / orbit.period,
    };
    Ok(DeviceLinearisation {
        physical,
        hill: physical.hill()?,
        lti: LtiModel::new(rate / count, k2 * inv_m22 / count)?,
        lti_sinusoidal: physical.lti()?,
        lti_averaged: LtiModel::new(-dq2_dot / count, -dq2 / count)?,
        geometric_stiffness: -dq2 / inv_m22 - k2,
    })
}

/// Options of [`disturbance_response`]; deserialises from a partial record (missing fields
/// take the defaults, unknown ones are rejected).
#[derive(Clone, Debug, PartialEq, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DisturbanceOptions {
    /// Drive cycles simulated with the disturbance before measuring (transient decay).
    pub settle_cycles: usize,
    /// The window is the number of drive cycles `k ≤ max_window_cycles` that holds the closest
    /// to an integer number of disturbance periods.
    pub max_window_cycles: usize,
    /// Samples per drive cycle in the window.
    pub samples_per_cycle: usize,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
}

impl Default for DisturbanceOptions {
    fn default() -> Self {
        Self {
            settle_cycles: 40,
            max_window_cycles: 12,
            samples_per_cycle: 400,
            rtol: 1e-11,
            atol: 1e-13,
        }
    }
}

/// The body roll response of the nonlinear model to a sinusoidal wing roll disturbance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisturbanceResponse {
    /// Disturbance frequency (Hz).
    pub frequency_hz: f64,
    /// Disturbance amplitude (mN·mm).
    pub amplitude: f64,
    /// Measured transfer `τ̂/d̂` at the disturbance frequency (complex amplitude ratio).
    pub transfer: Complex<f64>,
    /// Measurement window (ms, an integer number of drive cycles).
    pub window_ms: f64,
    /// Distance of the window from an integer number of disturbance periods (in periods).
    pub commensurability_error: f64,
    /// `|H1 − H2| / |H2|` between the transfer measured on the window and on the window that
    /// follows it: large when the transient has not decayed or the orbit is unstable.
    pub drift: f64,
}

/// Measures the body roll response of the nonlinear model to `d(t) = ±amplitude · sin(2πft)`
/// ([`RollDisturbance`]) started on the periodic orbit: after `settle_cycles` and one more
/// window (compared for [`DisturbanceResponse::drift`]), the complex amplitude at `f` of the
/// body roll torque over the window, from the antisymmetric difference
/// of the `+amplitude` and `−amplitude` runs (which cancels the undisturbed orbit and the even
/// nonlinear terms), divided by that of `d`.
///
/// # Errors
/// [`Error::Constraint`] unless the device uses drivetrain coordinates;
/// [`Error::InvalidParameter`] for bad arguments; [`Error::Integration`].
pub fn disturbance_response(
    device: &Device,
    orbit: &PeriodicOrbit,
    frequency_hz: f64,
    amplitude: f64,
    options: &DisturbanceOptions,
) -> Result<DisturbanceResponse> {
    check_positive("frequency_hz", frequency_hz)?;
    check_positive("amplitude", amplitude)?;
    if options.samples_per_cycle < 16 {
        bail!(invalid "samples_per_cycle", options.samples_per_cycle, ">= 16");
    }
    if options.max_window_cycles == 0 || options.max_window_cycles > 10_000 {
        bail!(invalid "max_window_cycles", options.max_window_cycles, "in [1, 10000]");
    }
    if options.settle_cycles > 100_000 {
        bail!(invalid "settle_cycles", options.settle_cycles, "<= 100000");
    }
    let integrator = RungeKutta::new(Method::Dop853, options.rtol, options.atol, 10_000_000)?;
    let period = orbit.period;
    let f_per_ms = frequency_hz * 1e-3;
    let (mut best_k, mut best_err) = (1, f64::INFINITY);
    for k in 1..=options.max_window_cycles {
        let periods = k as f64 * period * f_per_ms;
        let err = (periods - periods.round()).abs();
        if err < best_err - 1e-12 {
            (best_k, best_err) = (k, err);
        }
    }
    let window = best_k as f64 * period;
    let t_start = orbit.t0 + options.settle_cycles as f64 * period;
    // Two consecutive windows: the second one is the measurement, their difference the drift.
    let n = best_k * options.samples_per_cycle;
    let times: Vec<f64> = (0..2 * n)
        .map(|j| t_start + window * j as f64 / n as f64)
        .collect();
    let omega = 2.0 * PI * f_per_ms;
    let run = |sign: f64| -> Result<[Complex<f64>; 2]> {
        let system = RollDisturbance::new(device, sign * amplitude, frequency_hz)?;
        let y0 = if t_start > orbit.t0 {
            integrator.integrate(&system, orbit.t0, &orbit.state, t_start, &[t_start])?[0]
        } else {
            orbit.state
        };
        let states = integrator.integrate(&system, t_start, &y0, t_start + 2.0 * window, &times)?;
        let mut acc = [Complex::new(0.0, 0.0); 2];
        for (j, (t, y)) in times.iter().zip(&states).enumerate() {
            let roll = system.body_roll(*t, y)?;
            acc[j / n] += Complex::from_polar(roll, -omega * t);
        }
        Ok(acc.map(|a| a * (2.0 / n as f64)))
    };
    // The two signs in parallel on the sweep engine's pool, under the caller's budget.
    let signs = super::rows::run_parts(2, |i| run(if i == 0 { 1.0 } else { -1.0 }))?;
    let (plus, minus) = (signs[0], signs[1]);
    // d(t) = A sin(ωt) has complex amplitude −iA under the same projection.
    let [first, transfer] =
        [0, 1].map(|w| (plus[w] - minus[w]) * 0.5 / Complex::new(0.0, -amplitude));
    if !(transfer.re.is_finite() && transfer.im.is_finite() && first.norm().is_finite()) {
        return Err(Error::Integration {
            time: t_start + 2.0 * window,
            state: vec![],
            reason: "non-finite disturbance response (is the orbit unstable?)".into(),
        });
    }
    Ok(DisturbanceResponse {
        frequency_hz,
        amplitude,
        transfer,
        window_ms: window,
        commensurability_error: best_err,
        drift: (transfer - first).norm() / transfer.norm().max(f64::MIN_POSITIVE),
    })
}

/// [`disturbance_response`] at each of `frequencies_hz`, one row each, on the sweep engine's
/// pool ([`super::rows`]).
///
/// # Errors
/// A failing frequency is its row's error, located as `frequency_hz[i]`; the call itself
/// fails only when cancelled ([`Error::Cancelled`]) or for a bad thread count.
pub fn disturbance_responses(
    device: &Device,
    orbit: &PeriodicOrbit,
    frequencies_hz: &[f64],
    amplitude: f64,
    options: &DisturbanceOptions,
) -> Result<Rows<DisturbanceResponse>> {
    super::rows::run_rows(frequencies_hz.len(), None, Some("frequency_hz"), |i| {
        disturbance_response(device, orbit, frequencies_hz[i], amplitude, options)
    })
}
