//! Steady-state sensitivities (issue 31): the implicit-function derivatives against central
//! differences of whole `simulate` runs, and the neutral family flagged, not divided by.

use paritysim_dynamics::SteadyState;
use paritysim_dynamics::sensitivity::steady_sensitivity;
use paritysim_kinematics::drivetrain::LinearDifferential;

use super::*;

/// The §3.3 drag device at `[Ω^L, K2, amplitude (V), frequency (Hz)]`.
fn design(p: &[f64]) -> paritysim_dynamics::Result<Device> {
    if p[1] < 0.0 {
        return Err(paritysim_dynamics::Error::invalid("k2", p[1], "at least 0"));
    }
    let wing = |omega: f64| fixed_wing(drag(omega));
    let actuator = Actuator::thesis(Waveform::sine(p[2], p[3], 0.0, 0.0)?);
    Ok(two_wing_device(
        [wing(p[0]), wing(31.3)],
        "drag_parity_fixed",
        Drivetrain::LinearDifferential(LinearDifferential::new(2.5, 2.5, 1.0)?),
        p[1],
        actuator,
        Formulation::Auto,
    ))
}

fn tight() -> SimulationOptions {
    SimulationOptions {
        steady_state: SteadyState::Shooting,
        rtol: 1e-11,
        atol: 1e-13,
        steady_tol: 1e-11,
        samples_per_cycle: 400,
        ..Default::default()
    }
}

fn metrics_at(p: &[f64]) -> Vec<(String, f64)> {
    let r = simulate(&design(p).unwrap(), &tight()).unwrap();
    assert!(r.converged);
    r.metrics
}

#[test]
fn metric_derivatives_equal_central_differences_of_whole_runs() {
    let p0 = [18.75, 5.0, 50.0, 110.0];
    let s = steady_sensitivity(&design, &design(&p0).unwrap(), &p0, None, &tight()).unwrap();
    assert_eq!(s.neutral_directions, 0, "K2 > 0: no neutral family");
    assert!(s.residual < 1e-9, "orbit residual {:e}", s.residual);
    let mut checked = 0;
    for j in 0..p0.len() {
        // Whole runs at steps h and h/2: where they agree the metric is smooth over the step
        // (a sampled peak can switch to its neighbouring sample within a larger one).
        let reference = |h: f64| {
            let mut plus = p0;
            plus[j] += h;
            let mut minus = p0;
            minus[j] -= h;
            let (mp, mm) = (metrics_at(&plus), metrics_at(&minus));
            move |name: &str| {
                let value = |ms: &[(String, f64)]| ms.iter().find(|(m, _)| m == name).unwrap().1;
                (value(&mp) - value(&mm)) / (2.0 * h)
            }
        };
        let h = 1e-3 * p0[j].abs();
        let (coarse, fine) = (reference(h), reference(h / 2.0));
        for (i, (name, m0)) in s.metrics.iter().enumerate() {
            if s.not_differentiable[i].is_some() {
                continue;
            }
            let (coarse, fine, ours) = (coarse(name), fine(name), s.jacobian[(i, j)]);
            // The whole runs' own error (measured: ~3e-10 of the metric, their grids picked
            // anew at each point) divided by the step: what the reference resolves.
            let resolved = 1e-9 * (1.0 + m0.abs()) / (h / 2.0);
            if (coarse - fine).abs() > 1e-5 * fine.abs() + resolved {
                continue;
            }
            assert!(
                (ours - fine).abs() <= 1e-5 * fine.abs() + resolved,
                "d {name} / d p{j}: {ours:e} against {fine:e} from whole runs"
            );
            checked += 1;
        }
    }
    eprintln!("CHECKED {checked}");
    assert!(checked >= 4 * 5, "only {checked} derivatives compared");
}

#[test]
fn a_neutral_family_is_left_out_and_the_metrics_moving_along_it_are_flagged() {
    // K2 = 0 with identical wings: every constant q2 offset is an orbit (a multiplier at 1).
    // K2 = 0 is its range's end: its derivative takes the one-sided formula.
    let p0 = [31.3, 0.0, 50.0, 110.0];
    let s = steady_sensitivity(&design, &design(&p0).unwrap(), &p0, None, &tight()).unwrap();
    assert_eq!(s.neutral_directions, 1);
    for (i, (name, m)) in s.metrics.iter().enumerate() {
        if m.is_finite() {
            assert!(s.jacobian.row(i).iter().all(|v| v.is_finite()), "{name}");
        }
    }
    assert!(
        s.multipliers
            .iter()
            .any(|m| (m - nalgebra::Complex::new(1.0, 0.0)).norm() < 1e-6),
        "{:?}",
        s.multipliers
    );
    let flagged: Vec<&str> = s
        .metrics
        .iter()
        .zip(&s.not_differentiable)
        .filter(|(_, f)| f.is_some())
        .map(|((m, _), _)| m.as_str())
        .collect();
    assert!(
        !flagged.is_empty(),
        "a stroke offset moves along the family"
    );
}

#[test]
fn a_parameter_that_breaks_the_family_has_no_derivative_where_the_wings_differ() {
    // On identical wings symmetry keeps the orbit's member (no offset) as K2 leaves 0: every
    // parameter is differentiable. On wings that differ the run from rest ends on a member
    // with an offset, and K2 > 0 pulls the orbit to another one: no derivative in K2 (a NaN
    // column with the reason), while Ω^L, the amplitude and the frequency keep the family.
    let symmetric = [31.3, 0.0, 50.0, 110.0];
    let s = steady_sensitivity(
        &design,
        &design(&symmetric).unwrap(),
        &symmetric,
        None,
        &tight(),
    )
    .unwrap();
    assert!(
        s.parameter_not_differentiable.iter().all(Option::is_none),
        "{:?}",
        s.parameter_not_differentiable
    );
    let cut = [25.0, 0.0, 50.0, 110.0];
    let s = steady_sensitivity(&design, &design(&cut).unwrap(), &cut, None, &tight()).unwrap();
    assert_eq!(s.neutral_directions, 1);
    for (j, reason) in s.parameter_not_differentiable.iter().enumerate() {
        assert_eq!(reason.is_some(), j == 1, "parameter {j}: {reason:?}");
        let column_defined = s.state_jacobian.column(j).iter().all(|v| v.is_finite());
        assert_eq!(column_defined, j != 1, "parameter {j}");
    }
    assert!(s.jacobian.column(1).iter().all(|v| v.is_nan()));
    assert!(
        s.parameter_not_differentiable[1]
            .as_ref()
            .unwrap()
            .contains("family")
    );
}

#[test]
fn bad_steps_are_named() {
    let e = steady_sensitivity(
        &design,
        &design(&[18.75, 5.0, 50.0, 110.0]).unwrap(),
        &[18.75, 5.0, 50.0, 110.0],
        Some(&[1e-4]),
        &tight(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("steps"), "{e}");
}

/// The perturbed periods of a linear-map device with stroke metrics run in the SIMD lanes
/// (`lanes::batch`; bit-identical to the scalar ones: tests/test_gradients.py), two maps per
/// parameter whose windows are replayed from their samples moved by Φ(t)·δ; the derivatives
/// agree with those of integrated windows (all metrics asked: they read work integrals).
#[test]
fn the_perturbed_periods_run_in_the_lanes() {
    let p0 = [18.75, 5.0, 50.0, 110.0];
    let stroke: Vec<String> = ["tau_r_peak", "tau_l_peak", "delta_tau_peak"]
        .map(String::from)
        .to_vec();
    let options = SimulationOptions {
        metrics: Some(stroke.clone()),
        ..tight()
    };
    let before = paritysim_dynamics::lanes::periods_completed_in_lanes();
    let lanes = steady_sensitivity(&design, &design(&p0).unwrap(), &p0, None, &options).unwrap();
    assert!(paritysim_dynamics::lanes::periods_completed_in_lanes() - before >= 2 * p0.len());
    let all = steady_sensitivity(&design, &design(&p0).unwrap(), &p0, None, &tight()).unwrap();
    for (i, (name, value)) in lanes.metrics.iter().enumerate() {
        let k = all.metrics.iter().position(|(m, _)| m == name).unwrap();
        for (j, p) in p0.iter().enumerate() {
            let (a, b) = (lanes.jacobian[(i, j)], all.jacobian[(k, j)]);
            // Relative to the derivative's scale (measured: within 5e-9).
            let scale = (value.abs() / p.abs()).max(b.abs());
            assert!(
                (a - b).abs() <= 1e-7 * scale,
                "d {name} / d p{j}: {a:e} against {b:e}"
            );
        }
    }
}

/// The orbit's last shooting period kept by its run (`sampled_orbit`) is the period a
/// sensitivity integrates otherwise: the same derivatives to the bit, and the run itself (its
/// orbit, residual and metrics) is the run without it.
#[test]
fn the_runs_kept_period_gives_the_bits_of_a_period_of_its_own() {
    use paritysim_dynamics::sensitivity::{Orbit, orbit_options, steady_sensitivity_at};
    let p0 = [18.75, 5.0, 50.0, 110.0];
    let options = SimulationOptions {
        metrics: Some(
            ["tau_r_peak", "delta_tau_peak", "left_stroke_amplitude"]
                .map(String::from)
                .to_vec(),
        ),
        ..tight()
    };
    let device = design(&p0).unwrap();
    let plain = simulate(&device, &orbit_options(&options)).unwrap();
    let kept_run = simulate(
        &device,
        &SimulationOptions {
            sampled_orbit: true,
            ..orbit_options(&options)
        },
    )
    .unwrap();
    assert!(plain.orbit_samples.is_none());
    let samples = kept_run
        .orbit_samples
        .clone()
        .expect("the last period kept");
    assert_eq!(kept_run.steady_state, plain.steady_state);
    assert_eq!(kept_run.residual, plain.residual);
    // Bit for bit, NaN (the metrics these samples do not compute) included.
    let bits = |m: &[(String, f64)]| -> Vec<(String, u64)> {
        m.iter().map(|(n, v)| (n.clone(), v.to_bits())).collect()
    };
    assert_eq!(bits(&kept_run.metrics), bits(&plain.metrics));
    assert_eq!(bits(&samples.metrics), bits(&plain.metrics));
    let orbit = |samples| Orbit {
        state: plain.steady_state,
        grid: plain.step_grid.clone(),
        cycles: plain.orbit_cycles,
        samples,
    };
    let at = |samples| {
        steady_sensitivity_at(&design, &device, &p0, None, &options, &orbit(samples)).unwrap()
    };
    let (kept, own) = (at(Some(samples)), at(None));
    assert_eq!(kept.jacobian, own.jacobian);
    assert_eq!(bits(&kept.metrics), bits(&own.metrics));
    assert_eq!(kept.multipliers, own.multipliers);
    assert_eq!(kept.residual, own.residual);
    assert_eq!(kept.not_differentiable, own.not_differentiable);
}
