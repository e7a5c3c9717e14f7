//! sweep tests (submodule of the one dynamics integration binary).

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use paritysim_dynamics::Error;
use paritysim_dynamics::sweep::{
    Grid, ParameterTable, SweepControl, SweepSettings, metric_names, resolve_threads, run_indexed,
    run_point, select, sweep, trajectory_columns,
};

use super::*;

/// C_N(90°) of eqs. 3.5-3.6, as in `examples/drag_parity.toml`.
const CN90: f64 = 3.4609;

/// The Drag PARITY study device with a cut left wing (`omega_left`), K2 and drive voltage.
/// Voltages far above 100 V (80 V with a cut wing) drive the linkage out of its reach: the integration fails.
fn study_device(values: &[f64]) -> paritysim_dynamics::Result<Device> {
    let (omega_left, k2, volts) = (values[0], values[1], values[2]);
    let actuator = Actuator::new(
        1.2,
        467.0,
        Waveform::sine(volts, 110.0, 0.0, 0.0)?,
        DcOffset::AsForce,
    )?;
    Device::new(DeviceSpec {
        wings: vec![
            fixed_wing(WingAero::stroke_drag(omega_left, CN90)?),
            fixed_wing(WingAero::stroke_drag(31.3, CN90)?),
        ],
        constraints: Constraints::configuration("drag_parity_fixed")?,
        transmission: Some(Transmission::new(
            Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
            k2,
        )?),
        actuator: Some(actuator),
        formulation: Formulation::Auto,
    })
}

fn fast_options() -> SimulationOptions {
    SimulationOptions {
        // Shooting: the points run in continuation chains (what these tests are about).
        steady_state: paritysim_dynamics::SteadyState::Shooting,
        max_cycles: 6,
        samples_per_cycle: 40,
        ..Default::default()
    }
}

fn study_grid() -> Grid {
    Grid::new()
        .axis("wings[0].aero.omega1", [18.75, 25.0, 31.3])
        .unwrap()
        .axis("drivetrain.balance_spring", [5.0, 20.0])
        .unwrap()
        .axis("actuator.waveform.amplitude_v", [40.0, 50.0])
        .unwrap()
}

fn settings(threads: usize) -> SweepSettings {
    SweepSettings {
        threads: Some(threads),
        ..Default::default()
    }
}

#[test]
fn grid_is_row_major_like_itertools_product() {
    let grid = Grid::new()
        .axis("a", [1.0, 2.0])
        .unwrap()
        .axis("b", [10.0, 20.0, 30.0])
        .unwrap();
    assert_eq!(grid.len(), 6);
    let table = grid.table();
    assert_eq!(table.names, ["a", "b"]);
    assert_eq!(table.rows[0], [1.0, 10.0]);
    assert_eq!(table.rows[2], [1.0, 30.0]);
    assert_eq!(table.rows[3], [2.0, 10.0]);
    assert_eq!(Grid::new().len(), 1, "no axes: the base design alone");
    assert_eq!(
        Grid::new().axis("a", []).unwrap_err().field(),
        Some("grid.a")
    );
    assert!(
        Grid::new()
            .axis("a", [1.0])
            .unwrap()
            .axis("a", [2.0])
            .is_err()
    );
    assert!(matches!(
        ParameterTable::new(vec!["x".into()], vec![vec![1.0, 2.0]]),
        Err(Error::Shape(_))
    ));
    assert!(ParameterTable::new(vec!["x".into(), "x".into()], vec![]).is_err());
}

#[test]
fn results_are_in_input_order_and_bit_identical_for_1_2_and_3_threads() {
    let table = study_grid().table();
    let options = fast_options();
    // 2 twice: repeated runs are bit-identical too.
    let runs: Vec<_> = [1, 2, 3, 2]
        .iter()
        .map(|&t| {
            let control = SweepControl::new();
            let r = sweep(&table, study_device, &options, &settings(t), &control).unwrap();
            assert_eq!(control.finished(), table.len());
            assert!(!r.cancelled);
            r
        })
        .collect();
    // `PartialEq` on f64 is bitwise for non-NaN values; NaN metrics (no rotation: phase lag)
    // are compared by bits below.
    for r in &runs[1..] {
        assert_eq!(r.rows.len(), runs[0].rows.len());
        for (a, b) in r.rows.iter().zip(&runs[0].rows) {
            assert_eq!(a.index, b.index);
            assert_eq!(a.parameters, b.parameters);
            let (a, b) = (a.outcome.as_ref().unwrap(), b.outcome.as_ref().unwrap());
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&a.metrics), bits(&b.metrics));
            assert_eq!((a.converged, a.cycles_run), (b.converged, b.cycles_run));
        }
    }
    // In input order, and each row is a plain `simulate` of that point: the same periodic
    // orbit, reached from a neighbour's start on the neighbour's step grid, so equal to the
    // accuracy of the orbit (issue 12's 1e-7 at rtol 1e-8), not bit for bit.
    let names = &runs[0].metrics;
    assert_eq!(names, &metric_names(&study_device(&table.rows[0]).unwrap()));
    // Differences relative to each metric's scale over the grid (a mean stroke near zero
    // carries the stroke amplitude's absolute error).
    let directs: Vec<_> = (0..table.len())
        .map(|i| simulate(&study_device(&table.rows[i]).unwrap(), &options).unwrap())
        .collect();
    let scale: Vec<f64> = names
        .iter()
        .map(|name| {
            directs
                .iter()
                .flat_map(|d| d.metrics.iter().filter(|(n, _)| n == name))
                .map(|(_, v)| v.abs())
                .filter(|v| v.is_finite())
                .fold(1e-12, f64::max)
        })
        .collect();
    let mut worst: f64 = 0.0;
    for (i, row) in runs[1].rows.iter().enumerate() {
        assert_eq!(row.index, i);
        assert_eq!(row.parameters, table.rows[i]);
        let direct = &directs[i];
        let out = row.outcome.as_ref().unwrap();
        assert_eq!(out.converged, direct.converged, "point {i}");
        for (k, name) in names.iter().enumerate() {
            let v = direct.metrics.iter().find(|(n, _)| n == name).unwrap().1;
            let got = out.metrics[k];
            if !direct.converged {
                // No orbit (here: unstable ones, the transient diverging): the chain reruns
                // the point from the spec's own start, exactly as `simulate` does.
                assert_eq!(got.to_bits(), v.to_bits(), "{name} at point {i}");
                continue;
            }
            if v.is_nan() {
                assert!(got.is_nan(), "{name} at point {i}: {got} vs NaN");
                continue;
            }
            let rel = (got - v).abs() / scale[k];
            worst = worst.max(rel);
            assert!(rel <= 1e-7, "{name} at point {i}: {got} vs {v} ({rel:e})");
        }
    }
    eprintln!("worst difference sweep vs direct, relative to each metric's scale: {worst:e}");
    // The sweep moved the physics: a cut wing strokes further under PARITY.
    let amp = |i: usize| runs[0].rows[i].outcome.as_ref().unwrap().metrics[0];
    assert!(
        amp(0) > amp(8),
        "left stroke amplitude should fall as omega1 rises"
    );
}

#[test]
fn failing_points_become_error_rows_and_the_others_are_kept() {
    // Point 1: negative K2 (cannot build). Point 2: 5 kV drives the linkage out of reach
    // (integration fails). Points 0 and 3 are fine.
    let table = ParameterTable::new(
        vec!["omega".into(), "k2".into(), "volts".into()],
        vec![
            vec![31.3, 1.0, 50.0],
            vec![31.3, -1.0, 50.0],
            vec![31.3, 1.0, 5000.0],
            vec![20.0, 1.0, 50.0],
        ],
    )
    .unwrap();
    for threads in [1, 2] {
        let control = SweepControl::new();
        let r = sweep(
            &table,
            study_device,
            &fast_options(),
            &settings(threads),
            &control,
        )
        .unwrap();
        assert_eq!(r.rows.len(), 4);
        assert!(r.rows[0].outcome.is_ok() && r.rows[3].outcome.is_ok());
        match &r.rows[1].outcome {
            Err(e) => assert_eq!(e.field(), Some("balance_spring"), "{e}"),
            Ok(_) => panic!("negative K2 must fail"),
        }
        assert!(
            matches!(r.rows[2].outcome, Err(Error::Integration { .. })),
            "{:?}",
            r.rows[2].outcome
        );
        assert_eq!(control.finished(), 4);
    }
}

#[test]
fn cancel_stops_scheduling_and_returns_the_finished_points() {
    let table = study_grid().table();
    // Cancelled before it starts: nothing runs.
    let control = SweepControl::new();
    control.cancel();
    let r = sweep(
        &table,
        study_device,
        &fast_options(),
        &settings(2),
        &control,
    )
    .unwrap();
    assert!(r.cancelled && r.rows.is_empty());
    assert_eq!(control.finished(), 0);

    // Cancelled from inside point 4 (one thread): points 0..=4 finish, the rest never start.
    let control = SweepControl::new();
    let slots = run_indexed(table.len(), 1, &control, |i| {
        if i == 4 {
            control.cancel();
        }
        Ok(i)
    })
    .unwrap();
    let done: Vec<usize> = slots
        .iter()
        .flatten()
        .map(|r| *r.as_ref().unwrap())
        .collect();
    assert_eq!(done, [0, 1, 2, 3, 4]);
    assert!(slots[5..].iter().all(Option::is_none));
    assert_eq!(control.finished(), 5);

    // With several threads, the cancel also stops the running points inside their
    // integration: the point that cancels and any other one stopped mid-run count as not run,
    // and every finished slot is a real result (never a `Cancelled` row).
    let control = Arc::new(SweepControl::new());
    let started = AtomicUsize::new(0);
    let canceller = AtomicUsize::new(usize::MAX);
    let options = fast_options();
    let slots = run_indexed(table.len(), 3, &control, |i| {
        if started.fetch_add(1, Ordering::SeqCst) == 3 {
            canceller.store(i, Ordering::SeqCst);
            control.cancel();
        }
        run_point(&study_device(&table.rows[i])?, &options, &[], false).map(|o| o.cycles_run)
    })
    .unwrap();
    let finished = slots.iter().filter(|s| s.is_some()).count();
    assert!(finished < 4, "{finished}");
    assert_eq!(finished, control.finished());
    assert!(slots[canceller.load(Ordering::SeqCst)].is_none());
    assert!(slots.iter().flatten().all(Result::is_ok));
}

#[test]
fn progress_counter_can_be_polled_from_another_thread() {
    let table = study_grid().table();
    let control = Arc::new(SweepControl::new());
    let observer = {
        let control = Arc::clone(&control);
        std::thread::spawn(move || {
            let mut seen = vec![control.finished()];
            while *seen.last().unwrap() < 12 {
                std::thread::sleep(std::time::Duration::from_micros(200));
                seen.push(control.finished());
            }
            seen
        })
    };
    sweep(
        &table,
        study_device,
        &fast_options(),
        &settings(2),
        &control,
    )
    .unwrap();
    let seen = observer.join().unwrap();
    assert!(seen.windows(2).all(|w| w[0] <= w[1]), "monotone: {seen:?}");
    assert_eq!(*seen.last().unwrap(), 12);
}

#[test]
fn a_panicking_point_is_reported_not_propagated() {
    let control = SweepControl::new();
    for threads in [1, 2] {
        let slots = run_indexed(4, threads, &control, |i| {
            if i == 2 {
                panic!("boom at {i}");
            }
            Ok(i)
        })
        .unwrap();
        match slots[2].as_ref().unwrap() {
            Err(Error::Integration { reason, .. }) => {
                assert!(
                    reason.contains("panic") && reason.contains("boom at 2"),
                    "{reason}"
                )
            }
            other => panic!("expected a reported panic, got {other:?}"),
        }
        assert_eq!(*slots[3].as_ref().unwrap().as_ref().unwrap(), 3);
    }
}

#[test]
fn metric_names_are_validated_and_selected_in_order() {
    let device = study_device(&[31.3, 1.0, 50.0]).unwrap();
    let valid = metric_names(&device);
    assert!(valid.contains(&"left_stroke_amplitude".to_string()));
    let err = select("metrics", Some(&["left_stroke_amplitud".into()]), &valid).unwrap_err();
    assert_eq!(err.field(), Some("metrics"));
    assert!(
        err.to_string().contains("q2_amplitude"),
        "lists valid names: {err}"
    );
    let want = vec![
        "q2_amplitude".to_string(),
        "left_stroke_amplitude".to_string(),
    ];
    assert_eq!(select("metrics", Some(&want), &valid).unwrap(), want);
    assert_eq!(select("metrics", None, &valid).unwrap(), valid);

    // Unknown metrics are rejected before any point runs.
    let control = SweepControl::new();
    let bad = SweepSettings {
        metrics: Some(vec!["nope".into()]),
        ..settings(2)
    };
    let err = sweep(
        &study_grid().table(),
        study_device,
        &fast_options(),
        &bad,
        &control,
    )
    .unwrap_err();
    assert_eq!(err.field(), Some("metrics"));
    assert_eq!(control.finished(), 0);

    let out = run_point(&device, &fast_options(), &want, false).unwrap();
    let direct = simulate(&device, &fast_options()).unwrap();
    let get = |n: &str| direct.metrics.iter().find(|(k, _)| k == n).unwrap().1;
    assert_eq!(
        out.metrics,
        [get("q2_amplitude"), get("left_stroke_amplitude")]
    );
}

#[test]
fn keep_cycle_returns_the_last_recorded_cycle() {
    let device = study_device(&[25.0, 1.0, 50.0]).unwrap();
    let options = SimulationOptions {
        record_cycles: 2,
        ..fast_options()
    };
    let out = run_point(&device, &options, &[], true).unwrap();
    let cycle = out.cycle.unwrap();
    let full = simulate(&device, &options).unwrap().trajectory;
    assert_eq!(cycle.time.len(), options.samples_per_cycle + 1);
    assert_eq!(cycle.time[..], full.time[options.samples_per_cycle..]);
    assert_eq!(cycle.columns.len(), full.columns.len());
    let names: Vec<String> = cycle.columns.iter().map(|(n, _)| n.clone()).collect();
    assert_eq!(names, trajectory_columns(&device));
    let phi = cycle.column("left_phi").unwrap();
    assert_eq!(
        phi,
        &full.column("left_phi").unwrap()[options.samples_per_cycle..]
    );
    // Without keep_cycle nothing is kept.
    assert!(
        run_point(&device, &options, &[], false)
            .unwrap()
            .cycle
            .is_none()
    );
}

#[test]
fn thread_counts_are_validated() {
    assert_eq!(resolve_threads(Some(3)).unwrap(), 3);
    assert_eq!(
        resolve_threads(Some(0)).unwrap_err().field(),
        Some("threads")
    );
    assert!(resolve_threads(Some(100_000)).is_err());
    // The environment default (PARITYSIM_THREADS) is exercised from Python in a subprocess:
    // mutating the environment of this multi-threaded test binary would be unsound.
    assert!(resolve_threads(None).unwrap() >= 1);
}

#[test]
fn a_cancel_stops_a_continuation_chain_between_its_points() {
    // 12 shooting points form one chain; on one thread the chain is cancelled once two points
    // finished: the finished points are rows and counted, the rest of the chain never runs.
    let table = study_grid().table();
    let control = Arc::new(SweepControl::new());
    let observer = {
        let control = Arc::clone(&control);
        std::thread::spawn(move || {
            while control.finished() < 2 {
                std::thread::sleep(std::time::Duration::from_micros(50));
            }
            control.cancel();
        })
    };
    let r = sweep(
        &table,
        study_device,
        &fast_options(),
        &settings(1),
        &control,
    )
    .unwrap();
    observer.join().unwrap();
    assert!(r.cancelled);
    assert!(
        r.rows.len() >= 2 && r.rows.len() < table.len(),
        "{}",
        r.rows.len()
    );
    assert_eq!(r.rows.len(), control.finished());
    assert!(r.rows.iter().enumerate().all(|(i, row)| row.index == i));
    assert!(r.rows.iter().all(|row| row.outcome.is_ok()));
}

/// A sweep inside a cancellable call (a binding's Ctrl-C, `budget::cancellable`) takes the
/// call's cancel flag with `SweepControl::of_current_budget`: once cancelled, no point runs
/// (the sensitivity rows of `sweep(gradients=)` sweep for their orbits this way); outside such
/// a call the control is a fresh one.
#[test]
fn a_control_of_the_current_budget_stops_with_the_call() {
    use paritysim_dynamics::integrate::budget::{CancelFlag, cancellable};
    use paritysim_dynamics::sweep::run_points;
    let points: Vec<_> = [18.75, 25.0, 31.3]
        .into_iter()
        .flat_map(|omega| [5.0, 20.0].map(|k2| study_device(&[omega, k2, 50.0])))
        .map(|d| d.map(|d| (d, fast_options())))
        .collect();
    assert!(!SweepControl::of_current_budget().is_cancelled());
    let cancel = CancelFlag::new();
    let mut slots = Vec::new();
    cancellable(&cancel, || {
        let control = SweepControl::of_current_budget();
        assert!(!control.is_cancelled());
        cancel.cancel(); // the call's Ctrl-C, before its sweep
        assert!(control.is_cancelled());
        slots = run_points(&points, &[], false, Some(1), &control)?;
        Ok(())
    })
    .unwrap();
    assert_eq!(slots.len(), points.len());
    assert!(
        slots.iter().all(Option::is_none),
        "a point ran after the cancel"
    );
    // The same points with a fresh control all run.
    let ran = run_points(&points, &[], false, Some(1), &SweepControl::new()).unwrap();
    assert!(ran.iter().all(Option::is_some));
}
