//! Devices shared by the flight tests (built in Rust: the spec crate depends on this one).
#![allow(dead_code, missing_docs)]

use nalgebra::{Matrix3, Vector3};
use paritysim_aero::{BladeElementModel, CoefficientSet, Omegas};
use paritysim_constraints::Constraints;
use paritysim_dynamics::device::{DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::{
    Actuator, DcOffset, Device, JointSpring, SimulationOptions, Waveform, Wing, WingAero,
};
use paritysim_kinematics::SphericalShoulder;
use paritysim_kinematics::drivetrain::{Drivetrain, LinearDifferential};

/// Table 3.3 wing (Uncut right wing or the left wing) with blade-element aero.
pub fn wing_3_4(uncut_right: bool, omega_scale: f64, hinge: f64) -> Wing {
    let (inertia, o) = if uncut_right {
        (
            Matrix3::new(47.1, 0.0, 3.87, 0.0, 48.6, 0.0, 3.87, 0.0, 1.49),
            [38.2, 0.438, 13.5, 0.952],
        )
    } else {
        (
            Matrix3::new(49.0, 0.0, 4.2, 0.0, 50.5, 0.0, 4.2, 0.0, 1.56),
            [46.8, 0.587, 17.5, 0.712],
        )
    };
    let omegas = Omegas::new(
        o[0] * omega_scale,
        o[1] * omega_scale,
        o[2] * omega_scale,
        o[3] * omega_scale,
    )
    .unwrap();
    let aero = WingAero::BladeElement(
        BladeElementModel::new(omegas, CoefficientSet::from_name("dickinson1999").unwrap())
            .unwrap(),
    );
    let mut springs = [JointSpring::default(); 6];
    springs[5] = JointSpring::linear(hinge, 0.0).unwrap();
    Wing::new(
        SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0).unwrap(),
        inertia,
        springs,
        aero,
    )
    .unwrap()
}

pub fn linear_differential() -> Drivetrain {
    Drivetrain::LinearDifferential(LinearDifferential::new(3.0543261909900763, 2.5, 1.0).unwrap())
}

/// The §3.4 Drag PARITY device with the given wings (left first).
pub fn device_3_4(left: Wing, right: Wing, k2: f64) -> Device {
    Device::new(DeviceSpec {
        wings: vec![left, right],
        constraints: Constraints::configuration("drag_parity").unwrap(),
        transmission: Some(Transmission::new(linear_differential(), k2).unwrap()),
        actuator: Some(
            Actuator::new(
                1.2,
                467.0,
                Waveform::sine(100.0, 110.0, 100.0, 0.0).unwrap(),
                DcOffset::Ignore,
            )
            .unwrap(),
        ),
        formulation: Formulation::Auto,
    })
    .unwrap()
}

/// The symmetric §3.4 device (both wings the left wing of Table 3.3).
pub fn symmetric_3_4() -> Device {
    device_3_4(
        wing_3_4(false, 1.0, 2.533928021702924),
        wing_3_4(false, 1.0, 2.533928021702924),
        0.0,
    )
}

/// A vacuum device with springs everywhere, no actuator: a conservative oscillator.
pub fn vacuum_device() -> Device {
    let mk = |ixx: f64, kphi: f64| {
        let inertia = Matrix3::new(ixx, 0.0, 4.2, 0.0, ixx + 1.56, 0.0, 4.2, 0.0, 1.56);
        let mut springs = [JointSpring::default(); 6];
        springs[0] = JointSpring::nonlinear(kphi, 0.3, 0.1).unwrap();
        springs[5] = JointSpring::linear(2.5, 0.0).unwrap();
        Wing::new(
            SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0).unwrap(),
            inertia,
            springs,
            WingAero::None,
        )
        .unwrap()
    };
    Device::new(DeviceSpec {
        wings: vec![mk(49.0, 20.0), mk(45.0, 26.0)],
        constraints: Constraints::configuration("drag_parity").unwrap(),
        transmission: Some(Transmission::new(linear_differential(), 3.0).unwrap()),
        actuator: None,
        formulation: Formulation::Auto,
    })
    .unwrap()
}

pub fn tight() -> SimulationOptions {
    SimulationOptions {
        rtol: 1e-12,
        atol: 1e-14,
        ..SimulationOptions::default()
    }
}

pub fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
    Vector3::new(x, y, z)
}

/// An HMF-class airframe (the spec crate's defaults, written out: test data).
pub fn hmf_body(mode: paritysim_flight::BodyMode) -> paritysim_flight::Body {
    paritysim_flight::Body {
        mode,
        mass: 60.0,
        inertia: Matrix3::from_diagonal(&Vector3::new(153.8, 1745.0, 1649.0)),
        center_of_mass: Vector3::zeros(),
        shoulders: [Vector3::new(6.0, 0.0, -1.5), Vector3::new(6.0, 0.0, 1.5)],
        gravity: Vector3::new(-9.81e-3, 0.0, 0.0),
        force_radius: 12.0,
        wing_mass: [0.0; 2],
        wing_center_of_mass: [Vector3::zeros(); 2],
    }
}

/// A §3.3-like stroke-only PARITY device (fixed wings, drag torques), right wing cut to 60 %.
pub fn drag_only_1cut() -> Device {
    let shoulder = SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0).unwrap();
    let wing = |omega1: f64| {
        Wing::stroke_only(shoulder, 29.0, WingAero::stroke_drag(omega1, 1.0).unwrap()).unwrap()
    };
    Device::new(DeviceSpec {
        wings: vec![wing(31.3), wing(0.6 * 31.3)],
        constraints: Constraints::configuration("drag_parity_fixed").unwrap(),
        transmission: Some(Transmission::new(linear_differential(), 0.5).unwrap()),
        actuator: Some(
            Actuator::new(
                1.2,
                467.0,
                Waveform::sine(100.0, 110.0, 0.0, 0.0).unwrap(),
                DcOffset::Ignore,
            )
            .unwrap(),
        ),
        formulation: Formulation::Auto,
    })
    .unwrap()
}
