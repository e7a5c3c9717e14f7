//! The generic elementary functions: one value per lane equals the scalar value bit for bit,
//! and both are within a few ulp of libm.

use paritysim_simd::{SIN_COS_REDUCED_UP_TO, atan2, cos, sin, sin_cos};
use proptest::prelude::*;
use wide::f64x4;

/// Distance in units in the last place of the larger magnitude.
fn ulps(a: f64, b: f64) -> f64 {
    let scale = a.abs().max(b.abs());
    if scale == 0.0 {
        return 0.0;
    }
    (a - b).abs() / (scale * f64::EPSILON)
}

fn lanes(x: [f64; 4]) -> ([f64; 4], [f64; 4]) {
    let (s, c) = sin_cos(f64x4::new(x));
    (s.to_array(), c.to_array())
}

#[test]
fn sin_cos_is_within_two_ulp_of_libm_on_the_angles_of_the_models() {
    // Hinge, stroke and deviation angles and the fits' arguments: |x| <= 2π, densely.
    let n = 200_000;
    let (mut worst_sin, mut worst_cos) = (0.0_f64, 0.0_f64);
    for i in 0..=n {
        let x = -std::f64::consts::TAU + 2.0 * std::f64::consts::TAU * i as f64 / n as f64;
        let (s, c) = sin_cos(x);
        // Near a zero of sin or cos the relative error is not the measure: compare to 1.
        worst_sin = worst_sin.max(ulps(s, x.sin()).min((s - x.sin()).abs() / f64::EPSILON));
        worst_cos = worst_cos.max(ulps(c, x.cos()).min((c - x.cos()).abs() / f64::EPSILON));
    }
    assert!(worst_sin <= 2.0, "sin: {worst_sin} ulp");
    assert!(worst_cos <= 2.0, "cos: {worst_cos} ulp");
}

#[test]
fn sin_cos_keeps_1e_15_absolute_for_drive_phases() {
    // A 110 Hz drive over 10^4 periods reaches ~6e4 rad.
    let mut worst = 0.0_f64;
    for i in 0..100_000 {
        let x = 0.7 * i as f64 + 0.123;
        let (s, c) = sin_cos(x);
        worst = worst.max((s - x.sin()).abs()).max((c - x.cos()).abs());
    }
    assert!(worst <= 1e-15, "{worst:e}");
}

#[test]
fn special_values_follow_libm() {
    for x in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
        let (s, c) = sin_cos(x);
        assert!(s.is_nan() && c.is_nan(), "{x}: {s} {c}");
    }
    assert_eq!(sin_cos(0.0), (0.0, 1.0));
    let big = 2.0 * SIN_COS_REDUCED_UP_TO;
    assert_eq!(sin_cos(big), (big.sin(), big.cos()));
    // One lane beyond the range sends the whole vector to libm, so lanes still agree.
    let x = [0.3, big, -1.0, 2.0];
    let (s, c) = lanes(x);
    for l in 0..4 {
        assert_eq!((s[l], c[l]), (x[l].sin(), x[l].cos()));
    }
}

#[test]
fn quadrant_signs_are_those_of_libm() {
    use std::f64::consts::FRAC_PI_4;
    for k in -16..=16 {
        let x = (k as f64 + 0.5) * FRAC_PI_4;
        let (s, c) = sin_cos(x);
        assert_eq!(s.signum(), x.sin().signum(), "sin({x})");
        assert_eq!(c.signum(), x.cos().signum(), "cos({x})");
        assert_eq!(sin(x), s);
        assert_eq!(cos(x), c);
    }
}

proptest! {
    #[test]
    fn every_lane_equals_the_scalar_call_bit_for_bit(
        x in prop::array::uniform4(-2.0e3..2.0e3_f64),
    ) {
        let (s, c) = lanes(x);
        for l in 0..4 {
            let (sl, cl) = sin_cos(x[l]);
            prop_assert_eq!(s[l].to_bits(), sl.to_bits());
            prop_assert_eq!(c[l].to_bits(), cl.to_bits());
        }
    }
}

#[test]
fn atan2_is_within_two_ulp_of_libm() {
    // Every direction, at several radii, and the axes.
    let mut worst = 0.0_f64;
    for i in 0..=100_000 {
        let angle = -std::f64::consts::PI + 2.0 * std::f64::consts::PI * i as f64 / 100_000.0;
        for r in [1e-3, 0.7, 42.0] {
            let (y, x) = (r * angle.sin(), r * angle.cos());
            let (got, want) = (atan2(y, x), y.atan2(x));
            worst = worst.max(ulps(got, want));
        }
    }
    assert!(worst <= 2.0, "{worst} ulp");
    for (y, x) in [
        (0.0, 1.0),
        (0.0, -1.0),
        (-0.0, -1.0),
        (1.0, 0.0),
        (-1.0, 0.0),
        (0.0, 0.0),
    ] {
        assert_eq!(
            atan2(y, x).to_bits(),
            f64::atan2(y, x).to_bits(),
            "atan2({y}, {x})"
        );
    }
    for (y, x) in [
        (f64::INFINITY, 1.0),
        (1.0, f64::NEG_INFINITY),
        (f64::NAN, 1.0),
    ] {
        let (got, want) = (atan2(y, x), y.atan2(x));
        assert!(
            got == want || (got.is_nan() && want.is_nan()),
            "atan2({y}, {x})"
        );
    }
}

proptest! {
    #[test]
    fn every_atan2_lane_equals_the_scalar_call_bit_for_bit(
        y in prop::array::uniform4(-50.0..50.0_f64),
        x in prop::array::uniform4(-50.0..50.0_f64),
    ) {
        let v = atan2(f64x4::new(y), f64x4::new(x)).to_array();
        for l in 0..4 {
            prop_assert_eq!(v[l].to_bits(), atan2(y[l], x[l]).to_bits());
        }
    }
}
