//! One §3.3 Drag PARITY trial (linear map eq. 2.15, T = L = 2.5, K2 = 10, 1-Cut, 120 mN; 20
//! wingbeats at rtol 1e-8, 4000 samples in the last cycle), repeated `N` times (first
//! argument, default 20): a fixed workload for callgrind
//! (`valgrind --tool=callgrind target/release/examples/trial 5`) and wall-clock comparisons
//! against older engines. Second argument `metrics` builds no trajectory column.
//!
//! Environment: `SAMPLES` overrides the 4000 samples, `RTOL` the relative tolerance,
//! `METRICS` (with `metrics`) lists the asked metrics, and
//! `DEVICE` picks another device for the same workload: `rotating` (§3.4 Drag PARITY, Table
//! 3.3 1-Cut wings, blade element, hinge spring), `lift` / `dual` (§2.5 Lift / Dual PARITY on
//! those wings: free deviation θ with a deviation spring and the tunable hinge, as
//! `paritysim.devices`' `sreetharan2012_2_5_*_parity_1cut`). `STEADY=default` runs the
//! shipped devices' options instead (default shooting, 200 samples, `max_cycles` 200);
//! `STATS=1` also prints the run's cycles, convergence and the transient's step counters,
//! `PRINT=1` the last run's metrics.

use nalgebra::{Matrix3, Vector3};
use paritysim_constraints::Constraints;
use paritysim_dynamics::device::{Device, DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::{
    Actuator, JointSpring, SimulationOptions, Waveform, Wing, WingAero, simulate,
};
use paritysim_kinematics::drivetrain::LinearDifferential;
use paritysim_kinematics::{Drivetrain, SphericalShoulder};

fn wing(omega: f64) -> Wing {
    let sh = SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0).unwrap();
    Wing::new(
        sh,
        Matrix3::from_diagonal(&Vector3::new(29.0, 29.0, 1.0)),
        [JointSpring::default(); 6],
        WingAero::stroke_drag(omega, 3.4609).unwrap(),
    )
    .unwrap()
}

/// A Table 3.3 wing: blade element (Ω1..Ω4), hinge spring 2.53 mN·mm/rad; with
/// `free_deviation`, the §2.5 deviation spring (10 mN·mm/rad) and tunable hinge.
fn rotating_wing(inertia: [f64; 4], omegas: [f64; 4], free_deviation: bool) -> Wing {
    use paritysim_aero::{BladeElementModel, CoefficientSet, Omegas};
    let [ixx, iyy, izz, ixz] = inertia;
    let sh = SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0).unwrap();
    let mut springs = [JointSpring::default(); 6];
    let blade = BladeElementModel::new(
        Omegas::new(omegas[0], omegas[1], omegas[2], omegas[3]).unwrap(),
        CoefficientSet::default(),
    )
    .unwrap();
    let matrix = Matrix3::new(ixx, 0.0, ixz, 0.0, iyy, 0.0, ixz, 0.0, izz);
    if !free_deviation {
        springs[5] = JointSpring::linear(2.53, 0.0).unwrap();
        return Wing::new(sh, matrix, springs, WingAero::BladeElement(blade)).unwrap();
    }
    springs[3] = JointSpring::linear(10.0, 0.0).unwrap();
    Wing::new(sh, matrix, springs, WingAero::BladeElement(blade))
        .unwrap()
        .with_tunable_hinge(
            paritysim_dynamics::TunableHinge::new(2.533928021702924, 0.0, 20.0).unwrap(),
        )
}

/// §3.4 (`configuration` drag_parity) or §2.5 (lift_parity / dual_parity) on the Table 3.3
/// 1-Cut wings, eq. 2.15 with ±200 µm → ±35°, V = 100 + 100 sin(2π 110 Hz t), DC ignored.
fn rotating_device(configuration: &str) -> Device {
    let free = configuration != "drag_parity";
    Device::new(DeviceSpec {
        wings: vec![
            rotating_wing([49.0, 50.5, 1.56, 4.2], [46.8, 0.587, 17.5, 0.712], free),
            rotating_wing([40.6, 42.0, 1.43, 3.38], [28.7, 0.419, 10.6, 0.787], free),
        ],
        constraints: Constraints::configuration(configuration).unwrap(),
        transmission: Some(
            Transmission::new(
                Drivetrain::LinearDifferential(
                    LinearDifferential::new(35f64.to_radians() / 0.2, 2.5, 1.0).unwrap(),
                ),
                0.0,
            )
            .unwrap(),
        ),
        actuator: Some(
            Actuator::new(
                paritysim_dynamics::actuator::THESIS_FORCE_PER_VOLT,
                paritysim_dynamics::actuator::THESIS_STIFFNESS,
                Waveform::sine(100.0, 110.0, 100.0, 0.0).unwrap(),
                paritysim_dynamics::DcOffset::Ignore,
            )
            .unwrap(),
        ),
        formulation: Formulation::Auto,
    })
    .unwrap()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let repeat: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(20);
    let metrics_only = args.next().is_some_and(|a| a == "metrics");
    let which = std::env::var("DEVICE").unwrap_or_default();
    let device = match which.as_str() {
        "rotating" => Some(rotating_device("drag_parity")),
        "lift" => Some(rotating_device("lift_parity")),
        "dual" => Some(rotating_device("dual_parity")),
        _ => None,
    };
    let device = device.unwrap_or_else(|| {
        Device::new(DeviceSpec {
            wings: vec![wing(0.6 * 31.3), wing(31.3)],
            constraints: Constraints::configuration("drag_parity_fixed").unwrap(),
            transmission: Some(
                Transmission::new(
                    Drivetrain::LinearDifferential(LinearDifferential::new(2.5, 2.5, 1.0).unwrap()),
                    10.0,
                )
                .unwrap(),
            ),
            actuator: Some(Actuator::thesis(
                Waveform::sine(100.0, 110.0, 0.0, 0.0).unwrap(),
            )),
            formulation: Formulation::Auto,
        })
        .unwrap()
    });
    #[allow(unused_mut)]
    let mut options = SimulationOptions {
        rtol: std::env::var("RTOL")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(1e-8),
        atol: 1e-10,
        min_cycles: 19,
        max_cycles: 19,
        steady_tol: 1e-30,
        samples_per_cycle: std::env::var("SAMPLES")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(4000),
        ..Default::default()
    };
    // STEADY-LINE: the fixed workload is 20 wingbeats of transient, whatever the default.
    options.steady_state = paritysim_dynamics::SteadyState::Transient;
    if metrics_only {
        // COLUMNS-LINE (absent in engines without streamed metrics)
        options.columns = Some(Vec::new());
        // `METRICS=a,b,...`: only these metrics (vs_jax.py's trial asks the five of Table 3.2).
        if let Ok(names) = std::env::var("METRICS") {
            options.metrics = Some(names.split(',').map(String::from).collect());
        }
        // STEADY-LINE: `STEADY=shooting` uses Newton shooting (default cycles as configured).
        if std::env::var("STEADY").is_ok_and(|s| s == "shooting") {
            options.steady_state = paritysim_dynamics::SteadyState::Shooting;
            options.min_cycles = 3;
            options.max_cycles = 300;
            options.steady_tol = 1e-7;
        }
    }
    if std::env::var("STEADY").is_ok_and(|s| s == "default") {
        let default = SimulationOptions::default();
        // `RTOL` (with atol 1e-2 × rtol as the shipped options) for a tight reference.
        let rtol = std::env::var("RTOL")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(default.rtol);
        options = SimulationOptions {
            rtol,
            atol: 1e-2 * rtol,
            max_cycles: 200,
            columns: options.columns.clone(),
            metrics: options.metrics.clone(),
            ..Default::default()
        };
    }
    let start = std::time::Instant::now();
    let mut check = 0.0;
    let mut last = None;
    for _ in 0..repeat {
        let r = simulate(&device, &options).unwrap();
        check += r.metrics[0].1;
        last = Some(r);
    }
    let ms = start.elapsed().as_secs_f64() * 1e3 / repeat as f64;
    let n_dof = device.n_dof();
    println!("{ms:.3} ms per trial (checksum {check:.12e}; {n_dof} DOF)");
    if let (Ok(_), Some(r)) = (std::env::var("STATS"), &last) {
        println!(
            "run: {} cycles, converged {}, orbit cycles {}, residual {:e}, shooting {}",
            r.cycles_run,
            r.converged,
            r.orbit_cycles,
            r.residual,
            r.monodromy.is_some()
        );
        let moduli: Vec<String> = r
            .multipliers
            .iter()
            .map(|m| format!("{:.3e}", m.norm()))
            .collect();
        println!("multiplier moduli: {}", moduli.join(" "));
    }
    if let (Ok(_), Some(r)) = (std::env::var("PRINT"), &last) {
        for (name, value) in &r.metrics {
            println!("{name} {value:.17e}");
        }
    }
    if std::env::var("STATS").is_ok() {
        // The transient's step counters (the 19 cycles before the recorded one).
        use paritysim_dynamics::integrate::RungeKutta;
        let rk = RungeKutta::new(
            options.method,
            options.rtol,
            options.atol,
            options.max_steps,
        )
        .unwrap()
        .with_work(false);
        let y0 = device
            .state_from(
                device.spec().constraints.particular(),
                &paritysim_constraints::Vec6::zeros(),
            )
            .unwrap();
        let t_end = 19.0 * device.period().unwrap();
        let (_, stats) = rk
            .integrate_counted(&device, 0.0, &y0, t_end, &[], &mut |_, _, _| Ok(()))
            .unwrap();
        println!(
            "transient: {} rhs calls, {} accepted, {} rejected steps",
            stats.rhs_calls, stats.accepted, stats.rejected
        );
    }
}
