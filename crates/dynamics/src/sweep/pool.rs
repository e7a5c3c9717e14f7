//! The sweep's thread pool, cancellation and panic-safe indexed tasks.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

use paritysim_error::{Error, Result, bail};

use crate::integrate::budget::{Budget, CancelFlag};

/// Environment variable read by [`resolve_threads`] when no thread count is given:
/// a positive integer (`PARITYSIM_THREADS=4`).
pub const THREADS_ENV: &str = "PARITYSIM_THREADS";

/// Largest accepted thread count (a sanity bound against typos such as `threads=10000`).
pub const MAX_THREADS: usize = 1024;

/// The thread count a sweep uses: `requested` if given, else [`THREADS_ENV`], else the number
/// of available cores.
///
/// # Errors
/// [`Error::InvalidParameter`] for `0`, more than [`MAX_THREADS`], or an environment value that
/// is not such an integer (the message names `threads` or `PARITYSIM_THREADS`).
pub fn resolve_threads(requested: Option<usize>) -> Result<usize> {
    let allowed = format!("an integer in [1, {MAX_THREADS}]");
    if let Some(n) = requested {
        if !(1..=MAX_THREADS).contains(&n) {
            bail!(invalid "threads", n, allowed);
        }
        return Ok(n);
    }
    if let Ok(raw) = std::env::var(THREADS_ENV) {
        let raw = raw.trim();
        if !raw.is_empty() {
            return match raw.parse::<usize>() {
                Ok(n) if (1..=MAX_THREADS).contains(&n) => Ok(n),
                _ => Err(Error::invalid(THREADS_ENV, format!("{raw:?}"), allowed)),
            };
        }
    }
    Ok(std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// Progress counter and cancel flag shared between a running sweep and its observers
/// (wrap it in an `Arc` to share it with another thread).
#[derive(Debug, Default)]
pub struct SweepControl {
    finished: AtomicUsize,
    cancelled: CancelFlag,
}

impl SweepControl {
    /// A fresh control: nothing finished, not cancelled.
    pub fn new() -> Self {
        Self::default()
    }

    /// A control whose cancel flag is the calling thread's budget's ([`budget::current`]),
    /// if it has one: a sweep run inside a cancellable call (a binding's Ctrl-C) stops with
    /// it.
    ///
    /// [`budget::current`]: crate::integrate::budget::current
    pub fn of_current_budget() -> Self {
        Self {
            finished: AtomicUsize::new(0),
            cancelled: crate::integrate::budget::current()
                .and_then(|b| b.cancel_flag())
                .unwrap_or_default(),
        }
    }

    /// Points finished so far (successfully or not).
    pub fn finished(&self) -> usize {
        self.finished.load(Ordering::Acquire)
    }

    /// Counts one finished point unless it was stopped by the cancel (then it did not finish).
    pub(crate) fn count_point<T>(&self, result: &Result<T>) {
        if !(matches!(result, Err(Error::Cancelled)) && self.is_cancelled()) {
            self.finished.fetch_add(1, Ordering::AcqRel);
        }
    }

    /// Stops scheduling new points and stops the running ones at their next budget check
    /// (they are reported as not run).
    pub fn cancel(&self) {
        self.cancelled.cancel();
    }

    /// Whether [`SweepControl::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.cancelled.is_cancelled()
    }
}

/// Runs `f(0..n)` on a pool of `threads` threads; slot `i` holds `f(i)`, or `None` when the
/// point was not started because the sweep was cancelled. A panic in `f` becomes an
/// [`Error::Integration`] whose reason starts with `internal error (panic)`.
///
/// # Errors
/// [`Error::InvalidParameter`] for a bad thread count; the pool itself failing to start is
/// reported the same way (`threads`).
pub fn run_indexed<T, F>(
    n: usize,
    threads: usize,
    control: &SweepControl,
    f: F,
) -> Result<Vec<Option<Result<T>>>>
where
    T: Send,
    F: Fn(usize) -> Result<T> + Sync,
{
    run_tasks(n, threads, control, true, f)
}

/// [`run_indexed`]; `count`: whether a finished task counts as one finished point (a chain
/// of points counts its points itself).
pub(crate) fn run_tasks<T, F>(
    n: usize,
    threads: usize,
    control: &SweepControl,
    count: bool,
    f: F,
) -> Result<Vec<Option<Result<T>>>>
where
    T: Send,
    F: Fn(usize) -> Result<T> + Sync,
{
    let threads = resolve_threads(Some(threads))?;
    let one = |i: usize| -> Option<Result<T>> {
        if control.is_cancelled() {
            return None;
        }
        // The sweep's cancel flag reaches the integrator of a running point too.
        let _budget = Budget::new(None, Some(control.cancelled.clone())).enter();
        let out = catch_unwind(AssertUnwindSafe(|| f(i))).unwrap_or_else(|payload| {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| (*s).to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(Error::Integration {
                time: f64::NAN,
                state: Vec::new(),
                reason: format!("internal error (panic) at sweep point {i}: {what}"),
            })
        });
        if matches!(out, Err(Error::Cancelled)) && control.is_cancelled() {
            // Stopped mid-run by the cancel: not finished (a resume recomputes it).
            return None;
        }
        if count {
            control.finished.fetch_add(1, Ordering::AcqRel);
        }
        Some(out)
    };
    // A pool even for one thread: the parallel parts of a point (a sensitivity's columns,
    // `stability::rows::run_parts`) then run inside it, on the sweep's threads, instead of
    // opening a pool of every core from the calling thread.
    let pool = pool_of(threads)?;
    // One point per task: points take milliseconds, so scheduling overhead is negligible and
    // fine-grained stealing keeps both ends of the run busy.
    Ok(pool.install(|| (0..n).into_par_iter().with_max_len(1).map(one).collect()))
}

/// The process's pool of `threads` threads, built on first use: a sensitivity runs its
/// parameter groups on one per call, and a pool built per call started its threads anew each
/// time.
///
/// # Errors
/// [`Error::InvalidParameter`] when the OS cannot start the threads.
fn pool_of(threads: usize) -> Result<std::sync::Arc<rayon::ThreadPool>> {
    type Pools = Vec<(u32, usize, std::sync::Arc<rayon::ThreadPool>)>;
    static POOLS: std::sync::Mutex<Pools> = std::sync::Mutex::new(Vec::new());
    let pid = std::process::id();
    let mut pools = POOLS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    // A forked child (a process pool's worker) has none of its parent's threads: its pools
    // are forgotten, not shut down.
    let (stale, own): (Pools, Pools) = std::mem::take(&mut *pools)
        .into_iter()
        .partition(|(owner, _, _)| *owner != pid);
    std::mem::forget(stale);
    *pools = own;
    if let Some((_, _, pool)) = pools.iter().find(|(_, n, _)| *n == threads) {
        return Ok(pool.clone());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("paritysim-sweep-{i}"))
        .build()
        .map_err(|e| {
            Error::invalid(
                "threads",
                threads,
                format!("a count the OS can start ({e})"),
            )
        })?;
    let pool = std::sync::Arc::new(pool);
    pools.push((pid, threads, pool.clone()));
    Ok(pool)
}
