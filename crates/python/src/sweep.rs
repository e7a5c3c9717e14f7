//! Bindings for the sweep engine (prefix `sweep_`; the run handle is `SweepRun`).
//!
//! Python builds one device dict per point (overrides applied to the base spec's dict), this
//! module parses them with the GIL held (a point that does not parse becomes an error row), then
//! [`SweepRun::start`] runs them on a background thread with a local rayon pool, without the GIL.
//! Python polls [`SweepRun::finished`] for its progress bar and calls [`SweepRun::cancel`] on
//! Ctrl-C; [`SweepRun::result`] returns the finished rows in input order as numpy arrays.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use numpy::PyArray1;
use paritysim_dynamics::sweep::{
    self, PointOutput, SweepControl, THREADS_ENV, metric_names, resolve_threads, trajectory_columns,
};
use paritysim_dynamics::{Device, Error, Result, SimulationOptions};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::convert::shaped;
use crate::dynamics::{parse_device, parse_options};
use crate::errors::IntoPyResult;

type Points = Vec<Result<(Device, SimulationOptions)>>;
type Slots = Vec<Option<Result<PointOutput>>>;

enum State {
    Ready(Points),
    Running(JoinHandle<Result<Slots>>),
    Joining,
    Done(Result<Slots>),
}

/// A batch of sweep points and its background run: progress counter, cancel flag, results.
#[pyclass(module = "paritysim._core", frozen)]
pub struct SweepRun {
    total: usize,
    metrics: Vec<String>,
    columns: Vec<String>,
    keep_cycle: bool,
    threads: usize,
    control: Arc<SweepControl>,
    /// Set by the worker thread when it returns.
    worker_done: Arc<AtomicBool>,
    state: Mutex<State>,
}

fn lock(m: &Mutex<State>) -> MutexGuard<'_, State> {
    // A poisoned lock only means a panic elsewhere while holding it; the state is still usable.
    m.lock().unwrap_or_else(|p| p.into_inner())
}

impl SweepRun {
    /// Joins the worker (GIL released) and stores its outcome. The state lock is never held
    /// while the GIL is released, so concurrent Python callers cannot deadlock.
    fn join(&self, py: Python<'_>) {
        loop {
            let handle = {
                let mut state = lock(&self.state);
                match &*state {
                    State::Ready(_) | State::Done(_) => return,
                    State::Joining => None,
                    State::Running(_) => match std::mem::replace(&mut *state, State::Joining) {
                        State::Running(handle) => Some(handle),
                        _ => unreachable!(),
                    },
                }
            };
            match handle {
                Some(handle) => {
                    let outcome = py.detach(|| handle.join()).unwrap_or_else(|_| {
                        Err(Error::Integration {
                            time: f64::NAN,
                            state: Vec::new(),
                            reason: "internal error (panic) in the sweep thread".into(),
                        })
                    });
                    *lock(&self.state) = State::Done(outcome);
                    return;
                }
                // Another Python thread is joining: wait for it.
                None => py.detach(|| std::thread::sleep(Duration::from_millis(1))),
            }
        }
    }

    fn start_locked(&self, state: &mut State) -> PyResult<()> {
        if !matches!(state, State::Ready(_)) {
            return Err(PyRuntimeError::new_err("this SweepRun was already started"));
        }
        let State::Ready(points) = std::mem::replace(state, State::Done(Ok(vec![]))) else {
            unreachable!()
        };
        let (metrics, keep_cycle, threads) = (self.metrics.clone(), self.keep_cycle, self.threads);
        let control = Arc::clone(&self.control);
        let done = Arc::clone(&self.worker_done);
        let handle = std::thread::Builder::new()
            .name("paritysim-sweep".into())
            .spawn(move || {
                let out = sweep::run_points(&points, &metrics, keep_cycle, Some(threads), &control);
                done.store(true, Ordering::Release);
                out
            })
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start the sweep thread: {e}")))?;
        *state = State::Running(handle);
        Ok(())
    }
}

impl Drop for SweepRun {
    fn drop(&mut self) {
        // Never leave a detached worker behind: stop scheduling and wait for running points.
        self.control.cancel();
        let state = self.state.get_mut().unwrap_or_else(|p| p.into_inner());
        if let State::Running(_) = state {
            if let State::Running(handle) = std::mem::replace(state, State::Done(Ok(vec![]))) {
                let _ = handle.join();
            }
        }
    }
}

#[pymethods]
impl SweepRun {
    /// Parses the points (one device dict each) with their options (one dict for all, or one
    /// per point). A device that does not parse becomes that point's error; bad shared options
    /// or metric names raise here, before anything runs.
    #[new]
    #[pyo3(signature = (devices, options, metrics=None, keep_cycle=false, threads=None))]
    fn new(
        devices: &Bound<'_, PyList>,
        options: &Bound<'_, PyAny>,
        metrics: Option<Vec<String>>,
        keep_cycle: bool,
        threads: Option<usize>,
    ) -> PyResult<Self> {
        let threads = resolve_threads(threads).py_err()?;
        let mut parsed: Vec<Result<Device>> = Vec::with_capacity(devices.len());
        for (i, d) in devices.iter().enumerate() {
            parsed.push(match d.cast_into::<PyDict>() {
                Ok(d) => parse_device(&d),
                Err(_) => Err(Error::invalid(
                    format!("devices[{i}]"),
                    "not a dict",
                    "a device spec dict",
                )),
            });
        }
        let first = parsed.iter().find_map(|d| d.as_ref().ok());
        let n_coords = first.map_or(6, Device::n_coords);
        let valid = first.map(metric_names).unwrap_or_default();
        let metrics = match (&metrics, first) {
            (Some(m), Some(_)) => sweep::select("metrics", Some(m), &valid).py_err()?,
            (Some(m), None) => m.clone(),
            (None, _) => valid,
        };
        let columns = first.map(trajectory_columns).unwrap_or_default();
        let points: Points = if let Ok(shared) = options.cast::<PyDict>() {
            let opts = parse_options(shared, n_coords).py_err()?;
            parsed
                .into_iter()
                .map(|d| d.map(|d| (d, opts.clone())))
                .collect()
        } else {
            let list = options.cast::<PyList>().map_err(|_| {
                crate::errors::to_pyerr(Error::invalid(
                    "options",
                    "neither a dict nor a list",
                    "an options dict or one per point",
                ))
            })?;
            if list.len() != parsed.len() {
                return Err(crate::errors::to_pyerr(Error::Shape(format!(
                    "{} option dicts for {} points",
                    list.len(),
                    parsed.len()
                ))));
            }
            parsed
                .into_iter()
                .zip(list.iter())
                .map(|(d, o)| {
                    let d = d?;
                    let o = o
                        .cast_into::<PyDict>()
                        .map_err(|_| Error::invalid("options", "not a dict", "an options dict"))?;
                    let opts = parse_options(&o, d.n_coords())?;
                    Ok((d, opts))
                })
                .collect()
        };
        Ok(Self {
            total: points.len(),
            metrics,
            columns,
            keep_cycle,
            threads,
            control: Arc::new(SweepControl::new()),
            worker_done: Arc::new(AtomicBool::new(false)),
            state: Mutex::new(State::Ready(points)),
        })
    }

    /// Starts the run on a background thread (the GIL is not needed while it runs).
    fn start(&self) -> PyResult<()> {
        let mut state = lock(&self.state);
        self.start_locked(&mut state)
    }

    /// Stops scheduling new points; running points finish and are kept.
    fn cancel(&self) {
        self.control.cancel();
    }

    /// Waits up to `timeout` seconds (None: until done) with the GIL released; True when done.
    #[pyo3(signature = (timeout=None))]
    fn wait(&self, py: Python<'_>, timeout: Option<f64>) -> PyResult<bool> {
        let deadline = match timeout {
            None => None,
            Some(t) if t.is_finite() && t >= 0.0 => {
                Some(Instant::now() + Duration::from_secs_f64(t))
            }
            Some(t) => {
                return Err(crate::errors::to_pyerr(Error::invalid(
                    "timeout",
                    t,
                    "None or finite and >= 0 (s)",
                )));
            }
        };
        if matches!(&*lock(&self.state), State::Ready(_)) {
            return Err(PyRuntimeError::new_err("this SweepRun was not started"));
        }
        let done = Arc::clone(&self.worker_done);
        let finished = py.detach(move || {
            loop {
                if done.load(Ordering::Acquire) {
                    return true;
                }
                if deadline.is_some_and(|d| Instant::now() >= d) {
                    return false;
                }
                std::thread::sleep(Duration::from_millis(1));
            }
        });
        if finished {
            self.join(py);
        }
        Ok(finished)
    }

    /// Number of points.
    #[getter]
    fn total(&self) -> usize {
        self.total
    }

    /// Points finished so far (successfully or not).
    #[getter]
    fn finished(&self) -> usize {
        self.control.finished()
    }

    /// Whether the run was cancelled.
    #[getter]
    fn cancelled(&self) -> bool {
        self.control.is_cancelled()
    }

    /// Threads of the local pool.
    #[getter]
    fn threads(&self) -> usize {
        self.threads
    }

    /// Reported metric names (the columns of `result()["metrics"]`).
    #[getter]
    fn metric_names(&self) -> Vec<String> {
        self.metrics.clone()
    }

    /// Waits for the run (starting it if needed) and returns, over all points in input order:
    /// `finished` and `ok` (bool arrays), `metrics` (float array `(n, len(metric_names))`,
    /// NaN where not ok), `converged` (bool), `cycles_run` (int, -1 where not ok), `error` and
    /// `error_kind` (lists of str or None) and, with `keep_cycle`, `cycle`: a dict from
    /// `time_ms` and every trajectory column to a list of arrays (None where not ok).
    fn result<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        {
            let mut state = lock(&self.state);
            if matches!(&*state, State::Ready(_)) {
                self.start_locked(&mut state)?;
            }
        }
        self.join(py);
        let state = lock(&self.state);
        let State::Done(outcome) = &*state else {
            return Err(PyRuntimeError::new_err("the sweep did not finish"));
        };
        let slots = outcome
            .as_ref()
            .map_err(|e| crate::errors::to_pyerr(e.clone()))?;
        let n = slots.len();
        let m = self.metrics.len();
        let mut finished = vec![false; n];
        let mut ok = vec![false; n];
        let mut metrics = vec![f64::NAN; n * m];
        let mut converged = vec![false; n];
        let mut cycles = vec![-1_i64; n];
        let errors = PyList::empty(py);
        let kinds = PyList::empty(py);
        for (i, slot) in slots.iter().enumerate() {
            finished[i] = slot.is_some();
            match slot {
                Some(Ok(out)) => {
                    ok[i] = true;
                    metrics[i * m..(i + 1) * m].copy_from_slice(&out.metrics);
                    converged[i] = out.converged;
                    cycles[i] = out.cycles_run as i64;
                    errors.append(py.None())?;
                    kinds.append(py.None())?;
                }
                Some(Err(e)) => {
                    errors.append(e.to_string())?;
                    kinds.append(e.kind())?;
                }
                None => {
                    errors.append(py.None())?;
                    kinds.append(py.None())?;
                }
            }
        }
        let out = PyDict::new(py);
        out.set_item("finished", PyArray1::from_vec(py, finished))?;
        out.set_item("ok", PyArray1::from_vec(py, ok))?;
        out.set_item("metrics", shaped(py, metrics, &[n, m])?)?;
        out.set_item("converged", PyArray1::from_vec(py, converged))?;
        out.set_item("cycles_run", PyArray1::from_vec(py, cycles))?;
        out.set_item("error", errors)?;
        out.set_item("error_kind", kinds)?;
        if self.keep_cycle {
            let cycle = PyDict::new(py);
            let names: Vec<&str> = std::iter::once("time_ms")
                .chain(self.columns.iter().map(String::as_str))
                .collect();
            for (k, name) in names.iter().enumerate() {
                let list = PyList::empty(py);
                for slot in slots {
                    match slot {
                        Some(Ok(PointOutput {
                            cycle: Some(traj), ..
                        })) => {
                            let values = if k == 0 {
                                traj.time.clone()
                            } else {
                                traj.columns[k - 1].1.clone()
                            };
                            list.append(PyArray1::from_vec(py, values))?;
                        }
                        _ => list.append(py.None())?,
                    }
                }
                cycle.set_item(*name, list)?;
            }
            out.set_item("cycle", cycle)?;
        }
        Ok(out)
    }
}

/// Metric names `simulate` reports for a device spec dict, in order.
#[pyfunction]
fn sweep_metric_names(spec: &Bound<'_, PyDict>) -> PyResult<Vec<String>> {
    Ok(metric_names(&parse_device(spec).py_err()?))
}

/// Trajectory column names (without `time_ms`) recorded for a device spec dict, in order.
#[pyfunction]
fn sweep_trajectory_columns(spec: &Bound<'_, PyDict>) -> PyResult<Vec<String>> {
    Ok(trajectory_columns(&parse_device(spec).py_err()?))
}

/// The thread count a sweep would use: `threads`, else `$PARITYSIM_THREADS`, else all cores.
#[pyfunction]
#[pyo3(signature = (threads=None))]
fn sweep_resolve_threads(threads: Option<usize>) -> PyResult<usize> {
    resolve_threads(threads).py_err()
}

/// Adds the sweep functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<SweepRun>()?;
    m.add("SWEEP_THREADS_ENV", THREADS_ENV)?;
    m.add_function(wrap_pyfunction!(sweep_metric_names, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_trajectory_columns, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_resolve_threads, m)?)?;
    Ok(())
}
