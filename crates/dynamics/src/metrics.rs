//! Metrics over a recorded trajectory.
//!
//! Per wing (`left_`, `right_` or `wing_`): stroke amplitude (half peak-to-peak), mean and
//! peak-to-peak; rotation amplitude and mean; phase lag of rotation behind stroke (from the
//! fundamental Fourier components, rad in (−π, π]); peak and mean of the roll aerodynamic torque.
//! Device: actuator and aerodynamic work per cycle, mean actuator power, peak actuator force,
//! whippletree amplitude, peak total roll torque.

use crate::device::Device;
use crate::simulate::Trajectory;

fn extrema(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        })
}

/// Fundamental Fourier coefficient of `v` at angular frequency `w` (uniform samples, the last
/// sample closing the window is excluded).
fn fundamental(time: &[f64], v: &[f64], w: f64) -> (f64, f64) {
    let n = v.len().saturating_sub(1).max(1);
    let (mut re, mut im) = (0.0, 0.0);
    for i in 0..n {
        re += v[i] * (w * time[i]).cos();
        im -= v[i] * (w * time[i]).sin();
    }
    (re, im)
}

/// Drops the sample that closes a periodic window.
fn body(v: &[f64]) -> &[f64] {
    if v.len() > 1 { &v[..v.len() - 1] } else { v }
}

fn wrap(a: f64) -> f64 {
    let mut a = (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    if a <= -std::f64::consts::PI {
        a += std::f64::consts::TAU;
    }
    a
}

/// Computes the metrics; names are stable and documented above.
pub fn compute(device: &Device, traj: &Trajectory, period: Option<f64>) -> Vec<(String, f64)> {
    let mut out: Vec<(String, f64)> = Vec::new();
    let prefixes: &[&str] = if device.n_wings() == 2 {
        &["left", "right"]
    } else {
        &["wing"]
    };
    let n = traj.time.len();
    let duration =
        traj.time.last().copied().unwrap_or(0.0) - traj.time.first().copied().unwrap_or(0.0);
    let cycles = period.map_or(1.0, |p| (duration / p).round().max(1.0));
    let col = |name: &str| traj.column(name).unwrap_or(&[]);
    for p in prefixes {
        let phi = col(&format!("{p}_phi"));
        let psi = col(&format!("{p}_psi"));
        let (lo, hi) = extrema(phi);
        out.push((format!("{p}_stroke_amplitude"), 0.5 * (hi - lo)));
        out.push((format!("{p}_stroke_peak_to_peak"), hi - lo));
        out.push((
            format!("{p}_stroke_mean"),
            body(phi).iter().sum::<f64>() / body(phi).len().max(1) as f64,
        ));
        let (rlo, rhi) = extrema(psi);
        out.push((format!("{p}_rotation_amplitude"), 0.5 * (rhi - rlo)));
        out.push((
            format!("{p}_rotation_mean"),
            body(psi).iter().sum::<f64>() / body(psi).len().max(1) as f64,
        ));
        let lag = match period {
            Some(period) if rhi - rlo > 1e-9 && n > 2 => {
                let w = std::f64::consts::TAU / period;
                let (a, b) = fundamental(&traj.time, phi, w);
                let (c, d) = fundamental(&traj.time, psi, w);
                wrap(b.atan2(a) - d.atan2(c))
            }
            _ => f64::NAN,
        };
        out.push((format!("{p}_rotation_phase_lag"), lag));
        let roll = col(&format!("{p}_roll_aero"));
        let (rl, rh) = extrema(roll);
        out.push((format!("{p}_roll_aero_peak"), rl.abs().max(rh.abs())));
        out.push((
            format!("{p}_roll_aero_mean"),
            body(roll).iter().sum::<f64>() / body(roll).len().max(1) as f64,
        ));
    }
    let last = |name: &str| col(name).last().copied().unwrap_or(0.0);
    out.push((
        "work_actuator_per_cycle".into(),
        last("work_actuator") / cycles,
    ));
    out.push(("work_aero_per_cycle".into(), last("work_aero") / cycles));
    out.push((
        "mean_actuator_power".into(),
        if duration > 0.0 {
            last("work_actuator") / duration
        } else {
            0.0
        },
    ));
    let (flo, fhi) = extrema(col("actuator_force"));
    out.push(("actuator_force_peak".into(), flo.abs().max(fhi.abs())));
    let (qlo, qhi) = extrema(col("q2"));
    out.push(("q2_amplitude".into(), 0.5 * (qhi - qlo)));
    let (tlo, thi) = extrema(col("roll_total"));
    out.push(("roll_total_peak".into(), tlo.abs().max(thi.abs())));
    out
}
