//! Elementary rotations and the skew matrix of Appendix A.1, on nalgebra fixed-size types.

use nalgebra::{Matrix3, Unit, Vector3};

/// Rotation by `angle` about the x axis.
#[inline]
pub fn rot_x(angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Rotation by `angle` about the y axis.
#[inline]
pub fn rot_y(angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Rotation by `angle` about the z axis.
#[inline]
pub fn rot_z(angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Rotation by `angle` about the unit `axis` (Rodrigues' formula): `R_v̂(η)` of A.1.
#[inline]
pub fn rot_axis(axis: &Unit<Vector3<f64>>, angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    let k = skew(axis.as_ref());
    Matrix3::identity() + k * s + k * k * (1.0 - c)
}

/// The skew-symmetric matrix `S(v)` of A.1, so that `S(a) b = a × b`.
#[inline]
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}
