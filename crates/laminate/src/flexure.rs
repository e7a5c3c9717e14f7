//! Flexure joints: torsional stiffness of a thin-film flexure and the castellated folding joint
//! of §4.4.3, usable as linear joint springs in the dynamics engine (§3.2.2, assumption 3).
//!
//! # Model and its limits
//!
//! A flexure of free length `L`, width `w` and thickness `t` bent by an angle θ has, by
//! Euler–Bernoulli beam theory under a pure moment, uniform curvature `θ / L` and the linear
//! torsional stiffness
//!
//! `k = E w t³ / (12 L)`   (mN·mm/rad with `E` mN/mm², lengths mm).
//!
//! The thesis (§3.2.2, assumption 3) adopts exactly this "lossless linear torsion spring ...
//! derived from Euler beam bending theory", and warns that it is "presumably inadequate for the
//! large deformations exhibited by many devices, often exceeding the elastic limit of the
//! flexure". The surface strain `ε = t θ / (2 L)` quantifies the caveat: a 7.5 µm polyimide
//! flexure of 30 µm length folded by 90° reaches ε ≈ 20 %, far beyond the ≈3 % yield strain of
//! Kapton ([`Flexure::max_strain`], [`Flexure::elastic_limit_angle`]). Beyond it the stiffness
//! is neither linear nor lossless; the engine may substitute nonlinear models.
//!
//! Wide flexures (`w ≫ L`) bend in near plane strain, stiffer by `1 / (1 − ν12 ν21)`
//! ([`Flexure::plate_stiffness`]); the thesis formula ([`Flexure::stiffness`]) ignores this
//! (≈ 13 % for polyimide).

use paritysim_error::{Error, Result, check_length_mm, check_positive};

use crate::material::{Material, library};

/// Yield strain of Kapton HN polyimide film, ≈3 % (DuPont Kapton HN datasheet: "yield point at
/// 3 %", 69 MPa at 23 °C), dimensionless.
pub const KAPTON_YIELD_STRAIN: f64 = 0.03;

/// Flexure length of Mobee's castellated folding joints (§4.4.3: "limit the length of the
/// flexure joint to 20–40 µm"), mm: `(min, max)`.
pub const CASTELLATED_FLEXURE_LENGTH_MM: (f64, f64) = (0.020, 0.040);

/// Thickness of Mobee's polyimide flexure film (§4.4.2: two 7.5 µm polyimide layers), mm.
pub const MOBEE_POLYIMIDE_THICKNESS_MM: f64 = 0.0075;

/// A straight thin-film flexure hinge.
#[derive(Clone, Debug, PartialEq)]
pub struct Flexure {
    material: Material,
    width: f64,
    thickness: f64,
    length: f64,
}

impl Flexure {
    /// A flexure of `width`, `thickness` and free `length` (mm); the bending modulus is the
    /// material's `E1` (axis 1 along the flexure length).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the field unless each length is in
    /// [`paritysim_error::plausible::LENGTH_MM`].
    pub fn new(material: Material, width: f64, thickness: f64, length: f64) -> Result<Flexure> {
        check_length_mm("width", width)?;
        check_length_mm("thickness", thickness)?;
        check_length_mm("length", length)?;
        Ok(Flexure {
            material,
            width,
            thickness,
            length,
        })
    }

    /// A Kapton polyimide flexure of Mobee's 7.5 µm film ([`library::polyimide`]).
    pub fn polyimide(width: f64, length: f64) -> Result<Flexure> {
        Flexure::new(
            library::polyimide(),
            width,
            MOBEE_POLYIMIDE_THICKNESS_MM,
            length,
        )
    }

    /// The material.
    pub fn material(&self) -> &Material {
        &self.material
    }
    /// Width along the joint axis, mm.
    pub fn width(&self) -> f64 {
        self.width
    }
    /// Film thickness, mm.
    pub fn thickness(&self) -> f64 {
        self.thickness
    }
    /// Free (unsupported) length across the joint axis, mm.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// Euler-beam torsional stiffness `E w t³ / (12 L)`, mN·mm/rad (thesis §3.2.2).
    pub fn stiffness(&self) -> f64 {
        self.material.e1() * self.width * self.thickness.powi(3) / (12.0 * self.length)
    }

    /// Plate (plane-strain) stiffness `stiffness / (1 − ν12 ν21)`, mN·mm/rad, for `w ≫ L`.
    pub fn plate_stiffness(&self) -> f64 {
        self.stiffness() / (1.0 - self.material.nu12() * self.material.nu21())
    }

    /// Peak surface bending strain `t |θ| / (2 L)` at joint angle `angle` (rad), dimensionless.
    pub fn max_strain(&self, angle: f64) -> Result<f64> {
        paritysim_error::check_finite("angle", angle)?;
        Ok(self.thickness * angle.abs() / (2.0 * self.length))
    }

    /// Joint angle at which the surface strain reaches `yield_strain` (> 0), rad:
    /// `2 L ε_y / t`. Beyond it the linear-spring model of §3.2.2 is invalid.
    pub fn elastic_limit_angle(&self, yield_strain: f64) -> Result<f64> {
        check_positive("yield_strain", yield_strain)?;
        Ok(2.0 * self.length * yield_strain / self.thickness)
    }

    /// Restoring torque `−k θ` at joint angle `angle` (rad), mN·mm (linear model).
    pub fn torque(&self, angle: f64) -> Result<f64> {
        paritysim_error::check_finite("angle", angle)?;
        Ok(-self.stiffness() * angle)
    }
}

/// Castellated folding joint (Fig. 4.25d, §4.4.3).
///
/// Two rigid linkage-sublaminate faces interlock in a square-wave ("castellated") pattern so
/// that the exposed polyimide flexure between them is only `flexure_length` long (20–40 µm in
/// Mobee), which keeps the rotation axis from drifting and resists off-axis motion — the
/// justification of the pseudo-rigid-body assumption (§3.2.2, assumption 2).
///
/// Model: the castellations split the joint width into `n_segments` equal flexure segments that
/// share one axis, so the bending stiffness is that of a straight flexure of the total exposed
/// width `joint_width · flexure_fraction`. Off-axis stiffness is not modelled.
#[derive(Clone, Debug, PartialEq)]
pub struct CastellatedJoint {
    flexure: Flexure,
    joint_width: f64,
    n_segments: usize,
    flexure_fraction: f64,
}

impl CastellatedJoint {
    /// A castellated joint of total `joint_width` (mm, along the axis), `n_segments` (≥ 1)
    /// castellations, exposed-flexure fraction `flexure_fraction` of the width (in (0, 1]),
    /// flexure `thickness` and `flexure_length` (mm) of `material`.
    pub fn new(
        material: Material,
        joint_width: f64,
        n_segments: usize,
        flexure_fraction: f64,
        thickness: f64,
        flexure_length: f64,
    ) -> Result<CastellatedJoint> {
        check_length_mm("joint_width", joint_width)?;
        if n_segments == 0 {
            return Err(Error::invalid("n_segments", n_segments, ">= 1"));
        }
        check_positive("flexure_fraction", flexure_fraction)?;
        if flexure_fraction > 1.0 {
            return Err(Error::invalid(
                "flexure_fraction",
                flexure_fraction,
                "in (0, 1]",
            ));
        }
        let flexure = Flexure::new(
            material,
            joint_width * flexure_fraction,
            thickness,
            flexure_length,
        )?;
        Ok(CastellatedJoint {
            flexure,
            joint_width,
            n_segments,
            flexure_fraction,
        })
    }

    /// Mobee's joint: 7.5 µm Kapton, `flexure_length` (mm, thesis 0.020–0.040), the whole width
    /// exposed in `n_segments` castellations.
    pub fn mobee(
        joint_width: f64,
        n_segments: usize,
        flexure_length: f64,
    ) -> Result<CastellatedJoint> {
        CastellatedJoint::new(
            library::polyimide(),
            joint_width,
            n_segments,
            1.0,
            MOBEE_POLYIMIDE_THICKNESS_MM,
            flexure_length,
        )
    }

    /// The equivalent straight flexure (total exposed width).
    pub fn flexure(&self) -> &Flexure {
        &self.flexure
    }
    /// Total joint width along the axis, mm.
    pub fn joint_width(&self) -> f64 {
        self.joint_width
    }
    /// Number of castellation segments.
    pub fn n_segments(&self) -> usize {
        self.n_segments
    }
    /// Exposed-flexure fraction of the joint width.
    pub fn flexure_fraction(&self) -> f64 {
        self.flexure_fraction
    }
    /// Width of one castellation segment, mm.
    pub fn segment_width(&self) -> f64 {
        self.joint_width / self.n_segments as f64
    }
    /// Torsional stiffness, mN·mm/rad (Euler-beam formula of the equivalent flexure).
    pub fn stiffness(&self) -> f64 {
        self.flexure.stiffness()
    }
    /// `true` if the flexure length lies in the thesis' 20–40 µm range.
    pub fn within_thesis_range(&self) -> bool {
        let l = self.flexure.length();
        let (lo, hi) = CASTELLATED_FLEXURE_LENGTH_MM;
        l >= lo - 1e-12 && l <= hi + 1e-12
    }
}
