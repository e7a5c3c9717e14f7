//! [`Device::rhs_stroke_plane`] for four stroke-plane devices at once, one per SIMD lane
//! (`f64x4`): the right-hand side the ensembles of the sweep engine need for the §3.4 device
//! (issue 12 item 6; docs/findings.md §24).
//!
//! Every lane performs the scalar [`Device::stroke_plane_step`]'s floating-point operations in
//! its order (the hinge's and the coefficient fits' `sin`/`cos` are the shared polynomials of
//! `paritysim_simd`, which the scalar path calls too), so each lane's derivative is bit-identical
//! to the scalar one (tested in `tests.rs`). A lane the closed form does not cover (`cos ψ <= 0`
//! or a state off its held branch, an implausible drivetrain coordinate, `ω_x = ω_y = 0`, a
//! reduced mass matrix that is not positive definite) is evaluated on its own by the scalar
//! right-hand side, which also names the error of a lane that fails.

use paritysim_aero::{BladeElementModel, Branch, CoefficientSet, HeldBranch};
use paritysim_simd::{f64x4, sin_cos};

use super::{Device, N, StrokePlane};
use crate::WingAero;
use crate::device::switched_lanes::{LaneEval, SwitchedLanes, evaluate_scalar_lanes};

type V = f64x4;

/// Lanes evaluated together.
pub(crate) const LANES: usize = 4;

/// Compact state entries: `x` then `ẋ`.
pub(crate) const M: usize = 2 * N;

/// Every lane's bit.
const ALL: u32 = (1 << LANES) - 1;

/// The per-lane constants of four stroke-plane devices, gathered into vectors.
pub(crate) struct StrokePlaneLanes<'a> {
    devices: [&'a Device; LANES],
    /// Rows `φ`, `ψ` of the null basis per wing, entry `i`.
    rows: [[[V; N]; 2]; 2],
    offset: [[V; 2]; 2],
    inverse: [[V; 2]; 2],
    inverse_transpose: [[V; 2]; 2],
    /// The actuator and balance springs `K1`, `K2`.
    k1: V,
    k2: V,
    /// Each wing's inertia `I` (mg·mm²), entry `(r, c)`.
    inertia: [[[V; 3]; 3]; 2],
    /// Each wing's blade-element model, when all lanes share it (else every lane is scalar).
    aero: [Option<&'a BladeElementModel<CoefficientSet>>; 2],
    /// Each wing's stroke (joint 1) and hinge (joint 6) springs: stiffness, cubic, rest.
    springs: [[[V; 3]; 2]; 2],
    /// Each wing's tunable hinge `k(θ = 0)` and the lanes that have one (a mask).
    hinge: [(V, V); 2],
}

/// `a · x` of the scalar `dot`, lane by lane.
#[inline(always)]
fn dot(a: &[V; N], b: &[V]) -> V {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

/// `I v` as nalgebra's `Matrix3 * Vector3` accumulates it (column by column).
#[inline(always)]
fn mat_vec(m: &[[V; 3]; 3], v: [V; 3]) -> [V; 3] {
    std::array::from_fn(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
}

#[inline(always)]
fn dot3(a: [V; 3], b: [V; 3]) -> V {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn cross(a: [V; 3], b: [V; 3]) -> [V; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

impl<'a> StrokePlaneLanes<'a> {
    /// Whether `device` can take a lane: the closed-form stroke-plane model with a blade
    /// element on both wings and a single drive.
    pub(crate) fn supports(device: &Device) -> bool {
        device.stroke_plane_rhs.is_some()
            && !device.is_dual()
            && device
                .spec
                .wings
                .iter()
                .all(|w| matches!(w.aero(), WingAero::BladeElement(_)))
    }

    /// The lanes of `devices`, or `None` unless every one has the closed-form stroke-plane
    /// model with a blade element on both wings and a single drive (not a dual drivetrain).
    pub(crate) fn new(devices: [&'a Device; LANES]) -> Option<Self> {
        let mut leans: [Option<&StrokePlane>; LANES] = [None; LANES];
        for (l, device) in devices.iter().enumerate() {
            if !Self::supports(device) {
                return None;
            }
            leans[l] = device.stroke_plane_rhs.as_ref();
        }
        let lean = leans.map(|l| l.expect("every lane checked above"));
        let gather = |f: &dyn Fn(usize) -> f64| V::new(std::array::from_fn(f));
        let rows = std::array::from_fn(|w| {
            std::array::from_fn(|r| std::array::from_fn(|i| gather(&|l| lean[l].rows[w][r][i])))
        });
        let offset =
            std::array::from_fn(|w| std::array::from_fn(|r| gather(&|l| lean[l].offset[w][r])));
        let inverse =
            std::array::from_fn(|r| std::array::from_fn(|c| gather(&|l| lean[l].inverse[(r, c)])));
        let inverse_transpose = std::array::from_fn(|r| {
            std::array::from_fn(|c| gather(&|l| lean[l].inverse_transpose[(r, c)]))
        });
        let stiffness = |l: usize| {
            devices[l]
                .spec
                .actuator
                .as_ref()
                .map_or(0.0, |a| a.stiffness())
        };
        let balance = |l: usize| {
            devices[l]
                .spec
                .transmission
                .as_ref()
                .map_or(0.0, |tr| tr.balance_stiffness)
        };
        let inertia = std::array::from_fn(|w| {
            std::array::from_fn(|r| {
                std::array::from_fn(|c| gather(&|l| devices[l].spec.wings[w].inertia()[(r, c)]))
            })
        });
        let aero = std::array::from_fn(|w| {
            let model = |l: usize| match devices[l].spec.wings[w].aero() {
                WingAero::BladeElement(m) => Some(m),
                _ => None,
            };
            let first = model(0)?;
            (1..LANES).all(|l| model(l) == Some(first)).then_some(first)
        });
        let springs = std::array::from_fn(|w| {
            [0, 5].map(|joint| {
                let spring = |l: usize| devices[l].spec.wings[w].springs()[joint];
                [
                    gather(&|l| spring(l).stiffness()),
                    gather(&|l| spring(l).cubic()),
                    gather(&|l| spring(l).rest_angle()),
                ]
            })
        });
        let hinge = std::array::from_fn(|w| {
            let hinge = |l: usize| devices[l].spec.wings[w].tunable_hinge();
            let has = gather(&|l| {
                if hinge(l).is_some() {
                    f64::from_bits(!0)
                } else {
                    0.0
                }
            });
            (gather(&|l| hinge(l).map_or(0.0, |h| h.stiffness(0.0))), has)
        });
        Some(Self {
            springs,
            hinge,
            devices,
            rows,
            offset,
            inverse,
            inverse_transpose,
            k1: gather(&stiffness),
            k2: gather(&balance),
            inertia,
            aero,
        })
    }
}

impl SwitchedLanes<M> for StrokePlaneLanes<'_> {
    /// The actuator force is `forces[l][0]` (a single drive).
    fn eval(
        &self,
        t: [f64; LANES],
        forces: [[f64; 2]; LANES],
        y: &[V; M],
        branches: [[Branch; 2]; LANES],
        dydt: &mut [V; M],
    ) -> LaneEval {
        let (x, x_dot) = (&y[..N], &y[N..]);
        let mut scalar = 0u32;
        let k = V::splat;
        let zero = k(0.0);
        let mut stroke = [k(0.0); 2];
        let mut stroke_rate = [k(0.0); 2];
        for w in 0..2 {
            stroke[w] = self.offset[w][0] + dot(&self.rows[w][0], x);
            stroke_rate[w] = dot(&self.rows[w][0], x_dot);
        }
        let mat2 = |m: &[[V; 2]; 2], v: [V; 2]| {
            [
                m[0][0] * v[0] + m[0][1] * v[1],
                m[1][0] * v[0] + m[1][1] * v[1],
            ]
        };
        let q = mat2(&self.inverse, stroke);
        let plausible = q[0].abs().simd_le(k(paritysim_error::plausible::OFFSET_MM))
            & q[1].abs().simd_le(k(paritysim_error::plausible::ANGLE_RAD));
        scalar |= !plausible.to_bitmask() & ALL;
        let drive = V::new(forces.map(|f| f[0]));
        let load = [drive - self.k1 * q[0], -self.k2 * q[1]];
        let drive_torque = mat2(&self.inverse_transpose, load);
        let mut x_ddot = [k(0.0); N];
        for w in 0..2 {
            let [row_phi, row_psi] = &self.rows[w];
            let (phi, phi_dot) = (stroke[w], stroke_rate[w]);
            let psi = self.offset[w][1] + dot(row_psi, x);
            let psi_dot = dot(row_psi, x_dot);
            let (s, c) = sin_cos(psi);
            let inertia = &self.inertia[w];
            let a = [c, -s, zero];
            let i_a = mat_vec(inertia, a);
            let i_z = [inertia[0][2], inertia[1][2], inertia[2][2]];
            let omega = [c * phi_dot, -s * phi_dot, psi_dot];
            let i_omega: [V; 3] = std::array::from_fn(|r| i_a[r] * phi_dot + i_z[r] * psi_dot);
            let pp = phi_dot * psi_dot;
            let jdot_pdot = [-s * pp, -c * pp, zero * pp];
            let inertial = mat_vec(inertia, jdot_pdot);
            let gyro = cross(omega, i_omega);
            let v: [V; 3] = std::array::from_fn(|r| inertial[r] + gyro[r]);
            // The closed form applies on the branch's own side with cos ψ > 0 (as the scalar
            // step decides); elsewhere the lane is scalar.
            let side = |positive: fn(&Branch) -> bool| {
                (0..LANES).fold(0u32, |m, l| m | (u32::from(positive(&branches[l][w])) << l))
            };
            let chordwise = omega[0].simd_ge(zero).to_bitmask();
            let normal = omega[1].simd_ge(zero).to_bitmask();
            let own_side = !(chordwise ^ side(|b| b.chordwise_positive))
                & !(normal ^ side(|b| b.normal_positive));
            scalar |= !(c.simd_gt(zero).to_bitmask() & own_side) & ALL;
            let held = HeldBranch::lanes(branches.map(|b| b[w]));
            let tau = self.aero[w].and_then(|model| {
                model.stroke_plane_torque_lanes(phi_dot, psi, (s, c), psi_dot, &held)
            });
            let Some(tau) = tau else {
                scalar = (1 << LANES) - 1;
                break;
            };
            // `Wing::stroke_plane_springs`: `JointSpring::torque` of joints 1 and 6, the
            // tunable hinge's `k(0) ψ` added where there is one.
            let torque = |[stiffness, cubic, rest]: [V; 3], angle: V| {
                let d = angle - rest;
                stiffness * d + cubic * d * d * d
            };
            let [stroke_spring, hinge_spring] = self.springs[w];
            let spring_phi = torque(stroke_spring, phi);
            let spring_psi = torque(hinge_spring, psi);
            let (k_hinge, has_hinge) = self.hinge[w];
            let spring_psi = has_hinge.select(spring_psi + k_hinge * psi, spring_psi);
            let aero_phi = dot3(a, tau);
            let f_phi = aero_phi - dot3(a, v) - spring_phi + drive_torque[w];
            let f_psi = tau[2] - v[2] - spring_psi;
            let (m_pp, m_ps, m_ss) = (dot3(a, i_a), i_a[2], inertia[2][2]);
            let det = m_pp * m_ss - m_ps * m_ps;
            scalar |= !(m_pp.simd_gt(zero) & det.simd_gt(zero)).to_bitmask() & ALL;
            let inverse = [m_ss / det, -m_ps / det, m_pp / det];
            let (phi_ddot, psi_ddot) = (
                inverse[0] * f_phi + inverse[1] * f_psi,
                inverse[1] * f_phi + inverse[2] * f_psi,
            );
            for i in 0..N {
                x_ddot[i] += row_phi[i] * phi_ddot + row_psi[i] * psi_ddot;
            }
        }
        dydt[..N].copy_from_slice(x_dot);
        dydt[N..].copy_from_slice(&x_ddot);
        evaluate_scalar_lanes(scalar, y, dydt, |l, state, out| {
            let device = self.devices[l];
            device.stroke_plane_rhs.as_ref().is_some_and(|lean| {
                device
                    .rhs_stroke_plane(lean, t[l], state, Some(branches[l]), out)
                    .is_ok()
            })
        })
    }
}
