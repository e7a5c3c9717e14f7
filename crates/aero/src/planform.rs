//! Wing planforms and their exact area integrals (thesis §3.2.4, Fig. 3.1, eqs. 3.12–3.15).
//!
//! # Frame (Fig. 3.1 / Fig. 3.10)
//! Points are `[z, x]` in mm (horizontal, vertical axis of Fig. 3.10):
//! * `z` runs spanwise along the wing hinge, measured from the spherical centre (the rotation
//!   centre of the shoulder). The membrane must lie outboard of it: `z >= 0` everywhere.
//! * `x` runs chordwise and **increases toward the leading edge**; the hinge line is `x = 0`.
//!   `l(z)` is the `x` of the leading edge (its signed distance ahead of the hinge line) and the
//!   strip at `z` spans `x ∈ [l(z) − c(z), l(z)]`. A passively rotating wing hangs *behind* its
//!   hinge, so most of the membrane has `x < 0`. A planform lying entirely at `x >= 0` (the
//!   trailing edge ahead of the hinge) is "on the wrong side of the hinge line" and rejected:
//!   this is almost always an outline drawn with `x` pointing toward the trailing edge
//!   (mirror it, `x → −x`). Its centre of pressure would lie ahead of the hinge and passive
//!   rotation would be statically unstable.
//! * `y = z × x` is the wing normal.
//!
//! # Integration method
//! Integrals are exact for the polygon (up to round-off), not sampled. The `z` axis is cut into
//! slabs at every vertex `z` and at every `z` where an edge crosses the hinge line `x = 0`.
//! Inside a slab the set of edges crossing a line `z = const` is fixed and the edges do not cross
//! (the outline is simple), so every strip boundary `x_i(z)` is linear in `z`; hence
//! `c(z) = Σ (x_upper − x_lower)` and `l(z) = max x_i` are linear, and every integrand used here
//! (`z³c`, `z²c²`, `z²lc`, `∫|x|³dx`, `∫x²dx`, …) is a polynomial of degree ≤ 4 in `z` within a
//! slab. A 3-point Gauss–Legendre rule (exact to degree 5) per slab is therefore exact.
//! Construction is `O(n²)` in the vertex count (the simplicity check and the slab sweep).
//!
//! For outlines whose strips are not connected (a line `z = const` cuts the membrane in
//! several pieces) `c(z)` is the total cut length and `l(z)` the foremost edge: eqs. 3.14–3.15
//! then treat the strip as one chord of length `c` behind `l`, which is the thesis' assumption.

use paritysim_error::{
    Error, Result, bail, check_finite, check_length_mm, check_non_negative, check_offset_mm,
    check_positive,
};

use crate::blade::Omegas;

/// Density of air at sea level, 1.2 kg/m³ = 1.2·10⁻³ mg/mm³.
pub const DEFAULT_AIR_DENSITY: f64 = 1.2e-3;

/// Relative tolerance (to the outline's bounding-box diagonal) for coincident points, zero area
/// and points on the wrong side of the spherical centre.
const REL_TOL: f64 = 1e-12;

/// Gauss–Legendre 3-point nodes on `[-1, 1]` and weights.
const GL3: [(f64, f64); 3] = [
    (-0.774_596_669_241_483_4, 5.0 / 9.0),
    (0.0, 8.0 / 9.0),
    (0.774_596_669_241_483_4, 5.0 / 9.0),
];

/// Exact area integrals of a planform (mm^k); density-free.
///
/// All double integrals are over the membrane; `∫ … dz` integrals run over the span.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct PlanformIntegrals {
    /// `∬ dA` (mm²).
    pub area: f64,
    /// `∬ z dA` (mm³).
    pub z1: f64,
    /// `∬ x dA` (mm³).
    pub x1: f64,
    /// `∬ z² dA` (mm⁴); `½ρ` times this is the force parameter of [`Omegas::force`].
    pub z2: f64,
    /// `∬ x² dA` (mm⁴).
    pub x2: f64,
    /// `∬ x z dA` (mm⁴).
    pub xz: f64,
    /// `∬ z³ dA = ∫ z³ c(z) dz` (mm⁵), eq. 3.12 without `½ρ`.
    pub z3: f64,
    /// `∬ |x|³ dA` (mm⁵), eq. 3.13 without `½ρ`.
    pub x3_abs: f64,
    /// `∫ z² c(z)² dz` (mm⁵), eq. 3.14 without `½ρ`.
    pub z2_c2: f64,
    /// `∫ z² l(z) c(z) dz` (mm⁵), eq. 3.15 without `½ρ`.
    pub z2_lc: f64,
    /// `∫ z c² x_m dz` (mm⁵), `x_m = l − c/2` the mid-chord: Ω5 without `½ρ`
    /// ([`crate::whitney_wood`]).
    pub z_c2_xm: f64,
    /// `∫ c² x_m² dz` (mm⁵): Ω6 without `½ρ`.
    pub c2_xm2: f64,
    /// `∫ c⁴ dz` (mm⁵): Ω7 without `½ρ`.
    pub c4: f64,
    /// `∫ z c (l − c/4)(¾c − l) dz` (mm⁵): Ω8 without `½ρ`.
    pub z_rotational_lift: f64,
}

/// A validated wing outline (simple polygon, counter-clockwise in the `(z, x)` plane) with its
/// exact integrals. Immutable, `Send + Sync`.
#[derive(Clone, Debug, PartialEq)]
pub struct Planform {
    vertices: Vec<[f64; 2]>,
    integrals: PlanformIntegrals,
    z_min: f64,
    z_max: f64,
    x_min: f64,
    x_max: f64,
}

#[inline]
fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// `p` (collinear with `a, b`) lies within the segment's bounding box.
#[inline]
fn within(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> bool {
    p[0] >= a[0].min(b[0])
        && p[0] <= a[0].max(b[0])
        && p[1] >= a[1].min(b[1])
        && p[1] <= a[1].max(b[1])
}

/// Closed-segment intersection test (touching counts).
fn segments_intersect(p1: [f64; 2], p2: [f64; 2], q1: [f64; 2], q2: [f64; 2]) -> bool {
    if p1[0].max(p2[0]) < q1[0].min(q2[0])
        || q1[0].max(q2[0]) < p1[0].min(p2[0])
        || p1[1].max(p2[1]) < q1[1].min(q2[1])
        || q1[1].max(q2[1]) < p1[1].min(p2[1])
    {
        return false;
    }
    let d1 = orient(q1, q2, p1);
    let d2 = orient(q1, q2, p2);
    let d3 = orient(p1, p2, q1);
    let d4 = orient(p1, p2, q2);
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && within(q1, q2, p1))
        || (d2 == 0.0 && within(q1, q2, p2))
        || (d3 == 0.0 && within(p1, p2, q1))
        || (d4 == 0.0 && within(p1, p2, q2))
}

/// `∫_0^x |t|³ dt = x³|x|/4`.
#[inline]
fn abs_cube_antiderivative(x: f64) -> f64 {
    x * x * x * x.abs() / 4.0
}

/// A parametric outline must reach behind the hinge line (`x < 0`): named at `le_offset`.
fn behind_hinge(le_offset: f64, chord: f64) -> Result<()> {
    if le_offset < chord {
        Ok(())
    } else {
        Err(Error::invalid(
            "le_offset",
            le_offset,
            format!("< the chord ({chord} mm): the membrane must extend behind the hinge line"),
        ))
    }
}

fn fmt_pt(p: [f64; 2]) -> String {
    format!("(z = {}, x = {})", p[0], p[1])
}

impl Planform {
    /// A planform from the vertices of its outline, `[z, x]` in mm (see the module docs for the
    /// frame). The closing edge (last → first vertex) is implicit; a repeated first vertex at
    /// the end is accepted. Either orientation is accepted; consecutive duplicate vertices are
    /// dropped.
    ///
    /// # Errors
    /// * [`Error::InvalidParameter`] for a non-finite coordinate (`points[i]`).
    /// * [`Error::Geometry`] if fewer than 3 distinct vertices remain, the area is zero
    ///   (collinear points), two edges intersect or touch (self-intersecting outline), the
    ///   outline reaches `z < 0` (inboard of the spherical centre), or it lies entirely at
    ///   `x >= 0` (on the wrong side of the hinge line).
    pub fn from_points(points: &[[f64; 2]]) -> Result<Self> {
        let reach = paritysim_error::plausible::OFFSET_MM;
        for (i, p) in points.iter().enumerate() {
            let plausible = |c: f64| c.is_finite() && c.abs() <= reach;
            if !(plausible(p[0]) && plausible(p[1])) {
                return Err(Error::invalid(
                    format!("points[{i}]"),
                    format!("[{}, {}]", p[0], p[1]),
                    format!("finite [z, x] in mm with |z|, |x| <= {reach:e}"),
                ));
            }
        }
        if points.len() < 3 {
            bail!(Geometry
                "outline needs at least 3 vertices, got {}", points.len());
        }
        let scale = Self::bbox_diagonal(points);
        let tol = REL_TOL * scale;
        let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) <= tol;

        let mut v: Vec<[f64; 2]> = Vec::with_capacity(points.len());
        for &p in points {
            if v.last().is_none_or(|&q| !close(p, q)) {
                v.push(p);
            }
        }
        while v.len() > 1 && close(v[0], v[v.len() - 1]) {
            v.pop();
        }
        if v.len() < 3 {
            bail!(Geometry
                "degenerate outline: only {} distinct vertices (need at least 3)", v.len());
        }

        // All vertices on one line: zero area (reported before the fold-backs it implies).
        let far = v
            .iter()
            .copied()
            .max_by(|a, b| {
                let da = (a[0] - v[0][0]).hypot(a[1] - v[0][1]);
                let db = (b[0] - v[0][0]).hypot(b[1] - v[0][1]);
                da.total_cmp(&db)
            })
            .unwrap_or(v[0]);
        if v.iter()
            .all(|&p| orient(v[0], far, p).abs() <= REL_TOL * scale * scale)
        {
            bail!(Geometry
                "degenerate outline: zero area (all {} vertices are collinear)", v.len());
        }
        Self::check_simple(&v)?;
        let mut area2 = 0.0;
        for i in 0..v.len() {
            let (a, b) = (v[i], v[(i + 1) % v.len()]);
            area2 += a[0] * b[1] - b[0] * a[1];
        }
        if area2.abs() <= 2.0 * REL_TOL * scale * scale {
            bail!(Geometry "degenerate outline: zero area");
        }
        if area2 < 0.0 {
            v.reverse();
        }

        let z_min = v.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min);
        let z_max = v.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max);
        let x_min = v.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
        let x_max = v.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max);
        if z_min < -tol {
            let p = v
                .iter()
                .find(|p| p[0] == z_min)
                .copied()
                .unwrap_or([z_min, 0.0]);
            bail!(Geometry
                "planform is on the wrong side of the spherical centre: vertex {} has z < 0; \
                 z runs spanwise along the hinge from the rotation centre, so every point needs \
                 z >= 0", fmt_pt(p));
        }
        if x_min >= 0.0 {
            bail!(Geometry
                "planform is on the wrong side of the hinge line: it lies entirely at x >= 0 \
                 (x from {x_min} to {x_max} mm). x increases toward the leading edge and the \
                 membrane must extend behind the hinge (x < 0); mirror the outline (x -> -x) if \
                 it was drawn with x toward the trailing edge");
        }
        let integrals = Self::integrate(&v);
        Ok(Self {
            vertices: v,
            integrals,
            z_min: z_min.max(0.0),
            z_max,
            x_min,
            x_max,
        })
    }

    /// A planform from a traced (e.g. photogrammetric) outline that must come back to its start:
    /// the first and last points must lie within `closure_tolerance` mm of each other; the last
    /// point is then dropped and the outline validated as in [`Self::from_points`].
    ///
    /// # Errors
    /// [`Error::Geometry`] if the outline is open (ends farther apart than the tolerance), and
    /// everything [`Self::from_points`] reports; [`Error::InvalidParameter`] for a negative or
    /// non-finite `closure_tolerance`.
    pub fn from_traced_outline(points: &[[f64; 2]], closure_tolerance: f64) -> Result<Self> {
        check_non_negative("closure_tolerance", closure_tolerance)?;
        if let Some(i) = points
            .iter()
            .position(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            let p = points[i];
            return Err(Error::invalid(
                format!("points[{i}]"),
                format!("[{}, {}]", p[0], p[1]),
                "finite [z, x] in mm",
            ));
        }
        if points.len() < 4 {
            bail!(Geometry
                "a traced outline needs at least 4 points (3 vertices plus the closing point), \
                 got {}", points.len());
        }
        let (a, b) = (points[0], points[points.len() - 1]);
        let gap = (a[0] - b[0]).hypot(a[1] - b[1]);
        if gap > closure_tolerance {
            bail!(Geometry
                "outline is open: first point {} and last point {} are {gap} mm apart \
                 (closure tolerance {closure_tolerance} mm)", fmt_pt(a), fmt_pt(b));
        }
        Self::from_points(&points[..points.len() - 1])
    }

    /// Rectangle `z ∈ [root_offset, root_offset + span]`, `x ∈ [le_offset − chord, le_offset]`
    /// (leading edge `le_offset` ahead of the hinge line; 0 puts the leading edge on it).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `span` and `chord` are lengths in
    /// [`paritysim_error::plausible::LENGTH_MM`], `0 <= root_offset` and `|le_offset|` are within
    /// [`paritysim_error::plausible::OFFSET_MM`], and `le_offset < chord` (the membrane must reach
    /// behind the hinge line).
    pub fn rectangle(span: f64, chord: f64, root_offset: f64, le_offset: f64) -> Result<Self> {
        check_length_mm("span", span)?;
        check_length_mm("chord", chord)?;
        check_non_negative("root_offset", root_offset)?;
        check_offset_mm("root_offset", root_offset)?;
        check_offset_mm("le_offset", le_offset)?;
        behind_hinge(le_offset, chord)?;
        let (z0, z1) = (root_offset, root_offset + span);
        let (xt, xl) = (le_offset - chord, le_offset);
        Self::from_points(&[[z0, xt], [z1, xt], [z1, xl], [z0, xl]])
    }

    /// Half of an ellipse cut along its major axis, the cut being a straight leading edge at
    /// `x = le_offset` from `z = root_offset` to `root_offset + span`; the chord is
    /// `c(z) = max_chord·sqrt(1 − u²)`, `u = 2(z − root_offset)/span − 1` (elliptic trailing
    /// edge, zero chord at root and tip).
    ///
    /// Represented as a polygon: the trailing edge is sampled at `segments` equal steps of the
    /// eccentric angle (`z = z_c − (span/2) cos t`, `c = max_chord sin t`), so the polygon's
    /// integrals (exact for the polygon) converge to the ellipse's as `O(segments⁻²)`; the
    /// polygon area is `(segments/π) sin(π/segments)` times `π/4 · span · max_chord`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `span` and `max_chord` are lengths in
    /// [`paritysim_error::plausible::LENGTH_MM`], `0 <= root_offset` and `|le_offset|` are within
    /// [`paritysim_error::plausible::OFFSET_MM`], `le_offset < max_chord` (the membrane reaches
    /// behind the hinge line) and `4 <= segments <= 1_000_000`.
    pub fn semi_ellipse(
        span: f64,
        max_chord: f64,
        root_offset: f64,
        le_offset: f64,
        segments: usize,
    ) -> Result<Self> {
        check_length_mm("span", span)?;
        check_length_mm("max_chord", max_chord)?;
        check_non_negative("root_offset", root_offset)?;
        check_offset_mm("root_offset", root_offset)?;
        check_offset_mm("le_offset", le_offset)?;
        behind_hinge(le_offset, max_chord)?;
        if !(4..=1_000_000).contains(&segments) {
            return Err(Error::invalid("segments", segments, "in [4, 1000000]"));
        }
        let a = 0.5 * span;
        let zc = root_offset + a;
        let mut pts = Vec::with_capacity(segments + 1);
        pts.push([root_offset, le_offset]);
        for k in 1..segments {
            let t = std::f64::consts::PI * k as f64 / segments as f64;
            pts.push([zc - a * t.cos(), le_offset - max_chord * t.sin()]);
        }
        pts.push([root_offset + span, le_offset]);
        Self::from_points(&pts)
    }

    /// A smooth wing shaped like the Harvard Microrobotic Fly wing of §3.4 (Fig. 3.10), scaled
    /// to `tip_radius` (mm from the spherical centre to the tip).
    ///
    /// With `R = tip_radius` and `η ∈ [0, 1]` along the membrane: root offset `0.25 R`, chord
    /// `c(η) = 0.31 R · sqrt(1 − η⁶) · (0.55 + 0.45 sin(min(η/0.55, 1)·π/2))` (root chord
    /// 0.55·c_max, full chord from 55 % of the membrane span, rounded tip), leading edge
    /// `l = 0.04 c` ahead of the hinge line, trailing edge `−0.96 c`. Sampled at `segments`
    /// stations per edge, clustered toward the tip. At `R ≈ 16.6 mm` its Ω1..Ω4 are close to
    /// the left wing of Table 3.3 (see the crate tests); it is a stand-in, not the measured
    /// outline.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `tip_radius` is a length in
    /// [`paritysim_error::plausible::LENGTH_MM`] and `4 <= segments <= 1_000_000`.
    pub fn hmf_like(tip_radius: f64, segments: usize) -> Result<Self> {
        check_length_mm("tip_radius", tip_radius)?;
        if !(4..=1_000_000).contains(&segments) {
            return Err(Error::invalid("segments", segments, "in [4, 1000000]"));
        }
        let r = tip_radius;
        let (z_root, c_max, lead) = (0.25 * r, 0.31 * r, 0.04);
        let chord = |eta: f64| {
            let shape = 0.55 + 0.45 * (std::f64::consts::FRAC_PI_2 * (eta / 0.55).min(1.0)).sin();
            c_max * (1.0 - eta.powi(6)).max(0.0).sqrt() * shape
        };
        let eta = |k: usize| (std::f64::consts::FRAC_PI_2 * k as f64 / segments as f64).sin();
        let z = |e: f64| z_root + (r - z_root) * e;
        let mut pts = Vec::with_capacity(2 * segments + 1);
        for k in 0..=segments {
            let e = if k == segments { 1.0 } else { eta(k) };
            pts.push([z(e), lead * chord(e)]);
        }
        for k in (0..segments).rev() {
            let e = eta(k);
            pts.push([z(e), (lead - 1.0) * chord(e)]);
        }
        Self::from_points(&pts)
    }

    /// This planform scaled uniformly by `factor` about the spherical centre.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `factor > 0`.
    pub fn scaled(&self, factor: f64) -> Result<Self> {
        check_positive("factor", factor)?;
        let pts: Vec<[f64; 2]> = self
            .vertices
            .iter()
            .map(|p| [p[0] * factor, p[1] * factor])
            .collect();
        Self::from_points(&pts)
    }

    /// This planform translated by `dz` (spanwise) and `dx` (chordwise, toward the leading
    /// edge); `dx` moves the wing relative to the hinge line, i.e. moves the hinge line by `−dx`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for non-finite offsets; [`Error::Geometry`] if the result
    /// reaches `z < 0` or lies entirely ahead of the hinge line.
    pub fn translated(&self, dz: f64, dx: f64) -> Result<Self> {
        check_finite("dz", dz)?;
        check_finite("dx", dx)?;
        let pts: Vec<[f64; 2]> = self
            .vertices
            .iter()
            .map(|p| [p[0] + dz, p[1] + dx])
            .collect();
        Self::from_points(&pts)
    }

    fn bbox_diagonal(points: &[[f64; 2]]) -> f64 {
        let (mut z0, mut z1, mut x0, mut x1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for p in points {
            z0 = z0.min(p[0]);
            z1 = z1.max(p[0]);
            x0 = x0.min(p[1]);
            x1 = x1.max(p[1]);
        }
        (z1 - z0).hypot(x1 - x0)
    }

    /// Rejects touching/crossing non-adjacent edges and fold-backs of adjacent edges.
    fn check_simple(v: &[[f64; 2]]) -> Result<()> {
        let n = v.len();
        for i in 0..n {
            let (a, b, c) = (v[(i + n - 1) % n], v[i], v[(i + 1) % n]);
            let dot = (b[0] - a[0]) * (c[0] - b[0]) + (b[1] - a[1]) * (c[1] - b[1]);
            if orient(a, b, c) == 0.0 && dot < 0.0 {
                bail!(Geometry
                    "self-intersecting outline: it folds back on itself at vertex {i} {}",
                    fmt_pt(b));
            }
        }
        // Sweep over z: only edges whose z-ranges overlap can meet, so a sampled outline of
        // n vertices costs O(n log n) instead of O(n²) (segments = 10⁶ took over a minute).
        let edge = |i: usize| (v[i], v[(i + 1) % n]);
        let z_range = |i: usize| {
            let (a, b) = edge(i);
            (a[0].min(b[0]), a[0].max(b[0]))
        };
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| z_range(a).0.total_cmp(&z_range(b).0));
        let mut active: Vec<usize> = Vec::new();
        for &j in &order {
            let z_lo = z_range(j).0;
            active.retain(|&i| z_range(i).1 >= z_lo);
            for &i in &active {
                let (lo, hi) = (i.min(j), i.max(j));
                if hi - lo == 1 || (lo == 0 && hi == n - 1) {
                    continue; // adjacent edges share a vertex
                }
                let ((p1, p2), (q1, q2)) = (edge(lo), edge(hi));
                if segments_intersect(p1, p2, q1, q2) {
                    bail!(Geometry
                        "self-intersecting outline: edge {lo} {} -> {} meets edge {hi} {} -> {}",
                        fmt_pt(p1), fmt_pt(p2), fmt_pt(q1), fmt_pt(q2));
                }
            }
            active.push(j);
        }
        Ok(())
    }

    /// Sorted `x` of the edges crossing the line `z` (half-open crossing rule).
    fn crossings(v: &[[f64; 2]], z: f64, out: &mut Vec<f64>) {
        out.clear();
        let n = v.len();
        for i in 0..n {
            let (a, b) = (v[i], v[(i + 1) % n]);
            if (a[0] <= z && z < b[0]) || (b[0] <= z && z < a[0]) {
                out.push(a[1] + (z - a[0]) * (b[1] - a[1]) / (b[0] - a[0]));
            }
        }
        out.sort_unstable_by(f64::total_cmp);
    }

    fn integrate(v: &[[f64; 2]]) -> PlanformIntegrals {
        let n = v.len();
        let mut breaks: Vec<f64> = v.iter().map(|p| p[0]).collect();
        for i in 0..n {
            let (a, b) = (v[i], v[(i + 1) % n]);
            if (a[1] < 0.0 && b[1] > 0.0) || (a[1] > 0.0 && b[1] < 0.0) {
                // z where the edge crosses the hinge line x = 0 (kink of |x|³).
                breaks.push(a[0] + (b[0] - a[0]) * a[1] / (a[1] - b[1]));
            }
        }
        breaks.sort_unstable_by(f64::total_cmp);
        breaks.dedup();

        let mut s = PlanformIntegrals::default();
        let mut xs = Vec::with_capacity(8);
        // Every vertex z is a break, so the edges crossing a slab's interior span all of it:
        // sweep them in z order (O(n log n); a full scan per node was O(n²)).
        let mut by_start: Vec<usize> = (0..n).filter(|&i| v[i][0] != v[(i + 1) % n][0]).collect();
        by_start.sort_by(|&a, &b| {
            let lo = |i: usize| v[i][0].min(v[(i + 1) % n][0]);
            lo(a).total_cmp(&lo(b))
        });
        let mut next_edge = 0;
        let mut active: Vec<usize> = Vec::new();
        for w in breaks.windows(2) {
            let (z0, z1) = (w[0], w[1]);
            if z1 <= z0 {
                continue;
            }
            let (mid, half) = (0.5 * (z0 + z1), 0.5 * (z1 - z0));
            while next_edge < by_start.len() {
                let i = by_start[next_edge];
                if v[i][0].min(v[(i + 1) % n][0]) > mid {
                    break;
                }
                active.push(i);
                next_edge += 1;
            }
            active.retain(|&i| v[i][0].max(v[(i + 1) % n][0]) > mid);
            for &(t, wt) in &GL3 {
                let z = mid + half * t;
                xs.clear();
                for &i in &active {
                    let (a, b) = (v[i], v[(i + 1) % n]);
                    xs.push(a[1] + (z - a[0]) * (b[1] - a[1]) / (b[0] - a[0]));
                }
                xs.sort_unstable_by(f64::total_cmp);
                let (mut c, mut m1, mut m2, mut m3) = (0.0, 0.0, 0.0, 0.0);
                let mut lead = f64::NEG_INFINITY;
                for pair in xs.chunks_exact(2) {
                    let (lo, hi) = (pair[0], pair[1]);
                    c += hi - lo;
                    m1 += 0.5 * (hi * hi - lo * lo);
                    m2 += (hi * hi * hi - lo * lo * lo) / 3.0;
                    m3 += abs_cube_antiderivative(hi) - abs_cube_antiderivative(lo);
                    lead = lead.max(hi);
                }
                if c == 0.0 {
                    continue;
                }
                let wz = wt * half;
                let z2 = z * z;
                s.area += wz * c;
                s.z1 += wz * z * c;
                s.x1 += wz * m1;
                s.z2 += wz * z2 * c;
                s.x2 += wz * m2;
                s.xz += wz * z * m1;
                s.z3 += wz * z2 * z * c;
                s.x3_abs += wz * m3;
                s.z2_c2 += wz * z2 * c * c;
                s.z2_lc += wz * z2 * lead * c;
                let xm = lead - 0.5 * c;
                s.z_c2_xm += wz * z * c * c * xm;
                s.c2_xm2 += wz * c * c * xm * xm;
                s.c4 += wz * c * c * c * c;
                s.z_rotational_lift += wz * z * c * (lead - 0.25 * c) * (0.75 * c - lead);
            }
        }
        s
    }

    /// Outline vertices `[z, x]` (mm), counter-clockwise in the `(z, x)` plane, without the
    /// closing repeat.
    pub fn vertices(&self) -> &[[f64; 2]] {
        &self.vertices
    }

    /// The exact density-free integrals.
    pub fn integrals(&self) -> &PlanformIntegrals {
        &self.integrals
    }

    /// Membrane area (mm²).
    pub fn area(&self) -> f64 {
        self.integrals.area
    }

    /// Distance from the spherical centre to the wing tip, `max z` (mm): the "16.0 mm beyond
    /// the wing pivot" of §3.3.2.
    pub fn tip_radius(&self) -> f64 {
        self.z_max
    }

    /// Innermost membrane `z` (mm), the root offset from the spherical centre.
    pub fn root_offset(&self) -> f64 {
        self.z_min
    }

    /// Spanwise extent of the membrane, `max z − min z` (mm).
    pub fn span(&self) -> f64 {
        self.z_max - self.z_min
    }

    /// Chordwise extent `(min x, max x)` (mm).
    pub fn x_range(&self) -> (f64, f64) {
        (self.x_min, self.x_max)
    }

    /// Geometric mean chord, area / span (mm).
    pub fn mean_chord(&self) -> f64 {
        self.integrals.area / self.span()
    }

    /// Area centroid `[z, x]` (mm).
    pub fn centroid(&self) -> [f64; 2] {
        let a = self.integrals.area;
        [self.integrals.z1 / a, self.integrals.x1 / a]
    }

    /// Chord `c(z)` (mm): total length of the membrane cut by the line `z`; 0 outside the span
    /// (and for non-finite `z`).
    pub fn chord(&self, z: f64) -> f64 {
        let mut xs = Vec::with_capacity(8);
        Self::crossings(&self.vertices, z, &mut xs);
        xs.chunks_exact(2).map(|p| p[1] - p[0]).sum()
    }

    /// Leading edge `l(z)` (mm, the foremost membrane `x` on the line `z`), `None` outside the
    /// span or for non-finite `z`.
    pub fn leading_edge(&self, z: f64) -> Option<f64> {
        let mut xs = Vec::with_capacity(8);
        Self::crossings(&self.vertices, z, &mut xs);
        xs.last().copied()
    }

    /// Ω1..Ω4 (eqs. 3.12–3.15, mg·mm²) and the force parameter `½ρ∬z²dA` (mg·mm) for air of
    /// `density` mg/mm³ (use [`DEFAULT_AIR_DENSITY`] for 1.2 kg/m³):
    ///
    /// ```text
    /// Ω1 = ½ρ ∬ z³ dA        Ω2 = ½ρ ∬ |x|³ dA
    /// Ω3 = ½ρ ∫ z² c² dz     Ω4 = ½ρ ∫ z² l c dz
    /// ```
    ///
    /// No force coefficient is folded in: the moments multiply by `C_N(α)`, `C_T(α)`, `C_rd`
    /// and `d̂_cp(α)` at run time (eqs. 3.8–3.11). See docs/errata.md#12 for the `Ω φ̇²` form.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`density`) unless `density` is finite and > 0.
    pub fn omegas(&self, density: f64) -> Result<Omegas> {
        check_positive("density", density)?;
        let h = 0.5 * density;
        let s = &self.integrals;
        Ok(Omegas {
            omega1: h * s.z3,
            omega2: h * s.x3_abs,
            omega3: h * s.z2_c2,
            omega4: h * s.z2_lc,
            force: Some(h * s.z2),
        })
    }

    /// Ω5..Ω8 of the Whitney & Wood 2010 model ([`crate::whitney_wood`], mg·mm²) for air of
    /// `density` mg/mm³, with the mid-chord `x_m = l − c/2`:
    ///
    /// ```text
    /// Ω5 = ½ρ ∫ z c² x_m dz     Ω6 = ½ρ ∫ c² x_m² dz
    /// Ω7 = ½ρ ∫ c⁴ dz           Ω8 = ½ρ ∫ z c (l − c/4)(¾c − l) dz
    /// ```
    ///
    /// `c` is the membrane's total chord at `z` and `l` its foremost edge, as in Ω3, Ω4; each
    /// integrand is a polynomial of degree 4 on a slab, so the 3-point Gauss rule is exact.
    ///
    /// # Errors
    /// As [`Self::omegas`].
    pub fn quasi_steady_omegas(&self, density: f64) -> Result<crate::QuasiSteadyOmegas> {
        check_positive("density", density)?;
        let h = 0.5 * density;
        let s = &self.integrals;
        Ok(crate::QuasiSteadyOmegas {
            omega5: h * s.z_c2_xm,
            omega6: h * s.c2_xm2,
            omega7: h * s.c4,
            omega8: h * s.z_rotational_lift,
        })
    }
}
