//! Integration tests of paritysim-aero (one binary for the crate): physics and closed forms,
//! not recorded outputs.
//!
//! # Closed forms used below (derived by hand; `h = ½ρ`)
//!
//! **Rectangle** `z ∈ [z0, z1]`, `x ∈ [l0 − c, l0]`, `F(x) = x³|x|/4`:
//! `A = c(z1 − z0)`, `Ω1 = h c (z1⁴ − z0⁴)/4`, `Ω2 = h (z1 − z0)(F(l0) − F(l0 − c))`,
//! `Ω3 = h c² (z1³ − z0³)/3`, `Ω4 = h l0 c (z1³ − z0³)/3`.
//! Membrane inertia (areal density σ): `Ixx = σ c (z1³ − z0³)/3`,
//! `Izz = σ (z1 − z0)(l0³ − (l0 − c)³)/3`, `Ixz = −σ (z1² − z0²)/2 · (l0² − (l0 − c)²)/2`.
//! A line mass λ along `z ∈ [z0, z1]` at `x = x_s` adds `λ(z1³ − z0³)/3` to Ixx, `λ L x_s²` to
//! Izz and `−λ x_s (z1² − z0²)/2` to Ixz; a point mass m at `(z, x)` adds `m z²`, `m x²`,
//! `−m x z`.
//!
//! **Triangle** `(0, l0), (R, l0), (0, l0 − c0)`: `c(z) = c0 (1 − z/R)`, `l = l0`.
//! `A = c0 R/2`, `∫z³c = c0 R⁴/20`, `∫z²c² = c0² R³ (1/3 − 1/2 + 1/5) = c0² R³/30`,
//! `∫z² l c = l0 c0 R³/12`; with `l0 = 0`: `∬|x|³ = ∫c⁴/4 = c0⁴ R/20`, `∬z² = c0 R³/12`,
//! `∬x² = ∫c³/3 = c0³ R/12`, `∬xz = −∫z c²/2 = −c0² R²/24`.
//!
//! **Semi-ellipse** with straight leading edge `x = l0` on `z ∈ [z0, z0 + 2a]`, `zc = z0 + a`,
//! `c = cm √(1 − u²)`, `z = zc + a u`, using `∫√(1−u²) = π/2`, `∫u²√(1−u²) = π/8`,
//! `∫(1−u²) = 4/3`, `∫u²(1−u²) = 4/15`, `∫(1−u²)² = 16/15`, `∫(1−u²)^{3/2} = 3π/8`:
//! `A = π a cm/2`, `∫z³c = cm a π (zc³/2 + 3 zc a²/8)`, `∫z²c² = cm² a (4zc²/3 + 4a²/15)`,
//! `∫z² l c = l0 cm a π (zc²/2 + a²/8)`; with `l0 = 0`: `∬|x|³ = 4 cm⁴ a/15`,
//! `∬z² = cm a π (zc²/2 + a²/8)`, `∬x² = π cm³ a/8`, `∬xz = −2 cm² a zc/3`.
//! The polygon with `N` equal eccentric-angle steps has area `(N/π) sin(π/N)` times `A`.

use std::f64::consts::{FRAC_PI_2, PI};

use approx::assert_relative_eq;
use nalgebra::Vector3;
use paritysim_aero::coefficients::checked_coefficients;
use paritysim_aero::{
    BladeElementModel, CoefficientModel, CoefficientSet, DEFAULT_AIR_DENSITY, Dickinson1999, Error,
    LineMass, MassDistribution, NormalForceLaw, Omegas, Planform, PointMass, WhitneyWood2010,
    WingState, center_of_pressure, drag_torque_eq_2_16, from_normal_tangential,
    to_normal_tangential,
};
use proptest::prelude::*;

const RHO: f64 = DEFAULT_AIR_DENSITY;
const H: f64 = 0.5 * RHO;

fn abs_cube(x: f64) -> f64 {
    x * x * x * x.abs() / 4.0
}

/// Table 3.3, left wing ("All" trials).
fn table_3_3_left() -> Omegas {
    Omegas::new(46.8, 0.587, 17.5, 0.712).unwrap()
}

fn dickinson_model(o: Omegas) -> BladeElementModel {
    BladeElementModel::new(o, CoefficientSet::default()).unwrap()
}

// ---------------------------------------------------------------- planform closed forms

#[test]
fn rectangle_matches_closed_forms() {
    let (z0, span, c, l0) = (1.5, 12.0, 3.0, 0.4);
    let z1 = z0 + span;
    let p = Planform::rectangle(span, c, z0, l0).unwrap();
    let o = p.omegas(RHO).unwrap();
    assert_relative_eq!(p.area(), c * span, max_relative = 1e-13);
    assert_relative_eq!(p.span(), span, max_relative = 1e-13);
    assert_relative_eq!(p.tip_radius(), z1, max_relative = 1e-13);
    assert_relative_eq!(p.root_offset(), z0, max_relative = 1e-13);
    assert_relative_eq!(p.mean_chord(), c, max_relative = 1e-13);
    assert_relative_eq!(
        o.omega1,
        H * c * (z1.powi(4) - z0.powi(4)) / 4.0,
        max_relative = 1e-12
    );
    assert_relative_eq!(
        o.omega2,
        H * span * (abs_cube(l0) - abs_cube(l0 - c)),
        max_relative = 1e-12
    );
    assert_relative_eq!(
        o.omega3,
        H * c * c * (z1.powi(3) - z0.powi(3)) / 3.0,
        max_relative = 1e-12
    );
    assert_relative_eq!(
        o.omega4,
        H * l0 * c * (z1.powi(3) - z0.powi(3)) / 3.0,
        max_relative = 1e-12
    );
    assert_relative_eq!(
        o.force.unwrap(),
        H * c * (z1.powi(3) - z0.powi(3)) / 3.0,
        max_relative = 1e-12
    );
    // c(z), l(z)
    assert_relative_eq!(p.chord(0.5 * (z0 + z1)), c, max_relative = 1e-13);
    assert_relative_eq!(p.leading_edge(7.0).unwrap(), l0, max_relative = 1e-13);
    assert_eq!(p.chord(z1 + 0.1), 0.0);
    assert_eq!(p.leading_edge(z0 - 0.1), None);
    assert_eq!(p.chord(f64::NAN), 0.0);
}

#[test]
fn rectangle_inertia_with_spar_and_point_mass() {
    let (z0, span, c, l0) = (1.0, 10.0, 3.0, 0.5);
    let z1 = z0 + span;
    let p = Planform::rectangle(span, c, z0, l0).unwrap();
    let (sigma, lambda, xs, m, pz, px) = (2.0e-3, 0.03, 0.2, 0.05, 2.0, -1.0);
    let dist = MassDistribution {
        areal_density: sigma,
        line_masses: vec![LineMass {
            start: [z0, xs],
            end: [z1, xs],
            linear_density: lambda,
        }],
        point_masses: vec![PointMass {
            position: [pz, px],
            mass: m,
        }],
    };
    let i = p.inertia(&dist).unwrap();
    let dz3 = (z1.powi(3) - z0.powi(3)) / 3.0;
    let dz2 = (z1 * z1 - z0 * z0) / 2.0;
    let ixx = sigma * c * dz3 + lambda * dz3 + m * pz * pz;
    let izz = sigma * span * (l0.powi(3) - (l0 - c).powi(3)) / 3.0
        + lambda * span * xs * xs
        + m * px * px;
    let ixz = -sigma * dz2 * (l0 * l0 - (l0 - c).powi(2)) / 2.0 - lambda * xs * dz2 - m * px * pz;
    let mass = sigma * c * span + lambda * span + m;
    assert_relative_eq!(i.mass, mass, max_relative = 1e-13);
    assert_relative_eq!(i.ixx, ixx, max_relative = 1e-12);
    assert_relative_eq!(i.izz, izz, max_relative = 1e-12);
    assert_relative_eq!(i.iyy, ixx + izz, max_relative = 1e-12);
    assert_relative_eq!(i.ixz, ixz, max_relative = 1e-12);
    let zc = (sigma * c * span * 0.5 * (z0 + z1) + lambda * span * 0.5 * (z0 + z1) + m * pz) / mass;
    assert_relative_eq!(i.center_of_mass[0], zc, max_relative = 1e-12);
    let t = i.tensor();
    assert_eq!(t[(0, 2)], t[(2, 0)]);
    assert_eq!(t[(0, 1)], 0.0);
    // Wing hanging behind the hinge: Ixz > 0, the sign of Table 3.3.
    let behind = Planform::rectangle(10.0, 3.0, 1.0, 0.0).unwrap();
    assert!(
        behind
            .inertia(&MassDistribution::membrane(1e-3))
            .unwrap()
            .ixz
            > 0.0
    );
}

#[test]
fn triangle_matches_closed_forms() {
    let (r, c0) = (9.0, 4.0);
    let p = Planform::from_points(&[[0.0, 0.0], [r, 0.0], [0.0, -c0]]).unwrap();
    let s = p.integrals();
    assert_relative_eq!(s.area, c0 * r / 2.0, max_relative = 1e-13);
    assert_relative_eq!(s.z3, c0 * r.powi(4) / 20.0, max_relative = 1e-12);
    assert_relative_eq!(s.x3_abs, c0.powi(4) * r / 20.0, max_relative = 1e-12);
    assert_relative_eq!(s.z2_c2, c0 * c0 * r.powi(3) / 30.0, max_relative = 1e-12);
    assert!(s.z2_lc.abs() < 1e-12);
    assert_relative_eq!(s.z2, c0 * r.powi(3) / 12.0, max_relative = 1e-12);
    assert_relative_eq!(s.x2, c0.powi(3) * r / 12.0, max_relative = 1e-12);
    assert_relative_eq!(s.xz, -c0 * c0 * r * r / 24.0, max_relative = 1e-12);
    let i = p.inertia(&MassDistribution::membrane(1.0)).unwrap();
    assert_relative_eq!(i.ixz, c0 * c0 * r * r / 24.0, max_relative = 1e-12);
    // Leading edge 0.3 mm ahead of the hinge: Ω4 = h l0 c0 R³/12, Ω1 and Ω3 unchanged.
    let l0 = 0.3;
    let q = p.translated(0.0, l0).unwrap();
    let o = q.omegas(RHO).unwrap();
    assert_relative_eq!(
        o.omega4,
        H * l0 * c0 * r.powi(3) / 12.0,
        max_relative = 1e-12
    );
    assert_relative_eq!(o.omega1, H * c0 * r.powi(4) / 20.0, max_relative = 1e-12);
    assert_relative_eq!(
        o.omega3,
        H * c0 * c0 * r.powi(3) / 30.0,
        max_relative = 1e-12
    );
    // Ω2 across the hinge line: ∫ (F(l0) − F(l0 − c)) dz with c linear, checked against a
    // fine midpoint rule (the integrand is smooth in z).
    let n = 200_000;
    let mut x3 = 0.0;
    for k in 0..n {
        let z = (k as f64 + 0.5) * r / n as f64;
        let c = c0 * (1.0 - z / r);
        x3 += abs_cube(l0) - abs_cube(l0 - c);
    }
    x3 *= r / n as f64;
    assert_relative_eq!(o.omega2, H * x3, max_relative = 1e-8);
}

/// The simple-outline check and the integrals sweep in z, so a finely sampled outline is
/// cheap; its polygon area is still exact (issue 14: 10⁶ segments took over a minute).
#[test]
fn finely_sampled_outlines_are_exact() {
    let n = 1_000_000;
    let (span, cm) = (3.0, 3.0);
    let p = Planform::semi_ellipse(span, cm, 0.0, 0.0, n).unwrap();
    let nf = n as f64;
    let area = PI * span * cm / 4.0 * nf / PI * (PI / nf).sin();
    assert_relative_eq!(p.integrals().area, area, max_relative = 1e-9);
    let hmf = Planform::hmf_like(16.6, n).unwrap();
    let coarse = Planform::hmf_like(16.6, 4096).unwrap();
    assert_relative_eq!(
        hmf.integrals().z3,
        coarse.integrals().z3,
        max_relative = 1e-6
    );
}

/// Implausible magnitudes are rejected at the field instead of overflowing (issue 14).
#[test]
fn implausible_sizes_name_the_field() {
    let field = |r: paritysim_error::Result<Planform>| r.unwrap_err().field().map(str::to_owned);
    assert_eq!(
        field(Planform::hmf_like(1e300, 64)).as_deref(),
        Some("tip_radius")
    );
    assert_eq!(
        field(Planform::rectangle(1e300, 3.0, 0.0, 0.0)).as_deref(),
        Some("span")
    );
    assert_eq!(
        field(Planform::semi_ellipse(3.0, 3.0, 0.0, 1e300, 64)).as_deref(),
        Some("le_offset")
    );
    assert_eq!(
        field(Planform::from_points(&[
            [0.0, 0.0],
            [1e301, 0.0],
            [1.0, -1.0]
        ]))
        .as_deref(),
        Some("points[1]")
    );
    let small = Planform::rectangle(10.0, 3.0, 0.0, 0.0).unwrap();
    assert!(small.scaled(1e300).is_err());
}

#[test]
fn semi_ellipse_converges_to_closed_forms() {
    let (span, cm, z0) = (14.0, 4.0, 0.8);
    let a = span / 2.0;
    let zc = z0 + a;
    let n = 4096;
    let p = Planform::semi_ellipse(span, cm, z0, 0.0, n).unwrap();
    let s = p.integrals();
    let area = PI * a * cm / 2.0;
    // The polygon's own area is exact.
    let nf = n as f64;
    assert_relative_eq!(
        s.area,
        area * nf / PI * (PI / nf).sin(),
        max_relative = 1e-12
    );
    let tol = 2e-6; // O(N⁻²) ≈ (π/N)²
    assert_relative_eq!(
        s.z3,
        cm * a * PI * (zc.powi(3) / 2.0 + 3.0 * zc * a * a / 8.0),
        max_relative = tol
    );
    assert_relative_eq!(
        s.z2_c2,
        cm * cm * a * (4.0 * zc * zc / 3.0 + 4.0 * a * a / 15.0),
        max_relative = tol
    );
    assert_relative_eq!(s.x3_abs, 4.0 * cm.powi(4) * a / 15.0, max_relative = tol);
    assert_relative_eq!(
        s.z2,
        cm * a * PI * (zc * zc / 2.0 + a * a / 8.0),
        max_relative = tol
    );
    assert_relative_eq!(s.x2, PI * cm.powi(3) * a / 8.0, max_relative = tol);
    assert_relative_eq!(s.xz, -2.0 * cm * cm * a * zc / 3.0, max_relative = tol);
    let l0 = 0.25;
    let o = Planform::semi_ellipse(span, cm, z0, l0, n)
        .unwrap()
        .omegas(RHO)
        .unwrap();
    assert_relative_eq!(
        o.omega4,
        H * l0 * cm * a * PI * (zc * zc / 2.0 + a * a / 8.0),
        max_relative = tol
    );
    // c(z) at mid-span is the full chord.
    assert_relative_eq!(p.chord(zc), cm, max_relative = 1e-6);
}

/// §3.3.2: "a 16.0 mm, 51.4 mm² wing has Ω1 = 31.3 mg·mm²". The definition that reproduces it
/// is eq. 3.12 as printed, Ω1 = ½ρ∬z³dA with ρ = 1.2 kg/m³ = 1.2·10⁻³ mg/mm³ and no force
/// coefficient: a 16.0 × 3.2125 mm rectangle gives 31.58, an elliptic planform of the same
/// span and area 27.6, and the real wing (broad, rounded tip) lies between. Folding in
/// C_N(90°) = 3.46 would give 109, and ρ = 1.2·10⁻⁶ mg/mm³ would give 0.0316.
#[test]
fn section_3_3_2_sanity_check_fixes_the_omega1_definition() {
    let (span, area) = (16.0, 51.4);
    let rect = Planform::rectangle(span, area / span, 0.0, 0.0).unwrap();
    let o_rect = rect.omegas(RHO).unwrap().omega1;
    assert_relative_eq!(
        o_rect,
        0.6e-3 * (area / span) * span.powi(4) / 4.0,
        max_relative = 1e-12
    );
    assert!((o_rect - 31.6).abs() < 0.05, "rectangle Ω1 = {o_rect}");
    let ell = Planform::semi_ellipse(span, 4.0 * area / (PI * span), 0.0, 0.0, 2048).unwrap();
    assert_relative_eq!(ell.area(), area, max_relative = 1e-5);
    let o_ell = ell.omegas(RHO).unwrap().omega1;
    assert!(
        o_ell < 31.3 && 31.3 < o_rect,
        "ellipse {o_ell} < 31.3 < rectangle {o_rect}"
    );
    let cn90 = Dickinson1999.coefficients(FRAC_PI_2).normal;
    assert!((o_rect * cn90 - 31.3).abs() > 50.0);
    assert!(rect.omegas(1.2e-6).unwrap().omega1 < 0.1);
    println!(
        "16 mm / 51.4 mm²: rectangle Ω1 = {o_rect:.3}, semi-ellipse Ω1 = {o_ell:.3} mg·mm² \
         (thesis 31.3); Ω1·C_N(90°) = {:.1}",
        o_rect * cn90
    );
}

#[test]
fn hmf_like_wing_is_close_to_table_3_3() {
    let p = Planform::hmf_like(16.6, 128).unwrap();
    let o = p.omegas(RHO).unwrap();
    let t = table_3_3_left();
    println!(
        "hmf_like(16.6): area {:.2} mm², span {:.2}, Ω = [{:.2}, {:.3}, {:.2}, {:.3}] vs Table 3.3 \
         left [46.8, 0.587, 17.5, 0.712]",
        p.area(),
        p.span(),
        o.omega1,
        o.omega2,
        o.omega3,
        o.omega4
    );
    for (got, want) in [
        (o.omega1, t.omega1),
        (o.omega2, t.omega2),
        (o.omega3, t.omega3),
        (o.omega4, t.omega4),
    ] {
        assert!((got / want - 1.0).abs() < 0.15, "{got} vs {want}");
    }
    // Scaled copies scale as length⁵.
    let q = Planform::hmf_like(8.3, 128).unwrap().omegas(RHO).unwrap();
    assert_relative_eq!(q.omega1 * 32.0, o.omega1, max_relative = 1e-12);
}

// ---------------------------------------------------------------- invariances

/// Star-shaped (hence simple) random polygon around `(zc, xc)`.
fn star_polygon(zc: f64, xc: f64, radii: &[f64]) -> Vec<[f64; 2]> {
    let n = radii.len();
    (0..n)
        .map(|k| {
            let t = 2.0 * PI * k as f64 / n as f64;
            [zc + radii[k] * t.cos(), xc + radii[k] * t.sin()]
        })
        .collect()
}

/// `∬ z^a x^b dA` by Green's theorem on the CCW (z, x) polygon: `∮ z^{a+1} x^b/(a+1) dx`,
/// each edge by 4-point Gauss–Legendre (exact to degree 7). Independent of the slab sweep.
fn green(v: &[[f64; 2]], a: i32, b: i32) -> f64 {
    let g = [
        (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
        (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    ];
    let n = v.len();
    let mut s = 0.0;
    for i in 0..n {
        let (p, q) = (v[i], v[(i + 1) % n]);
        for (t, w) in g {
            let u = 0.5 * (t + 1.0);
            let z = p[0] + u * (q[0] - p[0]);
            let x = p[1] + u * (q[1] - p[1]);
            s += 0.5 * w * z.powi(a + 1) * x.powi(b) / (a as f64 + 1.0) * (q[1] - p[1]);
        }
    }
    s
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn polynomial_integrals_match_greens_theorem(
        radii in proptest::collection::vec(0.5f64..2.5, 5..24),
        zc in 3.0f64..6.0,
        xc in -2.0f64..0.5,
    ) {
        let pts = star_polygon(zc, xc, &radii);
        let p = Planform::from_points(&pts).unwrap();
        let v = p.vertices();
        let s = p.integrals();
        for (got, a, b) in [(s.area, 0, 0), (s.z1, 1, 0), (s.x1, 0, 1), (s.z2, 2, 0),
                            (s.x2, 0, 2), (s.xz, 1, 1), (s.z3, 3, 0)] {
            let want = green(v, a, b);
            prop_assert!((got - want).abs() <= 1e-10 * (1.0 + want.abs()), "{a},{b}: {got} vs {want}");
        }
        // Reversed orientation and a cyclic shift give the same integrals.
        let mut rev = pts.clone();
        rev.reverse();
        rev.rotate_left(2);
        let q = Planform::from_points(&rev).unwrap();
        prop_assert!((q.integrals().z2_c2 - s.z2_c2).abs() <= 1e-10 * s.z2_c2.abs());
        prop_assert!((q.integrals().z2_lc - s.z2_lc).abs() <= 1e-10 * (1.0 + s.z2_lc.abs()));
    }

    #[test]
    fn omegas_scale_as_length_to_the_fifth(k in 0.2f64..5.0, radii in proptest::collection::vec(0.5f64..2.5, 5..16)) {
        let p = Planform::from_points(&star_polygon(4.0, -1.0, &radii)).unwrap();
        let q = p.scaled(k).unwrap();
        let (a, b) = (p.omegas(RHO).unwrap(), q.omegas(RHO).unwrap());
        let k5 = k.powi(5);
        for (x, y) in [(a.omega1, b.omega1), (a.omega2, b.omega2), (a.omega3, b.omega3), (a.omega4, b.omega4)] {
            prop_assert!((x * k5 - y).abs() <= 1e-10 * (1.0 + y.abs()), "{x} * {k5} vs {y}");
        }
        prop_assert!((q.area() - k * k * p.area()).abs() <= 1e-12 * q.area());
    }

    /// Moving the hinge line along x (translating the wing by dx) leaves Ω1 and Ω3 unchanged and
    /// shifts Ω4 by exactly ½ρ·dx·∬z²dA (l → l + dx).
    #[test]
    fn hinge_offset_changes_omega4_not_omega1(dx in -1.0f64..1.0, radii in proptest::collection::vec(0.5f64..2.0, 5..16)) {
        let p = Planform::from_points(&star_polygon(4.0, -1.2, &radii)).unwrap();
        let q = p.translated(0.0, dx).unwrap();
        let (a, b) = (p.omegas(RHO).unwrap(), q.omegas(RHO).unwrap());
        prop_assert!((a.omega1 - b.omega1).abs() <= 1e-11 * a.omega1);
        prop_assert!((a.omega3 - b.omega3).abs() <= 1e-11 * a.omega3);
        let shift = H * dx * p.integrals().z2;
        prop_assert!((b.omega4 - a.omega4 - shift).abs() <= 1e-10 * (1.0 + a.omega4.abs() + shift.abs()));
    }
}

// ---------------------------------------------------------------- planform errors

fn geometry_msg(r: paritysim_aero::Result<Planform>) -> String {
    match r {
        Err(Error::Geometry(m)) => m,
        other => panic!("expected Error::Geometry, got {other:?}"),
    }
}

#[test]
fn bad_outlines_give_typed_errors() {
    // Bow tie.
    let m = geometry_msg(Planform::from_points(&[
        [1.0, 0.0],
        [5.0, -2.0],
        [5.0, 0.0],
        [1.0, -2.0],
    ]));
    assert!(m.contains("self-intersecting"), "{m}");
    // Fold-back spike along the trailing edge.
    let spike = [
        [1.0, 0.0],
        [6.0, 0.0],
        [6.0, -2.0],
        [3.0, -2.0],
        [4.0, -2.0],
        [1.0, -2.0],
    ];
    let m = geometry_msg(Planform::from_points(&spike));
    assert!(
        m.contains("self-intersecting") && m.contains("folds back"),
        "{m}"
    );
    // Open traced outline.
    let traced = [
        [1.0, 0.0],
        [6.0, 0.0],
        [6.0, -2.0],
        [1.0, -2.0],
        [1.0, -0.5],
    ];
    let m = geometry_msg(Planform::from_traced_outline(&traced, 0.01));
    assert!(m.contains("open"), "{m}");
    let closed = [
        [1.0, 0.0],
        [6.0, 0.0],
        [6.0, -2.0],
        [1.0, -2.0],
        [1.0, 0.001],
    ];
    assert_relative_eq!(
        Planform::from_traced_outline(&closed, 0.01).unwrap().area(),
        10.0
    );
    // Inboard of the spherical centre.
    let m = geometry_msg(Planform::from_points(&[
        [-1.0, 0.0],
        [6.0, 0.0],
        [6.0, -2.0],
    ]));
    assert!(m.contains("wrong side") && m.contains("z"), "{m}");
    // Entirely ahead of the hinge line (outline drawn with x toward the trailing edge).
    let m = geometry_msg(Planform::from_points(&[
        [0.0, 0.0],
        [10.0, 0.0],
        [10.0, 3.0],
        [0.0, 3.0],
    ]));
    assert!(m.contains("wrong side of the hinge line"), "{m}");
    // The parametric shapes name the field that put them there.
    let e = Planform::rectangle(10.0, 3.0, 0.0, 3.0).unwrap_err();
    assert_eq!(e.field(), Some("le_offset"));
    // Degenerate.
    let m = geometry_msg(Planform::from_points(&[
        [1.0, 0.0],
        [2.0, -1.0],
        [3.0, -2.0],
    ]));
    assert!(m.contains("zero area"), "{m}");
    let m = geometry_msg(Planform::from_points(&[
        [1.0, 0.0],
        [2.0, -1.0],
        [1.0, 0.0],
    ]));
    assert!(m.contains("degenerate"), "{m}");
    // Non-finite point and bad scalars name the field.
    let e = Planform::from_points(&[[1.0, 0.0], [f64::NAN, -1.0], [3.0, -2.0]]).unwrap_err();
    assert_eq!(e.field(), Some("points[1]"));
    let p = Planform::rectangle(10.0, 3.0, 0.0, 0.0).unwrap();
    assert_eq!(p.omegas(-1.2e-3).unwrap_err().field(), Some("density"));
    assert_eq!(p.omegas(f64::NAN).unwrap_err().field(), Some("density"));
    assert_eq!(
        Planform::rectangle(-1.0, 3.0, 0.0, 0.0)
            .unwrap_err()
            .field(),
        Some("span")
    );
    assert_eq!(
        Planform::semi_ellipse(10.0, 3.0, 0.0, 0.0, 2)
            .unwrap_err()
            .field(),
        Some("segments")
    );
    let e = p.inertia(&MassDistribution::membrane(-1.0)).unwrap_err();
    assert_eq!(e.field(), Some("areal_density"));
    let e = p.inertia(&MassDistribution::default()).unwrap_err();
    assert_eq!(e.field(), Some("mass"));
    assert_eq!(
        Omegas::new(0.0, 1.0, 1.0, 0.0).unwrap_err().field(),
        Some("omegas.omega1")
    );
    let model = dickinson_model(table_3_3_left());
    assert_eq!(
        model.with_rotational_damping(-1.0).unwrap_err().field(),
        Some("rotational_damping")
    );
    let st = WingState::planar(0.0, 0.0, 1.0, 0.0).unwrap();
    assert_eq!(model.loads(&st).unwrap_err().field(), Some("omegas.force"));
    assert_eq!(
        WingState::new(0.0, 0.0, f64::INFINITY, 0.0, 0.0, 0.0)
            .unwrap_err()
            .field(),
        Some("psi")
    );
    assert_eq!(
        CoefficientSet::from_name("quasi").unwrap_err().field(),
        Some("model")
    );
    assert_eq!(
        checked_coefficients(&Dickinson1999, -0.1)
            .unwrap_err()
            .field(),
        Some("alpha")
    );
}

// ---------------------------------------------------------------- coefficients

#[test]
fn dickinson_fits_at_0_45_90_degrees() {
    // Hand-evaluated from eqs. 3.5–3.6 with α in degrees.
    for (deg, cl, cd) in [
        (0.0, 0.026973, 0.392710),
        (45.0, 1.804561, 1.703746),
        (90.0, 0.101035, 3.460875),
    ] {
        let c = Dickinson1999.coefficients(f64::to_radians(deg));
        assert!((c.lift - cl).abs() < 2e-6, "{deg}: C_L {}", c.lift);
        assert!((c.drag - cd).abs() < 2e-6, "{deg}: C_D {}", c.drag);
    }
    // At 90° the normal coefficient is the drag, the tangential minus the lift.
    let c = Dickinson1999.coefficients(FRAC_PI_2);
    assert_relative_eq!(c.normal, c.drag, max_relative = 1e-12);
    assert_relative_eq!(c.tangential, -c.lift, max_relative = 1e-9);
    let w = WhitneyWood2010::default();
    let c = w.coefficients(FRAC_PI_2);
    assert_relative_eq!(c.normal, 3.4, max_relative = 1e-12);
    assert!(c.tangential.abs() < 1e-12);
    assert_relative_eq!(w.coefficients(PI / 4.0).lift, 1.8, max_relative = 1e-12);
    assert_relative_eq!(w.coefficients(0.0).drag, 0.4, max_relative = 1e-12);
    assert_relative_eq!(center_of_pressure(0.0), 0.05);
    assert_relative_eq!(center_of_pressure(FRAC_PI_2), 0.46);
}

proptest! {
    #![proptest_config(ProptestConfig { failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn normal_tangential_transform_round_trips(alpha in 0.0f64..PI, cl in -3.0f64..3.0, cd in 0.0f64..4.0) {
        let (cn, ct) = to_normal_tangential(alpha, cl, cd);
        let (l, d) = from_normal_tangential(alpha, cn, ct);
        prop_assert!((l - cl).abs() < 1e-14 && (d - cd).abs() < 1e-14);
        prop_assert!((cn.hypot(ct) - cl.hypot(cd)).abs() < 1e-14);
    }

    #[test]
    fn coefficients_have_flat_plate_symmetry(alpha in 0.0f64..FRAC_PI_2, which in 0usize..2) {
        let set = [CoefficientSet::Dickinson1999(Dickinson1999), CoefficientSet::WhitneyWood2010(WhitneyWood2010::default())][which];
        let (a, b) = (set.coefficients(alpha), set.coefficients(PI - alpha));
        prop_assert!((a.normal - b.normal).abs() < 1e-12);
        prop_assert!((a.tangential + b.tangential).abs() < 1e-12);
        prop_assert!(a.drag > 0.0 && a.normal > 0.0);
    }
}

// ---------------------------------------------------------------- blade element

fn state_strategy() -> impl Strategy<Value = WingState> {
    (
        -1.5f64..1.5,
        -0.6f64..0.6,
        -1.4f64..1.4,
        -1.0f64..1.0,
        -0.5f64..0.5,
        -2.0f64..2.0,
    )
        .prop_map(|(phi, theta, psi, phi_dot, theta_dot, psi_dot)| WingState {
            phi,
            theta,
            psi,
            phi_dot,
            theta_dot,
            psi_dot,
        })
}

#[test]
fn wind_relative_reduces_to_plain_coordinates_without_deviation() {
    for (psi, phi_dot, psi_dot) in [(-1.0, 0.6, 0.3), (0.7, -0.4, -1.0), (0.2, 0.9, 0.0)] {
        let s = WingState::planar(0.3, psi, phi_dot, psi_dot).unwrap();
        let w = s.wind_relative();
        assert_relative_eq!(w.phi_dot_rw, phi_dot, max_relative = 1e-15);
        assert_relative_eq!(w.psi_rw, psi, max_relative = 1e-15);
        assert_relative_eq!(w.psi_dot_rw, psi_dot, max_relative = 1e-15);
        // α = π/2 + ψ sgn φ̇ (eq. 3.4 with docs/errata.md#5's sign).
        assert_relative_eq!(
            w.alpha,
            FRAC_PI_2 + psi * phi_dot.signum(),
            max_relative = 1e-12
        );
    }
    // ψ = −60° on the downstroke: leading edge leads at α = 30°.
    let s = WingState::planar(0.0, -PI / 3.0, 0.5, 0.0).unwrap();
    assert_relative_eq!(s.wind_relative().alpha, PI / 6.0, max_relative = 1e-12);
    // No motion: α = π/2 by convention, moments only from rotation.
    let st = WingState::planar(0.0, 0.4, 0.0, 0.0).unwrap();
    assert_eq!(st.wind_relative().alpha, FRAC_PI_2);
    assert_eq!(
        dickinson_model(table_3_3_left()).moments(&st).torque(),
        Vector3::zeros()
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn alpha_matches_wind_relative_coordinates(s in state_strategy()) {
        let w = s.wind_relative();
        prop_assume!(w.phi_dot_rw.abs() > 1e-9);
        let omega = s.angular_velocity();
        prop_assert!((omega.x.hypot(omega.y) - w.phi_dot_rw.abs()).abs() < 1e-12);
        let want = (-w.phi_dot_rw.signum() * w.psi_rw.sin()).clamp(-1.0, 1.0).acos();
        prop_assert!((w.alpha - want).abs() < 1e-9, "{} vs {}", w.alpha, want);
        if w.psi_rw.abs() <= FRAC_PI_2 {
            prop_assert!((w.alpha - (FRAC_PI_2 + w.psi_rw * w.phi_dot_rw.signum())).abs() < 1e-9);
        }
    }

    /// Translational moments dissipate exactly the drag power, `−Ω1 |φ̇_rw|³ C_D(α)`;
    /// rotational damping dissipates `Ω2 C_rd |ψ̇_rw|³`.
    #[test]
    fn aerodynamic_damping_power_is_never_positive(s in state_strategy(), which in 0usize..2) {
        let set = [CoefficientSet::Dickinson1999(Dickinson1999), CoefficientSet::WhitneyWood2010(WhitneyWood2010::default())][which];
        let o = table_3_3_left();
        let model = BladeElementModel::new(o, set).unwrap();
        let m = model.moments(&s);
        let w = s.angular_velocity();
        let p_trans = m.normal * w.x + m.tangential * w.y;
        let speed = w.x.hypot(w.y);
        let cd = set.coefficients(m.alpha).drag;
        prop_assert!(p_trans <= 0.0);
        prop_assert!((p_trans + o.omega1 * speed.powi(3) * cd).abs() < 1e-10 * (1.0 + p_trans.abs()));
        let p_rd = m.rotational_damping * w.z;
        prop_assert!(p_rd <= 0.0);
        prop_assert!((p_rd + o.omega2 * model.rotational_damping() * w.z.abs().powi(3)).abs() < 1e-12);
    }

    /// Quadratic-with-sign laws: reversing every rate (ω → −ω, α → π − α) reverses M_N, M_T
    /// and M_rd exactly; M_r reverses up to the asymmetry of eq. 3.7 about 90°
    /// (d̂_cp(π − α) ≠ d̂_cp(α)).
    #[test]
    fn moments_flip_with_velocity(s in state_strategy()) {
        let o = table_3_3_left();
        let model = dickinson_model(o);
        let r = WingState { phi_dot: -s.phi_dot, theta_dot: -s.theta_dot, psi_dot: -s.psi_dot, ..s };
        let (a, b) = (model.moments(&s), model.moments(&r));
        // Away from α = 90° exactly, where the extended Dickinson C_T jumps.
        prop_assume!((a.alpha - FRAC_PI_2).abs() > 1e-9);
        prop_assert!((a.alpha + b.alpha - PI).abs() < 1e-12);
        let tol = 1e-12 * (1.0 + a.torque().norm());
        prop_assert!((a.normal + b.normal).abs() <= tol);
        prop_assert!((a.tangential + b.tangential).abs() <= tol);
        prop_assert!((a.rotational_damping + b.rotational_damping).abs() <= tol);
        let lever = |al: f64| o.omega3 * center_of_pressure(al) - o.omega4;
        prop_assert!((a.rotational * lever(b.alpha) + b.rotational * lever(a.alpha)).abs() <= tol * 20.0);
    }

    /// The mirrored half-stroke (φ̇, θ̇, ψ, ψ̇) → (−φ̇, −θ̇, −ψ, −ψ̇) at θ = 0 has the same α;
    /// M_N, M_r and M_rd reverse exactly and M_T keeps its sign (chordwise drag toward the
    /// trailing edge, about the wing normal). The printed eq. 3.9 (with sgn φ̇_rw) would flip it.
    #[test]
    fn mirrored_half_strokes_reverse_moments(s in state_strategy()) {
        let s = WingState { theta: 0.0, theta_dot: 0.0, ..s };
        let model = dickinson_model(table_3_3_left());
        let r = WingState { phi_dot: -s.phi_dot, theta_dot: -s.theta_dot, psi: -s.psi, psi_dot: -s.psi_dot, ..s };
        let (a, b) = (model.moments(&s), model.moments(&r));
        let tol = 1e-12 * (1.0 + a.torque().norm());
        prop_assert!((a.alpha - b.alpha).abs() < 1e-12);
        prop_assert!((a.normal + b.normal).abs() <= tol);
        prop_assert!((a.rotational + b.rotational).abs() <= tol);
        prop_assert!((a.rotational_damping + b.rotational_damping).abs() <= tol);
        prop_assert!((a.tangential - b.tangential).abs() <= tol);
    }

    /// Lift ⟂ velocity, drag ∥ −velocity, and the body-frame torque of lift + drag + damping is
    /// the wing-frame moment vector rotated by R_6^1.
    #[test]
    fn loads_are_consistent_with_moments(s in state_strategy()) {
        let p = Planform::hmf_like(16.6, 64).unwrap();
        let model = dickinson_model(p.omegas(RHO).unwrap());
        let l = model.loads(&s).unwrap();
        let torque = s.rotation() * l.moments.torque();
        prop_assert!((l.torque() - torque).norm() <= 1e-12 * (1.0 + torque.norm()));
        let omega = s.angular_velocity();
        let vel = s.rotation() * Vector3::new(omega.y, -omega.x, 0.0); // element velocity / z
        if vel.norm() > 1e-6 {
            prop_assert!(l.lift.dot(&vel).abs() <= 1e-10 * (1.0 + l.lift.norm() * vel.norm()));
            prop_assert!(l.drag.dot(&vel) <= 0.0);
            prop_assert!(l.drag.cross(&vel).norm() <= 1e-10 * (1.0 + l.drag.norm() * vel.norm()));
        }
    }
}

#[test]
fn rotational_moment_drives_leading_edge_forward() {
    // Wing behind the hinge: Ω3 d̂_cp > Ω4 at every α, so at ψ = 0 the rotational moment has the
    // sign of −φ̇, turning ψ opposite to φ̇ (leading edge leads, ψ lags φ).
    let model = dickinson_model(table_3_3_left());
    for phi_dot in [-0.8, -0.1, 0.1, 0.8] {
        let m = model.moments(&WingState::planar(0.0, 0.0, phi_dot, 0.0).unwrap());
        assert!(m.rotational * phi_dot < 0.0);
        assert_relative_eq!(m.alpha, FRAC_PI_2);
    }
}

/// Prescribed stroke `φ = Φ sin ωt` (±50°, 110 Hz) and the hinge equation
/// `Izz ψ̈ = −k ψ + M_r + M_rd` (wing inertial coupling omitted: this isolates the aerodynamic
/// moment). ψ must lag φ by about 90°, with α ≈ 90° at stroke reversal and well below 90° with
/// the leading edge leading at mid-stroke (docs/errata.md#5; §3.4: α = 90° at the extents, ≈ 30°
/// mid-stroke).
#[test]
fn passive_rotation_lags_stroke_by_about_90_degrees() {
    let model = dickinson_model(table_3_3_left());
    let (izz, k) = (1.56, 2.5); // mg·mm², mN·mm/rad
    let (amp, w) = (50f64.to_radians(), 2.0 * PI * 0.11);
    let rhs = |t: f64, y: [f64; 2]| -> [f64; 2] {
        let phi_dot = amp * w * (w * t).cos();
        let s = WingState::planar(amp * (w * t).sin(), y[0], phi_dot, y[1]).unwrap();
        let m = model.moments(&s);
        [
            y[1],
            (-k * y[0] + m.rotational + m.rotational_damping) / izz,
        ]
    };
    let (dt, period) = (1e-3, 2.0 * PI / w);
    let steps_per_period = (period / dt).round() as usize;
    let dt = period / steps_per_period as f64;
    let (mut y, mut t) = ([0.0, 0.0], 0.0);
    let (mut a, mut b, mut psi_max, mut alpha_mid, mut alpha_rev) = (0.0, 0.0, 0.0f64, 0.0, 0.0);
    let cycles = 12;
    for step in 0..cycles * steps_per_period {
        let k1 = rhs(t, y);
        let k2 = rhs(
            t + dt / 2.0,
            [y[0] + dt / 2.0 * k1[0], y[1] + dt / 2.0 * k1[1]],
        );
        let k3 = rhs(
            t + dt / 2.0,
            [y[0] + dt / 2.0 * k2[0], y[1] + dt / 2.0 * k2[1]],
        );
        let k4 = rhs(t + dt, [y[0] + dt * k3[0], y[1] + dt * k3[1]]);
        for i in 0..2 {
            y[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        t += dt;
        if step >= (cycles - 1) * steps_per_period {
            a += y[0] * (w * t).sin();
            b += y[0] * (w * t).cos();
            psi_max = psi_max.max(y[0].abs());
            let phase = (step + 1) % steps_per_period;
            let s = WingState::planar(amp * (w * t).sin(), y[0], amp * w * (w * t).cos(), y[1])
                .unwrap();
            if phase == 0 {
                alpha_mid = s.wind_relative().alpha; // φ = 0, φ̇ max
            }
            if phase == steps_per_period / 4 + 1 {
                alpha_rev = s.wind_relative().alpha; // just after φ = Φ
            }
        }
    }
    assert!(y[0].is_finite());
    let lag = (-b).atan2(a).to_degrees();
    println!(
        "passive rotation: |ψ|max = {:.1}°, lag = {lag:.1}°, α mid-stroke = {:.1}°, α near reversal = {:.1}°",
        psi_max.to_degrees(),
        alpha_mid.to_degrees(),
        alpha_rev.to_degrees()
    );
    assert!((60.0..120.0).contains(&lag), "lag {lag}");
    assert!(psi_max > 20f64.to_radians() && psi_max < 90f64.to_radians());
    assert!(
        alpha_mid < 70f64.to_radians(),
        "α mid {}",
        alpha_mid.to_degrees()
    );
    assert!(
        alpha_rev > alpha_mid + 20f64.to_radians(),
        "α near reversal {}",
        alpha_rev.to_degrees()
    );
}

#[test]
fn lift_points_along_the_stroke_axis_on_both_half_strokes() {
    let p = Planform::hmf_like(16.6, 64).unwrap();
    let model = dickinson_model(p.omegas(RHO).unwrap());
    for (psi, phi_dot) in [(-PI / 3.0, 0.6), (PI / 3.0, -0.6)] {
        let l = model
            .loads(&WingState::planar(0.0, psi, phi_dot, 0.0).unwrap())
            .unwrap();
        assert!(l.lift.x > 0.0 && l.lift.y.abs() < 1e-12 * l.lift.norm() && l.lift.z.abs() < 1e-15);
        // Drag torque opposes the stroke: roll component has the sign of −φ̇.
        assert!(l.drag_torque.x * phi_dot < 0.0);
        // Lift along +x̂₁ acting outboard (+ẑ) yaws about +ŷ₁: ẑ × x̂ = ŷ.
        assert!(l.lift_torque.y > 0.0);
    }
}

#[test]
fn normal_force_law_exposes_errata_item_12() {
    let o = table_3_3_left();
    let thesis = dickinson_model(o);
    let unit = thesis.with_normal_force_law(NormalForceLaw::Unit);
    let s = WingState::planar(0.0, 0.0, 0.5, 0.0).unwrap();
    let (a, b) = (thesis.moments(&s), unit.moments(&s));
    assert_relative_eq!(
        b.normal,
        drag_torque_eq_2_16(o.omega1, 0.5),
        max_relative = 1e-14
    );
    assert_eq!(b.tangential, 0.0);
    assert_relative_eq!(
        a.normal / b.normal,
        Dickinson1999.coefficients(FRAC_PI_2).normal,
        max_relative = 1e-12
    );
    // §3.3 numbers: Ω = 31.3 mg·mm², ±35° at 110 Hz → peak φ̇ = 0.423 rad/ms.
    let phi_dot = 35f64.to_radians() * 2.0 * PI * 0.11;
    let o33 = Omegas::new(31.3, 0.0, 0.0, 0.0).unwrap();
    let m = dickinson_model(o33).moments(&WingState::planar(0.0, 0.0, phi_dot, 0.0).unwrap());
    println!(
        "docs/errata.md#12 at Ω = 31.3, ±35°, 110 Hz: Ω φ̇² = {:.2} mN·mm, Ω C_N(90°) φ̇² = {:.2} mN·mm \
         (Table 3.2 peak: 12.42)",
        -drag_torque_eq_2_16(31.3, phi_dot),
        -m.normal
    );
}

#[test]
fn models_are_send_sync_and_cheap_to_copy() {
    fn assert_send_sync<T: Send + Sync + Copy>() {}
    assert_send_sync::<BladeElementModel>();
    assert_send_sync::<BladeElementModel<Dickinson1999>>();
    assert_send_sync::<WingState>();
    fn assert_send_sync_clone<T: Send + Sync + Clone>() {}
    assert_send_sync_clone::<Planform>();
}
