//! Linear coupling constraints `C p = c0` between wings (thesis §3.2.5) and the eight
//! configurations of Table 3.1.
//!
//! The configuration of a two-wing device is `p = (φL, θL, ψL, φR, θR, ψR)` (eq. 3.21); a
//! one-wing device uses the first three entries. [`Constraints`] validates `C` (size, rank,
//! finiteness) and precomputes what both formulations of the constrained dynamics need:
//!
//! * **null space** (default): `p = p_part + N z` with `N` an orthonormal basis of `ker C` and
//!   `C p_part = c0`; the reduced coordinates `z` cannot drift off the constraint;
//! * **projection** (eq. 3.20 with the `Cᵀ` restored, docs/errata.md#4):
//!   `p̈ = M⁻¹ (I − Cᵀ (C M⁻¹ Cᵀ)⁻¹ C M⁻¹) (f + τ)`, see [`Constraints::project`].

use nalgebra::{DMatrix, SMatrix, SVector};
use paritysim_error::{Error, Result, bail};

/// Largest configuration size: two wings × (φ, θ, ψ).
pub const MAX_COORDS: usize = 6;

/// A 6-vector (unused trailing entries are zero for one-wing devices).
pub type Vec6 = SVector<f64, MAX_COORDS>;
/// A 6×6 matrix (padded with zeros / identity for one-wing devices).
pub type Mat6 = SMatrix<f64, MAX_COORDS, MAX_COORDS>;

/// Relative singular-value threshold for the rank of `C`.
const RANK_TOL: f64 = 1e-10;

/// A validated constraint set `C p = c0`.
#[derive(Clone, Debug, PartialEq)]
pub struct Constraints {
    n_coords: usize,
    rows: Vec<[f64; MAX_COORDS]>,
    c0: Vec<f64>,
    /// Orthonormal basis of `ker C`, first `n_free` columns used.
    null_basis: Mat6,
    n_free: usize,
    /// Minimum-norm particular solution of `C p = c0`.
    particular: Vec6,
}

impl Constraints {
    /// Builds `C p = c0` for `n_coords` (3 or 6) coordinates.
    ///
    /// # Errors
    /// [`Error::Shape`] when a row's length differs from `n_coords` or `c0` has the wrong length;
    /// [`Error::InvalidParameter`] for non-finite entries; [`Error::Constraint`] when `C` is rank
    /// deficient (a redundant or contradictory row) or leaves no degree of freedom.
    pub fn new(n_coords: usize, rows: &[Vec<f64>], c0: &[f64]) -> Result<Self> {
        if n_coords != 3 && n_coords != 6 {
            bail!(invalid "n_coords", n_coords, "3 (one wing) or 6 (two wings)");
        }
        if c0.len() != rows.len() {
            bail!(Shape "C has {} rows but c0 has {} entries", rows.len(), c0.len());
        }
        let mut padded = Vec::with_capacity(rows.len());
        for (i, row) in rows.iter().enumerate() {
            if row.len() != n_coords {
                bail!(Shape "row {i} of C has {} columns; expected {n_coords} (3 per wing)", row.len());
            }
            let mut r = [0.0; MAX_COORDS];
            for (j, v) in row.iter().enumerate() {
                if !v.is_finite() {
                    return Err(Error::invalid(format!("C[{i}][{j}]"), v, "a finite number"));
                }
                r[j] = *v;
            }
            padded.push(r);
        }
        for (i, v) in c0.iter().enumerate() {
            if !v.is_finite() {
                return Err(Error::invalid(format!("c0[{i}]"), v, "a finite number"));
            }
        }
        let m = rows.len();
        if m >= n_coords {
            bail!(Constraint "{m} constraints on {n_coords} coordinates leave no degree of freedom");
        }
        // Null space and particular solution from the SVD of the square-padded Cᵀ C.
        let mut null_basis = Mat6::zeros();
        let mut particular = Vec6::zeros();
        let n_free;
        if m == 0 {
            for j in 0..n_coords {
                null_basis[(j, j)] = 1.0;
            }
            n_free = n_coords;
        } else {
            let c = DMatrix::from_fn(m, n_coords, |i, j| padded[i][j]);
            let svd = c.clone().svd(true, true);
            let smax = svd.singular_values.max();
            let rank = svd
                .singular_values
                .iter()
                .filter(|s| **s > RANK_TOL * smax.max(1.0))
                .count();
            if rank < m {
                bail!(Constraint
                    "C is rank deficient (rank {rank} < {m} rows): a row is redundant or contradictory; \
                     singular values {:?}", svd.singular_values.as_slice());
            }
            // Full SVD of Cᵀ (n × m) gives U (n × n)? nalgebra's thin SVD does not: use the
            // eigen-decomposition of Cᵀ C instead, whose zero eigenvectors span ker C.
            let ctc = c.transpose() * &c;
            let eig = ctc.symmetric_eigen();
            let mut idx: Vec<usize> = (0..n_coords).collect();
            idx.sort_by(|a, b| eig.eigenvalues[*a].total_cmp(&eig.eigenvalues[*b]));
            n_free = n_coords - m;
            for (k, &col) in idx.iter().take(n_free).enumerate() {
                for j in 0..n_coords {
                    null_basis[(j, k)] = eig.eigenvectors[(j, col)];
                }
            }
            let rhs = nalgebra::DVector::from_column_slice(c0);
            let sol = svd
                .solve(&rhs, RANK_TOL)
                .map_err(|e| Error::Constraint(format!("cannot solve C p = c0: {e}")))?;
            for j in 0..n_coords {
                particular[j] = sol[j];
            }
        }
        Ok(Self {
            n_coords,
            rows: padded,
            c0: c0.to_vec(),
            null_basis,
            n_free,
            particular,
        })
    }

    /// No constraint on `n_coords` coordinates.
    pub fn none(n_coords: usize) -> Result<Self> {
        Self::new(n_coords, &[], &[])
    }

    /// One of the eight named configurations of Table 3.1, with `c0 = 0`:
    /// `hmf` (#1), `hmf_fixed` (#2), `drag_parity` (#3), `drag_parity_fixed` (#4),
    /// `lift_parity` (#5), `lift_parity_fixed` (#6), `dual_parity` (#7), `dual_parity_fixed` (#8).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the valid names for an unknown one.
    pub fn configuration(name: &str) -> Result<Self> {
        // Built once per process: every device of a spec (a sweep's points, a sensitivity's
        // perturbed devices) named one, and its SVD was 33 k instructions a device.
        static BUILT: std::sync::OnceLock<Vec<(&str, Option<Constraints>)>> =
            std::sync::OnceLock::new();
        let built = BUILT.get_or_init(|| {
            CONFIGURATION_NAMES
                .iter()
                .map(|&n| (n, Self::build_configuration(n).ok()))
                .collect()
        });
        match built.iter().find(|(n, _)| *n == name) {
            Some((_, Some(c))) => Ok(c.clone()),
            _ => Self::build_configuration(name),
        }
    }

    /// The constraints of [`Constraints::configuration`], built.
    fn build_configuration(name: &str) -> Result<Self> {
        let e = |k: usize| {
            let mut r = vec![0.0; 6];
            r[k] = 1.0;
            r
        };
        let diff = |a: usize, b: usize| {
            let mut r = vec![0.0; 6];
            r[a] = 1.0;
            r[b] = -1.0;
            r
        };
        // p = (φL, θL, ψL, φR, θR, ψR): indices 0..6.
        let rows: Vec<Vec<f64>> = match name {
            "hmf" => vec![e(1), e(4), diff(0, 3)],
            "hmf_fixed" => vec![e(1), e(4), diff(0, 3), e(2), e(5)],
            "drag_parity" => vec![e(1), e(4)],
            "drag_parity_fixed" => vec![e(1), e(4), e(2), e(5)],
            "lift_parity" => vec![diff(1, 4), diff(0, 3)],
            "lift_parity_fixed" => vec![diff(1, 4), diff(0, 3), e(2), e(5)],
            "dual_parity" => vec![diff(1, 4)],
            "dual_parity_fixed" => vec![diff(1, 4), e(2), e(5)],
            other => {
                return Err(Error::invalid(
                    "configuration",
                    other,
                    format!("one of {}", CONFIGURATION_NAMES.join(", ")),
                ));
            }
        };
        let zeros = vec![0.0; rows.len()];
        Self::new(6, &rows, &zeros)
    }

    /// Number of coordinates (3 or 6).
    pub fn n_coords(&self) -> usize {
        self.n_coords
    }

    /// Number of constraint rows.
    pub fn n_rows(&self) -> usize {
        self.rows.len()
    }

    /// Degrees of freedom left: `n_coords − rank C`.
    pub fn n_free(&self) -> usize {
        self.n_free
    }

    /// The rows of `C` (padded to 6 columns).
    pub fn rows(&self) -> &[[f64; MAX_COORDS]] {
        &self.rows
    }

    /// `c0`.
    pub fn c0(&self) -> &[f64] {
        &self.c0
    }

    /// Orthonormal null-space basis `N` (first [`Self::n_free`] columns).
    pub fn null_basis(&self) -> &Mat6 {
        &self.null_basis
    }

    /// Minimum-norm `p_part` with `C p_part = c0`.
    pub fn particular(&self) -> &Vec6 {
        &self.particular
    }

    /// `C p − c0` (max-abs residual).
    pub fn residual(&self, p: &Vec6) -> f64 {
        self.rows
            .iter()
            .zip(&self.c0)
            .map(|(r, c)| (r.iter().zip(p.iter()).map(|(a, b)| a * b).sum::<f64>() - c).abs())
            .fold(0.0, f64::max)
    }

    /// `C ṗ` (max-abs residual).
    pub fn velocity_residual(&self, p_dot: &Vec6) -> f64 {
        self.rows
            .iter()
            .map(|r| {
                r.iter()
                    .zip(p_dot.iter())
                    .map(|(a, b)| a * b)
                    .sum::<f64>()
                    .abs()
            })
            .fold(0.0, f64::max)
    }

    /// Checks that an initial state satisfies `C p = c0` and `C ṗ = 0` to `tol`.
    ///
    /// # Errors
    /// [`Error::Constraint`] with both residuals when it does not.
    pub fn check_consistent(&self, p: &Vec6, p_dot: &Vec6, tol: f64) -> Result<()> {
        let (r, v) = (self.residual(p), self.velocity_residual(p_dot));
        if r > tol || v > tol {
            bail!(Constraint
                "initial state violates the constraints: |C p - c0| = {r:e}, |C p_dot| = {v:e} \
                 (tolerance {tol:e})");
        }
        Ok(())
    }

    /// Constrained accelerations by eq. 3.20 with the `Cᵀ` of docs/errata.md#4:
    /// `p̈ = M⁻¹ (I − Cᵀ (C M⁻¹ Cᵀ)⁻¹ C M⁻¹) (f + τ)`, given `M⁻¹` and the force `f + τ`.
    ///
    /// # Errors
    /// [`Error::Singular`] when `C M⁻¹ Cᵀ` is singular.
    pub fn project(&self, m_inv: &Mat6, force: &Vec6) -> Result<Vec6> {
        let unconstrained = m_inv * force;
        let m = self.rows.len();
        if m == 0 {
            return Ok(unconstrained);
        }
        // Up to 5 rows: use a 6×6 padded with identity below the used block.
        let mut c = Mat6::zeros();
        for (i, r) in self.rows.iter().enumerate() {
            for j in 0..MAX_COORDS {
                c[(i, j)] = r[j];
            }
        }
        let mut a = c * m_inv * c.transpose();
        for i in m..MAX_COORDS {
            a[(i, i)] = 1.0;
        }
        let rhs = c * unconstrained;
        let lambda = a
            .lu()
            .solve(&rhs)
            .ok_or_else(|| Error::Singular("C M^-1 C^T is singular".into()))?;
        Ok(unconstrained - m_inv * (c.transpose() * lambda))
    }
}

/// Names accepted by [`Constraints::configuration`], in Table 3.1 order.
pub const CONFIGURATION_NAMES: [&str; 8] = [
    "hmf",
    "hmf_fixed",
    "drag_parity",
    "drag_parity_fixed",
    "lift_parity",
    "lift_parity_fixed",
    "dual_parity",
    "dual_parity_fixed",
];

#[cfg(test)]
mod tests {
    use super::*;

    /// The configurations built once per process are those built on each call; an unknown
    /// name is still refused with the valid names.
    #[test]
    fn kept_configurations_equal_built_ones() {
        for name in CONFIGURATION_NAMES {
            let kept = Constraints::configuration(name).unwrap();
            assert_eq!(
                kept,
                Constraints::build_configuration(name).unwrap(),
                "{name}"
            );
            assert_eq!(kept.n_coords(), 6);
        }
        let e = Constraints::configuration("drag_parityy").unwrap_err();
        assert_eq!(e.kind(), "InvalidParameter");
        assert!(e.to_string().contains("drag_parity"), "{e}");
    }
}
