//! The default steady state (Newton shooting) on the shipped §3.4 devices: mirror symmetry of
//! identical rotating wings, where the differential stroke offset is a neutral direction.

use paritysim_dynamics::{SteadyState, simulate};
use paritysim_spec::from_toml;

fn shipped_device(name: &str) -> String {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    std::fs::read_to_string(root.join("python/paritysim/devices").join(name)).unwrap()
}

fn largest_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn largest(a: &[f64]) -> f64 {
    a.iter().map(|x| x.abs()).fold(0.0, f64::max)
}

#[test]
fn shooting_keeps_identical_rotating_wings_mirror_images() {
    // The §3.4 PARITY with both wings the right one: linear differential with K2 = 0, so any
    // constant differential stroke offset is an orbit too (a Floquet multiplier 1). The
    // mirror-symmetric start must give the mirror-symmetric orbit: with the former SVD cutoff
    // (1e-10 of the largest singular value, which the variational Jacobian's 2e-10 for the
    // neutral direction may or may not clear) Newton moved 8.4e-4 rad along it here at a hinge
    // stiffness of 2.0 mN·mm/rad (7e-4 at 2.5 with the Python trial's options).
    let (mut spec, _) = from_toml(&shipped_device("sreetharan2012_3_4_parity.toml")).unwrap();
    spec.wings[0] = spec.wings[1].clone();
    for hinge in [2.5, 2.0, 3.0] {
        for wing in &mut spec.wings {
            wing.springs.hinge.stiffness = hinge;
        }
        let (device, options) = spec.model().unwrap();
        assert_eq!(options.steady_state, SteadyState::Shooting, "the default");
        let r = simulate(&device, &options).unwrap();
        assert!(r.converged);
        // Shooting found the orbit itself (no transient fallback), and it has the neutral mode.
        assert!(
            r.monodromy.is_some(),
            "the shooting's orbit, not the fallback's"
        );
        let neutral = r.multipliers.iter().any(|m| (m - 1.0).norm() < 1e-6);
        assert!(neutral, "a multiplier 1: {:?}", r.multipliers);
        let col = |name: &str| r.trajectory.column(name).unwrap();
        for angle in ["phi", "psi", "phi_dot", "psi_dot"] {
            let (left, right) = (
                col(&format!("left_{angle}")),
                col(&format!("right_{angle}")),
            );
            let d = largest_difference(left, right);
            assert!(
                d < 1e-9 * largest(right).max(1.0),
                "hinge {hinge}, {angle}: {d:e}"
            );
        }
        let scale = largest(col("right_roll_aero"));
        for net in ["roll_total", "yaw_total"] {
            let v = largest(col(net));
            assert!(
                v < 1e-7 * scale,
                "hinge {hinge}, {net}: {v:e} vs scale {scale}"
            );
        }
    }
}
