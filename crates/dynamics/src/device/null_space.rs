//! The general equations of a device (eq. 3.20): `p̈ = N (Nᵀ M N)⁻¹ Nᵀ f` in null-space
//! coordinates (or the projection formulation), for any wings, shoulder and drivetrain; the
//! lean right-hand sides (`drivetrain_coordinates.rs`, `stroke_plane/`) are tested against it.

use nalgebra::Vector3;
use paritysim_aero::Branch;
use paritysim_constraints::{Mat6, Vec6};
use paritysim_error::{Error, Result};

use super::equations::Equations;
use super::{Device, Evaluation, Formulation, empty_terms};
use crate::integrate::State;

/// The general form: eq. 3.20 through the null space or the projection, any wing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct General;

impl Equations for General {
    #[inline]
    fn rhs(
        &self,
        device: &Device,
        t: f64,
        y: &State,
        branches: Option<[Branch; 2]>,
        dydt: &mut State,
    ) -> Result<()> {
        device.rhs_null_space_on(t, y, branches, dydt)
    }
}

impl Device {
    /// Full evaluation at `(t, p, ṗ)`, including the constrained accelerations.
    pub fn evaluate(&self, t: f64, p: &Vec6, p_dot: &Vec6) -> Result<Evaluation> {
        self.evaluate_on(t, p, p_dot, None)
    }

    /// [`Self::evaluate`] with the blade elements on `branches` when given (event location).
    pub(super) fn evaluate_on(
        &self,
        t: f64,
        p: &Vec6,
        p_dot: &Vec6,
        branches: Option<[Branch; 2]>,
    ) -> Result<Evaluation> {
        let mut wings = [empty_terms(); 2];
        let mut mass = Mat6::identity();
        let mut force = Vec6::zeros();
        for (w, wing) in self.spec.wings.iter().enumerate() {
            let k = 3 * w;
            let pw = Vector3::new(p[k], p[k + 1], p[k + 2]);
            let vw = Vector3::new(p_dot[k], p_dot[k + 1], p_dot[k + 2]);
            let branch = branches.map(|b| b[w]);
            let terms = if self.stroke_plane[w] {
                wing.stroke_plane_terms_on(&pw, &vw, branch)
            } else if let Some(terms) = self.free_deviation[w]
                .then(|| wing.free_deviation_terms_on(&pw, &vw, branch))
                .flatten()
            {
                terms
            } else {
                wing.terms_on(&pw, &vw, branch)?
            };
            mass.fixed_view_mut::<3, 3>(k, k).copy_from(&terms.mass);
            let mut f = terms.aero - terms.coriolis - terms.spring;
            let hinge_damping = wing.hinge_damping();
            if hinge_damping != 0.0 {
                f.z -= hinge_damping * vw.z;
            }
            force.fixed_view_mut::<3, 1>(k, 0).copy_from(&f);
            wings[w] = terms;
        }
        let drive = self.drive(t, p, p_dot)?;
        force[0] += drive.stroke_torque.x;
        if self.n_wings() == 2 {
            force[3] += drive.stroke_torque.y;
        }
        // The actuator's effective mass couples the strokes (the only entries off the wings'
        // blocks: `solve_reduced` reads (0, 3)).
        if let Some((inertia, bias)) = self.actuator_inertia(&drive)? {
            let rows = if self.n_wings() == 2 { [0, 3] } else { [0, 0] };
            let n = if self.n_wings() == 2 { 2 } else { 1 };
            for i in 0..n {
                force[rows[i]] += bias[i];
                for j in 0..n {
                    mass[(rows[i], rows[j])] += inertia[(i, j)];
                }
            }
        }
        // The null-space solve also serves the drivetrain-coordinate devices here (recording).
        let p_ddot = match self.formulation {
            Formulation::NullSpace | Formulation::Auto | Formulation::DrivetrainCoordinates => {
                let solved = match self.n_dof {
                    1 => self.solve_reduced::<1>(&mass, &force),
                    2 => self.solve_reduced::<2>(&mass, &force),
                    3 => self.solve_reduced::<3>(&mass, &force),
                    4 => self.solve_reduced::<4>(&mass, &force),
                    5 => self.solve_reduced::<5>(&mass, &force),
                    _ => self.solve_reduced::<6>(&mass, &force),
                };
                solved.ok_or_else(|| {
                    Error::Singular(format!(
                        "reduced mass matrix is not positive definite at p = {:?}",
                        p.as_slice()
                    ))
                })?
            }
            Formulation::Projection => {
                let m_inv = mass.try_inverse().ok_or_else(|| {
                    Error::Singular(format!("mass matrix is singular at p = {:?}", p.as_slice()))
                })?;
                self.spec.constraints.project(&m_inv, &force)?
            }
        };
        Ok(Evaluation {
            p: *p,
            p_dot: *p_dot,
            p_ddot,
            wings,
            drive,
        })
    }

    /// `p̈ = N (Nᵀ M N)⁻¹ Nᵀ f` (eq. 3.20 in null-space coordinates) on `n = N` integrated
    /// coordinates, using that `M` is block diagonal (one 3 × 3 block per wing): the reduced
    /// matrices are `Σ_w N_wᵀ M_w N_w` and `Σ_w N_wᵀ f_w` of fixed size `N` (unrolled, no dense
    /// 6 × 6 products, an `N × N` Cholesky). `None` when `Nᵀ M N` is not positive definite.
    #[inline]
    fn solve_reduced<const N: usize>(&self, mass: &Mat6, force: &Vec6) -> Option<Vec6> {
        let mut reduced_mass = nalgebra::SMatrix::<f64, N, N>::zeros();
        let mut reduced_force = nalgebra::SVector::<f64, N>::zeros();
        for w in 0..self.n_wings() {
            let k = 3 * w;
            let basis_w: nalgebra::SMatrix<f64, 3, N> =
                self.basis.fixed_view::<3, N>(k, 0).into_owned();
            let mass_w: nalgebra::Matrix3<f64> = mass.fixed_view::<3, 3>(k, k).into_owned();
            reduced_mass += basis_w.transpose() * (mass_w * basis_w);
            reduced_force += basis_w.transpose() * force.fixed_rows::<3>(k);
        }
        // The strokes' coupling by the actuator's mass (zero without one).
        let coupling = if self.n_wings() == 2 {
            mass[(0, 3)]
        } else {
            0.0
        };
        if coupling != 0.0 {
            let left: nalgebra::SMatrix<f64, 1, N> =
                self.basis.fixed_view::<1, N>(0, 0).into_owned();
            let right: nalgebra::SMatrix<f64, 1, N> =
                self.basis.fixed_view::<1, N>(3, 0).into_owned();
            reduced_mass += (left.transpose() * right + right.transpose() * left) * coupling;
        }
        let x_ddot = reduced_mass.cholesky()?.solve(&reduced_force);
        Some(self.basis.fixed_columns::<N>(0) * x_ddot)
    }

    /// [`Self::rhs`] through [`Self::evaluate`] (null space or projection, any wing).
    pub(super) fn rhs_null_space(&self, t: f64, y: &State, dydt: &mut State) -> Result<()> {
        self.rhs_null_space_on(t, y, None, dydt)
    }

    /// [`Self::rhs_null_space`] with the blade elements on `branches` when given.
    pub(super) fn rhs_null_space_on(
        &self,
        t: f64,
        y: &State,
        branches: Option<[Branch; 2]>,
        dydt: &mut State,
    ) -> Result<()> {
        let (p, p_dot) = self.coordinates(y)?;
        let e = self.evaluate_on(t, &p, &p_dot, branches)?;
        let x_ddot = self.basis.transpose() * e.p_ddot;
        for i in 0..6 {
            dydt.coords[i] = if i < self.n_dof { y.rates[i] } else { 0.0 };
            dydt.rates[i] = if i < self.n_dof { x_ddot[i] } else { 0.0 };
        }
        dydt.work_actuator = self.actuator_power(t, e.drive.actuator_force, &e.drive.q_dot);
        let mut aero_power = 0.0;
        for (w, terms) in e.wings.iter().take(self.n_wings()).enumerate() {
            aero_power += terms.aero.dot(&Vector3::new(
                p_dot[3 * w],
                p_dot[3 * w + 1],
                p_dot[3 * w + 2],
            ));
        }
        dydt.work_aero = aero_power;
        Ok(())
    }
}
