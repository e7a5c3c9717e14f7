//! The drivetrain-coordinate right-hand side of [`Formulation::DrivetrainCoordinates`] for the
//! linear differential map (eq. 2.15) in SIMD lanes, one device per lane.
//!
//! With the constant Jacobian `J` of eq. 2.15 the mass matrix `M_q = Σ_k I_k J_kᵀ J_k` is
//! constant and the velocity products vanish: per lane only the stroke springs, the stroke
//! drag (eq. 2.16) and the actuator force `F(t)` remain. Every operation is the one of
//! `Device::drivetrain_step` in the same order, so a lane's derivative is bit-identical to
//! the scalar one; the force is the scalar [`Actuator::force`] of each lane's time (any
//! waveform).

use wide::f64x4;

use crate::actuator::Actuator;
use crate::device::{Device, Formulation};
use std::rc::Rc;

use crate::integrate::DIRECTIONAL_STEP;
use crate::integrate::lanes::{LANES, LaneRhs, stage_times};
use crate::wing::WingAero;
use paritysim_kinematics::Drivetrain;

type V = f64x4;

/// Per-device constants of the lane right-hand side.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LinearStroke<'a> {
    actuator: &'a Actuator,
    /// `J` by rows: `(J00, J01, J10, J11)`.
    jacobian: [f64; 4],
    /// `M_q` entries `(m00, m01, m11)` and `det M_q`, summed as the scalar path sums them.
    mass: [f64; 3],
    det: f64,
    /// `−Ω1 C` per wing (0 without aerodynamics).
    drag: [f64; 2],
    /// Wings without aerodynamics (their torque is exactly 0).
    vacuum: [bool; 2],
    /// Stroke springs per wing: `(stiffness, cubic, rest angle)`.
    springs: [[f64; 3]; 2],
    k1: f64,
    k2: f64,
}

impl<'a> LinearStroke<'a> {
    /// The constants of `device`, or `None` unless it integrates drivetrain coordinates of a
    /// two-DOF linear differential with an actuator and stroke drag (or no aerodynamics) on
    /// both wings: the devices whose scalar right-hand side this model reproduces exactly.
    pub(crate) fn of(device: &'a Device) -> Option<Self> {
        if device.formulation() != Formulation::DrivetrainCoordinates || device.n_dof() != 2 {
            return None;
        }
        let spec = device.spec();
        let transmission = spec.transmission.as_ref()?;
        let Drivetrain::LinearDifferential(d) = transmission.kinematics() else {
            return None;
        };
        let actuator = spec.actuator.as_ref()?;
        let t = d.transmission_ratio();
        let (hl, hr) = d.arms();
        // As `LinearDifferential::evaluate` builds it.
        let jacobian = [-t, t * hl, -t, -t * hr];
        let (mut m00, mut m01, mut m11) = (0.0, 0.0, 0.0);
        let mut drag = [0.0; 2];
        let mut vacuum = [false; 2];
        let mut springs = [[0.0; 3]; 2];
        for k in 0..2 {
            let wing = spec.wings.get(k)?;
            let (a, b) = (jacobian[2 * k], jacobian[2 * k + 1]);
            let inertia = wing.inertia()[(0, 0)];
            m00 += inertia * a * a;
            m01 += inertia * a * b;
            m11 += inertia * b * b;
            drag[k] = match wing.aero() {
                WingAero::None => {
                    vacuum[k] = true;
                    0.0
                }
                WingAero::StrokeDrag {
                    omega1,
                    coefficient,
                } => -omega1 * coefficient,
                WingAero::BladeElement(_) => return None,
            };
            let s = &wing.springs()[0];
            springs[k] = [s.stiffness(), s.cubic(), s.rest_angle()];
        }
        let det = m00 * m11 - m01 * m01;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        Some(Self {
            actuator,
            jacobian,
            mass: [m00, m01, m11],
            det,
            drag,
            vacuum,
            springs,
            k1: actuator.stiffness(),
            k2: transmission.balance_stiffness(),
        })
    }
}

impl LinearStroke<'_> {
    /// The actuator force at `t` (mN).
    pub(crate) fn force(&self, t: f64) -> f64 {
        self.actuator.force(t)
    }

    /// The actuator.
    pub(crate) fn actuator(&self) -> &Actuator {
        self.actuator
    }

    /// The actuator force at every [`stage_times`] of `grid`: the drive's `sin` once per
    /// grid instead of once per evaluation (the grid is shared by a point's Newton periods
    /// and usually by its chain neighbours).
    pub(crate) fn forcing(&self, grid: &[f64]) -> Rc<[f64]> {
        stage_times(grid)
            .into_iter()
            .map(|t| self.actuator.force(t))
            .collect()
    }

    /// What `StrokeSample::of_stroke_device` computes at up to four states of this device
    /// (one per vector lane, compact `[q1, q2, q̇1, q̇2]`), with its operations: the mask of
    /// states inside the drivetrain's domain, the strokes `(φL, φR)` and the roll torques
    /// (left mirrored).
    pub(crate) fn stroke_samples(&self, y: &[V; 4]) -> (u32, [V; 2], [V; 2]) {
        let [q1, q2, q1_dot, q2_dot] = *y;
        let inside = (q1
            .abs()
            .simd_le(V::splat(paritysim_error::plausible::OFFSET_MM))
            & q2.abs()
                .simd_le(V::splat(paritysim_error::plausible::ANGLE_RAD)))
        .to_bitmask();
        let j = self.jacobian.map(V::splat);
        let stroke = [j[0] * q1 + j[1] * q2, j[2] * q1 + j[3] * q2];
        let rate = [j[0] * q1_dot + j[1] * q2_dot, j[2] * q1_dot + j[3] * q2_dot];
        let torque = |k: usize| {
            if self.vacuum[k] {
                V::splat(0.0)
            } else {
                V::splat(self.drag[k]) * rate[k].abs() * rate[k]
            }
        };
        (inside, stroke, [-torque(0), torque(1)])
    }
}

/// [`LANES`] devices side by side (vectors of their constants).
pub(crate) struct LinearStrokeLanes<'a> {
    actuators: [Option<&'a Actuator>; LANES],
    /// Each lane's [`LinearStroke::forcing`] of its current grid.
    forcing: [Option<Rc<[f64]>>; LANES],
    j: [V; 4],
    m00: V,
    m01: V,
    m11: V,
    det: V,
    drag: [V; 2],
    stiffness: [V; 2],
    cubic: [V; 2],
    rest: [V; 2],
    k1: V,
    k2: V,
}

fn set(v: &mut V, l: usize, x: f64) {
    let mut a = v.to_array();
    a[l] = x;
    *v = V::new(a);
}

impl<'a> LinearStrokeLanes<'a> {
    /// No device in any lane (idle lanes evaluate a unit-mass system).
    pub(crate) fn new() -> Self {
        let (z, one) = (V::splat(0.0), V::splat(1.0));
        Self {
            actuators: [None; LANES],
            forcing: std::array::from_fn(|_| None),
            j: [one, z, z, one],
            m00: one,
            m01: z,
            m11: one,
            det: one,
            drag: [z; 2],
            stiffness: [z; 2],
            cubic: [z; 2],
            rest: [z; 2],
            k1: z,
            k2: z,
        }
    }

    /// The forcing table lane `l` reads (`None`: the actuator is evaluated).
    pub(crate) fn load_forcing(&mut self, l: usize, forcing: Option<Rc<[f64]>>) {
        self.forcing[l] = forcing;
    }

    /// Puts `model` into lane `l`.
    pub(crate) fn load(&mut self, l: usize, model: &LinearStroke<'a>) {
        self.actuators[l] = Some(model.actuator);
        for i in 0..4 {
            set(&mut self.j[i], l, model.jacobian[i]);
        }
        set(&mut self.m00, l, model.mass[0]);
        set(&mut self.m01, l, model.mass[1]);
        set(&mut self.m11, l, model.mass[2]);
        set(&mut self.det, l, model.det);
        for k in 0..2 {
            set(&mut self.drag[k], l, model.drag[k]);
            set(&mut self.stiffness[k], l, model.springs[k][0]);
            set(&mut self.cubic[k], l, model.springs[k][1]);
            set(&mut self.rest[k], l, model.springs[k][2]);
        }
        set(&mut self.k1, l, model.k1);
        set(&mut self.k2, l, model.k2);
    }
}

impl LinearStrokeLanes<'_> {
    /// The actuator force of every lane at its time (from its forcing table at `stage`).
    #[inline(always)]
    fn force(&self, t: [f64; LANES], stage: [usize; LANES]) -> V {
        V::new(std::array::from_fn(|l| {
            match (&self.forcing[l], self.actuators[l]) {
                (Some(table), _) if stage[l] < table.len() => table[stage[l]],
                (_, Some(a)) => a.force(t[l]),
                _ => 0.0,
            }
        }))
    }

    /// The right-hand side at the actuator force `force` (see [`LaneRhs::eval`]).
    #[inline(always)]
    fn eval_with(&self, force: V, y: &[V; 4], dydt: &mut [V; 4]) -> u32 {
        let [q1, q2, q1_dot, q2_dot] = *y;
        // `Drivetrain::evaluate`'s plausibility check (the scalar path errs outside it).
        let inside = q1
            .abs()
            .simd_le(V::splat(paritysim_error::plausible::OFFSET_MM))
            & q2.abs()
                .simd_le(V::splat(paritysim_error::plausible::ANGLE_RAD));
        let failed = !inside.to_bitmask() & ((1 << LANES) - 1);
        let [j00, j01, j10, j11] = self.j;
        let stroke = [j00 * q1 + j01 * q2, j10 * q1 + j11 * q2];
        let phi_dot = [j00 * q1_dot + j01 * q2_dot, j10 * q1_dot + j11 * q2_dot];
        let mut g0 = force - self.k1 * q1;
        let mut g1 = -self.k2 * q2;
        let rows = [(j00, j01), (j10, j11)];
        for k in 0..2 {
            let (a, b) = rows[k];
            let tau_aero = self.drag[k] * phi_dot[k].abs() * phi_dot[k];
            let d = stroke[k] - self.rest[k];
            let spring = self.stiffness[k] * d + self.cubic[k] * d * d * d;
            let tau = tau_aero - spring;
            g0 += a * tau;
            g1 += b * tau;
        }
        dydt[0] = q1_dot;
        dydt[1] = q2_dot;
        dydt[2] = (self.m11 * g0 - self.m01 * g1) / self.det;
        dydt[3] = (self.m00 * g1 - self.m01 * g0) / self.det;
        failed
    }
}

impl LaneRhs<4> for LinearStrokeLanes<'_> {
    // Inlined into the stages of the lane stepper (it is generic over the right-hand side).
    #[inline(always)]
    fn eval(&self, t: [f64; LANES], stage: [usize; LANES], y: &[V; 4], dydt: &mut [V; 4]) -> u32 {
        self.eval_with(self.force(t, stage), y, dydt)
    }
}

/// The variational equations of [`LinearStrokeLanes`] on `[y (4), Φ (4 × 4, by columns)]`,
/// formed as integrate/variational.rs forms them (`J Φ` column by column by central
/// differences along each column, the same steps and operations), one device per lane.
pub(crate) struct VariationalLanes<'m, 'a>(pub(crate) &'m LinearStrokeLanes<'a>);

impl LaneRhs<20> for VariationalLanes<'_, '_> {
    fn eval(&self, t: [f64; LANES], stage: [usize; LANES], c: &[V; 20], dc: &mut [V; 20]) -> u32 {
        let rhs = self.0;
        let force = rhs.force(t, stage);
        let y: [V; 4] = std::array::from_fn(|i| c[i]);
        let mut f = [V::splat(0.0); 4];
        let mut failed = rhs.eval_with(force, &y, &mut f);
        dc[..4].copy_from_slice(&f);
        let mut largest = V::splat(0.0);
        for v in &y {
            largest = largest.max(v.abs());
        }
        let scale = V::splat(1.0) + largest;
        for j in 0..4 {
            let col = 4 + 4 * j;
            let v: [V; 4] = std::array::from_fn(|i| c[col + i]);
            let mut size = V::splat(0.0);
            for x in &v {
                size = size.max(x.abs());
            }
            // A zero column stays zero (and its differences are never evaluated).
            let zero = size.simd_eq(V::splat(0.0));
            let delta = V::splat(DIRECTIONAL_STEP) * scale / size;
            let yp: [V; 4] = std::array::from_fn(|i| y[i] + delta * v[i]);
            let ym: [V; 4] = std::array::from_fn(|i| y[i] - delta * v[i]);
            let (mut fp, mut fm) = ([V::splat(0.0); 4], [V::splat(0.0); 4]);
            let mut column_failed = rhs.eval_with(force, &yp, &mut fp);
            column_failed |= rhs.eval_with(force, &ym, &mut fm);
            failed |= column_failed & !zero.to_bitmask();
            for i in 0..4 {
                let d = (fp[i] - fm[i]) / (V::splat(2.0) * delta);
                dc[col + i] = zero.bitselect(V::splat(0.0), d);
            }
        }
        failed
    }
}
