//! The free-deviation right-hand side on a held branch, written once over
//! [`paritysim_simd::Real`]: of one state (`f64`, the scalar path's event-located
//! integrations and variational equations) or of four devices' states in SIMD lanes
//! (`f64x4`, the sweep ensembles), so that every lane computes the scalar bits (issue 12
//! item 6; docs/findings.md §24).
//!
//! The equations are those of [`Device::free_deviation_step`] (eq. 3.20 in null-space
//! coordinates with each wing's closed form, `wing/free_deviation.rs`), with the small linear
//! algebra written out (3 × 3 products, the reduced `N × N` Cholesky factorisation, in
//! nalgebra's operation order) and the shared polynomial `sin`, `cos` and `atan2`.

// Index loops on purpose: they spell out the operation order (the lanes' contract).
#![allow(clippy::needless_range_loop)]

use paritysim_aero::{BladeElementModel, CoefficientSet, HeldBranch};
use paritysim_simd::{Real, sin_cos};

use super::super::Device;
use super::super::drive::DriveSprings;
use crate::WingAero;

type V3<R> = [R; 3];
type M3<R> = [[R; 3]; 3];

/// A wing's constants: inertia, the springs on joints 1, 4, 6 (stiffness, cubic, rest
/// angle), the tunable hinge `(k0, k1, k2)` and where there is one, the blade element.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WingConstants<R: Real> {
    inertia: M3<R>,
    springs: [[R; 3]; 3],
    hinge: [R; 3],
    has_hinge: R::Mask,
}

/// The constants of [`step`] for `N` integrated coordinates, per device (one per lane).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Constants<R: Real, const N: usize> {
    basis: [[R; N]; 6],
    offset: [R; 6],
    inverse: [[R; 2]; 2],
    inverse_transpose: [[R; 2]; 2],
    /// The drive's springs ([`DriveSprings`]).
    drive: DriveSprings<R>,
    wings: [WingConstants<R>; 2],
}

/// The blade elements of a device's two wings (`None` unless both wings have one).
pub(crate) fn blade_models(device: &Device) -> Option<[BladeElementModel<CoefficientSet>; 2]> {
    let model = |w: usize| match device.spec.wings.get(w)?.aero() {
        WingAero::BladeElement(m) => Some(*m),
        _ => None,
    };
    Some([model(0)?, model(1)?])
}

impl<const N: usize> Constants<f64, N> {
    /// The constants of a free-deviation device on `N` coordinates with blade elements on both
    /// wings, or `None`.
    pub(crate) fn of(device: &Device, lean: &super::FreeDeviation) -> Option<Self> {
        blade_models(device)?;
        if device.n_dof != N {
            return None;
        }
        let wing = |w: usize| {
            let wing = &device.spec.wings[w];
            let inertia = wing.inertia();
            let springs = [0, 3, 5].map(|j| {
                let s = wing.springs()[j];
                [s.stiffness(), s.cubic(), s.rest_angle()]
            });
            let hinge = wing.tunable_hinge();
            WingConstants {
                inertia: std::array::from_fn(|r| std::array::from_fn(|c| inertia[(r, c)])),
                springs,
                hinge: hinge.map_or([0.0; 3], |h| [h.k0, h.k1, h.k2]),
                has_hinge: hinge.is_some(),
            }
        };
        Some(Self {
            basis: std::array::from_fn(|i| std::array::from_fn(|k| device.basis[(i, k)])),
            offset: std::array::from_fn(|i| device.offset[i]),
            inverse: std::array::from_fn(|r| std::array::from_fn(|c| lean.inverse[(r, c)])),
            inverse_transpose: std::array::from_fn(|r| {
                std::array::from_fn(|c| lean.inverse_transpose[(r, c)])
            }),
            drive: device.drive,
            wings: [wing(0), wing(1)],
        })
    }
}

impl<const N: usize> Constants<paritysim_simd::f64x4, N> {
    /// Four devices' constants, one per lane.
    pub(crate) fn lanes(devices: [&Constants<f64, N>; 4]) -> Self {
        use paritysim_simd::f64x4;
        let v = |f: &dyn Fn(&Constants<f64, N>) -> f64| f64x4::new(devices.map(f));
        let mask = |f: &dyn Fn(&Constants<f64, N>) -> bool| {
            f64x4::new(devices.map(|d| if f(d) { f64::from_bits(!0) } else { 0.0 }))
        };
        let wing = |w: usize| WingConstants {
            inertia: std::array::from_fn(|r| {
                std::array::from_fn(|c| v(&|d| d.wings[w].inertia[r][c]))
            }),
            springs: std::array::from_fn(|j| {
                std::array::from_fn(|e| v(&|d| d.wings[w].springs[j][e]))
            }),
            hinge: std::array::from_fn(|e| v(&|d| d.wings[w].hinge[e])),
            has_hinge: mask(&|d| d.wings[w].has_hinge),
        };
        Self {
            basis: std::array::from_fn(|i| std::array::from_fn(|k| v(&|d| d.basis[i][k]))),
            offset: std::array::from_fn(|i| v(&|d| d.offset[i])),
            inverse: std::array::from_fn(|r| std::array::from_fn(|c| v(&|d| d.inverse[r][c]))),
            inverse_transpose: std::array::from_fn(|r| {
                std::array::from_fn(|c| v(&|d| d.inverse_transpose[r][c]))
            }),
            drive: DriveSprings {
                k1: v(&|d| d.drive.k1),
                k2: v(&|d| d.drive.k2),
                preload: v(&|d| d.drive.preload),
                k1_cubic: v(&|d| d.drive.k1_cubic),
                k2_cubic: v(&|d| d.drive.k2_cubic),
                b1: v(&|d| d.drive.b1),
                b2: v(&|d| d.drive.b2),
                mass: v(&|d| d.drive.mass),
                dual: mask(&|d| d.drive.dual),
                lossless: devices.iter().all(|d| d.drive.lossless),
            },
            wings: [wing(0), wing(1)],
        }
    }
}

/// What [`step`] computes.
pub(crate) struct Step<R: Real, const N: usize> {
    /// `ẍ`.
    pub(crate) x_ddot: [R; N],
    /// `q̇` of the drivetrain and the aerodynamic power (the work integrals' integrands).
    pub(crate) q_dot: [R; 2],
    pub(crate) aero_power: R,
    /// Lanes the closed form does not cover (an implausible drivetrain coordinate, a pose
    /// near the singular ones): the general path takes them.
    pub(crate) general: R::Mask,
    /// Lanes whose reduced mass matrix is not positive definite.
    pub(crate) singular: R::Mask,
}

#[inline(always)]
fn mat_vec<R: Real>(m: &M3<R>, v: &V3<R>) -> V3<R> {
    std::array::from_fn(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
}

/// `mᵀ v`.
#[inline(always)]
fn mat_t_vec<R: Real>(m: &M3<R>, v: &V3<R>) -> V3<R> {
    std::array::from_fn(|c| m[0][c] * v[0] + m[1][c] * v[1] + m[2][c] * v[2])
}

#[inline(always)]
fn mat_mat<R: Real>(a: &M3<R>, b: &M3<R>) -> M3<R> {
    std::array::from_fn(|r| {
        std::array::from_fn(|c| a[r][0] * b[0][c] + a[r][1] * b[1][c] + a[r][2] * b[2][c])
    })
}

/// `aᵀ b`.
#[inline(always)]
fn mat_t_mat<R: Real>(a: &M3<R>, b: &M3<R>) -> M3<R> {
    std::array::from_fn(|r| {
        std::array::from_fn(|c| a[0][r] * b[0][c] + a[1][r] * b[1][c] + a[2][r] * b[2][c])
    })
}

#[inline(always)]
fn cross<R: Real>(a: &V3<R>, b: &V3<R>) -> V3<R> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline(always)]
fn dot<R: Real>(a: &V3<R>, b: &V3<R>) -> R {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Whether `x` is finite, lane by lane.
#[inline(always)]
fn finite<R: Real>(x: R) -> R::Mask {
    x.abs().le(R::splat(f64::MAX))
}

/// One wing's closed-form terms (`Wing::free_deviation_kinematics` and
/// `free_deviation_dynamics`, eqs. 2.12, A.6, A.9, A.13): its generalised force
/// `f = J6ᵀ τ_aero − c − ∂V/∂p` (before the drive torque), `M = J6ᵀ I J6`, `J6ᵀ τ_aero`, and
/// where the closed form applies.
#[inline(always)]
fn wing_terms<R: Real>(
    c: &WingConstants<R>,
    aero: &BladeElementModel<CoefficientSet>,
    p: V3<R>,
    p_dot: V3<R>,
    branch: &HeldBranch<R>,
) -> (V3<R>, M3<R>, V3<R>, R::Mask) {
    let k = R::splat;
    let (zero, one) = (k(0.0), k(1.0));
    let [phi, theta, psi] = p;
    // Pose::of.
    let (sp, cp) = sin_cos(phi);
    let (st, ct) = sin_cos(theta);
    let d = ct * ct + cp * cp * st * st;
    let valid = finite(phi)
        & finite(theta)
        & finite(psi)
        & !d.lt(k(1e-12))
        & !(cp * cp + ct * ct * sp * sp).lt(k(1e-12));
    let root = d.sqrt();
    let (ss, cs) = sin_cos(psi);
    let (s5, c5) = (cp * st / root, ct / root);
    let g5_phi = -sp * st * ct / d;
    let g5_theta = cp / d;
    // free_deviation_kinematics.
    let d_sq = d * d;
    let two = k(2.0);
    let h_pp = -st * ct * cp * (d + two * st * st * sp * sp) / d_sq;
    let h_pt = -sp * (d - two * cp * cp * st * st) / d_sq;
    let h_tt = two * cp * st * ct * sp * sp / d_sq;
    let r3 = [[one, zero, zero], [zero, cp, -sp], [zero, sp, cp]];
    let r4 = mat_mat(&r3, &[[c5, zero, s5], [zero, one, zero], [-s5, zero, c5]]);
    let r61 = mat_mat(&r4, &[[cs, -ss, zero], [ss, cs, zero], [zero, zero, one]]);
    let y4 = [ss, cs, zero];
    let x3 = r61[0];
    // J6 = [ŷ4 ∂γ5/∂φ + x̂3, ŷ4 ∂γ5/∂θ, ẑ] by columns; row r below.
    let j6: M3<R> = std::array::from_fn(|r| {
        [
            y4[r] * g5_phi + x3[r],
            y4[r] * g5_theta,
            if r == 2 { one } else { zero },
        ]
    });
    let omega = mat_vec(&j6, &p_dot);
    let g5_dot = g5_phi * p_dot[0] + g5_theta * p_dot[1];
    let y3 = [zero, cp, sp];
    let z4 = [r4[0][2], r4[1][2], r4[2][2]];
    let x_axis = [one, zero, zero];
    let omega4: V3<R> = std::array::from_fn(|i| x_axis[i] * p_dot[0] + y3[i] * g5_dot);
    let (rx, ry) = (p_dot[0], p_dot[1]);
    let quadratic = rx * (h_pp * rx + h_pt * ry) + ry * (h_pt * rx + h_tt * ry);
    let x_cross_y3 = cross(&x_axis, &y3);
    let omega4_cross_z4 = cross(&omega4, &z4);
    let accel: V3<R> = std::array::from_fn(|i| {
        y3[i] * quadratic + x_cross_y3[i] * (g5_dot * p_dot[0]) + omega4_cross_z4[i] * p_dot[2]
    });
    let jdot_pdot = mat_t_vec(&r61, &accel);
    // free_deviation_dynamics.
    let i_omega = mat_vec(&c.inertia, &omega);
    let mass = mat_mat(&mat_t_mat(&j6, &c.inertia), &j6);
    let i_jdot = mat_vec(&c.inertia, &jdot_pdot);
    let gyro = cross(&omega, &i_omega);
    let coriolis = mat_t_vec(&j6, &std::array::from_fn(|i| i_jdot[i] + gyro[i]));
    let torque = |[stiffness, cubic, rest]: [R; 3], angle: R| {
        let d = angle - rest;
        stiffness * d + cubic * d * d * d
    };
    let mut spring = [
        torque(c.springs[0], phi),
        torque(c.springs[1], theta),
        torque(c.springs[2], psi),
    ];
    // The tunable hinge (`Wing::add_tunable_hinge`): k(θ) ψ on ψ, ½ k'(θ) ψ² on θ.
    let [k0, k1, k2] = c.hinge;
    let stiffness = k0 + (k1 + k2 * theta) * theta;
    spring[2] = R::select(c.has_hinge, spring[2] + stiffness * psi, spring[2]);
    spring[1] = R::select(
        c.has_hinge,
        spring[1] + k(0.5) * (k1 + two * k2 * theta) * psi * psi,
        spring[1],
    );
    let aero6 = aero.torque_on_branch(omega, branch);
    let generalised_aero = mat_t_vec(&j6, &aero6);
    let force = std::array::from_fn(|i| generalised_aero[i] - coriolis[i] - spring[i]);
    (force, mass, generalised_aero, valid)
}

/// The derivative `ẍ` of the free-deviation device at `(x, ẋ)` with the drive forces
/// `forces` (the actuator's, or the dual drivetrain's left and right) and the blade elements
/// on `branches` (see the module).
#[inline(always)]
pub(crate) fn step<R: Real, const N: usize>(
    c: &Constants<R, N>,
    aero: &[BladeElementModel<CoefficientSet>; 2],
    forces: [R; 2],
    (x, x_dot): (&[R; N], &[R; N]),
    branches: &[HeldBranch<R>; 2],
) -> Step<R, N> {
    let k = R::splat;
    let zero = k(0.0);
    // p = offset + N x, ṗ = N ẋ.
    let p: [R; 6] = std::array::from_fn(|i| {
        let mut v = c.offset[i];
        for j in 0..N {
            v = v + c.basis[i][j] * x[j];
        }
        v
    });
    let p_dot: [R; 6] = std::array::from_fn(|i| {
        let mut r = zero;
        for j in 0..N {
            r = r + c.basis[i][j] * x_dot[j];
        }
        r
    });
    let mat2 = |m: &[[R; 2]; 2], v: [R; 2]| {
        [
            m[0][0] * v[0] + m[0][1] * v[1],
            m[1][0] * v[0] + m[1][1] * v[1],
        ]
    };
    let q = mat2(&c.inverse, [p[0], p[3]]);
    let plausible = q[0].abs().le(k(paritysim_error::plausible::OFFSET_MM))
        & q[1].abs().le(k(paritysim_error::plausible::ANGLE_RAD));
    let q_dot = mat2(&c.inverse, [p_dot[0], p_dot[3]]);
    let load = c.drive.load(forces, q, q_dot);
    let drive_torque = mat2(&c.inverse_transpose, load);
    let mut reduced_mass = [[zero; N]; N];
    let mut reduced_force = [zero; N];
    let mut aero_power = zero;
    let mut valid = plausible;
    for w in 0..2 {
        let kw = 3 * w;
        let pw = [p[kw], p[kw + 1], p[kw + 2]];
        let vw = [p_dot[kw], p_dot[kw + 1], p_dot[kw + 2]];
        let (mut f, mass, generalised_aero, ok) =
            wing_terms(&c.wings[w], &aero[w], pw, vw, &branches[w]);
        valid = valid & ok;
        f[0] = f[0] + drive_torque[w];
        aero_power = aero_power + dot(&generalised_aero, &vw);
        // Bᵀ (M B) and Bᵀ f with B the wing's three rows of the basis.
        let b: [[R; N]; 3] = [c.basis[kw], c.basis[kw + 1], c.basis[kw + 2]];
        let mb: [[R; N]; 3] = std::array::from_fn(|r| {
            std::array::from_fn(|j| {
                mass[r][0] * b[0][j] + mass[r][1] * b[1][j] + mass[r][2] * b[2][j]
            })
        });
        for i in 0..N {
            for j in 0..N {
                reduced_mass[i][j] = reduced_mass[i][j]
                    + (b[0][i] * mb[0][j] + b[1][i] * mb[1][j] + b[2][i] * mb[2][j]);
            }
            reduced_force[i] =
                reduced_force[i] + (b[0][i] * f[0] + b[1][i] * f[1] + b[2][i] * f[2]);
        }
    }
    // Cholesky (nalgebra's column order), then the two triangular solves.
    let mut l = reduced_mass;
    let mut positive = !zero.lt(zero);
    for j in 0..N {
        for kk in 0..j {
            let factor = -l[j][kk];
            for i in j..N {
                l[i][j] = factor * l[i][kk] + l[i][j];
            }
        }
        let diag = l[j][j];
        positive = positive & zero.lt(diag);
        let denom = diag.sqrt();
        l[j][j] = denom;
        for i in j + 1..N {
            l[i][j] = l[i][j] / denom;
        }
    }
    let mut b = reduced_force;
    for i in 0..N {
        let coeff = b[i] / l[i][i];
        b[i] = coeff;
        for r in i + 1..N {
            b[r] = -coeff * l[r][i] + b[r];
        }
    }
    for i in (0..N).rev() {
        let mut dot = zero;
        for r in i + 1..N {
            dot = dot + l[r][i] * b[r];
        }
        b[i] = (b[i] - dot) / l[i][i];
    }
    Step {
        x_ddot: b,
        q_dot,
        aero_power,
        general: !valid,
        singular: !positive,
    }
}
