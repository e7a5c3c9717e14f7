//! A §3.4 design sweep without Python: the rotating-wing Drag PARITY device (Table 3.3 1-Cut
//! wings, blade element, eq. 2.15 with ±200 µm → ±35°, `100 + V sin(2π 110 Hz t)`) on a
//! `GRID × GRID` grid over the hinge stiffness ∈ [1, 4] mN·mm/rad × drive amplitude V ∈
//! [60, 100], stroke and rotation metrics of the last cycle from 200 samples (the shipped
//! devices' default). Prints ms per point and how many points ran in SIMD lanes.
//!
//! Environment: `GRID` (16), `THREADS` (1), `REPEAT` (3), `PARITYSIM_LANES` (lane width,
//! 1 = scalar). Compare `PARITYSIM_LANES=1` and `=4` (issue 12 item 6; docs/findings.md §24).

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

fn wing(inertia: [f64; 4], omegas: [f64; 4], hinge: f64) -> Result<Wing> {
    let [ixx, iyy, izz, ixz] = inertia;
    let mut springs = [JointSpring::default(); 6];
    springs[5] = JointSpring::linear(hinge, 0.0)?;
    let blade = BladeElementModel::new(
        Omegas::new(omegas[0], omegas[1], omegas[2], omegas[3])?,
        CoefficientSet::default(),
    )?;
    Wing::new(
        SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0)?,
        Matrix3::new(ixx, 0.0, ixz, 0.0, iyy, 0.0, ixz, 0.0, izz),
        springs,
        WingAero::BladeElement(blade),
    )
}

fn device(values: &[f64]) -> Result<Device> {
    let (hinge, amplitude_v) = (values[0], values[1]);
    Device::new(DeviceSpec {
        wings: vec![
            wing([49.0, 50.5, 1.56, 4.2], [46.8, 0.587, 17.5, 0.712], hinge)?,
            wing([40.6, 42.0, 1.43, 3.38], [28.7, 0.419, 10.6, 0.787], hinge)?,
        ],
        constraints: Constraints::configuration("drag_parity")?,
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
            Waveform::sine(100.0, 110.0, amplitude_v, 0.0)?,
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
    let table = Grid::new()
        .axis(
            "hinge",
            (0..grid).map(|i| 1.0 + 3.0 * i as f64 / (grid - 1) as f64),
        )
        .and_then(|g| {
            g.axis(
                "amplitude_v",
                (0..grid).map(|i| 60.0 + 40.0 * i as f64 / (grid - 1) as f64),
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
