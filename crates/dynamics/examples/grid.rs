//! The `benchmarks/vs_jax.py` design sweep without Python: the §3.3 Drag PARITY device of issue
//! 12 (linear map eq. 2.15, T = L = 2.5, I = 29, drag C = 1, Ω^R = 31.3, K1 = 467, 120 mN at
//! 110 Hz) on a `GRID × GRID` grid over Ω^L/Ω^R ∈ [0.3, 1] × K2 ∈ [0, 100], Table 3.2
//! metrics of the last cycle from `SAMPLES` samples (default 4000).
//!
//! Prints ms per point and the worst error against an rtol 1e-12 shooting reference (cached in
//! `$TMPDIR/paritysim-grid-reference-<grid>-<samples>.txt`). A fixed workload for callgrind:
//! `GRID=8 THREADS=1 valgrind --tool=callgrind target/release/examples/grid`.
//!
//! Environment: `GRID` (32), `THREADS` (2), `SAMPLES` (4000), `RTOL` (1e-8; atol = rtol/100),
//! `STEADY` (`shooting` or `transient`; default: the engine's default), `REPEAT` (1),
//! `METHOD` (`dop853`/`dopri5`), `RANGE=a..b` (points a..b as one single-thread sweep; with
//! `DUMP` every metric of every point, exactly), `PARITYSIM_LANES` (SIMD lane width, 1 = scalar).

use std::time::Instant;

use nalgebra::{Matrix3, Vector3};
use paritysim_constraints::Constraints;
use paritysim_dynamics::device::{Device, DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::integrate::Method;
use paritysim_dynamics::sweep::{Grid, SweepControl, SweepSettings, sweep};
use paritysim_dynamics::{
    Actuator, JointSpring, Result, SimulationOptions, SteadyState, Waveform, Wing, WingAero,
};
use paritysim_kinematics::drivetrain::LinearDifferential;
use paritysim_kinematics::{Drivetrain, SphericalShoulder};

const OMEGA_R: f64 = 31.3;
const METRICS: [&str; 5] = [
    "delta_tau_peak",
    "tau_r_peak",
    "tau_l_peak",
    "imbalance_instantaneous_pct",
    "imbalance_peak_pct",
];

fn wing(omega: f64) -> Result<Wing> {
    Wing::new(
        SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0)?,
        Matrix3::from_diagonal(&Vector3::new(29.0, 29.0, 1.0)),
        [JointSpring::default(); 6],
        WingAero::stroke_drag(omega, 1.0)?,
    )
}

fn device(values: &[f64]) -> Result<Device> {
    Device::new(DeviceSpec {
        wings: vec![wing(values[0] * OMEGA_R)?, wing(OMEGA_R)?],
        constraints: Constraints::configuration("drag_parity_fixed")?,
        transmission: Some(Transmission::new(
            Drivetrain::LinearDifferential(LinearDifferential::new(2.5, 2.5, 1.0)?),
            values[1],
        )?),
        actuator: Some(Actuator::thesis(Waveform::sine(100.0, 110.0, 0.0, 0.0)?)),
        formulation: Formulation::Auto,
    })
}

fn env<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

fn run(grid: usize, threads: usize, options: &SimulationOptions) -> (f64, Vec<[f64; 5]>, f64) {
    let table = Grid::new()
        .axis(
            "omega_ratio",
            (0..grid).map(|i| 0.3 + 0.7 * i as f64 / (grid - 1) as f64),
        )
        .and_then(|g| {
            g.axis(
                "k2",
                (0..grid).map(|i| 100.0 * i as f64 / (grid - 1) as f64),
            )
        })
        .unwrap()
        .table();
    let settings = SweepSettings {
        threads: Some(threads),
        metrics: Some(METRICS.iter().map(|s| s.to_string()).collect()),
        keep_cycle: false,
    };
    let start = Instant::now();
    let r = sweep(&table, device, options, &settings, &SweepControl::new()).unwrap();
    let ms = start.elapsed().as_secs_f64() * 1e3 / table.len() as f64;
    let mut cycles = 0.0;
    let rows = r
        .rows
        .iter()
        .map(|row| {
            let o = row.outcome.as_ref().expect("every point runs");
            cycles += o.cycles_run as f64;
            if std::env::var("VERBOSE").is_ok_and(|v| v == "2") {
                println!(
                    "point {}: cycles {} residual {:.2e} converged {}",
                    row.index, o.cycles_run, o.residual, o.converged
                );
            }
            [
                o.metrics[0],
                o.metrics[1],
                o.metrics[2],
                o.metrics[3],
                o.metrics[4],
            ]
        })
        .collect();
    (ms, rows, cycles / table.len() as f64)
}

fn main() {
    let grid: usize = env("GRID", 32);
    let threads: usize = env("THREADS", 2);
    let samples: usize = env("SAMPLES", 4000);
    let rtol: f64 = env("RTOL", 1e-8);
    let repeat: usize = env("REPEAT", 1);
    let mut options = SimulationOptions {
        rtol,
        atol: rtol * 1e-2,
        samples_per_cycle: samples,
        ..Default::default()
    };
    match std::env::var("STEADY").as_deref() {
        Ok("shooting") => options.steady_state = SteadyState::Shooting,
        Ok("transient") => options.steady_state = SteadyState::Transient,
        _ => {}
    }
    if std::env::var("METHOD").is_ok_and(|m| m == "dopri5") {
        options.method = Method::Dopri5;
    }
    let cache = std::env::temp_dir().join(format!("paritysim-grid-reference-{grid}-{samples}.txt"));
    let reference: Vec<[f64; 5]> = match std::fs::read_to_string(&cache) {
        Ok(text) => text
            .lines()
            .map(|l| {
                let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
                [v[0], v[1], v[2], v[3], v[4]]
            })
            .collect(),
        Err(_) => {
            let reference_options = SimulationOptions {
                rtol: 1e-12,
                atol: 1e-14,
                samples_per_cycle: samples,
                steady_state: SteadyState::Shooting,
                steady_tol: 1e-9,
                ..Default::default()
            };
            let (_, rows, _) = run(grid, threads, &reference_options);
            let text: String = rows
                .iter()
                .map(|r| format!("{:e} {:e} {:e} {:e} {:e}\n", r[0], r[1], r[2], r[3], r[4]))
                .collect();
            std::fs::write(&cache, text).unwrap();
            rows
        }
    };
    if let Ok(range) = std::env::var("RANGE") {
        // Points a..b of the grid as one sweep (a continuation chain when a = 16k).
        let (a, b) = range.split_once("..").unwrap();
        let (a, b): (usize, usize) = (a.parse().unwrap(), b.parse().unwrap());
        let rows: Vec<Vec<f64>> = (a..b)
            .map(|p| {
                vec![
                    0.3 + 0.7 * (p / grid) as f64 / (grid - 1) as f64,
                    100.0 * (p % grid) as f64 / (grid - 1) as f64,
                ]
            })
            .collect();
        let table =
            paritysim_dynamics::sweep::ParameterTable::new(vec!["r".into(), "k2".into()], rows)
                .unwrap();
        let settings = SweepSettings {
            threads: Some(1),
            metrics: Some(METRICS.iter().map(|s| s.to_string()).collect()),
            keep_cycle: false,
        };
        let r = sweep(&table, device, &options, &settings, &SweepControl::new()).unwrap();
        if std::env::var("DUMP").is_ok() {
            // Every metric of every point, round-trip exact (compare lane widths bit for bit).
            for row in &r.rows {
                let o = row.outcome.as_ref().unwrap();
                println!("{:?} {} {:e}", o.metrics, o.cycles_run, o.residual);
            }
            return;
        }
        for (row, p) in r.rows.iter().zip(a..b) {
            let o = row.outcome.as_ref().unwrap();
            let e = (0..3)
                .map(|k| (o.metrics[k] - reference[p][k]).abs() / reference[p][1])
                .fold(0.0, f64::max);
            println!(
                "point {p}: cycles {} residual {:.2e} torque err {e:.2e}",
                o.cycles_run, o.residual
            );
        }
        return;
    }
    if let Ok(point) = std::env::var("POINT") {
        let point: usize = point.parse().unwrap();
        let values = [
            0.3 + 0.7 * (point / grid) as f64 / (grid - 1) as f64,
            100.0 * (point % grid) as f64 / (grid - 1) as f64,
        ];
        let d = device(&values).unwrap();
        for (rtol, steady, tol) in [
            (1e-8, SteadyState::Shooting, 1e-7),
            (1e-9, SteadyState::Shooting, 1e-7),
            (1e-10, SteadyState::Shooting, 1e-7),
            (1e-12, SteadyState::Shooting, 1e-9),
            (1e-12, SteadyState::Shooting, 1e-11),
            (1e-8, SteadyState::Transient, 1e-7),
            (1e-8, SteadyState::Transient, 1e-10),
            (1e-12, SteadyState::Transient, 1e-12),
        ] {
            let o = SimulationOptions {
                rtol,
                atol: rtol * 1e-2,
                samples_per_cycle: samples,
                steady_state: steady,
                steady_tol: tol,
                max_cycles: 20000,
                columns: Some(vec![]),
                ..Default::default()
            };
            let r = paritysim_dynamics::simulate(&d, &o).unwrap();
            let m = |n: &str| r.metrics.iter().find(|(k, _)| k == n).unwrap().1;
            println!(
                "rtol {rtol:e} {steady:?} tol {tol:e}: cycles {} residual {:.2e} tau_r {:.12e} tau_l {:.12e} delta {:.12e} mult {:?}",
                r.cycles_run,
                r.residual,
                m("tau_r_peak"),
                m("tau_l_peak"),
                m("delta_tau_peak"),
                r.multipliers.iter().map(|c| c.norm()).collect::<Vec<_>>()
            );
        }
        println!("reference: {:?}", reference[point]);
        return;
    }
    for _ in 0..repeat {
        let (ms, rows, cycles) = run(grid, threads, &options);
        let (mut torque, mut pct): (f64, f64) = (0.0, 0.0);
        let mut worst = (0, 0.0);
        for (i, (v, r)) in rows.iter().zip(&reference).enumerate() {
            for k in 0..3 {
                let e = (v[k] - r[k]).abs() / r[1].abs();
                if e > worst.1 {
                    worst = (i, e);
                }
                torque = torque.max(e);
            }
            for k in 3..5 {
                pct = pct.max((v[k] - r[k]).abs());
            }
        }
        if std::env::var("VERBOSE").is_ok() {
            println!(
                "worst torque error at point {} (row {}, column {})",
                worst.0,
                worst.0 / grid,
                worst.0 % grid
            );
        }
        println!(
            "{grid}x{grid}, {threads} threads: {ms:.4} ms/point, {cycles:.2} cycles/point; \
             torque err {torque:.2e}, pct err {pct:.2e}"
        );
    }
}
