//! Cutting a wing membrane along a straight line (the 1-Cut / 2-Cut wings of §3.3 and §3.4).
//!
//! §3.4 removes "successive amounts of planform area from the distal extent of the right wing"
//! (Fig. 3.10); §3.3 trims the left wing's membrane (Fig. 3.5). [`Planform::cut`] keeps the
//! part of the outline on one side of a line `z = const` (tip cut) or `x = const` (trailing-edge
//! cut). The result is again a polygon, so its integrals (and Ω1..Ω4) stay exact: clipping a
//! polygon by a half-plane is exact (Sutherland–Hodgman with one clip edge).

use paritysim_error::{Error, Result};

use crate::planform::Planform;

/// Which edge of the membrane [`Planform::cut`] trims.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CutEdge {
    /// Remove the outboard part, `z > z_max − fraction · span` (the §3.4 cuts).
    Tip,
    /// Remove the rear part, `x < x_min + fraction · (x_max − x_min)`.
    TrailingEdge,
}

impl CutEdge {
    /// `"tip"` or `"trailing"` (what the Python binding passes).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`where`) for any other name.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "tip" => Ok(Self::Tip),
            "trailing" => Ok(Self::TrailingEdge),
            other => Err(Error::invalid("where", other, "\"tip\" or \"trailing\"")),
        }
    }
}

impl Planform {
    /// The membrane left after cutting away `fraction` of its spanwise extent at the tip
    /// ([`CutEdge::Tip`]) or of its chordwise extent at the trailing edge
    /// ([`CutEdge::TrailingEdge`]). `fraction = 0` returns the planform unchanged.
    ///
    /// The cut line is `z_c = z_max − fraction·(z_max − z_min)` (keep `z ≤ z_c`) or
    /// `x_c = x_min + fraction·(x_max − x_min)` (keep `x ≥ x_c`). A rectangle cut at the tip is
    /// the shorter rectangle, so its Ω_k follow in closed form (tested).
    ///
    /// ```
    /// use paritysim_aero::{CutEdge, DEFAULT_AIR_DENSITY, Planform};
    ///
    /// let wing = Planform::rectangle(16.0, 3.2, 0.0, 0.4)?;
    /// let cut = wing.cut(0.25, CutEdge::Tip)?; // a 12 mm long membrane is left
    /// let omega1 = 0.5 * DEFAULT_AIR_DENSITY * 3.2 * 12.0_f64.powi(4) / 4.0; // eq. 3.12
    /// assert!((cut.omegas(DEFAULT_AIR_DENSITY)?.omega1 - omega1).abs() < 1e-12 * omega1);
    /// # Ok::<(), paritysim_aero::Error>(())
    /// ```
    ///
    /// # Errors
    /// * [`Error::InvalidParameter`] (`fraction`) unless `0 ≤ fraction < 1`.
    /// * [`Error::Geometry`] if the line splits the membrane into several pieces (the outline
    ///   crosses it more than twice), or if what is left is not a valid planform (e.g. it lies
    ///   entirely ahead of the hinge line after a trailing-edge cut).
    pub fn cut(&self, fraction: f64, edge: CutEdge) -> Result<Self> {
        if !(fraction.is_finite() && (0.0..1.0).contains(&fraction)) {
            return Err(Error::invalid("fraction", fraction, "in [0, 1)"));
        }
        if fraction == 0.0 {
            return Ok(self.clone());
        }
        // Work in a coordinate `s` where the kept side is `s <= bound`.
        let (axis, sign, bound) = match edge {
            CutEdge::Tip => {
                let (z0, z1) = (self.root_offset(), self.tip_radius());
                (0, 1.0, z1 - fraction * (z1 - z0))
            }
            CutEdge::TrailingEdge => {
                let (x0, x1) = self.x_range();
                (1, -1.0, -(x0 + fraction * (x1 - x0)))
            }
        };
        let s = |p: [f64; 2]| sign * p[axis];
        let v = self.vertices();
        let n = v.len();
        let mut out = Vec::with_capacity(n + 2);
        let mut crossings = 0usize;
        for i in 0..n {
            let (a, b) = (v[i], v[(i + 1) % n]);
            let (sa, sb) = (s(a), s(b));
            if sa <= bound {
                out.push(a);
            }
            if (sa <= bound) != (sb <= bound) {
                crossings += 1;
                let t = (bound - sa) / (sb - sa);
                let mut p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
                p[axis] = sign * bound; // exactly on the cut line
                out.push(p);
            }
        }
        // More than two crossings with the kept part disconnected leaves a zero-width bridge
        // along the cut line, which the simplicity check rejects: name the real cause.
        Self::from_points(&out).map_err(|e| match e {
            Error::Geometry(msg) if crossings > 2 && msg.contains("self-intersecting") => {
                let (name, line) = match edge {
                    CutEdge::Tip => ("z", bound),
                    CutEdge::TrailingEdge => ("x", -bound),
                };
                Error::Geometry(format!(
                    "cutting {fraction} of the membrane at {name} = {line:.6} mm splits it into \
                     several pieces; Planform::cut keeps one connected membrane (choose another \
                     fraction or edge)"
                ))
            }
            other => other,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn zero_fraction_is_identity_and_bad_fractions_are_rejected() {
        let r = Planform::rectangle(10.0, 3.0, 1.0, 0.5).unwrap();
        assert_eq!(r.cut(0.0, CutEdge::Tip).unwrap(), r);
        for f in [-0.1, 1.0, 1.5, f64::NAN] {
            let e = r.cut(f, CutEdge::Tip).unwrap_err();
            assert!(matches!(e, Error::InvalidParameter { .. }), "{e}");
        }
        assert!(CutEdge::from_name("root").is_err());
    }

    #[test]
    fn rectangle_cut_at_tip_is_the_shorter_rectangle() {
        let (span, chord, root, le) = (16.0, 3.2, 1.5, 0.4);
        let full = Planform::rectangle(span, chord, root, le).unwrap();
        let f = 0.3;
        let cut = full.cut(f, CutEdge::Tip).unwrap();
        let short = Planform::rectangle(span * (1.0 - f), chord, root, le).unwrap();
        let (a, b) = (cut.omegas(1.2e-3).unwrap(), short.omegas(1.2e-3).unwrap());
        assert_relative_eq!(a.omega1, b.omega1, max_relative = 1e-13);
        assert_relative_eq!(a.omega2, b.omega2, max_relative = 1e-13);
        assert_relative_eq!(a.omega3, b.omega3, max_relative = 1e-13);
        assert_relative_eq!(a.omega4, b.omega4, max_relative = 1e-13);
        // Closed form, eq. 3.12: Ω1 = ½ρ c (z1⁴ − z0⁴)/4.
        let z1 = root + span * (1.0 - f);
        let omega1 = 0.5 * 1.2e-3 * chord * (z1.powi(4) - root.powi(4)) / 4.0;
        assert_relative_eq!(a.omega1, omega1, max_relative = 1e-13);
    }

    #[test]
    fn rectangle_cut_at_trailing_edge_has_the_shorter_chord() {
        let (span, chord, le) = (12.0, 4.0, 0.5);
        let full = Planform::rectangle(span, chord, 0.0, le).unwrap();
        let cut = full.cut(0.25, CutEdge::TrailingEdge).unwrap();
        let c = 0.75 * chord;
        // Ω3 = ½ρ ∫ z² c² dz, Ω4 = ½ρ ∫ z² l c dz, Ω2 = ½ρ ∬|x|³ (x from le − c to le).
        let h = 0.5 * 1.2e-3;
        let o = cut.omegas(1.2e-3).unwrap();
        assert_relative_eq!(
            o.omega3,
            h * c * c * span.powi(3) / 3.0,
            max_relative = 1e-13
        );
        assert_relative_eq!(
            o.omega4,
            h * le * c * span.powi(3) / 3.0,
            max_relative = 1e-13
        );
        let x_abs3 = |x: f64| x.abs().powi(3) * x / 4.0; // antiderivative of |x|³
        let omega2 = h * span * (x_abs3(le) - x_abs3(le - c));
        assert_relative_eq!(o.omega2, omega2, max_relative = 1e-13);
    }

    #[test]
    fn triangle_tip_cut_area_scales_with_the_kept_similar_triangle() {
        // Chord falls linearly to zero at the tip: cutting fraction f of the span at the tip
        // removes a similar triangle of area f² A.
        let tri = Planform::from_points(&[[0.0, 0.0], [10.0, 0.0], [0.0, -4.0]]).unwrap();
        let cut = tri.cut(0.4, CutEdge::Tip).unwrap();
        assert_relative_eq!(
            cut.area(),
            tri.area() * (1.0 - 0.4 * 0.4),
            max_relative = 1e-13
        );
    }

    #[test]
    fn a_cut_that_splits_the_membrane_is_a_geometry_error() {
        // A "U" whose base is the trailing edge and whose prongs reach the hinge line: a
        // trailing cut through the prongs leaves two pieces; a tip cut leaves one (an L).
        let u = Planform::from_points(&[
            [1.0, -6.0],
            [9.0, -6.0],
            [9.0, 0.0],
            [7.0, 0.0],
            [7.0, -4.0],
            [3.0, -4.0],
            [3.0, 0.0],
            [1.0, 0.0],
        ])
        .unwrap();
        let e = u.cut(0.5, CutEdge::TrailingEdge).unwrap_err();
        assert!(matches!(e, Error::Geometry(_)), "{e}");
        assert!(e.to_string().contains("several pieces"), "{e}");
        let l_shape = u.cut(0.5, CutEdge::Tip).unwrap();
        assert_relative_eq!(l_shape.area(), 4.0 * 2.0 + 2.0 * 4.0, max_relative = 1e-13);
    }

    #[test]
    fn a_cut_through_prongs_pointing_away_keeps_one_piece() {
        // Prongs toward the trailing edge, cut through them: four crossings, one membrane.
        let u = Planform::from_points(&[
            [1.0, 0.0],
            [1.0, -6.0],
            [3.0, -6.0],
            [3.0, -2.0],
            [7.0, -2.0],
            [7.0, -6.0],
            [9.0, -6.0],
            [9.0, 0.0],
        ])
        .unwrap();
        let cut = u.cut(0.5, CutEdge::TrailingEdge).unwrap();
        assert_relative_eq!(
            cut.area(),
            8.0 * 2.0 + 2.0 * (2.0 * 1.0),
            max_relative = 1e-13
        );
    }
}
