//! One §3.3 Drag PARITY trial (linear map eq. 2.15, T = L = 2.5, K2 = 10, 1-Cut, 120 mN) (20 wingbeats at rtol 1e-8, 4000 samples in the last cycle),
//! repeated `N` times (first argument, default 20): a fixed workload for callgrind
//! (`valgrind --tool=callgrind target/release/examples/trial 5`) and wall-clock comparisons
//! against older engines. Second argument `metrics` builds no trajectory column; `SAMPLES`
//! (environment) overrides the 4000 samples.

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

fn main() {
    let mut args = std::env::args().skip(1);
    let repeat: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(20);
    let metrics_only = args.next().is_some_and(|a| a == "metrics");
    let device = Device::new(DeviceSpec {
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
    .unwrap();
    #[allow(unused_mut)]
    let mut options = SimulationOptions {
        rtol: 1e-8,
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
        // STEADY-LINE: `STEADY=shooting` uses Newton shooting (default cycles as configured).
        if std::env::var("STEADY").is_ok_and(|s| s == "shooting") {
            options.steady_state = paritysim_dynamics::SteadyState::Shooting;
            options.min_cycles = 3;
            options.max_cycles = 300;
            options.steady_tol = 1e-7;
        }
    }
    let start = std::time::Instant::now();
    let mut check = 0.0;
    for _ in 0..repeat {
        let r = simulate(&device, &options).unwrap();
        check += r.metrics[0].1;
    }
    let ms = start.elapsed().as_secs_f64() * 1e3 / repeat as f64;
    println!("{ms:.3} ms per trial (checksum {check:.12e})");
}
