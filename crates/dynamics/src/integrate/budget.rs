//! Per-run budget and cancellation, checked inside the integration loop.
//!
//! A run ([`crate::simulate()`]) installs a [`Budget`] on its thread for its duration
//! ([`Budget::enter`]); every integrator call on that thread (transient, shooting, recording)
//! checks it every [`CHECK_EVERY`] steps. A thread-local scope rather than a parameter: the
//! budget then reaches every integration a run makes (Newton shooting, variational flows)
//! without threading it through each call, and integrations outside a run are unaffected.

use std::cell::RefCell;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use paritysim_error::{Error, Result};

/// Steps between two checks of the budget (a check costs a clock read and an atomic load;
/// a step costs microseconds, so 32 steps keep the reaction well below a millisecond).
pub const CHECK_EVERY: usize = 32;

/// A cancel flag shared between a run and whoever may stop it (another thread, a signal
/// handler's poller). Equality is identity.
#[derive(Clone, Debug, Default)]
pub struct CancelFlag(Arc<AtomicBool>);

impl CancelFlag {
    /// A flag not yet set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Asks the runs holding this flag to stop at their next check.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Release);
    }

    /// Whether [`Self::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Acquire)
    }
}

impl PartialEq for CancelFlag {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// What a run may spend: a wall-clock deadline and a cancel flag.
#[derive(Clone, Debug, Default)]
pub struct Budget {
    deadline: Option<(Instant, f64)>,
    cancel: Option<CancelFlag>,
}

thread_local! {
    static CURRENT: RefCell<Option<Budget>> = const { RefCell::new(None) };
    static WATCH: RefCell<Option<Watch>> = const { RefCell::new(None) };
}

/// A poll run by the budget checks of the thread that installed it ([`watched`]), at most
/// once per `every`: a binding's signal check when the work runs on the caller's own thread.
struct Watch {
    poll: Box<dyn FnMut() -> bool>,
    every: Duration,
    next: Instant,
    cancel: CancelFlag,
}

/// Runs `work` on this thread with `cancel` installed as its budget (as [`cancellable`]) and
/// `poll` called from its budget checks on this thread, at most once per `every`; when `poll`
/// returns `true` (an interruption) `cancel` is set and the work stops at its next check.
/// Tasks the work hands to other threads ([`carry`]) see the flag but never run `poll`.
///
/// Why: a short call then needs no worker thread (measured: spawning and joining one costs
/// 20-400 µs of wall time on a loaded 2-core machine, against a 0.6 ms trial).
///
/// # Errors
/// Those of `work`; [`Error::Cancelled`] when `cancel` is set before `work` starts.
pub fn watched<T>(
    cancel: &CancelFlag,
    every: Duration,
    poll: impl FnMut() -> bool + 'static,
    work: impl FnOnce() -> Result<T>,
) -> Result<T> {
    struct Restore(Option<Watch>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let previous = self.0.take();
            WATCH.with(|w| *w.borrow_mut() = previous);
        }
    }
    let watch = Watch {
        poll: Box::new(poll),
        every,
        next: Instant::now() + every,
        cancel: cancel.clone(),
    };
    let _restore = Restore(WATCH.with(|w| w.borrow_mut().replace(watch)));
    cancellable(cancel, work)
}

/// Runs this thread's [`Watch`] when it is due. Taken out while it polls: the poll may run
/// code that checks a budget itself.
fn run_watch() {
    let Some(mut watch) = WATCH.with(|w| w.borrow_mut().take()) else {
        return;
    };
    let now = Instant::now();
    if now >= watch.next {
        watch.next = now + watch.every;
        if (watch.poll)() {
            watch.cancel.cancel();
        }
    }
    WATCH.with(|w| *w.borrow_mut() = Some(watch));
}

/// Restores the previous budget of the thread when dropped.
#[must_use = "the budget applies while the guard lives"]
pub struct BudgetGuard {
    previous: Option<Budget>,
}

impl Drop for BudgetGuard {
    fn drop(&mut self) {
        let previous = self.previous.take();
        CURRENT.with(|c| *c.borrow_mut() = previous);
    }
}

impl Budget {
    /// `max_wall_ms` from now (None or non-finite: no deadline) and an optional cancel flag.
    pub fn new(max_wall_ms: Option<f64>, cancel: Option<CancelFlag>) -> Self {
        Self {
            deadline: deadline(max_wall_ms),
            cancel,
        }
    }

    /// Installs this budget on the current thread until the guard drops. A budget already
    /// installed (an outer run) still applies: the earlier deadline wins and either cancel
    /// flag stops the run.
    pub fn enter(self) -> BudgetGuard {
        let previous = CURRENT.with(|c| c.borrow().clone());
        let merged = match &previous {
            None => self,
            Some(outer) => Budget {
                deadline: match (self.deadline, outer.deadline) {
                    (Some(a), Some(b)) => Some(if a.0 <= b.0 { a } else { b }),
                    (a, b) => a.or(b),
                },
                cancel: self.cancel.or_else(|| outer.cancel.clone()),
            },
        };
        CURRENT.with(|c| *c.borrow_mut() = Some(merged));
        BudgetGuard { previous }
    }

    /// The cancel flag, if the budget has one.
    pub(crate) fn cancel_flag(&self) -> Option<CancelFlag> {
        self.cancel.clone()
    }

    fn check(&self) -> Result<(), Stop> {
        if self.cancel.as_ref().is_some_and(CancelFlag::is_cancelled) {
            return Err(Stop::Cancelled);
        }
        match self.deadline {
            Some((deadline, ms)) if Instant::now() >= deadline => Err(Stop::Wall(ms)),
            _ => Ok(()),
        }
    }
}

/// The budget installed on the current thread (an outer run's), if any: hand it to
/// [`carry`] inside parallel tasks so their integrations see the same deadline and cancel flag.
pub fn current() -> Option<Budget> {
    CURRENT.with(|c| c.borrow().clone())
}

/// Runs `work` under `budget` (from [`current`] on the spawning thread): a rayon task runs on
/// another thread, where the thread-local budget of the run would otherwise be absent.
pub fn carry<T>(budget: &Option<Budget>, work: impl FnOnce() -> T) -> T {
    let _guard = budget.clone().map(Budget::enter);
    work()
}

/// Runs `work` with `cancel` installed (no deadline of its own; an outer budget still
/// applies): the one entry the bindings use to make any long call cancellable.
///
/// # Errors
/// Those of `work`; [`Error::Cancelled`] when `cancel` is set before `work` starts.
pub fn cancellable<T>(cancel: &CancelFlag, work: impl FnOnce() -> Result<T>) -> Result<T> {
    let _guard = Budget::new(None, Some(cancel.clone())).enter();
    check(0.0)?;
    work()
}

/// Why the current thread's budget stops a run.
pub(crate) enum Stop {
    Cancelled,
    /// The wall-clock budget (ms) is spent.
    Wall(f64),
}

/// The instant `max_wall_ms` from now, with the budget (None or non-finite: no deadline).
pub(crate) fn deadline(max_wall_ms: Option<f64>) -> Option<(Instant, f64)> {
    max_wall_ms
        .filter(|ms| ms.is_finite() && *ms > 0.0)
        .and_then(|ms| {
            Instant::now()
                .checked_add(Duration::from_secs_f64(ms / 1e3))
                .map(|d| (d, ms))
        })
}

/// Checks the current thread's budget (no budget: always fine).
pub(crate) fn check_current() -> Result<(), Stop> {
    run_watch();
    CURRENT.with(|c| c.borrow().as_ref().map_or(Ok(()), Budget::check))
}

/// The error of a [`Stop`] at time `t` (ms) with `state`.
pub(crate) fn stop_error(stop: Stop, time: f64, state: Vec<f64>) -> Error {
    match stop {
        Stop::Cancelled => Error::Cancelled,
        Stop::Wall(ms) => Error::Integration {
            time,
            state,
            reason: format!(
                "exceeded the wall-time budget `options.max_wall_ms` = {ms} ms \
                 (raise it, or make the point cheaper)"
            ),
        },
    }
}

/// Checks the current thread's budget between integrator calls.
///
/// # Errors
/// [`Error::Cancelled`] when the run's cancel flag is set; [`Error::Integration`] naming
/// `options.max_wall_ms` when its deadline has passed.
pub fn check(time: f64) -> Result<()> {
    check_current().map_err(|s| stop_error(s, time, Vec::new()))
}
