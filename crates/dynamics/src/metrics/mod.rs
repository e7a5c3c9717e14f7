//! Metrics of the recorded window, accumulated sample by sample (no trajectory is stored).
//!
//! Means, rms and Fourier sums use the samples of whole periods (the sample closing the window
//! is left out); extrema use every sample. Names, per wing (`left_`, `right_` or `wing_`):
//!
//! * `stroke_amplitude` (half peak-to-peak), `stroke_peak_to_peak`, `stroke_mean`;
//!   `rotation_amplitude`, `rotation_mean`; `rotation_phase_lag` of rotation behind stroke
//!   (fundamental Fourier components, rad in (−π, π]); `roll_aero_peak`, `roll_aero_mean`;
//! * `roll_mean`, `roll_rms`, `roll_peak` (and `yaw_*`, `pitch_*`): the wing's body reaction
//!   torque (aerodynamic + inertial, mN·mm).
//!
//! Device: `work_actuator_per_cycle`, `work_aero_per_cycle`, `mean_actuator_power`,
//! `actuator_force_peak`, `q2_amplitude`; the net body torque `roll_total_peak` and
//! `{roll,yaw,pitch}_total_{mean,rms,peak}`. Two wings, Table 3.2 (§3.3.1, drag torques in the
//! body roll frame): `delta_tau_peak = max |τL + τR|` (eq. 3.23), `tau_l_peak`, `tau_r_peak`,
//! `imbalance_instantaneous_pct = 100 Δτ_peak / τR_peak`,
//! `imbalance_peak_pct = 100 (τR_peak − τL_peak) / τR_peak`.
//!
//! Forces and power (every device; docs/reference/metrics.md). The wings' aerodynamic force
//! in the body frame ([`forces`]: `x̂` the lift axis, `ŷ` fore-aft, `ẑ` spanwise toward the
//! right wing), where every wing has a force model ([`forces::offers_forces`]: blade
//! elements, not the stroke drag of eq. 2.16), per wing `{p}_{lift,aero_force_y,aero_force_z}`
//! and net `{lift,aero_force_y,aero_force_z}`, each `_mean`, `_rms`, `_peak` (mN), and
//! `aero_force_peak = max |F|` of the net force; `aero_power_mean` (mW: power given to the
//! air, `−work_aero` over the window's duration) and `actuator_power_mean` (mW, the same as
//! `mean_actuator_power`) on every device; `lift_per_power = lift_mean / actuator_power_mean`
//! (mN/mW); `lift_to_weight = lift_mean / weight` when a weight is given
//! ([`MetricsAccumulator::with_weight`]: a spec's `body` section), and on every device given a
//! weight `actuator_power_per_weight = actuator_power_mean / weight` (mW/mN = W/N).
//!
//! The thesis' aerodynamics (§3.2.4) gives moments only (eqs. 3.8–3.11, with `Ω1 = ½ρ∬z³dA`,
//! eq. 3.12); the force of the same strips is `½ρ∬z²dA · W² (C_L ℓ̂ − C_D û)` with `C_L`, `C_D`
//! of eqs. 3.5–3.6 at the α of eq. 3.4 (sign convention: docs/errata.md#5). On a stroke-plane
//! wing (θ ≡ 0) the lift is `½ρ∬z²dA · φ̇² C_L(α)` along the stroke axis and the drag lies in
//! the stroke plane. The actuator power is the mechanical power the actuator's force gives the
//! drivetrain (`F_a q̇1`; the piezo's electrical side is not modelled); on a periodic orbit
//! `actuator_power_mean = aero_power_mean` (the springs and the inertia return their energy,
//! and the one dissipation, rotational damping eq. 3.10, is part of the aerodynamic power;
//! with the drive's and hinges' dampers the actuator power also covers their `Σ b q̇²`).
//!
//! Undefined metrics are NaN (Python turns them into `None` / null): the phase lag of a wing
//! that does not rotate, the imbalance percentages when `τR_peak = 0`, `lift_per_power`
//! without actuator power, `lift_to_weight` at zero weight.

pub mod forces;
pub mod needs;
pub mod plane_sample;
mod report;
pub use needs::{StrokeNeeds, is_force_metric, is_stroke_metric, unavailable_reason};
use std::f64::consts::TAU;

use nalgebra::Vector3;

use crate::device::Device;
use crate::trajectory::{Sample, StrokeSample};
use plane_sample::PlaneSample;

const AXES: [&str; 3] = ["roll", "yaw", "pitch"];

/// Running extrema.
#[derive(Clone, Copy, Debug)]
struct Range {
    lo: f64,
    hi: f64,
}

impl Default for Range {
    fn default() -> Self {
        Self {
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
        }
    }
}

impl Range {
    /// Ignores NaN, as `f64::min`/`max` do (plain comparisons: fewer instructions per sample).
    #[inline]
    fn add(&mut self, v: f64) {
        if v < self.lo {
            self.lo = v;
        }
        if v > self.hi {
            self.hi = v;
        }
    }
    fn span(&self) -> f64 {
        self.hi - self.lo
    }
    fn abs_max(&self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }
}

/// Extrema, sum and sum of squares.
#[derive(Clone, Copy, Debug, Default)]
struct Stats {
    range: Range,
    sum: f64,
    sum_sq: f64,
}

impl Stats {
    #[inline]
    fn add(&mut self, v: f64, in_body: bool) {
        self.range.add(v);
        if in_body {
            self.sum += v;
            self.sum_sq += v * v;
        }
    }
    fn mean(&self, n: f64) -> f64 {
        self.sum / n
    }
    fn rms(&self, n: f64) -> f64 {
        (self.sum_sq / n).sqrt()
    }
}

#[derive(Clone, Copy, Debug, Default)]
struct WingAcc {
    phi: Stats,
    psi: Stats,
    roll_aero: Stats,
    torque: [Stats; 3],
    /// Fundamental Fourier sums `Σ v cos ωt`, `−Σ v sin ωt` of φ and ψ.
    phi_f: (f64, f64),
    psi_f: (f64, f64),
}

/// Up to four consecutive [`StrokeSample`]s by columns (see
/// [`MetricsAccumulator::add_stroke_block`]); entries past `count` are ignored.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StrokeBlock {
    /// Samples in the block (1 to 4).
    pub(crate) count: usize,
    /// Whether the last one closes the window.
    pub(crate) closing: bool,
    /// Times (ms).
    pub(crate) time: [f64; 4],
    /// `φL`, `φR` (rad).
    pub(crate) stroke: [[f64; 4]; 2],
    /// Roll torques, left mirrored (see [`StrokeSample::roll_aero`]).
    pub(crate) roll_aero: [[f64; 4]; 2],
    /// Actuator forces (mN).
    pub(crate) actuator_force: [f64; 4],
    /// `q2` (rad).
    pub(crate) q2: [f64; 4],
}

/// Accumulates the metrics over the samples of a recorded window.
#[derive(Clone, Debug)]
pub struct MetricsAccumulator {
    n_wings: usize,
    period: Option<f64>,
    omega: f64,
    wings: [WingAcc; 2],
    force: Range,
    q2: Range,
    total: [Stats; 3],
    delta_tau: Range,
    body_samples: usize,
    first_time: Option<f64>,
    last_time: f64,
    work_actuator: f64,
    work_aero: f64,
    /// Fed with [`StrokeSample`]s computing this much: the metrics they do not provide are NaN.
    lean: Option<StrokeNeeds>,
    /// The force metrics, when the device offers them ([`forces::offers_forces`]).
    forces: Option<ForceAcc>,
    /// Weight (mN) for `lift_to_weight`.
    weight: Option<f64>,
}

/// Force statistics: per wing and net, per body axis (lift, y, z), and the net magnitude.
#[derive(Clone, Copy, Debug, Default)]
struct ForceAcc {
    wings: [[Stats; 3]; 2],
    net: [Stats; 3],
    magnitude: Range,
}

/// The per-sample values every metric path shares.
struct Core {
    time: f64,
    phi: [f64; 2],
    psi: [f64; 2],
    roll_aero: [f64; 2],
    force: f64,
    q2: f64,
}

impl MetricsAccumulator {
    /// An empty accumulator for `device` with drive `period` (ms).
    pub fn new(device: &Device, period: Option<f64>) -> Self {
        Self::of_layout(device.n_wings(), period, forces::offers_forces(device))
    }

    /// An empty accumulator of `n_wings` wings, with force metrics or not.
    fn of_layout(n_wings: usize, period: Option<f64>, forces: bool) -> Self {
        Self {
            n_wings,
            period,
            omega: period.map_or(0.0, |p| TAU / p),
            wings: [WingAcc::default(); 2],
            force: Range::default(),
            q2: Range::default(),
            total: [Stats::default(); 3],
            delta_tau: Range::default(),
            body_samples: 0,
            first_time: None,
            last_time: 0.0,
            work_actuator: 0.0,
            work_aero: 0.0,
            lean: None,
            forces: forces.then(ForceAcc::default),
            weight: None,
        }
    }

    /// The same accumulator reporting `lift_to_weight` against `weight` (mN; a body's weight
    /// with its wings). A device without force metrics ignores it.
    pub fn with_weight(mut self, weight: Option<f64>) -> Self {
        self.weight = weight;
        self
    }

    /// Adds the wings' aerodynamic forces of a sample (body frame, as [`Sample::force`]);
    /// `closing` as in [`Self::add`]. Ignored when the device offers no force metric.
    #[inline]
    pub fn add_forces(&mut self, force: &[Vector3<f64>; 2], closing: bool) {
        let Some(acc) = &mut self.forces else {
            return;
        };
        let body = !closing;
        let mut net = Vector3::zeros();
        for (stats, f) in acc.wings.iter_mut().zip(force).take(self.n_wings) {
            for (k, st) in stats.iter_mut().enumerate() {
                st.add(f[k], body);
            }
            net += f;
        }
        for (k, st) in acc.net.iter_mut().enumerate() {
            st.add(net[k], body);
        }
        acc.magnitude.add(net.norm());
    }

    fn add_core(&mut self, c: &Core, body: bool) {
        if body {
            self.body_samples += 1;
        }
        self.first_time.get_or_insert(c.time);
        self.last_time = c.time;
        for w in 0..self.n_wings {
            let acc = &mut self.wings[w];
            acc.phi.add(c.phi[w], body);
            acc.psi.add(c.psi[w], body);
            acc.roll_aero.add(c.roll_aero[w], body);
        }
        if self.n_wings == 2 {
            self.delta_tau.add(c.roll_aero[0] + c.roll_aero[1]);
        }
        self.force.add(c.force);
        self.q2.add(c.q2);
    }

    /// Adds a sample; `closing` marks the sample that closes the window (left out of means).
    pub fn add(&mut self, s: &Sample, closing: bool) {
        let body = !closing;
        let p = &s.eval.p;
        self.add_core(
            &Core {
                time: s.time,
                phi: [p[0], p[3]],
                psi: [p[2], p[5]],
                roll_aero: [s.aero[0].x, s.aero[1].x],
                force: s.eval.drive.actuator_force,
                q2: s.eval.drive.q.y,
            },
            body,
        );
        let (cos, sin) = self.drive_phase(s.time, body);
        for w in 0..self.n_wings {
            let acc = &mut self.wings[w];
            let (phi, psi) = (p[3 * w], p[3 * w + 2]);
            let torque = s.wing_torque(w);
            for (k, stats) in acc.torque.iter_mut().enumerate() {
                stats.add(torque[k], body);
            }
            acc.phi_f.0 += phi * cos;
            acc.phi_f.1 -= phi * sin;
            acc.psi_f.0 += psi * cos;
            acc.psi_f.1 -= psi * sin;
        }
        for (k, stats) in self.total.iter_mut().enumerate() {
            stats.add(s.total[k], body);
        }
        self.add_forces(&s.force, closing);
        self.work_actuator = s.state.work_actuator;
        self.work_aero = s.state.work_aero;
    }

    /// `(cos ωt, sin ωt)` of the drive at a body sample (the first harmonics of φ and ψ), else
    /// zeros.
    fn drive_phase(&self, time: f64, body: bool) -> (f64, f64) {
        if body && self.period.is_some() {
            let (sin, cos) = (self.omega * time).sin_cos();
            (cos, sin)
        } else {
            (0.0, 0.0)
        }
    }

    /// Adds a [`PlaneSample`] with [`Self::add`]'s operations in its order (the same metrics
    /// from the same values); the metrics its [`StrokeNeeds`] do not provide are NaN.
    pub fn add_plane(&mut self, s: &PlaneSample, closing: bool) {
        let body = !closing;
        self.lean.get_or_insert(s.needs);
        self.add_core(
            &Core {
                time: s.time,
                phi: s.phi,
                psi: s.psi,
                roll_aero: s.roll_aero,
                force: s.actuator_force,
                q2: s.q2,
            },
            body,
        );
        let (cos, sin) = self.drive_phase(s.time, body);
        for w in 0..self.n_wings {
            let acc = &mut self.wings[w];
            let (phi, psi) = (s.phi[w], s.psi[w]);
            if s.needs.torques {
                for (k, stats) in acc.torque.iter_mut().enumerate() {
                    stats.add(s.torque[w][k], body);
                }
            }
            acc.phi_f.0 += phi * cos;
            acc.phi_f.1 -= phi * sin;
            acc.psi_f.0 += psi * cos;
            acc.psi_f.1 -= psi * sin;
        }
        if s.needs.torques {
            for (k, stats) in self.total.iter_mut().enumerate() {
                stats.add(s.total[k], body);
            }
        }
        (self.work_actuator, self.work_aero) = s.work;
    }

    /// Adds a [`StrokeSample`]; an accumulator fed this way reports NaN for the metrics its
    /// [`StrokeNeeds`] do not provide. The rotation Fourier sums are skipped: ψ ≡ 0, so the
    /// phase lag is undefined (NaN) on either path.
    #[inline]
    pub fn add_stroke(&mut self, s: &StrokeSample, closing: bool) {
        let body = !closing;
        if self.first_time.is_none() {
            self.lean = Some(s.needs);
            self.first_time = Some(s.time);
            // ψ ≡ 0: one zero gives the rotation metrics their (zero) range and mean.
            for acc in &mut self.wings {
                acc.psi.range.add(0.0);
            }
        }
        if body {
            self.body_samples += 1;
        }
        self.last_time = s.time;
        // Stroke-only devices have two wings.
        let [left, right] = &mut self.wings;
        left.phi.add(s.stroke.x, body);
        right.phi.add(s.stroke.y, body);
        left.roll_aero.add(s.roll_aero[0], body);
        right.roll_aero.add(s.roll_aero[1], body);
        self.delta_tau.add(s.roll_aero[0] + s.roll_aero[1]);
        self.force.add(s.actuator_force);
        self.q2.add(s.q2);
        if s.needs.torques {
            for (acc, torque) in self.wings.iter_mut().zip(&s.torque) {
                for (k, stats) in acc.torque.iter_mut().enumerate() {
                    stats.add(torque[k], body);
                }
            }
            for (k, stats) in self.total.iter_mut().enumerate() {
                stats.add(s.total[k], body);
            }
        }
        (self.work_actuator, self.work_aero) = s.work;
    }

    /// [`Self::add_stroke`] of up to four consecutive stroke samples given as columns (the
    /// SIMD-lane sweeps, `crate::lanes`): the same operations in the same order per
    /// accumulator (extrema keep the first extreme value, sums run in sample order), so the
    /// same metrics bit for bit; only the per-sample bookkeeping is shared.
    #[inline]
    pub(crate) fn add_stroke_block(&mut self, b: &StrokeBlock) {
        let n = b.count;
        let body = if b.closing { n - 1 } else { n };
        if self.first_time.is_none() {
            // The lanes compute the stroke state and the actuator force (no torques, no work).
            self.lean = Some(StrokeNeeds {
                force: true,
                torques: false,
                work: false,
                forces: false,
            });
            self.first_time = Some(b.time[0]);
            for acc in &mut self.wings {
                acc.psi.range.add(0.0);
            }
        }
        self.body_samples += body;
        self.last_time = b.time[n - 1];
        // A full block inside the window (nearly all of them) takes the same operations in
        // the same order through loops of a known length, which the compiler unrolls.
        if n == 4 && body == 4 {
            self.add_stroke_values(b, 4, 4);
        } else {
            self.add_stroke_values(b, n, body);
        }
    }

    /// The values of a block's first `n` samples (`body` of them in the means).
    #[inline(always)]
    fn add_stroke_values(&mut self, b: &StrokeBlock, n: usize, body: usize) {
        let stats = |st: &mut Stats, v: &[f64; 4]| {
            for &x in &v[..n] {
                st.range.add(x);
            }
            for &x in &v[..body] {
                st.sum += x;
                st.sum_sq += x * x;
            }
        };
        let [left, right] = &mut self.wings;
        stats(&mut left.phi, &b.stroke[0]);
        stats(&mut right.phi, &b.stroke[1]);
        stats(&mut left.roll_aero, &b.roll_aero[0]);
        stats(&mut right.roll_aero, &b.roll_aero[1]);
        for j in 0..n {
            self.delta_tau.add(b.roll_aero[0][j] + b.roll_aero[1][j]);
        }
        for j in 0..n {
            self.force.add(b.actuator_force[j]);
        }
        for j in 0..n {
            self.q2.add(b.q2[j]);
        }
    }
}

/// The metric names for `device`, in order.
pub fn names(device: &Device) -> Vec<String> {
    names_weighed(device, false)
}

/// [`names`] of an accumulator given a weight (`weighed`: `lift_to_weight` too, where the
/// device offers forces).
pub fn names_weighed(device: &Device, weighed: bool) -> Vec<String> {
    MetricsAccumulator::new(device, device.period())
        .with_weight(weighed.then_some(1.0))
        .finish()
        .into_iter()
        .map(|(name, _)| name)
        .collect()
}
