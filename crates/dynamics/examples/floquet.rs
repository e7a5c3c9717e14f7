//! The Floquet analysis of the §3.3 Drag PARITY device (rod-crank linkage, Ω = 31.3, 100 V,
//! 110 Hz; `K2` first argument, default 500; `CUT=1` cuts the left wing to Ω = 0.599 · 31.3 at
//! 70 V), repeated `N` times (second argument, default 1): a fixed workload for callgrind
//! (`valgrind --tool=callgrind target/release/examples/floquet 500 1`). Prints the orbit's
//! cost counters and the multipliers.

use nalgebra::{Matrix3, Vector3};
use paritysim_constraints::Constraints;
use paritysim_dynamics::device::{Device, DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::floquet::{ShootingOptions, eigenvalues, floquet};
use paritysim_dynamics::integrate::{Method, RungeKutta};
use paritysim_dynamics::{Actuator, JointSpring, Waveform, Wing, WingAero};
use paritysim_kinematics::drivetrain::LinkageDifferential;
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
    let k2: f64 = args.next().map_or(500.0, |a| a.parse().expect("K2"));
    let repeats: usize = args.next().map_or(1, |a| a.parse().expect("N"));
    let cut = std::env::var("CUT").is_ok_and(|v| v == "1");
    let (omega_left, volts) = if cut {
        (0.599 * 31.3, 70.0)
    } else {
        (31.3, 100.0)
    };
    let device = Device::new(DeviceSpec {
        wings: vec![wing(omega_left), wing(31.3)],
        constraints: Constraints::configuration("drag_parity_fixed").unwrap(),
        transmission: Some(
            Transmission::new(
                Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
                k2,
            )
            .unwrap(),
        ),
        actuator: Some(Actuator::thesis(
            Waveform::sine(volts, 110.0, 0.0, 0.0).unwrap(),
        )),
        formulation: Formulation::Auto,
    })
    .unwrap();
    let options = ShootingOptions::default();
    for _ in 0..repeats {
        let f = floquet(&device, &options).unwrap();
        println!(
            "newton {} cycles {} residual {:e} rho {:.12}",
            f.orbit.newton_iterations,
            f.orbit.cycles_simulated,
            f.orbit.residual,
            f.spectral_radius()
        );
        for m in &f.multipliers {
            println!("  {m:.12}");
        }
        println!("  monodromy uncertainty {:e}", f.monodromy_uncertainty);
        if std::env::var("REF").is_ok_and(|v| v == "1") {
            // A reference: the adaptive variational period at tighter tolerances.
            for rtol in [1e-12, 1e-13, 1e-14] {
                let rk = RungeKutta::new(Method::Dop853, rtol, rtol * 1e-2, 10_000_000).unwrap();
                let (_, m) = rk
                    .flow_with_sensitivity(&device, 0.0, &f.orbit.state, f.orbit.period)
                    .unwrap();
                println!(
                    "  rtol {rtol:e}: rho {:.12}",
                    eigenvalues(&m).unwrap()[0].norm()
                );
            }
        }
    }
}
