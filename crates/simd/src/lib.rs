//! Elementary functions written once over `f64` and [`wide::f64x4`].
//!
//! The SIMD lanes of the sweep engine promise results bit-identical to the scalar path. That
//! holds by construction when a lane and the scalar code perform the same IEEE operations in
//! the same order. libm's `sin`/`cos` have no four-lane twin, so the functions here are one
//! generic implementation over [`Real`] (plain `f64`, and `f64x4` lane by lane): the Cephes
//! polynomials of Agner Fog's vector class library (as in `wide`'s `f64x4::sin_cos`), with
//! unfused multiply-adds, so each lane of a vector call equals the scalar call bit for bit.
//!
//! They are also cheaper than libm's in the scalar path (docs/findings.md §24) and within
//! 2 ulp of it (tested in tests/simd.rs).

// The polynomial coefficients as Cephes and the vector class library print them.
#![allow(clippy::excessive_precision)]

use std::ops::{Add, Mul, Neg, Sub};

pub use wide::f64x4;

/// A floating-point value or a vector of them: what the generic functions compute with.
///
/// Every arithmetic operation is the IEEE operation of each lane (no fused multiply-add), so
/// a generic function gives every lane of an `f64x4` the bits it gives that lane's `f64`.
pub trait Real:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Neg<Output = Self>
{
    /// Every lane `x`.
    fn splat(x: f64) -> Self;
    /// `|self|`.
    fn abs(self) -> Self;
    /// Rounded to the nearest integer, ties to even.
    fn round_ties_even(self) -> Self;
    /// Whether some lane of `self` is above `bound` (or not a number).
    fn any_beyond(self, bound: f64) -> bool;
    /// `f` applied to every lane (the fallback for arguments outside the polynomials' range).
    fn map(self, f: impl Fn(f64) -> f64) -> Self;
    /// `(sin x, cos x)` from those of the reduced argument, `x = ±(y π/2 + r)` with the
    /// integer `y` (< 2^53): swaps and sign changes only, so exact. Each type does it its own
    /// branch-free way (integer bits, vector masks) with the same result.
    fn place_in_quadrant(x: Self, y: Self, sin_r: Self, cos_r: Self) -> (Self, Self);
}

impl Real for f64 {
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn round_ties_even(self) -> Self {
        f64::round_ties_even(self)
    }
    #[inline(always)]
    fn any_beyond(self, bound: f64) -> bool {
        self > bound || self.is_nan()
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        f(self)
    }
    #[inline(always)]
    fn place_in_quadrant(x: f64, y: f64, sin_r: f64, cos_r: f64) -> (f64, f64) {
        let q = y as u64;
        // Odd quadrants swap sin and cos (a bit mask, not a branch).
        let swap = (q & 1).wrapping_neg();
        let (s, c) = (sin_r.to_bits(), cos_r.to_bits());
        let sin1 = (c & swap) | (s & !swap);
        let cos1 = (s & swap) | (c & !swap);
        // sin changes sign in quadrants 2 and 3 and with x; cos in quadrants 1 and 2.
        let sign_sin = ((q & 2) << 62) ^ (x.to_bits() & SIGN);
        let sign_cos = ((q.wrapping_add(1)) & 2) << 62;
        (
            f64::from_bits(sin1 ^ sign_sin),
            f64::from_bits(cos1 ^ sign_cos),
        )
    }
}

/// The sign bit of an `f64`.
const SIGN: u64 = 1 << 63;

impl Real for f64x4 {
    #[inline(always)]
    fn splat(x: f64) -> Self {
        f64x4::splat(x)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64x4::abs(self)
    }
    #[inline(always)]
    fn round_ties_even(self) -> Self {
        f64x4::round_ties_even(self)
    }
    #[inline(always)]
    fn any_beyond(self, bound: f64) -> bool {
        // NaN compares false: `!(x <= bound)` is `x > bound || x is NaN`.
        self.simd_gt(f64x4::splat(bound)).any() || !self.simd_eq(self).all()
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        f64x4::new(self.to_array().map(f))
    }
    #[inline(always)]
    fn place_in_quadrant(x: Self, y: Self, sin_r: Self, cos_r: Self) -> (Self, Self) {
        // y mod 4 in floating point (exact for y < 2^53): cheaper here than integer lanes.
        let quadrant = y - f64x4::splat(4.0) * (y * f64x4::splat(0.25)).floor();
        let odd = quadrant.simd_eq(f64x4::splat(1.0)) | quadrant.simd_eq(f64x4::splat(3.0));
        let sin1 = odd.select(cos_r, sin_r);
        let cos1 = odd.select(sin_r, cos_r);
        let sign = f64x4::splat(-0.0);
        let sin_flip = quadrant.simd_ge(f64x4::splat(2.0)) & sign;
        let cos_flip =
            (quadrant.simd_eq(f64x4::splat(1.0)) | quadrant.simd_eq(f64x4::splat(2.0))) & sign;
        (sin1 ^ sin_flip ^ (x & sign), cos1 ^ cos_flip)
    }
}

/// Largest `|x|` the polynomials take (the three-part reduction by π/2 keeps about 1e-16
/// absolute error up to here); beyond it, and for non-finite `x`, every lane of the call
/// falls back to libm's `sin`/`cos` (which both paths then share).
pub const SIN_COS_REDUCED_UP_TO: f64 = 1.0e7;

/// `a·x + b` unfused (two roundings, as in the lanes).
#[inline(always)]
fn mul_add<R: Real>(a: R, x: R, b: R) -> R {
    a * x + b
}

/// `c0 + c1 x + … + c5 x⁵` by Estrin's scheme (as `wide`'s `polynomial_5!`).
#[inline(always)]
fn polynomial_5<R: Real>(x: R, c: [f64; 6]) -> R {
    let x2 = x * x;
    let x4 = x2 * x2;
    let s = R::splat;
    mul_add(
        mul_add(s(c[3]), x, s(c[2])),
        x2,
        mul_add(
            mul_add(s(c[5]), x, s(c[4])),
            x4,
            mul_add(s(c[1]), x, s(c[0])),
        ),
    )
}

const SIN: [f64; 6] = [
    -1.666_666_666_666_663_072_95E-1,
    8.333_333_333_322_118_588_78E-3,
    -1.984_126_982_958_953_859_96E-4,
    2.755_731_362_138_572_452_13E-6,
    -2.505_074_776_285_780_728_66E-8,
    1.589_623_015_765_465_680_60E-10,
];
const COS: [f64; 6] = [
    4.166_666_666_666_659_292_18E-2,
    -1.388_888_888_887_305_641_16E-3,
    2.480_158_728_885_170_453_48E-5,
    -2.755_731_417_929_673_881_12E-7,
    2.087_570_084_197_473_167_78E-9,
    -1.135_853_652_138_768_173_00E-11,
];
/// π/2 in three parts (Cody-Waite reduction).
const DP1: f64 = 7.853_981_554_508_209_228_515_625E-1 * 2.0;
const DP2: f64 = 7.946_627_356_147_928_367_14E-9 * 2.0;
const DP3: f64 = 3.061_616_997_868_382_943_07E-17 * 2.0;

/// `(sin x, cos x)` of every lane; bit-identical across [`Real`] types lane by lane.
///
/// Within 2 ulp of libm for `|x| ≤ π`, and about 1e-16 absolute up to
/// [`SIN_COS_REDUCED_UP_TO`]; beyond that (and for infinities and NaN) libm's values.
#[inline]
pub fn sin_cos<R: Real>(x: R) -> (R, R) {
    if x.abs().any_beyond(SIN_COS_REDUCED_UP_TO) {
        return (x.map(f64::sin), x.map(f64::cos));
    }
    let s = R::splat;
    let xa = x.abs();
    // The quadrant `y` and the reduced argument `r = |x| − y π/2` in [−π/4, π/4].
    let y = (xa * s(std::f64::consts::FRAC_2_PI)).round_ties_even();
    let r = ((xa - y * s(DP1)) - y * s(DP2)) - y * s(DP3);
    let r2 = r * r;
    let sin_r = mul_add(r * r2, polynomial_5(r2, SIN), r);
    let cos_r = mul_add(r2 * r2, polynomial_5(r2, COS), s(1.0) - r2 * s(0.5));
    R::place_in_quadrant(x, y, sin_r, cos_r)
}

/// `sin x` of [`sin_cos`].
#[inline]
pub fn sin<R: Real>(x: R) -> R {
    sin_cos(x).0
}

/// `cos x` of [`sin_cos`].
#[inline]
pub fn cos<R: Real>(x: R) -> R {
    sin_cos(x).1
}
