//! Integration tests of paritysim-laminate (one binary for the crate).
//!
//! Independent references used here (derived or quoted in the test, never taken from the code
//! under test):
//! * plate bending stiffness `D = E t³ / (12 (1 − ν²))` of an isotropic plate;
//! * the Euler–Bernoulli composite-beam bimorph (transformed-section moment and stiffness);
//! * the parallel-drive bimorph of Smits, Dalke & Cooney (1991): `δ = 3 d31 V L² / h²`,
//!   `F_b = 3 E w h d31 V / (4 L)`;
//! * Timoshenko's bimetal formula (1925, "Analysis of bi-metal thermostats");
//! * the tapered-actuator geometry factor `G_F` of Wood, Steltz & Fearing 2005 (ref. [42]),
//!   in the closed form published there (as transcribed in public re-implementations of the
//!   model);
//! * the thesis' numbers: 467 mN/mm, 120 mN at 100 V (§3.3.1), the Mobee layer counts and
//!   thicknesses (§4.2, §4.4.2), the 200 °C cure (§4.4.2), 20–40 µm castellated flexures
//!   (§4.4.3).

use approx::assert_relative_eq;
use nalgebra::Vector3;
use paritysim_laminate::flexure::{
    CASTELLATED_FLEXURE_LENGTH_MM, CastellatedJoint, Flexure, KAPTON_YIELD_STRAIN,
};
use paritysim_laminate::material::{GPA, PM_PER_V, PPM_PER_K, V_PER_UM};
use paritysim_laminate::pcmems::{
    CURE_DELTA_T, linkage_sublaminate, mobee_stack, mobee_stack_without_titanium, summarize,
};
use paritysim_laminate::{
    ActuatorConstants, Bimorph, BimorphGeometry, Error, Layer, Layup, Loads, Material,
    MaterialClass, MaterialSpec, Ply, library, reduced_stiffness, transformed_stiffness,
};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

fn iso(name: &str, e_gpa: f64, nu: f64, alpha_ppm: f64) -> Material {
    Material::isotropic(
        name,
        MaterialClass::Metal,
        e_gpa * GPA,
        nu,
        1.0,
        alpha_ppm * PPM_PER_K,
    )
    .unwrap()
}

fn piezo_iso(e_gpa: f64, nu: f64, d31_pm: f64) -> Material {
    Material::isotropic("piezo", MaterialClass::Piezo, e_gpa * GPA, nu, 7.8, 0.0)
        .unwrap()
        .with_piezo(d31_pm * PM_PER_V, 2.0 * V_PER_UM)
        .unwrap()
}

fn single(m: Material, t: f64, angle: f64) -> Layer {
    Layer::single(m.name().to_string(), m, t, angle).unwrap()
}

fn field(e: &Error) -> Option<&str> {
    e.field()
}

// ------------------------------------------------------------------ materials and errors

#[test]
fn library_materials_are_valid_and_resolvable() {
    let all = library::all();
    assert_eq!(all.len(), library::NAMES.len());
    for (key, m) in library::NAMES.iter().zip(&all) {
        assert_eq!(&library::by_name(key).unwrap(), m);
        assert!(m.e1() > 0.0 && m.e2() > 0.0 && m.g12() > 0.0 && m.density() > 0.0);
        // round-trips through the spec
        assert_eq!(&m.to_spec().build().unwrap(), m);
    }
    let pzt = library::pzt_5h();
    assert!(pzt.is_piezo());
    assert_relative_eq!(pzt.piezo().unwrap().d31, -320e-9);
    assert_eq!(library::by_name("kapton").unwrap(), library::polyimide());
    let e = library::by_name("unobtainium").unwrap_err();
    assert_eq!(e.kind(), "InvalidParameter");
    assert_eq!(field(&e), Some("material"));
}

#[test]
fn non_physical_materials_are_typed_errors() {
    // Poisson ratio of an isotropic material must be in (-1, 0.5).
    for nu in [0.5, 0.7, -1.0, -1.5, f64::NAN] {
        let e = Material::isotropic("x", MaterialClass::Metal, 1e6, nu, 1.0, 0.0).unwrap_err();
        assert_eq!(e.kind(), "InvalidParameter", "nu = {nu}");
        assert_eq!(field(&e), Some("nu12"));
    }
    let msg = Material::isotropic("x", MaterialClass::Metal, 1e6, 0.7, 1.0, 0.0)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("nu12") && msg.contains("(-1, 0.5)"), "{msg}");
    // E <= 0
    for e_mod in [0.0, -5.0, f64::INFINITY] {
        let e = Material::isotropic("x", MaterialClass::Metal, e_mod, 0.3, 1.0, 0.0).unwrap_err();
        assert_eq!(field(&e), Some("e1"));
    }
    // orthotropic: nu12^2 < E1/E2
    let spec = MaterialSpec {
        name: "ortho".into(),
        class: MaterialClass::Composite,
        e1: 10e6,
        e2: 1e6,
        g12: 0.5e6,
        nu12: 5.0,
        density: 1.5,
        alpha1: 0.0,
        alpha2: 0.0,
        piezo: None,
    };
    let e = spec.clone().build().unwrap_err();
    assert_eq!(field(&e), Some("nu12"));
    // nu12 = 3 < sqrt(10) is allowed for an orthotropic ply
    assert!(
        MaterialSpec {
            nu12: 3.0,
            ..spec.clone()
        }
        .build()
        .is_ok()
    );
    for (bad, name) in [
        (
            MaterialSpec {
                e2: -1.0,
                ..spec.clone()
            },
            "e2",
        ),
        (
            MaterialSpec {
                g12: 0.0,
                nu12: 0.3,
                ..spec.clone()
            },
            "g12",
        ),
        (
            MaterialSpec {
                density: 0.0,
                nu12: 0.3,
                ..spec.clone()
            },
            "density",
        ),
        (
            MaterialSpec {
                alpha1: f64::NAN,
                nu12: 0.3,
                ..spec.clone()
            },
            "alpha1",
        ),
    ] {
        assert_eq!(field(&bad.build().unwrap_err()), Some(name));
    }
    // piezo properties
    let e = library::polyimide().with_piezo(-1e-7, 0.0).unwrap_err();
    assert_eq!(field(&e), Some("max_field"));
    let e = library::polyimide().with_piezo(f64::NAN, 1.0).unwrap_err();
    assert_eq!(field(&e), Some("d31"));
    assert_eq!(
        MaterialClass::parse("Adhesive").unwrap(),
        MaterialClass::Adhesive
    );
    assert!(MaterialClass::parse("cheese").is_err());
}

#[test]
fn malformed_plies_and_layups_are_typed_errors() {
    let pi = library::polyimide();
    for t in [-0.01, 0.0, f64::NAN] {
        let e = Ply::new(pi.clone(), t, 0.0).unwrap_err();
        assert_eq!(field(&e), Some("thickness"));
    }
    assert_eq!(
        field(&Ply::new(pi.clone(), 0.01, f64::INFINITY).unwrap_err()),
        Some("angle")
    );
    assert_eq!(Layup::new(vec![]).unwrap_err().kind(), "Geometry");
    assert_eq!(
        Layer::from_plies("empty", vec![]).unwrap_err().kind(),
        "Geometry"
    );
    let e = Layup::from_plies(vec![
        ("ok".into(), pi.clone(), 0.01, 0.0),
        ("bad".into(), pi.clone(), -0.01, 0.0),
    ])
    .unwrap_err();
    assert_eq!(field(&e), Some("layers[1].thickness"));

    // voltages: wrong length, non-piezo layer, non-finite
    let lay = Bimorph::wood_layup(0.127, 0.04).unwrap();
    let shape = lay
        .response(&Loads {
            voltages: vec![1.0],
            ..Loads::default()
        })
        .unwrap_err();
    assert_eq!(shape.kind(), "Shape");
    let bad = lay
        .response(&Loads {
            voltages: vec![0.0, 5.0, 0.0],
            ..Loads::default()
        })
        .unwrap_err();
    assert_eq!(field(&bad), Some("voltages[1]"));
    let nan = lay
        .response(&Loads {
            voltages: vec![f64::NAN, 0.0, 0.0],
            ..Loads::default()
        })
        .unwrap_err();
    assert_eq!(field(&nan), Some("voltages[0]"));
    let e = lay
        .response(&Loads {
            delta_t: f64::NAN,
            ..Loads::default()
        })
        .unwrap_err();
    assert_eq!(field(&e), Some("delta_t"));
}

// ------------------------------------------------------------------ Q, Q̄, ABD

#[test]
fn reduced_stiffness_of_isotropic_ply_and_rotation_invariance() {
    let m = iso("steel", 200.0, 0.3, 11.0);
    let q = reduced_stiffness(&m);
    let e = 200.0 * GPA;
    assert_relative_eq!(q[(0, 0)], e / (1.0 - 0.09), max_relative = 1e-14);
    assert_relative_eq!(q[(0, 1)], 0.3 * e / (1.0 - 0.09), max_relative = 1e-14);
    assert_relative_eq!(q[(2, 2)], e / 2.6, max_relative = 1e-14);
    for th in [0.1, 0.7, 1.3, 2.9] {
        assert_relative_eq!(transformed_stiffness(&q, th), q, epsilon = 1e-12 * q.amax());
    }
}

#[test]
fn rotating_by_90_degrees_swaps_e1_and_e2() {
    let cf = library::cf_prepreg_ud();
    let q = reduced_stiffness(&cf);
    let q90 = transformed_stiffness(&q, FRAC_PI_2);
    assert_relative_eq!(q90[(0, 0)], q[(1, 1)], max_relative = 1e-12);
    assert_relative_eq!(q90[(1, 1)], q[(0, 0)], max_relative = 1e-12);
    assert!(q90[(0, 2)].abs() < 1e-9 * q[(0, 0)]);

    let t = 0.05;
    let a0 = Layup::new(vec![single(cf.clone(), t, 0.0)])
        .unwrap()
        .abd()
        .a;
    let a90 = Layup::new(vec![single(cf.clone(), t, FRAC_PI_2)])
        .unwrap()
        .abd()
        .a;
    assert_relative_eq!(a90[(0, 0)], a0[(1, 1)], max_relative = 1e-12);
    assert_relative_eq!(a90[(1, 1)], a0[(0, 0)], max_relative = 1e-12);
    // A11 of a single UD ply is E1 t / (1 − ν12 ν21)
    let denom = 1.0 - cf.nu12() * cf.nu21();
    assert_relative_eq!(a0[(0, 0)], cf.e1() * t / denom, max_relative = 1e-12);
    assert_relative_eq!(a90[(0, 0)], cf.e2() * t / denom, max_relative = 1e-12);
}

#[test]
fn single_isotropic_ply_reproduces_plate_stiffness() {
    let (e_gpa, nu, t) = (110.0, 0.34, 0.0125);
    let lay = Layup::new(vec![single(iso("brass", e_gpa, nu, 19.9), t, 0.3)]).unwrap();
    let abd = lay.abd();
    let e = e_gpa * GPA;
    let d_plate = e * t.powi(3) / (12.0 * (1.0 - nu * nu));
    assert_relative_eq!(abd.d[(0, 0)], d_plate, max_relative = 1e-12);
    assert_relative_eq!(abd.d[(0, 1)], nu * d_plate, max_relative = 1e-12);
    assert_relative_eq!(
        abd.d[(2, 2)],
        (1.0 - nu) / 2.0 * d_plate,
        max_relative = 1e-12
    );
    assert_relative_eq!(abd.a[(0, 0)], e * t / (1.0 - nu * nu), max_relative = 1e-12);
    assert!(abd.b.amax() < 1e-12 * abd.a.amax() * t);
    // narrow beam: 1/d11 = E t³ / 12
    assert_relative_eq!(
        lay.beam_bending_stiffness().unwrap(),
        e * t.powi(3) / 12.0,
        max_relative = 1e-10
    );
    assert_relative_eq!(lay.effective_modulus_x().unwrap(), e, max_relative = 1e-10);
    // uniaxial N: εx = N/(E t), εy = −ν N/(E t)
    let r = lay
        .response(&Loads {
            n: Vector3::new(3.0, 0.0, 0.0),
            ..Loads::default()
        })
        .unwrap();
    assert_relative_eq!(r.strain[0], 3.0 / (e * t), max_relative = 1e-10);
    assert_relative_eq!(r.strain[1], -nu * 3.0 / (e * t), max_relative = 1e-10);
    assert!(r.curvature.amax() < 1e-12);
}

#[test]
fn cross_ply_has_closed_form_coupling() {
    let cf = library::cf_prepreg_ud();
    let t = 0.03;
    let lay = Layup::new(vec![
        single(cf.clone(), t, 0.0),
        single(cf.clone(), t, FRAC_PI_2),
    ])
    .unwrap();
    let q = reduced_stiffness(&cf);
    let b = lay.abd().b;
    assert_relative_eq!(
        b[(0, 0)],
        (q[(1, 1)] - q[(0, 0)]) * t * t / 2.0,
        max_relative = 1e-12
    );
    assert_relative_eq!(
        b[(1, 1)],
        (q[(0, 0)] - q[(1, 1)]) * t * t / 2.0,
        max_relative = 1e-12
    );
    assert!(lay.abd().relative_coupling() > 0.1);
    assert!(!lay.is_symmetric());
    // a cross-ply cured hot curls on cooling; the 0-90-0 CF layer does not
    assert!(lay.thermal_curvature(-180.0).unwrap().amax() > 1e-4);
    let cf090 = Layup::new(vec![Layer::cf_0_90_0("CF", 0.1, 0.0).unwrap()]).unwrap();
    assert!(cf090.is_symmetric());
    assert!(cf090.abd().relative_coupling() < 1e-12);
    assert!(cf090.thermal_curvature(-180.0).unwrap().amax() < 1e-15);
}

fn arb_ply() -> impl Strategy<Value = (usize, f64, f64)> {
    (0..library::NAMES.len(), 0.005f64..0.2, -PI..PI)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn symmetric_layups_have_no_coupling_and_no_thermal_curvature(
        plies in prop::collection::vec(arb_ply(), 1..6),
        dt in -250.0f64..250.0,
    ) {
        let all = library::all();
        let layers: Vec<Layer> = plies
            .iter()
            .map(|&(i, t, a)| single(all[i].clone(), t, a))
            .collect();
        let lay = Layup::symmetric(layers).unwrap();
        prop_assert!(lay.is_symmetric());
        let abd = lay.abd();
        prop_assert!(abd.relative_coupling() < 1e-12, "B/scale = {}", abd.relative_coupling());
        // ABD symmetric positive definite
        let m = abd.matrix();
        prop_assert!((m - m.transpose()).amax() <= 1e-9 * m.amax());
        prop_assert!(m.cholesky().is_some());
        let kappa = lay.thermal_curvature(dt).unwrap();
        let h = lay.total_thickness();
        // curvature × thickness is the natural dimensionless measure (strain scale 1e-3)
        prop_assert!(kappa.amax() * h < 1e-15, "kappa = {kappa:?}");
    }

    #[test]
    fn q_bar_invariants_hold_for_any_angle(theta in -PI..PI) {
        let q = reduced_stiffness(&library::cf_prepreg_ud());
        let qb = transformed_stiffness(&q, theta);
        // Tsai–Pagano invariants: Q̄11 + Q̄22 + 2 Q̄12 and Q̄66 − Q̄12 do not depend on θ
        let s = q.amax();
        prop_assert!(((qb[(0,0)] + qb[(1,1)] + 2.0*qb[(0,1)]) - (q[(0,0)] + q[(1,1)] + 2.0*q[(0,1)])).abs() < 1e-12 * s);
        prop_assert!(((qb[(2,2)] - qb[(0,1)]) - (q[(2,2)] - q[(0,1)])).abs() < 1e-12 * s);
        prop_assert!(qb.cholesky().is_some());
        // rotating the layup by 90° swaps A11 and A22
        let cf = library::cf_prepreg_ud();
        let a = Layup::new(vec![single(cf.clone(), 0.03, theta), single(cf.clone(), 0.05, theta + 0.4)]).unwrap().abd().a;
        let a90 = Layup::new(vec![single(cf.clone(), 0.03, theta + FRAC_PI_2), single(cf, 0.05, theta + 0.4 + FRAC_PI_2)]).unwrap().abd().a;
        prop_assert!((a[(0,0)] - a90[(1,1)]).abs() < 1e-10 * a.amax());
        prop_assert!((a[(1,1)] - a90[(0,0)]).abs() < 1e-10 * a.amax());
    }
}

#[test]
fn ply_stresses_satisfy_equilibrium_and_vanish_for_free_expansion() {
    // a free single ply heated: no stress
    let lay = Layup::new(vec![single(library::titanium(), 0.05, 0.0)]).unwrap();
    let s = lay
        .ply_stresses(&Loads {
            delta_t: 100.0,
            ..Loads::default()
        })
        .unwrap();
    assert!(s[0].stress_bottom.amax() < 1e-6 && s[0].stress_top.amax() < 1e-6);

    // the Mobee stack after the cure with applied N and M: ∫σ dz = N, ∫σ z dz = M
    let stack = mobee_stack().unwrap();
    let loads = Loads {
        n: Vector3::new(5.0, -2.0, 1.0),
        m: Vector3::new(0.3, 0.1, -0.05),
        delta_t: CURE_DELTA_T,
        voltages: vec![],
    };
    let mut n = Vector3::zeros();
    let mut m = Vector3::zeros();
    for p in stack.ply_stresses(&loads).unwrap() {
        let (z0, z1) = (p.z_bottom, p.z_top);
        let t = z1 - z0;
        n += (p.stress_bottom + p.stress_top) * (t / 2.0);
        // exact for stresses linear in z
        m += (p.stress_bottom * (2.0 * z0 + z1) + p.stress_top * (z0 + 2.0 * z1)) * (t / 6.0);
    }
    assert_relative_eq!(n, loads.n, epsilon = 1e-9);
    assert_relative_eq!(m, loads.m, epsilon = 1e-9);
}

// ------------------------------------------------------------------ thermal: Timoshenko 1925

/// Timoshenko's bimetal curvature (1925) for layer 1 (bottom, thickness t1, modulus E1,
/// expansion a1) and layer 2 (top), temperature change dt; positive when the top stretches.
fn timoshenko(t1: f64, e1: f64, a1: f64, t2: f64, e2: f64, a2: f64, dt: f64) -> f64 {
    let m = t1 / t2;
    let n = e1 / e2;
    let h = t1 + t2;
    6.0 * (a2 - a1) * dt * (1.0 + m).powi(2)
        / (h * (3.0 * (1.0 + m).powi(2) + (1.0 + m * n) * (m * m + 1.0 / (m * n))))
}

#[test]
fn bimetal_curvature_matches_timoshenko() {
    // equal Poisson ratios: CLPT equals Timoshenko with the Young's moduli
    let (t1, t2) = (0.0125, 0.0508);
    let bottom = iso("brass", 110.0, 0.3, 19.9);
    let top = iso("ti", 100.0, 0.3, 9.5);
    let lay = Layup::new(vec![
        single(bottom.clone(), t1, 0.0),
        single(top.clone(), t2, 0.0),
    ])
    .unwrap();
    let k = lay.thermal_curvature(-180.0).unwrap();
    let kt = timoshenko(
        t1,
        bottom.e1(),
        bottom.alpha1(),
        t2,
        top.e1(),
        top.alpha1(),
        -180.0,
    );
    assert_relative_eq!(k[0], kt, max_relative = 1e-10);
    assert_relative_eq!(k[1], kt, max_relative = 1e-10);
    assert!(k[2].abs() < 1e-12 * kt.abs());

    // different Poisson ratios: a free plate curls spherically; Timoshenko holds with the
    // biaxial moduli E/(1 − ν)
    let b = library::brass();
    let p = library::polyimide();
    let (tb, tp) = (0.0125, 0.0075);
    let lay = Layup::new(vec![single(b.clone(), tb, 0.0), single(p.clone(), tp, 0.0)]).unwrap();
    let k = lay.thermal_curvature(CURE_DELTA_T).unwrap();
    let kt = timoshenko(
        tb,
        b.e1() / (1.0 - b.nu12()),
        b.alpha1(),
        tp,
        p.e1() / (1.0 - p.nu12()),
        p.alpha1(),
        CURE_DELTA_T,
    );
    assert_relative_eq!(k[0], kt, max_relative = 1e-10);
    assert_relative_eq!(k[1], kt, max_relative = 1e-10);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn bimetal_matches_timoshenko_for_random_pairs(
        t1 in 0.005f64..0.3, t2 in 0.005f64..0.3,
        e1 in 1.0f64..300.0, e2 in 1.0f64..300.0,
        a1 in -2.0f64..100.0, a2 in -2.0f64..100.0,
        nu in 0.0f64..0.45, dt in -300.0f64..300.0,
    ) {
        let lay = Layup::new(vec![
            single(iso("1", e1, nu, a1), t1, 0.0),
            single(iso("2", e2, nu, a2), t2, 0.7),
        ]).unwrap();
        let k = lay.thermal_curvature(dt).unwrap();
        let kt = timoshenko(t1, e1, a1 * 1e-6, t2, e2, a2 * 1e-6, dt);
        let scale = kt.abs().max(1e-9);
        prop_assert!((k[0] - kt).abs() <= 1e-9 * scale, "{} vs {}", k[0], kt);
        prop_assert!((k[1] - kt).abs() <= 1e-9 * scale);
    }
}

// ------------------------------------------------------------------ bimorph

/// Euler–Bernoulli composite beam, derived here: symmetric three-layer bimorph (piezo t_p, E_p
/// around a core t_c, E_c), plates driven ±V. Returns (curvature per volt, EI per width).
fn eb_bimorph(t_p: f64, e_p: f64, d31: f64, t_c: f64, e_c: f64) -> (f64, f64) {
    let lam = d31.abs() / t_p; // free strain per volt
    let m_per_w = e_p * lam * t_p * (t_c + t_p); // two plate forces E Λ t_p at ±(t_c+t_p)/2
    let ei_per_w = e_c * t_c.powi(3) / 12.0
        + 2.0 * e_p * (t_p.powi(3) / 12.0 + t_p * ((t_c + t_p) / 2.0).powi(2));
    (m_per_w / ei_per_w, ei_per_w)
}

#[test]
fn bimorph_matches_euler_bernoulli_beam() {
    // isotropic layers with equal ν: CLPT's narrow-beam result is exactly beam theory
    let (t_p, t_c, e_p, e_c, d31) = (0.127, 0.04, 62.0, 290.0, -320.0);
    let pzt = piezo_iso(e_p, 0.3, d31);
    let core = iso("core", e_c, 0.3, 0.0);
    let lay = Layup::new(vec![
        single(pzt.clone(), t_p, 0.0),
        single(core, t_c, 0.0),
        single(pzt, t_p, 0.0),
    ])
    .unwrap();
    let (l, ext, w) = (9.0, 3.0, 1.5);
    let b = Bimorph::new(lay, BimorphGeometry::new(l, ext, w, 1.0).unwrap()).unwrap();
    let (kv, ei_w) = eb_bimorph(t_p, e_p * GPA, d31 * PM_PER_V, t_c, e_c * GPA);
    assert_relative_eq!(b.curvature_per_volt(), kv, max_relative = 1e-10);
    assert_relative_eq!(b.bending_stiffness_per_width(), ei_w, max_relative = 1e-10);
    // δ = κ L (L/2 + L_ext); 1/k = ((L+L_ext)³ − L_ext³) / (3 EI)
    let v = 150.0;
    assert_relative_eq!(
        b.free_deflection(v).unwrap(),
        kv * v * l * (l / 2.0 + ext),
        max_relative = 1e-10
    );
    let ei = ei_w * w;
    let k = 3.0 * ei / ((l + ext).powi(3) - ext.powi(3));
    assert_relative_eq!(b.stiffness(), k, max_relative = 1e-10);
    assert_relative_eq!(
        b.blocked_force(v).unwrap(),
        k * kv * v * l * (l / 2.0 + ext),
        max_relative = 1e-10
    );
    // positive voltage deflects towards +z (d31 < 0, top plate at +V contracts)
    assert!(b.free_deflection(v).unwrap() > 0.0);
    assert_eq!(b.layer_voltages(10.0), vec![-10.0, 0.0, 10.0]);
}

#[test]
fn parallel_bimorph_matches_smits_formulas() {
    // two plates, no core: δ = 3 d31 V L² / h², F_b = 3 E w h d31 V / (4 L)
    let (t_p, e, d31_pm) = (0.127, 62.0, -320.0);
    let pzt = piezo_iso(e, 0.31, d31_pm);
    let lay = Layup::new(vec![single(pzt.clone(), t_p, 0.0), single(pzt, t_p, 0.0)]).unwrap();
    let (l, w, v) = (10.0, 2.0, 100.0);
    let b = Bimorph::new(lay, BimorphGeometry::new(l, 0.0, w, 1.0).unwrap()).unwrap();
    let h = 2.0 * t_p;
    let d31 = (d31_pm * PM_PER_V).abs();
    assert_relative_eq!(
        b.free_deflection(v).unwrap(),
        3.0 * d31 * v * l * l / (h * h),
        max_relative = 1e-10
    );
    assert_relative_eq!(
        b.blocked_force(v).unwrap(),
        3.0 * e * GPA * w * h * d31 * v / (4.0 * l),
        max_relative = 1e-10
    );
}

#[test]
fn tapered_actuator_matches_wood_geometry_factor() {
    // Wood et al. 2005: F_b = 3 κ w_nom / (2 d11 L) · G_F with
    // G_F = (1 + 2 l_r) / ((g_d + g_e) / g_c), g_c = 8 (1 − w_r)³,
    // g_d = 6 (w_r − 1)(3 + 4 l_r − 2 w_r − 4 l_r w_r),
    // g_e = 3 (−2 − 2 l_r + w_r + 2 l_r w_r)² ln((2 − w_r)/w_r), w_r = w0 / w_nom.
    let lay = Bimorph::wood_layup(0.127, 0.04).unwrap();
    for &(l, l_r, w_nom, w_r) in &[
        (9.0, 0.25, 1.125, 1.556),
        (8.0, 0.5, 2.25, 1.5556),
        (10.0, 1.0, 2.0, 1.25),
        (6.0, 0.0, 1.5, 1.8),
    ] {
        let g = BimorphGeometry::from_wood(l, l_r, w_nom, w_r).unwrap();
        assert_relative_eq!(g.nominal_width(), w_nom, max_relative = 1e-12);
        let b = Bimorph::new(lay.clone(), g).unwrap();
        let g_c = 8.0 * (1.0 - w_r).powi(3);
        let g_d = 6.0 * (w_r - 1.0) * (3.0 + 4.0 * l_r - 2.0 * w_r - 4.0 * l_r * w_r);
        let g_e =
            3.0 * (-2.0 - 2.0 * l_r + w_r + 2.0 * l_r * w_r).powi(2) * ((2.0 - w_r) / w_r).ln();
        let g_f = (1.0 + 2.0 * l_r) / ((g_d + g_e) / g_c);
        let d11 = 1.0 / b.bending_stiffness_per_width();
        let fb_per_v = 3.0 * b.curvature_per_volt() * w_nom / (2.0 * d11 * l) * g_f;
        assert_relative_eq!(b.force_per_volt(), fb_per_v, max_relative = 1e-9);
        // and Wood's free deflection δ = κ L² (1 + 2 l_r) / 2
        assert_relative_eq!(
            b.free_deflection_per_volt(),
            b.curvature_per_volt() * l * l * (1.0 + 2.0 * l_r) / 2.0,
            max_relative = 1e-12
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn bimorph_is_linear_in_voltage(
        v1 in -250.0f64..250.0, v2 in -250.0f64..250.0,
        l in 3.0f64..20.0, ext in 0.0f64..10.0, w in 0.5f64..5.0, wr in 0.2f64..2.0,
        t_cf in 0.01f64..0.2,
    ) {
        let b = Bimorph::new(
            Bimorph::wood_layup(0.127, t_cf).unwrap(),
            BimorphGeometry::new(l, ext, w, wr).unwrap(),
        ).unwrap();
        let d1 = b.free_deflection(v1).unwrap();
        let d2 = b.free_deflection(v2).unwrap();
        let d12 = b.free_deflection((v1 + v2) / 2.0).unwrap();
        prop_assert!((d12 - (d1 + d2) / 2.0).abs() <= 1e-12 * (d1.abs() + d2.abs() + 1e-12));
        let f1 = b.blocked_force(v1).unwrap();
        prop_assert!((f1 - b.stiffness() * d1).abs() <= 1e-10 * f1.abs().max(1e-12));
        // the CLPT curvature agrees with the full response at that voltage
        let r = b.layup().response(&Loads { voltages: b.layer_voltages(v1), ..Loads::default() }).unwrap();
        prop_assert!((-r.curvature[0] - b.curvature_per_volt() * v1).abs() <= 1e-12 * r.curvature.amax().max(1e-12));
        // narrower tip, longer extension: softer
        let softer = b.with_geometry(BimorphGeometry::new(l, ext + 1.0, w, wr).unwrap()).unwrap();
        prop_assert!(softer.stiffness() < b.stiffness());
    }
}

#[test]
fn bimorph_voltage_limit_and_layup_errors() {
    let b = Bimorph::new(
        Bimorph::wood_layup(0.127, 0.04).unwrap(),
        BimorphGeometry::new(9.0, 2.0, 1.5, 0.5).unwrap(),
    )
    .unwrap();
    // 2 V/µm on 127 µm plates
    assert_relative_eq!(b.max_voltage(), 254.0, max_relative = 1e-12);
    let e = b.free_deflection(300.0).unwrap_err();
    assert_eq!(e.kind(), "OutOfDomain");
    assert_eq!(
        field(&b.blocked_force(f64::NAN).unwrap_err()),
        Some("voltage")
    );
    // no piezo layer
    let passive = Layup::new(vec![single(library::brass(), 0.05, 0.0)]).unwrap();
    let e = Bimorph::new(passive, *b.geometry()).unwrap_err();
    assert_eq!(e.kind(), "Geometry");
    // a single piezo layer centred on the mid-plane cannot bend
    let mono = Layup::new(vec![single(library::pzt_5h(), 0.127, 0.0)]).unwrap();
    assert_eq!(
        Bimorph::new(mono, *b.geometry()).unwrap_err().kind(),
        "Geometry"
    );
    // geometry validation
    assert_eq!(
        field(&BimorphGeometry::new(9.0, -1.0, 1.0, 1.0).unwrap_err()),
        Some("extension")
    );
    assert_eq!(
        field(&BimorphGeometry::new(9.0, 1.0, 1.0, 0.0).unwrap_err()),
        Some("width_ratio")
    );
    assert_eq!(
        field(&BimorphGeometry::from_wood(9.0, 0.2, 1.0, 2.0).unwrap_err()),
        Some("wood_width_ratio")
    );
    assert_eq!(
        field(&ActuatorConstants::new(-1.0, 1.0).unwrap_err()),
        Some("stiffness_mn_per_mm")
    );
    // a unimorph (PZT on brass) works and bends the other way for a plate below the mid-plane
    let uni = Layup::new(vec![
        single(library::pzt_5h(), 0.127, 0.0),
        single(library::brass(), 0.05, 0.0),
    ])
    .unwrap();
    let u = Bimorph::new(uni, *b.geometry()).unwrap();
    assert_eq!(u.layer_voltages(1.0), vec![-1.0, 0.0]);
    assert!(u.free_deflection_per_volt() > 0.0);
}

#[test]
fn design_reproduces_the_thesis_actuator_constants() {
    // §3.3.1: 467 mN/mm and 120 mN at 100 V (1.2 mN/V) → 2.57 µm/V free deflection
    let target = ActuatorConstants::THESIS;
    assert_relative_eq!(
        target.free_deflection_per_volt(),
        1.2 / 467.0,
        max_relative = 1e-15
    );
    for layup in [
        Bimorph::mobee_layup().unwrap(),
        Bimorph::wood_layup(0.127, 0.04).unwrap(),
    ] {
        for (wr, lr) in [(1.0, 0.0), (0.5, 0.5), (0.4, 0.25)] {
            let b = Bimorph::design_for(layup.clone(), target, wr, lr).unwrap();
            let c = b.constants();
            assert_relative_eq!(c.stiffness_mn_per_mm, 467.0, max_relative = 1e-10);
            assert_relative_eq!(c.force_per_volt_mn_per_v, 1.2, max_relative = 1e-10);
            assert_relative_eq!(b.blocked_force(100.0).unwrap(), 120.0, max_relative = 1e-10);
            let g = b.geometry();
            assert_relative_eq!(g.width_ratio, wr);
            assert_relative_eq!(g.extension, lr * g.length, max_relative = 1e-12);
            assert!(g.length > 5.0 && g.length < 25.0, "L = {}", g.length);
        }
    }
    // the reported design: Mobee layup, tip/base 0.5, extension ratio 0.5
    let b = Bimorph::design_for(Bimorph::mobee_layup().unwrap(), target, 0.5, 0.5).unwrap();
    let g = b.geometry();
    assert_relative_eq!(g.length, 12.30, epsilon = 0.01);
    assert_relative_eq!(g.base_width, 3.97, epsilon = 0.01);
    assert_relative_eq!(b.free_deflection(100.0).unwrap(), 0.257, epsilon = 0.001);
}

// ------------------------------------------------------------------ flexures

#[test]
fn flexure_stiffness_and_large_deflection_caveat() {
    let f = Flexure::polyimide(1.0, 0.030).unwrap();
    // k = E w t³ / (12 L) = 2.5e6 · 1 · 0.0075³ / (12 · 0.03)
    let k = 2.5e6 * 0.0075f64.powi(3) / (12.0 * 0.030);
    assert_relative_eq!(f.stiffness(), k, max_relative = 1e-12);
    assert_relative_eq!(f.stiffness(), 2.9296875, max_relative = 1e-12);
    let nu = 0.34;
    assert_relative_eq!(
        f.plate_stiffness(),
        k / (1.0 - nu * nu),
        max_relative = 1e-12
    );
    assert_relative_eq!(f.torque(0.1).unwrap(), -0.1 * k, max_relative = 1e-12);
    // a 90° assembly fold strains the film ≈20 %, far beyond Kapton's ≈3 % yield
    let eps = f.max_strain(FRAC_PI_2).unwrap();
    assert_relative_eq!(eps, 0.0075 * FRAC_PI_2 / 0.06, max_relative = 1e-12);
    assert!(eps > 6.0 * KAPTON_YIELD_STRAIN);
    let lim = f.elastic_limit_angle(KAPTON_YIELD_STRAIN).unwrap();
    assert_relative_eq!(lim, 2.0 * 0.03 * 0.03 / 0.0075, max_relative = 1e-12);
    assert_relative_eq!(
        f.max_strain(lim).unwrap(),
        KAPTON_YIELD_STRAIN,
        max_relative = 1e-12
    );
    for (args, name) in [
        ((0.0, 0.0075, 0.03), "width"),
        ((1.0, -0.0075, 0.03), "thickness"),
        ((1.0, 0.0075, f64::NAN), "length"),
        // issue 14: magnitudes that overflowed to inf or divided by zero downstream
        ((1e300, 0.03, 0.0075), "width"),
        ((3.0, 5e-324, 2.0), "thickness"),
    ] {
        let e = Flexure::new(library::polyimide(), args.0, args.1, args.2).unwrap_err();
        assert_eq!(field(&e), Some(name));
    }
}

#[test]
fn castellated_joint_geometry() {
    let (lo, hi) = CASTELLATED_FLEXURE_LENGTH_MM;
    assert_eq!((lo, hi), (0.020, 0.040));
    let j = CastellatedJoint::mobee(2.0, 8, 0.030).unwrap();
    assert!(j.within_thesis_range());
    assert_relative_eq!(j.segment_width(), 0.25);
    assert_relative_eq!(
        j.stiffness(),
        Flexure::polyimide(2.0, 0.030).unwrap().stiffness(),
        max_relative = 1e-12
    );
    // stiffness scales as 1/L over the thesis range: 2× between 20 and 40 µm
    let k20 = CastellatedJoint::mobee(2.0, 8, lo).unwrap().stiffness();
    let k40 = CastellatedJoint::mobee(2.0, 8, hi).unwrap().stiffness();
    assert_relative_eq!(k20 / k40, 2.0, max_relative = 1e-12);
    assert!(
        !CastellatedJoint::mobee(2.0, 8, 0.1)
            .unwrap()
            .within_thesis_range()
    );
    let half = CastellatedJoint::new(library::polyimide(), 2.0, 8, 0.5, 0.0075, 0.03).unwrap();
    assert_relative_eq!(half.stiffness(), 0.5 * j.stiffness(), max_relative = 1e-12);
    assert_eq!(
        field(&CastellatedJoint::mobee(2.0, 0, 0.03).unwrap_err()),
        Some("n_segments")
    );
    assert_eq!(
        field(&CastellatedJoint::new(library::polyimide(), 2.0, 8, 1.5, 0.0075, 0.03).unwrap_err()),
        Some("flexure_fraction")
    );
}

// ------------------------------------------------------------------ PC-MEMS layups

#[test]
fn mobee_stack_matches_the_thesis_counts() {
    let s = mobee_stack().unwrap();
    assert_eq!(s.len(), 18);
    // §4.4.2: 5 × 100 µm CF, 2 × 7.5 µm PI, 2 × 12.5 µm brass, 1 × 50.8 µm Ti, 8 × 12.5 µm A
    let expect_h = 5.0 * 0.100 + 2.0 * 0.0075 + 2.0 * 0.0125 + 0.0508 + 8.0 * 0.0125;
    assert_relative_eq!(s.total_thickness(), expect_h, max_relative = 1e-12);
    assert_relative_eq!(s.total_thickness(), 0.6908, max_relative = 1e-12);
    let rho = |m: Material| m.density();
    let expect_m = 5.0 * 0.100 * rho(library::cf_prepreg_ud())
        + 2.0 * 0.0075 * rho(library::polyimide())
        + 2.0 * 0.0125 * rho(library::brass())
        + 0.0508 * rho(library::titanium())
        + 8.0 * 0.0125 * rho(library::pyralux_adhesive());
    assert_relative_eq!(s.areal_mass(), expect_m, max_relative = 1e-12);
    let sum = summarize(&s).unwrap();
    let count = |c: MaterialClass| {
        sum.by_class
            .iter()
            .find(|e| e.0 == c)
            .map(|e| e.1)
            .unwrap_or(0)
    };
    assert_eq!(count(MaterialClass::Composite), 5);
    assert_eq!(count(MaterialClass::Adhesive), 8);
    assert_eq!(count(MaterialClass::Polymer), 2);
    assert_eq!(count(MaterialClass::Metal), 3);
    // layer names carry the thesis numbering
    assert_eq!(s.layers()[8].name(), "9 CF");
    assert_eq!(s.layers()[17].name(), "18 Ti");
    assert_eq!(s.layers()[2].plies().len(), 3);
}

#[test]
fn cure_curvature_of_asymmetric_and_symmetric_stacks() {
    assert_relative_eq!(CURE_DELTA_T, -180.0);
    // the full stack is asymmetric (titanium on top): it curls after the 200 °C cure
    let s = mobee_stack().unwrap();
    assert!(!s.is_symmetric());
    let k = s.thermal_curvature(CURE_DELTA_T).unwrap();
    assert!(k[0].abs() > 1e-4 && k[1].abs() > 1e-4, "{k:?}");
    assert!(k[2].abs() < 1e-12);
    // linear in ΔT
    let k2 = s.thermal_curvature(2.0 * CURE_DELTA_T).unwrap();
    assert_relative_eq!(k2, 2.0 * k, max_relative = 1e-12);
    // layers 1–17 and the linkage sublaminate are symmetric: flat
    for flat in [
        mobee_stack_without_titanium().unwrap(),
        linkage_sublaminate().unwrap(),
    ] {
        assert!(flat.is_symmetric());
        assert!(flat.abd().relative_coupling() < 1e-12);
        let kf = flat.thermal_curvature(CURE_DELTA_T).unwrap();
        assert!(kf.amax() < 1e-15, "{kf:?}");
    }
    // the lower sublaminate of the first lamination (layers 1–7) is asymmetric: brass on one side
    let lower = Layup::new(s.layers()[..7].to_vec()).unwrap();
    assert!(lower.thermal_curvature(CURE_DELTA_T).unwrap().amax() > 1e-4);
}

#[test]
fn records_round_trip_and_name_the_dotted_field() {
    use paritysim_laminate::records::{LayerRecord, MaterialRecord, preset};
    let stack = preset("mobee").unwrap();
    let records = LayerRecord::all(&stack);
    let rebuilt = LayerRecord::build_layup(records.clone()).unwrap();
    assert_eq!(LayerRecord::all(&rebuilt), records);
    assert_eq!(rebuilt.abd().matrix(), stack.abd().matrix());
    let mut bad = records;
    bad[2].plies[0].thickness = -0.01;
    let err = LayerRecord::build_layup(bad).unwrap_err();
    assert_eq!(err.field(), Some("layers[2].plies[0].thickness"));
    let brass = MaterialRecord::of(&paritysim_laminate::library::by_name("brass").unwrap());
    let mut piezo_half = brass.clone();
    piezo_half.d31 = Some(1e-9);
    let err = piezo_half.build("material").unwrap_err();
    assert_eq!(err.field(), Some("material.max_field"));
    assert_eq!(MaterialRecord::of(&brass.clone().build("").unwrap()), brass);
}
