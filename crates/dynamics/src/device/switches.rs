//! The blade elements' switching functions of a device (event location, `integrate/events.rs`):
//! per wing `(ω_x, ω_y, ω_z)` of `ω⁶ = J6 ṗ` where the quasi-steady model switches (the stroke
//! reversal, α = π/2 where the coefficient fit jumps, the rotational damping's `ω_z = 0`;
//! [`paritysim_aero::BladeElementModel::switching_functions`]), `1` elsewhere.
//!
//! Declared for the stroke-plane devices (§3.4, [`super::stroke_plane`]) and for devices whose
//! wings all have a closed-form `ω`: the stroke-plane wing (θ held) and the free deviation on
//! an α2 = 90°, α3 = 0 shoulder (§2.5 Lift / Dual PARITY, [`crate::Wing::free_deviation_terms`],
//! θ̇ included). Their right-hand side then evaluates the branch the integrator holds
//! ([`Device::rhs_null_space_on`]), also in the variational equations.

use nalgebra::Vector3;
use paritysim_aero::Branch;
use paritysim_error::Result;

use super::Device;
use crate::integrate::{MAX_SWITCHES, Sides, State};

/// The blade elements' branches named by the sides of the switching functions (three per
/// wing).
pub(crate) fn branches(sides: Sides) -> [Branch; 2] {
    std::array::from_fn(|w| Branch {
        chordwise_positive: sides.positive(3 * w),
        normal_positive: sides.positive(3 * w + 1),
        spanwise_positive: sides.positive(3 * w + 2),
    })
}

impl Device {
    /// Number of switching functions: three per wing when a wing has a blade element and the
    /// device is a stroke-plane one or every wing's `ω` has a closed form; else none (the
    /// right-hand side is then integrated as smooth). Drivetrain-coordinate devices have none.
    pub(super) fn blade_switches(&self) -> usize {
        let blade = self
            .spec
            .wings
            .iter()
            .any(|w| w.aero().switching_blade().is_some());
        if !blade || self.form.stroke_only().is_some() {
            return 0;
        }
        let closed_form =
            (0..self.n_wings()).all(|w| self.stroke_plane[w] || self.free_deviation[w]);
        if self.form.stroke_plane().is_some() || closed_form {
            3 * self.n_wings()
        } else {
            0
        }
    }

    /// The switching functions of a (not stroke-plane) device at `y`: each blade element's at
    /// its wing's `ω⁶` ([`crate::Wing::free_deviation_omega`]; the stroke plane's closed form for
    /// a wing with θ held; the general terms where the closed form does not apply).
    ///
    /// # Errors
    /// As the general wing terms (a pose outside the shoulder's domain).
    pub(super) fn blade_switching_functions(
        &self,
        y: &State,
        g: &mut [f64; MAX_SWITCHES],
    ) -> Result<()> {
        let (p, p_dot) = self.coordinates(y)?;
        for (w, wing) in self.spec.wings.iter().enumerate() {
            let Some(model) = wing.aero().switching_blade() else {
                g[3 * w..3 * w + 3].fill(1.0);
                continue;
            };
            let k = 3 * w;
            let pw = Vector3::new(p[k], p[k + 1], p[k + 2]);
            let vw = Vector3::new(p_dot[k], p_dot[k + 1], p_dot[k + 2]);
            let closed = if self.stroke_plane[w] {
                Some(wing.stroke_plane_kinematics(&pw, &vw).omega)
            } else {
                wing.free_deviation_omega(&pw, &vw)
            };
            let omega = match closed {
                Some(omega) => omega,
                None => wing.terms(&pw, &vw)?.omega,
            };
            g[k..k + 3].copy_from_slice(&model.switching_functions(&omega));
        }
        Ok(())
    }
}

#[cfg(test)]
pub(super) mod tests {
    use nalgebra::Matrix3;
    use paritysim_aero::{BladeElementModel, CoefficientSet, Omegas};
    use paritysim_constraints::{Constraints, Vec6};
    use paritysim_kinematics::drivetrain::LinearDifferential;
    use paritysim_kinematics::{Drivetrain, SphericalShoulder};

    use super::*;
    use crate::device::{DeviceSpec, Formulation, Transmission};
    use crate::integrate::{Method, OdeSystem, RungeKutta};
    use crate::{Actuator, DcOffset, JointSpring, TunableHinge, Waveform, Wing, WingAero};

    /// A Table 3.3 wing with the §2.5 free deviation: blade element Ω1..Ω4, deviation spring
    /// 10 mN·mm/rad, tunable hinge `k(θ) = 2.53 + 20 θ²` (as `paritysim.devices`'
    /// `sreetharan2012_2_5_*_parity_1cut`).
    fn wing(inertia: [f64; 4], omegas: [f64; 4]) -> Wing {
        let [ixx, iyy, izz, ixz] = inertia;
        let shoulder = SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0).unwrap();
        let mut springs = [JointSpring::default(); 6];
        springs[3] = JointSpring::linear(10.0, 0.0).unwrap();
        let blade = BladeElementModel::new(
            Omegas::new(omegas[0], omegas[1], omegas[2], omegas[3]).unwrap(),
            CoefficientSet::default(),
        )
        .unwrap();
        let matrix = Matrix3::new(ixx, 0.0, ixz, 0.0, iyy, 0.0, ixz, 0.0, izz);
        Wing::new(shoulder, matrix, springs, WingAero::BladeElement(blade))
            .unwrap()
            .with_tunable_hinge(TunableHinge::new(2.53, 0.0, 20.0).unwrap())
    }

    /// The §2.5 Lift (`lift_parity`) or Dual (`dual_parity`) PARITY on the 1-Cut wings, eq.
    /// 2.15 with ±200 µm → ±35°, K2 = 0, V = 100 + 100 sin(2π 110 Hz t), DC ignored.
    pub(in crate::device) fn device(configuration: &str) -> Device {
        Device::new(DeviceSpec {
            wings: vec![
                wing([49.0, 50.5, 1.56, 4.2], [46.8, 0.587, 17.5, 0.712]),
                wing([40.6, 42.0, 1.43, 3.38], [28.7, 0.419, 10.6, 0.787]),
            ],
            constraints: Constraints::configuration(configuration).unwrap(),
            transmission: Some(
                Transmission::new(
                    Drivetrain::LinearDifferential(
                        LinearDifferential::new(35f64.to_radians() / 0.2, 2.5, 1.0).unwrap(),
                    ),
                    0.0,
                )
                .unwrap(),
            ),
            actuator: Some(
                Actuator::new(
                    crate::actuator::THESIS_FORCE_PER_VOLT,
                    crate::actuator::THESIS_STIFFNESS,
                    Waveform::sine(100.0, 110.0, 100.0, 0.0).unwrap(),
                    DcOffset::Ignore,
                )
                .unwrap(),
            ),
            formulation: Formulation::Auto,
        })
        .unwrap()
    }

    /// States of both signs of every `ω` component (both sides of every switch): `x` and `ẋ`
    /// of the device's coordinates from a grid of `(p, ṗ)` that satisfy `C`.
    pub(in crate::device) fn states(d: &Device) -> Vec<State> {
        let n = d.spec().constraints.null_basis();
        let angles = [-0.6, -0.15, 0.0, 0.3, 0.55];
        let rates = [-2.7, -0.05, 0.0, 0.4, 3.1];
        let mut out = Vec::new();
        for (k, &a) in angles.iter().enumerate() {
            for (l, &r) in rates.iter().enumerate() {
                let mut y = State::default();
                for i in 0..d.n_dof() {
                    let u = (i + 2 * k + 3 * l) % 5;
                    y.coords[i] = angles[u] * if i % 2 == 0 { 1.0 } else { 0.7 } + 0.1 * a;
                    y.rates[i] = rates[(u + i) % 5] * 9.0 + r;
                }
                // Keep the free coordinates' p within the shoulder's domain.
                let p = d.spec().constraints.particular()
                    + n * Vec6::from_iterator(
                        (0..6).map(|i| if i < d.n_dof() { y.coords[i] } else { 0.0 }),
                    );
                if p.iter().all(|v| v.abs() < 1.2) {
                    out.push(y);
                }
            }
        }
        out
    }

    /// The switching functions are the general path's `ω⁶ = J6 ṗ` (`Wing::terms`: the
    /// shoulder's pose, partials and A.9) to 1e-12 relative, θ̇ included; and on the state's
    /// own sides the held-branch right-hand side is the device's right-hand side.
    #[test]
    fn switching_functions_are_the_general_omega_and_own_sides_the_rhs() {
        for configuration in ["lift_parity", "dual_parity"] {
            let d = device(configuration);
            assert_eq!(d.n_switches(), 6, "{configuration}");
            let (mut worst_g, mut worst_rhs): (f64, f64) = (0.0, 0.0);
            let ys = states(&d);
            assert!(ys.len() > 20, "{} states", ys.len());
            for y in &ys {
                let mut g = [0.0; MAX_SWITCHES];
                d.switches(0.0, y, &mut g).unwrap();
                let (p, p_dot) = d.coordinates(y).unwrap();
                for (w, wing) in d.spec().wings.iter().enumerate() {
                    let k = 3 * w;
                    let general = wing
                        .terms(
                            &Vector3::new(p[k], p[k + 1], p[k + 2]),
                            &Vector3::new(p_dot[k], p_dot[k + 1], p_dot[k + 2]),
                        )
                        .unwrap()
                        .omega;
                    let scale = general.amax().max(1.0);
                    for i in 0..3 {
                        worst_g = worst_g.max((g[k + i] - general[i]).abs() / scale);
                    }
                }
                let t = 0.37;
                let (mut held, mut own) = (State::default(), State::default());
                d.rhs_on(t, y, Sides::of(&g[..6]), &mut held).unwrap();
                Device::rhs(&d, t, y, &mut own).unwrap();
                let (a, b) = (held.to_vec(), own.to_vec());
                let scale = b.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                for (u, v) in a.iter().zip(&b) {
                    worst_rhs = worst_rhs.max((u - v).abs() / scale);
                }
            }
            eprintln!(
                "{configuration}: switches vs general omega {worst_g:e}, own sides {worst_rhs:e}"
            );
            assert!(worst_g < 1e-12, "{configuration}: {worst_g:e}");
            assert!(worst_rhs < 1e-12, "{configuration}: {worst_rhs:e}");
        }
    }

    /// The device with its right-hand side only (the engine before free-θ event location).
    struct Smooth<'a>(&'a Device);

    impl OdeSystem for Smooth<'_> {
        fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> Result<()> {
            self.0.rhs(t, y, dydt)
        }
        fn n_active(&self) -> usize {
            self.0.n_dof()
        }
    }

    /// A lean right-hand side hands a drivetrain coordinate far beyond the linkage's plausible
    /// range to the general path, whose error names it: `d`'s right-hand side fails with the
    /// general path's error.
    pub(in crate::device) fn assert_implausible_coordinates_get_the_general_error(d: &Device) {
        let y = State {
            coords: [1e5, -1e5, 1e5, -1e5, 0.0, 0.0],
            ..State::default()
        };
        let mut out = State::default();
        let lean = d.rhs(0.0, &y, &mut out);
        let general = d.rhs_null_space(0.0, &y, &mut out);
        assert!(lean.is_err() && general.is_err());
        assert_eq!(
            format!("{:?}", lean.unwrap_err()),
            format!("{:?}", general.unwrap_err())
        );
    }

    /// Largest entry of `a − b` relative to `b`'s largest entry (at least 1); shared by the
    /// device tests.
    pub(in crate::device) fn relative_difference(a: &State, b: &State) -> f64 {
        let (a, b) = (a.to_vec(), b.to_vec());
        let scale = b.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        a.iter()
            .zip(&b)
            .fold(0.0f64, |m, (u, v)| m.max((u - v).abs() / scale))
    }

    /// Five wingbeats from rest: with the switches located the state is closer to an
    /// rtol-1e-12 reference than without (the steps across the kinks carry an error the
    /// estimate does not see; geometric mean over rtol 1e-7 … 1e-9, as one tolerance's error
    /// scatters), and at the default rtol 1e-8 with fewer rejected steps and right-hand sides
    /// (measured with the lean free-θ right-hand side: geometric means Lift 2.0e-9 vs 2.2e-8,
    /// Dual 6.0e-9 vs 1.9e-8 (one tolerance's ratio ranged 0.003–240); 4,697 vs 17,890
    /// right-hand sides, 74 vs 784 rejected (Lift); the two rtol-1e-12 references agree to
    /// 2e-12).
    #[test]
    fn located_switches_are_closer_to_a_tight_reference_with_fewer_steps() {
        for configuration in ["lift_parity", "dual_parity"] {
            let d = device(configuration);
            let y0 = d
                .state_from(d.spec().constraints.particular(), &Vec6::zeros())
                .unwrap();
            let t_end = 5.0 * d.period().unwrap();
            let run = |rtol: f64, system: &dyn OdeSystem| {
                RungeKutta::new(Method::Dop853, rtol, 1e-2 * rtol, 1_000_000)
                    .unwrap()
                    .integrate_counted(system, 0.0, &y0, t_end, &[], &mut |_, _, _| Ok(()))
                    .unwrap()
            };
            let (reference, _) = run(1e-12, &d);
            let (smooth_reference, _) = run(1e-12, &Smooth(&d));
            // One tolerance's errors scatter with where the unlocated steps meet the kinks
            // (and the last bits of the right-hand side): compare geometric means over five.
            let tolerances = [1e-7, 3e-8, 1e-8, 3e-9, 1e-9];
            let log_mean = |system: &dyn OdeSystem| {
                tolerances
                    .iter()
                    .map(|&rtol| relative_difference(&run(rtol, system).0, &reference).ln())
                    .sum::<f64>()
                    / tolerances.len() as f64
            };
            let (mean_with, mean_without) = (log_mean(&d).exp(), log_mean(&Smooth(&d)).exp());
            let (located, with) = run(1e-8, &d);
            let (smooth, without) = run(1e-8, &Smooth(&d));
            let (e_with, e_without) = (
                relative_difference(&located, &reference),
                relative_difference(&smooth, &reference),
            );
            eprintln!(
                "{configuration}: error {e_with:e} located, {e_without:e} smooth at rtol 1e-8, \
                 geometric means {mean_with:e} vs {mean_without:e} (references {:e} apart); \
                 {with:?} vs {without:?}",
                relative_difference(&smooth_reference, &reference)
            );
            assert!(with.events >= 5 * 4, "events: {}", with.events);
            assert!(
                mean_with < 0.5 * mean_without,
                "{mean_with:e} vs {mean_without:e}"
            );
            assert!(with.rejected < without.rejected && with.rhs_calls < without.rhs_calls);
        }
    }

    /// The §2.5 Dual PARITY has two period-1 orbits near the rest state: Newton from the
    /// warm-up finds an unstable one (multiplier 1.99), the transient settles on a stable one
    /// (0.855) after lingering near a period-2 saddle. The default run shoots again once the
    /// transient has settled away from the rejected orbit: it ends on the stable orbit by
    /// shooting (55 cycles; 97 by the transient before). Checked independently: an adaptive
    /// variational period at rtol 1e-10 from the result's state has all multipliers inside the
    /// unit circle and returns to it (measured 3.8e-12; 9.5e-5 with the branch held over whole
    /// grid steps), and a tight transient settles on the same state (4e-10).
    #[test]
    fn dual_parity_shooting_ends_on_the_stable_orbit_the_transient_settles_on() {
        use crate::{SimulationOptions, SteadyState, simulate};
        let d = device("dual_parity");
        let options = SimulationOptions {
            columns: Some(Vec::new()),
            max_cycles: 200,
            ..Default::default()
        };
        let r = simulate(&d, &options).unwrap();
        assert!(r.converged && r.orbit_cycles == 1, "{r:?}");
        assert!(
            r.monodromy.is_some(),
            "shooting's orbit, not the fallback's"
        );
        assert!(r.cycles_run < 70, "{} cycles", r.cycles_run);
        let period = d.period().unwrap();
        let y0 = r.steady_state.without_work();
        let rk = RungeKutta::new(Method::Dop853, 1e-10, 1e-12, 1_000_000)
            .unwrap()
            .with_work(false);
        let (y1, monodromy) = rk.flow_with_sensitivity(&d, 0.0, &y0, period).unwrap();
        let returned = relative_difference(&y1, &y0);
        let largest = crate::floquet::eigenvalues(&monodromy).unwrap()[0].norm();
        eprintln!("returns within {returned:e}; largest multiplier {largest}");
        assert!(returned < 1e-9, "{returned:e}");
        assert!(largest < 0.95, "{largest}");
        let transient = simulate(
            &d,
            &SimulationOptions {
                steady_state: SteadyState::Transient,
                rtol: 1e-10,
                atol: 1e-12,
                steady_tol: 1e-10,
                max_cycles: 400,
                ..options
            },
        )
        .unwrap();
        assert!(transient.converged);
        let apart = relative_difference(&transient.steady_state.without_work(), &y0);
        eprintln!("tight transient {apart:e} from the orbit");
        assert!(apart < 1e-7, "{apart:e}");
    }
}
