//! Integration tests of paritysim-constraints.

use approx::assert_relative_eq;
use paritysim_constraints::{CONFIGURATION_NAMES, Constraints, Mat6, Vec6};

#[test]
fn table_3_1_degrees_of_freedom() {
    // (name, dof): 6 coordinates minus the rows of Table 3.1.
    let expected = [3, 1, 4, 2, 4, 2, 5, 3];
    for (name, dof) in CONFIGURATION_NAMES.iter().zip(expected) {
        let c = Constraints::configuration(name).unwrap();
        assert_eq!(c.n_free(), dof, "{name}");
    }
}

#[test]
fn null_basis_is_orthonormal_and_annihilated_by_c() {
    for name in CONFIGURATION_NAMES {
        let c = Constraints::configuration(name).unwrap();
        let n = c.null_basis().columns(0, c.n_free()).into_owned();
        assert_relative_eq!(
            n.transpose() * &n,
            nalgebra::DMatrix::identity(c.n_free(), c.n_free()),
            epsilon = 1e-14
        );
        for k in 0..c.n_free() {
            let col: Vec6 = c.null_basis().column(k).into_owned();
            assert!(c.residual(&col) < 1e-14, "{name}");
        }
    }
}

#[test]
fn hmf_null_space_keeps_strokes_equal() {
    let c = Constraints::configuration("hmf_fixed").unwrap();
    let z = c.null_basis().column(0);
    assert_relative_eq!(z[0], z[3], epsilon = 1e-15);
    assert!(z[0].abs() > 0.5);
}

#[test]
fn particular_solution_satisfies_nonzero_c0() {
    let rows = vec![
        vec![0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
        vec![1.0, 0.0, 0.0, -1.0, 0.0, 0.0],
    ];
    let c = Constraints::new(6, &rows, &[0.2, -0.1]).unwrap();
    assert!(c.residual(c.particular()) < 1e-14);
}

#[test]
fn projection_agrees_with_null_space() {
    // A random SPD mass matrix and force: the projected acceleration of eq. 3.20 must equal the
    // null-space acceleration N (Nᵀ M N)⁻¹ Nᵀ f, and satisfy C p̈ = 0.
    let c = Constraints::configuration("drag_parity").unwrap();
    let a =
        Mat6::from_fn(|i, j| ((i * 7 + j * 3) % 5) as f64 * 0.1 + if i == j { 1.0 } else { 0.0 });
    let m = a * a.transpose();
    let f = Vec6::from_fn(|i, _| (i as f64 - 2.5) * 0.3);
    let m_inv = m.try_inverse().unwrap();
    let p_dd = c.project(&m_inv, &f).unwrap();
    assert!(c.velocity_residual(&p_dd) < 1e-13);
    let nf = c.n_free();
    let n = c.null_basis().columns(0, nf).into_owned();
    let mz = n.transpose() * m * &n;
    let z_dd = mz.lu().solve(&(n.transpose() * f)).unwrap();
    let p_dd_null = &n * z_dd;
    for i in 0..6 {
        assert_relative_eq!(p_dd[i], p_dd_null[i], epsilon = 1e-12);
    }
}

#[test]
fn erratum_4_printed_eq_3_20_violates_the_constraint() {
    // As printed (without Cᵀ), eq. 3.20 is dimensionally inconsistent for a non-square C; with
    // a square-padded reading it does not produce C p̈ = 0. Our projection does.
    let c = Constraints::configuration("hmf_fixed").unwrap();
    let m = Mat6::from_diagonal(&Vec6::new(2.0, 1.0, 3.0, 1.5, 1.0, 0.5));
    let f = Vec6::new(1.0, -0.5, 0.3, 0.7, 0.2, -0.4);
    let p_dd = c.project(&m.try_inverse().unwrap(), &f).unwrap();
    assert!(c.velocity_residual(&p_dd) < 1e-14);
    assert!(
        c.velocity_residual(&(m.try_inverse().unwrap() * f)) > 1e-2,
        "unconstrained acceleration violates C"
    );
}

#[test]
fn rejects_bad_constraint_matrices() {
    let redundant = vec![
        vec![0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
        vec![0.0, 2.0, 0.0, 0.0, 0.0, 0.0],
    ];
    assert!(
        Constraints::new(6, &redundant, &[0.0, 0.0])
            .unwrap_err()
            .to_string()
            .contains("rank deficient")
    );
    let short = vec![vec![1.0, 0.0]];
    assert!(
        Constraints::new(6, &short, &[0.0])
            .unwrap_err()
            .to_string()
            .contains("columns")
    );
    let one = vec![vec![1.0, 0.0, 0.0, 0.0, 0.0, 0.0]];
    assert!(
        Constraints::new(6, &one, &[0.0, 1.0])
            .unwrap_err()
            .to_string()
            .contains("c0")
    );
    let nan = vec![vec![f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0]];
    assert_eq!(
        Constraints::new(6, &nan, &[0.0]).unwrap_err().field(),
        Some("C[0][0]")
    );
    assert_eq!(
        Constraints::configuration("hmf2").unwrap_err().field(),
        Some("configuration")
    );
    let c = Constraints::configuration("hmf_fixed").unwrap();
    let p = Vec6::new(0.1, 0.0, 0.0, 0.2, 0.0, 0.0);
    assert!(c.check_consistent(&p, &Vec6::zeros(), 1e-12).is_err());
}
