//! A §3.4 design sweep without Python: the rotating-wing Drag PARITY device (Table 3.3 1-Cut
//! wings, blade element, eq. 2.15 with ±200 µm → ±35°, `100 + V sin(2π 110 Hz t)`) on a
//! `GRID × GRID` grid over the hinge stiffness ∈ [1, 4] mN·mm/rad × drive amplitude V ∈
//! [60, 100], stroke and rotation metrics of the last cycle from 200 samples (the shipped
//! devices' default). Prints ms per point and how many points ran in SIMD lanes.
//! `DEVICE=lift` / `dual`: the §2.5 Lift / Dual PARITY on those wings (free deviation θ,
//! tunable hinge) over the deviation stiffness ∈ [8, 12] × `V + V sin`, V ∈ [80, 100].
//!
//! Environment: `DEVICE`, `GRID` (16), `THREADS` (1), `REPEAT` (3), `PARITYSIM_LANES` (lane
//! width, 1 = scalar). Compare `PARITYSIM_LANES=1` and `=4` (issue 12 item 6;
//! docs/findings.md §24).

use std::time::Instant;

use nalgebra::Matrix3;
use paritysim_aero::{BladeElementModel, CoefficientSet, Omegas};
use paritysim_constraints::Constraints;
use paritysim_dynamics::device::{Device, DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::sweep::{Grid, SweepControl, SweepSettings, sweep};
use paritysim_dynamics::{
    Actuator, DcOffset, JointSpring, Result, SimulationOptions, Waveform, Wing, WingAero,
};
use paritysim_kinematics::drivetrain::LinearDifferential;
use paritysim_kinematics::{Drivetrain, SphericalShoulder};

const METRICS: [&str; 6] = [
    "left_stroke_amplitude",
    "right_stroke_amplitude",
    "left_rotation_amplitude",
    "right_rotation_amplitude",
    "imbalance_peak_pct",
    "q2_amplitude",
];

/// A Table 3.3 wing; `free_deviation`: the §2.5 wing (deviation spring `spring`, tunable
/// hinge), else the §3.4 one (hinge spring `spring`).
fn wing(inertia: [f64; 4], omegas: [f64; 4], spring: f64, free_deviation: bool) -> Result<Wing> {
    let [ixx, iyy, izz, ixz] = inertia;
    let mut springs = [JointSpring::default(); 6];
    springs[if free_deviation { 3 } else { 5 }] = JointSpring::linear(spring, 0.0)?;
    let blade = BladeElementModel::new(
        Omegas::new(omegas[0], omegas[1], omegas[2], omegas[3])?,
        CoefficientSet::default(),
    )?;
    let wing = Wing::new(
        SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0)?,
        Matrix3::new(ixx, 0.0, ixz, 0.0, iyy, 0.0, ixz, 0.0, izz),
        springs,
        WingAero::BladeElement(blade),
    )?;
    Ok(if free_deviation {
        wing.with_tunable_hinge(paritysim_dynamics::TunableHinge::new(
            2.533928021702924,
            0.0,
            20.0,
        )?)
    } else {
        wing
    })
}

/// `DEVICE`: `rotating` (§3.4, the default), `lift` or `dual` (§2.5 Lift / Dual PARITY).
fn configuration() -> String {
    match std::env::var("DEVICE").as_deref() {
        Ok("lift") => "lift_parity".into(),
        Ok("dual") => "dual_parity".into(),
        _ => "drag_parity".into(),
    }
}

fn device(values: &[f64]) -> Result<Device> {
    let (spring, amplitude_v) = (values[0], values[1]);
    let configuration = configuration();
    let free = configuration != "drag_parity";
    let offset_v = if free { amplitude_v } else { 100.0 };
    Device::new(DeviceSpec {
        wings: vec![
            wing(
                [49.0, 50.5, 1.56, 4.2],
                [46.8, 0.587, 17.5, 0.712],
                spring,
                free,
            )?,
            wing(
                [40.6, 42.0, 1.43, 3.38],
                [28.7, 0.419, 10.6, 0.787],
                spring,
                free,
            )?,
        ],
        constraints: Constraints::configuration(&configuration)?,
        transmission: Some(Transmission::new(
            Drivetrain::LinearDifferential(LinearDifferential::new(
                35f64.to_radians() / 0.2,
                2.5,
                1.0,
            )?),
            0.0,
        )?),
        actuator: Some(Actuator::new(
            paritysim_dynamics::actuator::THESIS_FORCE_PER_VOLT,
            paritysim_dynamics::actuator::THESIS_STIFFNESS,
            Waveform::sine(amplitude_v, 110.0, offset_v, 0.0)?,
            DcOffset::Ignore,
        )?),
        formulation: Formulation::Auto,
    })
}

fn env<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

fn main() {
    let grid: usize = env("GRID", 16);
    let threads: usize = env("THREADS", 1);
    let repeat: usize = env("REPEAT", 3);
    // §3.4: hinge 1–4 mN·mm/rad × 60–100 V; §2.5: deviation spring 8–12 × 80–100 V.
    let ((s0, s1), (v0, v1)) = if configuration() == "drag_parity" {
        ((1.0, 4.0), (60.0, 100.0))
    } else {
        ((8.0, 12.0), (80.0, 100.0))
    };
    let table = Grid::new()
        .axis(
            "spring",
            (0..grid).map(|i| s0 + (s1 - s0) * i as f64 / (grid - 1) as f64),
        )
        .and_then(|g| {
            g.axis(
                "amplitude_v",
                (0..grid).map(|i| v0 + (v1 - v0) * i as f64 / (grid - 1) as f64),
            )
        })
        .unwrap()
        .table();
    let settings = SweepSettings {
        threads: Some(threads),
        metrics: Some(METRICS.iter().map(|s| s.to_string()).collect()),
        keep_cycle: false,
    };
    let options = SimulationOptions {
        samples_per_cycle: 200,
        ..Default::default()
    };
    for _ in 0..repeat {
        let before = paritysim_dynamics::lanes::points_completed_in_lanes();
        let start = Instant::now();
        let r = sweep(&table, device, &options, &settings, &SweepControl::new()).unwrap();
        let ms = start.elapsed().as_secs_f64() * 1e3 / table.len() as f64;
        let in_lanes = paritysim_dynamics::lanes::points_completed_in_lanes() - before;
        if std::env::var("VERBOSE").is_ok() {
            for row in &r.rows {
                match &row.outcome {
                    Ok(o) => println!(
                        "point {}: cycles {} residual {:.1e} converged {} monodromy {}",
                        row.index,
                        o.cycles_run,
                        o.residual,
                        o.converged,
                        o.monodromy.is_some()
                    ),
                    Err(e) => println!("point {}: {e}", row.index),
                }
            }
        }
        let checksum: f64 = r
            .rows
            .iter()
            .map(|row| row.outcome.as_ref().map_or(0.0, |o| o.metrics.iter().sum()))
            .sum();
        println!(
            "{ms:.3} ms per point ({} points, {in_lanes} in lanes, checksum {checksum:.12e})",
            table.len()
        );
    }
}
