//! Sweeps over spec paths, and the handle of a sweep running on a background thread.
//!
//! [`SweepPlan::new`] resolves the parameter paths against the base spec (an unknown path,
//! metric or duplicate target is an error before anything runs); each point is the base spec
//! with one row of values applied ([`crate::paths::apply`]) and validated like any other spec,
//! so a point that does not validate becomes that point's error row. [`SweepJob`] runs a plan
//! on a background thread with the engine's local pool
//! ([`paritysim_dynamics::sweep::run_points`]): poll [`SweepJob::finished`], stop with
//! [`SweepJob::cancel`], collect [`SweepJob::outcome`] (rows in input order).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use paritysim_dynamics::sweep::{self as engine, PointOutput, SweepControl, resolve_threads};
use paritysim_dynamics::{Device, SimulationOptions};
use paritysim_error::{Error, Result};
use serde_json::Value;

use crate::paths::{Parameter, resolve_all};
use crate::spec::Simulation;

/// A validated sweep: base spec, resolved parameters, rows of values, what to report.
#[derive(Clone, Debug)]
pub struct SweepPlan {
    base: Simulation,
    parameters: Vec<Parameter>,
    rows: Vec<Vec<Value>>,
    metrics: Vec<String>,
    columns: Vec<String>,
    keep_cycle: bool,
    threads: usize,
}

impl SweepPlan {
    /// Resolves `names` against `base` and checks `metrics` against the base device.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for an unknown path (with the nearest valid one), two
    /// columns writing the same field, a row of the wrong length, an unknown metric or a bad
    /// thread count; the base spec's own errors when it does not build.
    pub fn new(
        base: Simulation,
        names: &[String],
        rows: Vec<Vec<Value>>,
        metrics: Option<&[String]>,
        keep_cycle: bool,
        threads: Option<usize>,
    ) -> Result<Self> {
        let threads = resolve_threads(threads)?;
        let (parameters, _) = resolve_all(&base, names)?;
        let mut seen: Vec<(&str, &str)> = Vec::new();
        for p in &parameters {
            for (target, _) in &p.targets {
                if let Some((_, other)) = seen.iter().find(|(t, n)| t == target && *n != p.name) {
                    return Err(Error::invalid(
                        p.name.clone(),
                        format!("<same field as {other:?}>"),
                        "each spec field swept by one column only",
                    ));
                }
                seen.push((target, &p.name));
            }
        }
        if let Some((i, row)) = rows
            .iter()
            .enumerate()
            .find(|(_, r)| r.len() != names.len())
        {
            return Err(Error::Shape(format!(
                "row {i} has {} values but there are {} parameters",
                row.len(),
                names.len()
            )));
        }
        let device = base.device()?;
        let valid = base.metric_names(&device)?;
        let metrics = crate::schema::select(
            "metrics",
            metrics.map(<[String]>::to_vec).as_deref(),
            &valid,
        )?;
        let columns = base.column_names(&device)?;
        Ok(Self {
            base,
            parameters,
            rows,
            metrics,
            columns,
            keep_cycle,
            threads,
        })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Reported metric names.
    pub fn metrics(&self) -> &[String] {
        &self.metrics
    }

    /// Trajectory columns of a kept cycle (without `time_ms`).
    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    /// Threads of the pool.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Deprecation notes of the parameter names.
    pub fn notes(&self) -> Vec<String> {
        self.parameters
            .iter()
            .flat_map(|p| p.notes.clone())
            .collect()
    }

    /// The spec of point `i`.
    ///
    /// # Errors
    /// The validation errors of the overridden spec.
    pub fn point_spec(&self, i: usize) -> Result<Simulation> {
        let overrides: Vec<(&Parameter, &Value)> =
            self.parameters.iter().zip(self.rows[i].iter()).collect();
        crate::paths::apply(&self.base, &overrides)
    }

    fn point(&self, i: usize) -> Result<(Device, SimulationOptions)> {
        self.point_spec(i)?.model()
    }
}

/// Kept cycles: per column (`time_ms` first), per point, the samples (None where not ok).
pub type KeptCycles = Vec<(String, Vec<Option<Vec<f64>>>)>;

/// Everything a finished (or cancelled) sweep reports, one entry per point in input order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SweepOutcome {
    /// Whether the point ran (false: cancelled before it started).
    pub finished: Vec<bool>,
    /// Whether it succeeded.
    pub ok: Vec<bool>,
    /// Row-major `(points, metrics)`, NaN where not ok.
    pub metrics: Vec<f64>,
    /// Steady state reached.
    pub converged: Vec<bool>,
    /// Cycles simulated before recording (-1 where not ok).
    pub cycles_run: Vec<i64>,
    /// Drive periods per period of the steady state: 1, 2 for a period-doubled orbit (-1
    /// where not ok; [`paritysim_dynamics::SimulationResult::orbit_cycles`]).
    pub orbit_cycles: Vec<i64>,
    /// Error message of a failed point.
    pub error: Vec<Option<String>>,
    /// Error kind (the Python class without `Error`) of a failed point.
    pub error_kind: Vec<Option<String>>,
    /// With `keep_cycle`: per column (`time_ms` first), per point, the last cycle.
    pub cycle: Option<KeptCycles>,
}

impl SweepOutcome {
    fn from_slots(
        slots: &[Option<Result<PointOutput>>],
        n_metrics: usize,
        columns: &[String],
        keep_cycle: bool,
    ) -> Self {
        let n = slots.len();
        let mut out = SweepOutcome {
            finished: vec![false; n],
            ok: vec![false; n],
            metrics: vec![f64::NAN; n * n_metrics],
            converged: vec![false; n],
            cycles_run: vec![-1; n],
            orbit_cycles: vec![-1; n],
            error: vec![None; n],
            error_kind: vec![None; n],
            cycle: None,
        };
        for (i, slot) in slots.iter().enumerate() {
            out.finished[i] = slot.is_some();
            match slot {
                Some(Ok(p)) => {
                    out.ok[i] = true;
                    out.metrics[i * n_metrics..(i + 1) * n_metrics].copy_from_slice(&p.metrics);
                    out.converged[i] = p.converged;
                    out.cycles_run[i] = i64::try_from(p.cycles_run).unwrap_or(i64::MAX);
                    out.orbit_cycles[i] = i64::try_from(p.orbit_cycles).unwrap_or(i64::MAX);
                }
                Some(Err(e)) => {
                    out.error[i] = Some(e.to_string());
                    out.error_kind[i] = Some(e.kind().to_string());
                }
                None => {}
            }
        }
        if keep_cycle {
            let names = std::iter::once("time_ms".to_string()).chain(columns.iter().cloned());
            out.cycle = Some(
                names
                    .enumerate()
                    .map(|(k, name)| {
                        let per_point = slots
                            .iter()
                            .map(|slot| match slot {
                                Some(Ok(PointOutput { cycle: Some(t), .. })) => Some(if k == 0 {
                                    t.time.clone()
                                } else {
                                    t.columns[k - 1].1.clone()
                                }),
                                _ => None,
                            })
                            .collect();
                        (name, per_point)
                    })
                    .collect(),
            );
        }
        out
    }
}

enum State {
    Ready,
    Running(JoinHandle<Result<SweepOutcome>>),
    Joining,
    Done(Result<SweepOutcome>),
}

/// A sweep on a background thread: progress counter, cancel flag, outcome.
///
/// Every method may be called from any thread; [`SweepJob::wait`] and [`SweepJob::outcome`]
/// block (callers holding an interpreter lock release it around them).
pub struct SweepJob {
    plan: Arc<SweepPlan>,
    control: Arc<SweepControl>,
    worker_done: Arc<(Mutex<bool>, Condvar)>,
    started: AtomicBool,
    state: Mutex<State>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A poisoned lock only means a panic elsewhere while holding it; the data is still usable.
    m.lock().unwrap_or_else(|p| p.into_inner())
}

impl SweepJob {
    /// A job for `plan`, not started.
    pub fn new(plan: SweepPlan) -> Self {
        Self {
            plan: Arc::new(plan),
            control: Arc::new(SweepControl::new()),
            worker_done: Arc::new((Mutex::new(false), Condvar::new())),
            started: AtomicBool::new(false),
            state: Mutex::new(State::Ready),
        }
    }

    /// The plan.
    pub fn plan(&self) -> &SweepPlan {
        &self.plan
    }

    /// Starts the background thread.
    ///
    /// # Errors
    /// [`Error::Constraint`] when already started; [`Error::InvalidParameter`] (`threads`)
    /// when the OS cannot start a thread.
    pub fn start(&self) -> Result<()> {
        let mut state = lock(&self.state);
        if !matches!(*state, State::Ready) {
            return Err(Error::Constraint("this sweep was already started".into()));
        }
        let plan = Arc::clone(&self.plan);
        let control = Arc::clone(&self.control);
        let done = Arc::clone(&self.worker_done);
        let handle = std::thread::Builder::new()
            .name("paritysim-sweep".into())
            .spawn(move || {
                let out = run(&plan, &control);
                let (flag, signal) = &*done;
                *lock(flag) = true;
                signal.notify_all();
                out
            })
            .map_err(|e| {
                Error::invalid("threads", 1, format!("a thread the OS can start ({e})"))
            })?;
        self.started.store(true, Ordering::Release);
        *state = State::Running(handle);
        Ok(())
    }

    /// Whether [`SweepJob::start`] was called.
    pub fn is_started(&self) -> bool {
        self.started.load(Ordering::Acquire)
    }

    /// Stops scheduling new points; running points stop at their next budget check and are
    /// reported as not run (`finished = false`, recomputed by a resume).
    pub fn cancel(&self) {
        self.control.cancel();
    }

    /// Whether [`SweepJob::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.control.is_cancelled()
    }

    /// Points finished so far.
    pub fn finished(&self) -> usize {
        self.control.finished()
    }

    /// Waits up to `timeout` (None: until done); true when the run is done.
    ///
    /// # Errors
    /// [`Error::Constraint`] when the job was not started.
    pub fn wait(&self, timeout: Option<Duration>) -> Result<bool> {
        if !self.is_started() {
            return Err(Error::Constraint("this sweep was not started".into()));
        }
        let (flag, signal) = &*self.worker_done;
        let deadline = timeout.map(|t| Instant::now() + t);
        let mut done = lock(flag);
        while !*done {
            match deadline {
                None => done = signal.wait(done).unwrap_or_else(|p| p.into_inner()),
                Some(d) => {
                    let now = Instant::now();
                    if now >= d {
                        return Ok(false);
                    }
                    done = signal
                        .wait_timeout(done, d - now)
                        .unwrap_or_else(|p| p.into_inner())
                        .0;
                }
            }
        }
        Ok(true)
    }

    /// Starts the job if needed, waits for it and returns its outcome.
    ///
    /// # Errors
    /// A bad thread count; a panic of the worker thread as [`Error::Integration`].
    pub fn outcome(&self) -> Result<SweepOutcome> {
        if !self.is_started() {
            // Another caller may have started it meanwhile: that is fine.
            let _ = self.start();
        }
        loop {
            let handle = {
                let mut state = lock(&self.state);
                match &*state {
                    State::Done(out) => return out.clone(),
                    State::Ready | State::Joining => None,
                    State::Running(_) => match std::mem::replace(&mut *state, State::Joining) {
                        State::Running(h) => Some(h),
                        _ => unreachable!("matched Running above"),
                    },
                }
            };
            match handle {
                Some(h) => {
                    let out = h.join().unwrap_or_else(|_| {
                        Err(Error::Integration {
                            time: f64::NAN,
                            state: Vec::new(),
                            reason: "internal error (panic) in the sweep thread".into(),
                        })
                    });
                    *lock(&self.state) = State::Done(out.clone());
                    return out;
                }
                // Another thread is joining.
                None => std::thread::sleep(Duration::from_millis(1)),
            }
        }
    }
}

impl Drop for SweepJob {
    fn drop(&mut self) {
        // Never leave a detached worker behind: stop scheduling and wait for running points.
        self.control.cancel();
        let state = self.state.get_mut().unwrap_or_else(|p| p.into_inner());
        if let State::Running(h) =
            std::mem::replace(state, State::Done(Ok(SweepOutcome::default())))
        {
            let _ = h.join();
        }
    }
}

fn run(plan: &SweepPlan, control: &SweepControl) -> Result<SweepOutcome> {
    if plan.base.flies() {
        // Free-flight points (paritysim-flight): built and run on the pool, no chains.
        let slots = engine::run_indexed(plan.len(), plan.threads, control, |i| {
            let spec = plan.point_spec(i)?;
            let (device, options) = spec.model()?;
            crate::flight::run_point(&spec, &device, &options, &plan.metrics, plan.keep_cycle)
        })?;
        return Ok(SweepOutcome::from_slots(
            &slots,
            plan.metrics.len(),
            &plan.columns,
            plan.keep_cycle,
        ));
    }
    // Points are built on the pool too (validation and model construction are per point).
    let points: Vec<Result<(Device, SimulationOptions)>> =
        engine::run_indexed(plan.len(), plan.threads, &SweepControl::new(), |i| {
            plan.point(i)
        })?
        .into_iter()
        .map(|slot| slot.unwrap_or(Err(Error::Cancelled)))
        .collect();
    let mut slots = engine::run_points(
        &points,
        &plan.metrics,
        plan.keep_cycle,
        Some(plan.threads),
        control,
    )?;
    // A point that failed while running names the field most responsible (its spec again).
    for (i, slot) in slots.iter_mut().enumerate() {
        if let Some(Err(e)) = slot
            && e.field().is_none()
            && let Ok(spec) = plan.point_spec(i)
        {
            *e = spec.attribute(e.clone());
        }
    }
    Ok(SweepOutcome::from_slots(
        &slots,
        plan.metrics.len(),
        &plan.columns,
        plan.keep_cycle,
    ))
}

/// Runs a plan to completion on the calling thread's pool (no background thread).
///
/// # Errors
/// See [`SweepJob::outcome`].
pub fn run_plan(plan: SweepPlan) -> Result<SweepOutcome> {
    run(&plan, &SweepControl::new())
}

/// The rows of a sweep from JSON text (a list of rows of values, `null` keeping the base value).
///
/// # Errors
/// [`Error::InvalidParameter`] on `rows` when the text is not a JSON list of lists.
pub fn rows_from_json(text: &str) -> Result<Vec<Vec<Value>>> {
    serde_json::from_str(text)
        .map_err(|e| Error::invalid("rows", e.to_string(), "a JSON list of rows"))
}

/// A wait timeout from seconds (`None`: no limit).
///
/// # Errors
/// [`Error::InvalidParameter`] on `timeout` when it is negative or not finite.
pub fn timeout_from_seconds(timeout: Option<f64>) -> Result<Option<Duration>> {
    match timeout {
        None => Ok(None),
        Some(t) if t.is_finite() && t >= 0.0 => Ok(Some(Duration::from_secs_f64(t))),
        Some(t) => Err(Error::invalid("timeout", t, "None or finite and >= 0 (s)")),
    }
}
