//! Integration tests of paritysim-dynamics: each checks physics against an independent
//! formulation or a conservation law, never against recorded outputs.

#[path = "dynamics/continuation.rs"]
mod continuation;
#[path = "dynamics/drive.rs"]
mod drive;
#[path = "dynamics/floquet/mod.rs"]
mod floquet;
#[path = "dynamics/formulations.rs"]
mod formulations;
#[path = "dynamics/lanes.rs"]
mod lanes;
#[path = "dynamics/lean.rs"]
mod lean;
#[path = "dynamics/linear_jacobian.rs"]
mod linear_jacobian;
#[path = "dynamics/mass_energy.rs"]
mod mass_energy;
#[path = "dynamics/metrics.rs"]
mod metrics;
#[path = "dynamics/polynomial.rs"]
mod polynomial;
#[path = "dynamics/sensitivity.rs"]
mod sensitivity;
#[path = "dynamics/steady_state.rs"]
mod steady_state;
#[path = "dynamics/sweep.rs"]
mod sweep;
#[path = "dynamics/wing_terms.rs"]
mod wing_terms;

use approx::assert_relative_eq;
use nalgebra::{Matrix3, Vector3};
use paritysim_constraints::{Constraints, Vec6};
use paritysim_dynamics::device::{Device, DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::simulate::PerturbTarget;
use paritysim_dynamics::{
    Actuator, DcOffset, JointSpring, Perturbation, SimulationOptions, Waveform, Wing, WingAero,
    simulate,
};
use paritysim_kinematics::drivetrain::{HmfFourBar, LinkageDifferential};
use paritysim_kinematics::{Drivetrain, RodCrank, SphericalShoulder};

fn shoulder(a2: f64, a3: f64) -> SphericalShoulder {
    SphericalShoulder::new(a2.to_radians(), a3.to_radians()).unwrap()
}

/// A full, positive-definite inertia tensor with Ixz ≠ 0 (a Table 3.3-like wing, mg·mm²).
fn full_inertia() -> Matrix3<f64> {
    Matrix3::new(29.0, 0.4, -3.1, 0.4, 30.5, 0.7, -3.1, 0.7, 2.2)
}

fn springs(k: [f64; 6]) -> [JointSpring; 6] {
    k.map(|k| JointSpring::linear(k, 0.0).unwrap())
}

/// A fixed-wing study wing: stroke inertia 29 mg·mm² (§3.3.2), no joint springs.
fn fixed_wing(aero: WingAero) -> Wing {
    let inertia = Matrix3::from_diagonal(&Vector3::new(29.0, 29.0, 1.0));
    Wing::new(
        shoulder(90.0, 0.0),
        inertia,
        [JointSpring::default(); 6],
        aero,
    )
    .unwrap()
}

/// Quadratic stroke drag with unit coefficient (eq. 2.16).
fn drag(omega: f64) -> WingAero {
    WingAero::stroke_drag(omega, 1.0).unwrap()
}

/// Two wings on a drivetrain driven by an actuator.
fn two_wing_device(
    wings: [Wing; 2],
    config: &str,
    drivetrain: Drivetrain,
    k2: f64,
    actuator: Actuator,
    formulation: Formulation,
) -> Device {
    Device::new(DeviceSpec {
        wings: wings.to_vec(),
        constraints: Constraints::configuration(config).unwrap(),
        transmission: Some(Transmission::new(drivetrain, k2).unwrap()),
        actuator: Some(actuator),
        formulation,
    })
    .unwrap()
}

fn hmf_drivetrain() -> Drivetrain {
    Drivetrain::HmfFourBar(HmfFourBar::new(RodCrank::THESIS))
}

fn free_wing_device(formulation: Formulation) -> Device {
    let wing = Wing::new(
        shoulder(120.0, 60.0),
        full_inertia(),
        springs([20.0, 3.0, 2.0, 15.0, 4.0, 1.5]),
        WingAero::None,
    )
    .unwrap();
    Device::new(DeviceSpec {
        wings: vec![wing],
        constraints: Constraints::none(3).unwrap(),
        transmission: None,
        actuator: None,
        formulation,
    })
    .unwrap()
}

fn parity_device(omega_left: f64, k2: f64, config: &str, formulation: Formulation) -> Device {
    parity_device_with(
        omega_left,
        k2,
        config,
        formulation,
        Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
    )
}

/// Long runs use eq. 2.15 (no reach limit): with a soft K2 the start-up transient of the
/// whippletree is slow and large.
fn linear_parity(omega_left: f64, formulation: Formulation) -> Device {
    let linear = Drivetrain::LinearDifferential(
        paritysim_kinematics::drivetrain::LinearDifferential::new(2.5, 2.5, 1.0).unwrap(),
    );
    parity_device_with(omega_left, 20.0, "drag_parity_fixed", formulation, linear)
}

fn parity_device_with(
    omega_left: f64,
    k2: f64,
    config: &str,
    formulation: Formulation,
    drivetrain: Drivetrain,
) -> Device {
    let wing = |omega: f64| fixed_wing(drag(omega));
    // 50 V keeps the unit-coefficient drag device inside the linkage's reach (about ±48°).
    let actuator = Actuator::thesis(Waveform::sine(50.0, 110.0, 0.0, 0.0).unwrap());
    two_wing_device(
        [wing(omega_left), wing(31.3)],
        config,
        drivetrain,
        k2,
        actuator,
        formulation,
    )
}

// A global allocator needs `unsafe impl`; this test-only module is the one place that allows it.
#[allow(unsafe_code)]
mod allocation {
    //! "No heap allocation inside the RHS", checked with a counting global allocator that only
    //! counts on the current thread while a flag is set (tests run on several threads).
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::cell::Cell;

    thread_local! {
        static COUNTING: Cell<bool> = const { Cell::new(false) };
        static COUNT: Cell<usize> = const { Cell::new(0) };
    }

    struct Counting;

    unsafe impl GlobalAlloc for Counting {
        unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
            if COUNTING.with(|c| c.get()) {
                COUNT.with(|n| n.set(n.get() + 1));
            }
            unsafe { System.alloc(layout) }
        }
        unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
            unsafe { System.dealloc(ptr, layout) }
        }
    }

    #[global_allocator]
    static ALLOCATOR: Counting = Counting;

    /// Number of allocations made by `f` on this thread.
    pub fn count<R>(f: impl FnOnce() -> R) -> (R, usize) {
        COUNT.with(|n| n.set(0));
        COUNTING.with(|c| c.set(true));
        let r = f();
        COUNTING.with(|c| c.set(false));
        (r, COUNT.with(|n| n.get()))
    }
}

#[test]
fn right_hand_side_does_not_allocate() {
    let actuator = || Actuator::thesis(Waveform::sine(100.0, 110.0, 0.0, 0.0).unwrap());
    let wing = || fixed_wing(WingAero::stroke_drag(31.3, 3.4609).unwrap());
    let linkage = || Drivetrain::LinkageDifferential(LinkageDifferential::thesis());
    let blade = paritysim_aero::BladeElementModel::new(
        paritysim_aero::Omegas::new(46.8, 0.59, 17.5, 0.71).unwrap(),
        paritysim_aero::CoefficientSet::default(),
    )
    .unwrap();
    let rotating = Wing::new(
        shoulder(120.0, 60.0),
        full_inertia(),
        springs([0.0, 0.0, 0.0, 0.0, 0.0, 3.0]),
        WingAero::BladeElement(blade),
    )
    .unwrap();
    let devices = [
        two_wing_device(
            [wing(), wing()],
            "drag_parity_fixed",
            linkage(),
            1.0,
            actuator(),
            Formulation::DrivetrainCoordinates,
        ),
        two_wing_device(
            [wing(), wing()],
            "drag_parity_fixed",
            linkage(),
            1.0,
            actuator(),
            Formulation::NullSpace,
        ),
        two_wing_device(
            [wing(), wing()],
            "drag_parity_fixed",
            linkage(),
            1.0,
            actuator(),
            Formulation::Projection,
        ),
        two_wing_device(
            [rotating.clone(), rotating],
            "drag_parity",
            linkage(),
            1.0,
            actuator(),
            Formulation::NullSpace,
        ),
    ];
    for device in &devices {
        let y = device
            .state_from(
                &Vec6::new(0.2, 0.0, 0.0, 0.25, 0.0, 0.0),
                &Vec6::new(0.3, 0.0, 0.0, 0.25, 0.0, 0.0),
            )
            .unwrap();
        let mut dydt = paritysim_dynamics::State::default();
        let (result, allocations) = allocation::count(|| {
            (0..100).try_for_each(|k| device.rhs(0.1 * k as f64, &y, &mut dydt))
        });
        result.unwrap();
        assert_eq!(
            allocations,
            0,
            "{:?}: {allocations} allocations in 100 right-hand sides",
            device.formulation()
        );
    }
    // The counter works: a Vec allocates.
    let (_, n) = allocation::count(|| vec![1.0f64; 8]);
    assert!(n >= 1);
}
