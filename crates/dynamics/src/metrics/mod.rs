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
pub use needs::{StrokeNeeds, is_force_metric, is_stroke_metric, unavailable_reason};
use std::f64::consts::{PI, TAU};

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

    /// The metrics, names as documented in the module.
    pub fn finish(&self) -> Vec<(String, f64)> {
        self.finish_only(None)
    }

    /// [`Self::finish`] keeping only the metrics named in `wanted` (all: `None`), in
    /// `finish`'s order: the others' names are not copied (a copy was most of what a window
    /// of a §3.3 sensitivity spent finishing).
    pub fn finish_only(&self, wanted: Option<&[String]>) -> Vec<(String, f64)> {
        let names = self.names();
        let mut out: Vec<(String, f64)> =
            Vec::with_capacity(wanted.map_or(names.len(), <[String]>::len));
        let mut index = 0;
        self.each(&mut |_, value| {
            let name = &names[index];
            index += 1;
            if wanted.is_none_or(|wanted| wanted.contains(name)) {
                out.push((name.clone(), value));
            }
        });
        if let Some(needs) = self.lean {
            for (name, value) in &mut out {
                if !needs.provides(name) {
                    *value = f64::NAN;
                }
            }
        }
        out
    }

    /// The names [`Self::finish`] gives, formatted once per process for each layout (one or
    /// two wings, forces or not, a weight or not): formatting them was half of finishing a
    /// window (docs/findings.md §30).
    fn names(&self) -> &'static [String] {
        static LAYOUTS: [std::sync::OnceLock<Vec<String>>; 8] =
            [const { std::sync::OnceLock::new() }; 8];
        let layout = usize::from(self.n_wings == 2)
            | usize::from(self.forces.is_some()) << 1
            | usize::from(self.weight.is_some()) << 2;
        LAYOUTS[layout].get_or_init(|| {
            let mut names = Vec::with_capacity(64);
            self.each(&mut |name, _| names.push(name.text()));
            names
        })
    }

    /// Every metric's name and value, in [`Self::finish`]'s order (its one definition).
    fn each(&self, push: &mut impl FnMut(Name, f64)) {
        let n = self.body_samples.max(1) as f64;
        let duration = self.last_time - self.first_time.unwrap_or(self.last_time);
        let cycles = self.period.map_or(1.0, |p| (duration / p).round().max(1.0));
        let prefixes: &[&str] = if self.n_wings == 2 {
            &["left", "right"]
        } else {
            &["wing"]
        };
        for (w, p) in prefixes.iter().enumerate() {
            let a = &self.wings[w];
            push(Name::Wing(p, "stroke_amplitude"), 0.5 * a.phi.range.span());
            push(Name::Wing(p, "stroke_peak_to_peak"), a.phi.range.span());
            push(Name::Wing(p, "stroke_mean"), a.phi.mean(n));
            push(
                Name::Wing(p, "rotation_amplitude"),
                0.5 * a.psi.range.span(),
            );
            push(Name::Wing(p, "rotation_mean"), a.psi.mean(n));
            let lag = match self.period {
                Some(_) if a.psi.range.span() > 1e-9 && self.body_samples > 1 => {
                    wrap(a.phi_f.1.atan2(a.phi_f.0) - a.psi_f.1.atan2(a.psi_f.0))
                }
                _ => f64::NAN,
            };
            push(Name::Wing(p, "rotation_phase_lag"), lag);
            push(Name::Wing(p, "roll_aero_peak"), a.roll_aero.range.abs_max());
            push(Name::Wing(p, "roll_aero_mean"), a.roll_aero.mean(n));
        }
        push(
            Name::Plain("work_actuator_per_cycle"),
            self.work_actuator / cycles,
        );
        push(Name::Plain("work_aero_per_cycle"), self.work_aero / cycles);
        push(
            Name::Plain("mean_actuator_power"),
            if duration > 0.0 {
                self.work_actuator / duration
            } else {
                0.0
            },
        );
        push(Name::Plain("actuator_force_peak"), self.force.abs_max());
        push(Name::Plain("q2_amplitude"), 0.5 * self.q2.span());
        push(
            Name::Plain("roll_total_peak"),
            self.total[0].range.abs_max(),
        );
        // Added with the streamed engine (after the original names, which keep their order).
        for (w, p) in prefixes.iter().enumerate() {
            for (k, axis) in AXES.iter().enumerate() {
                let t = &self.wings[w].torque[k];
                push(Name::WingAxis(p, axis, "mean"), t.mean(n));
                push(Name::WingAxis(p, axis, "rms"), t.rms(n));
                push(Name::WingAxis(p, axis, "peak"), t.range.abs_max());
            }
        }
        for (k, axis) in AXES.iter().enumerate() {
            let t = &self.total[k];
            push(Name::Axis(axis, "total_mean"), t.mean(n));
            push(Name::Axis(axis, "total_rms"), t.rms(n));
            if k > 0 {
                push(Name::Axis(axis, "total_peak"), t.range.abs_max());
            }
        }
        if self.n_wings == 2 {
            let delta = self.delta_tau.abs_max();
            let tau_l = self.wings[0].roll_aero.range.abs_max();
            let tau_r = self.wings[1].roll_aero.range.abs_max();
            push(Name::Plain("delta_tau_peak"), delta);
            push(Name::Plain("tau_l_peak"), tau_l);
            push(Name::Plain("tau_r_peak"), tau_r);
            let percent = |x: f64| {
                if tau_r > 0.0 {
                    100.0 * x / tau_r
                } else {
                    f64::NAN
                }
            };
            push(Name::Plain("imbalance_instantaneous_pct"), percent(delta));
            push(Name::Plain("imbalance_peak_pct"), percent(tau_r - tau_l));
        }
        let per_time = |work: f64| {
            if duration > 0.0 { work / duration } else { 0.0 }
        };
        let actuator_power = per_time(self.work_actuator);
        let mut lift = f64::NAN;
        if let Some(acc) = &self.forces {
            for (w, p) in prefixes.iter().enumerate() {
                for (k, axis) in forces::FORCE_AXES.iter().enumerate() {
                    let f = &acc.wings[w][k];
                    push(Name::WingAxis(p, axis, "mean"), f.mean(n));
                    push(Name::WingAxis(p, axis, "rms"), f.rms(n));
                    push(Name::WingAxis(p, axis, "peak"), f.range.abs_max());
                }
            }
            for (k, axis) in forces::FORCE_AXES.iter().enumerate() {
                let f = &acc.net[k];
                push(Name::Axis(axis, "mean"), f.mean(n));
                push(Name::Axis(axis, "rms"), f.rms(n));
                push(Name::Axis(axis, "peak"), f.range.abs_max());
            }
            push(Name::Plain("aero_force_peak"), acc.magnitude.hi.max(0.0));
            lift = acc.net[0].mean(n);
        }
        // −work_aero: the power the wings give to the air is positive.
        push(Name::Plain("aero_power_mean"), -per_time(self.work_aero));
        push(Name::Plain("actuator_power_mean"), actuator_power);
        let ratio = |x: f64, by: f64| if by != 0.0 { x / by } else { f64::NAN };
        if self.forces.is_some() {
            push(Name::Plain("lift_per_power"), ratio(lift, actuator_power));
            if let Some(weight) = self.weight {
                push(Name::Plain("lift_to_weight"), ratio(lift, weight));
            }
        }
        if let Some(weight) = self.weight {
            // mW/mN = W/N: the input power per newton carried.
            push(
                Name::Plain("actuator_power_per_weight"),
                ratio(actuator_power, weight),
            );
        }
    }
}

/// A metric's name in parts, formatted only when [`MetricsAccumulator::names`] lists a layout.
#[derive(Clone, Copy)]
enum Name {
    /// The name itself.
    Plain(&'static str),
    /// `{prefix}_{field}`: a wing's.
    Wing(&'static str, &'static str),
    /// `{prefix}_{axis}_{statistic}`: a wing's, about a body axis.
    WingAxis(&'static str, &'static str, &'static str),
    /// `{axis}_{field}`: the net one about a body axis.
    Axis(&'static str, &'static str),
}

impl Name {
    fn text(self) -> String {
        match self {
            Name::Plain(name) => name.to_string(),
            Name::Wing(p, field) => format!("{p}_{field}"),
            Name::WingAxis(p, axis, statistic) => format!("{p}_{axis}_{statistic}"),
            Name::Axis(axis, field) => format!("{axis}_{field}"),
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

fn wrap(a: f64) -> f64 {
    let mut a = (a + PI).rem_euclid(TAU) - PI;
    if a <= -PI {
        a += TAU;
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    fn accumulator(n_wings: usize, forces: bool, weight: bool) -> MetricsAccumulator {
        MetricsAccumulator::of_layout(n_wings, Some(10.0), forces)
            .with_weight(weight.then_some(1.0))
    }

    /// The names kept per layout are each layout's own, whatever layout came first: every
    /// layout, twice over in two orders, against its names formatted anew.
    #[test]
    fn kept_names_are_each_layouts_own() {
        let layouts: Vec<(usize, bool, bool)> = (0..8)
            .map(|i| (1 + (i & 1), i & 2 != 0, i & 4 != 0))
            .collect();
        for (n_wings, forces, weight) in layouts.iter().chain(layouts.iter().rev()) {
            let acc = accumulator(*n_wings, *forces, *weight);
            let mut fresh = Vec::new();
            acc.each(&mut |name, _| fresh.push(name.text()));
            let kept: Vec<String> = acc.finish().into_iter().map(|(name, _)| name).collect();
            assert_eq!(
                kept, fresh,
                "{n_wings} wings, forces {forces}, weight {weight}"
            );
            let has = |name: &str| kept.iter().any(|k| k == name);
            assert_eq!(has("delta_tau_peak"), *n_wings == 2);
            assert_eq!(has("left_yaw_rms"), *n_wings == 2);
            assert_eq!(has("wing_stroke_amplitude"), *n_wings == 1);
            assert_eq!(has("lift_mean"), *forces);
            assert_eq!(has("lift_to_weight"), *forces && *weight);
            assert_eq!(has("actuator_power_per_weight"), *weight);
        }
    }
}
