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

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

pub use wide::f64x4;

/// A floating-point value or a vector of them: what the generic functions compute with.
///
/// Every arithmetic operation is the IEEE operation of each lane (no fused multiply-add), so
/// a generic function gives every lane of an `f64x4` the bits it gives that lane's `f64`.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// A lane-wise boolean (`bool`, or all bits of a lane set).
    type Mask: Copy
        + std::fmt::Debug
        + PartialEq
        + BitAnd<Output = Self::Mask>
        + BitOr<Output = Self::Mask>
        + Not<Output = Self::Mask>;
    /// Every lane `x`.
    fn splat(x: f64) -> Self;
    /// `|self|`.
    fn abs(self) -> Self;
    /// The larger of `self` and `other` (the other one where one is NaN, as `f64::max`).
    fn max(self, other: Self) -> Self;
    /// The correctly rounded square root.
    fn sqrt(self) -> Self;
    /// `self < other`, lane by lane (false for NaN).
    fn lt(self, other: Self) -> Self::Mask;
    /// `self <= other`.
    fn le(self, other: Self) -> Self::Mask;
    /// `self == other`.
    fn eq(self, other: Self) -> Self::Mask;
    /// Whether the sign bit is set (also for −0 and negative NaN).
    fn sign_negative(self) -> Self::Mask;
    /// `mask ? a : b`, lane by lane.
    fn select(mask: Self::Mask, a: Self, b: Self) -> Self;
    /// The lanes where `mask` holds, as bits (lane `l` is bit `l`; a scalar is lane 0).
    fn bits(mask: Self::Mask) -> u32;
    /// Rounded to the nearest integer, ties to even.
    fn round_ties_even(self) -> Self;
    /// Whether some lane of `self` is above `bound` (or not a number).
    fn any_beyond(self, bound: f64) -> bool;
    /// `f` applied to every lane (the fallback for arguments outside the polynomials' range).
    fn map(self, f: impl Fn(f64) -> f64) -> Self;
    /// `f(self, other)` lane by lane (the fallback of two-argument functions).
    fn zip_map(self, other: Self, f: fn(f64, f64) -> f64) -> Self;
    /// `(sin x, cos x)` from those of the reduced argument, `x = ±(y π/2 + r)` with the
    /// integer `y` (< 2^53): swaps and sign changes only, so exact. Each type does it its own
    /// branch-free way (integer bits, vector masks) with the same result.
    fn place_in_quadrant(x: Self, y: Self, sin_r: Self, cos_r: Self) -> (Self, Self);
}

impl Real for f64 {
    type Mask = bool;
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> bool {
        self < other
    }
    #[inline(always)]
    fn le(self, other: Self) -> bool {
        self <= other
    }
    #[inline(always)]
    fn eq(self, other: Self) -> bool {
        self == other
    }
    #[inline(always)]
    fn sign_negative(self) -> bool {
        self.is_sign_negative()
    }
    #[inline(always)]
    fn select(mask: bool, a: Self, b: Self) -> Self {
        if mask { a } else { b }
    }
    #[inline(always)]
    fn bits(mask: bool) -> u32 {
        u32::from(mask)
    }
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f64::max(self, other)
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
    fn zip_map(self, other: Self, f: fn(f64, f64) -> f64) -> Self {
        f(self, other)
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
    type Mask = f64x4;
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64x4::sqrt(self)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> Self {
        self.simd_lt(other)
    }
    #[inline(always)]
    fn le(self, other: Self) -> Self {
        self.simd_le(other)
    }
    #[inline(always)]
    fn eq(self, other: Self) -> Self {
        self.simd_eq(other)
    }
    #[inline(always)]
    fn sign_negative(self) -> Self {
        self.is_sign_negative()
    }
    #[inline(always)]
    fn select(mask: Self, a: Self, b: Self) -> Self {
        mask.select(a, b)
    }
    #[inline(always)]
    fn bits(mask: Self) -> u32 {
        mask.to_bitmask()
    }
    #[inline(always)]
    fn splat(x: f64) -> Self {
        f64x4::splat(x)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64x4::abs(self)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f64x4::max(self, other)
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
    fn zip_map(self, other: Self, f: fn(f64, f64) -> f64) -> Self {
        let (a, b) = (self.to_array(), other.to_array());
        f64x4::new(std::array::from_fn(|l| f(a[l], b[l])))
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

/// `c0 + c1 x + … + c4 x⁴` (as `wide`'s `polynomial_4!`).
#[inline(always)]
fn polynomial_4<R: Real>(x: R, c: [f64; 5]) -> R {
    let x2 = x * x;
    let x4 = x2 * x2;
    let s = R::splat;
    mul_add(
        mul_add(s(c[3]), x, s(c[2])),
        x2,
        mul_add(s(c[1]), x, s(c[0])),
    ) + s(c[4]) * x4
}

/// `c0 + c1 x + … + c4 x⁴ + x⁵` (as `wide`'s `polynomial_5n!`).
#[inline(always)]
fn polynomial_5n<R: Real>(x: R, c: [f64; 5]) -> R {
    let x2 = x * x;
    let x4 = x2 * x2;
    let s = R::splat;
    mul_add(
        x2,
        mul_add(x, s(c[3]), s(c[2])),
        mul_add(x4, s(c[4]) + x, mul_add(x, s(c[1]), s(c[0]))),
    )
}

const ATAN_P: [f64; 5] = [
    -6.485_021_904_942_025_371_773E1,
    -1.228_866_684_490_136_173_410E2,
    -7.500_855_792_314_704_667_340E1,
    -1.615_753_718_733_365_076_637E1,
    -8.750_608_600_031_904_122_785E-1,
];
const ATAN_Q: [f64; 5] = [
    1.945_506_571_482_613_964_425E2,
    4.853_903_996_359_136_964_868E2,
    4.328_810_604_912_902_668_951E2,
    1.650_270_098_316_988_542_046E2,
    2.485_846_490_142_306_297_962E1,
];

/// `atan2(y, x)` of every lane (the vector class library's, as `wide`'s `f64x4::atan2`, with
/// unfused multiply-adds); bit-identical across [`Real`] types lane by lane. Within 2 ulp of
/// libm for finite arguments (tests/simd.rs); both infinite: libm's values.
#[inline]
pub fn atan2<R: Real>(y: R, x: R) -> R {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, SQRT_2};
    const MORE_BITS: f64 = 6.123_233_995_736_766E-17;
    if x.abs().any_beyond(f64::MAX) || y.abs().any_beyond(f64::MAX) {
        // An infinite or NaN argument in some lane: libm for every lane of the call.
        return y.zip_map(x, f64::atan2);
    }
    let s = R::splat;
    // Into the first octant.
    let (x1, y1) = (x.abs(), y.abs());
    let swap = x1.lt(y1);
    let x2 = R::select(swap, y1, x1);
    let y2 = R::select(swap, x1, y1);
    // x = y = 0 gives NaN here (replaced below).
    let t = y2 / x2;
    let not_big = t.le(s(SQRT_2 + 1.0));
    let not_small = !t.lt(s(0.66));
    let zero = s(0.0);
    let offset = R::select(
        not_small,
        R::select(not_big, s(FRAC_PI_4), s(FRAC_PI_2)),
        zero,
    );
    let fac = R::select(
        not_small,
        R::select(not_big, s(MORE_BITS * 0.5), s(MORE_BITS)),
        zero,
    );
    // small: z = t / 1; medium: (t − 1) / (t + 1); big: −1 / t.
    let a = R::select(not_big, t, zero);
    let a = R::select(not_small, a - s(1.0), a);
    let b = R::select(not_big, s(1.0), zero);
    let b = R::select(not_small, b + t, b);
    let z = a / b;
    let zz = z * z;
    let px = polynomial_4(zz, ATAN_P);
    let qx = polynomial_5n(zz, ATAN_Q);
    let re = mul_add(px / qx, z * zz, z) + (offset + fac);
    // Back in place.
    let re = R::select(swap, s(FRAC_PI_2) - re, re);
    let both_zero = x.eq(zero) & y.eq(zero);
    let re = R::select(both_zero, zero, re);
    let re = R::select(x.sign_negative(), s(PI) - re, re);
    R::select(y.sign_negative(), -re, re)
}
