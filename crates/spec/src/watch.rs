//! Running work on a worker thread while the calling thread polls for an interruption (a
//! language binding polls for Ctrl-C): on an interruption the work's [`CancelFlag`] is set, the
//! work stops at its next budget check, and the interruption is returned.

use std::cell::RefCell;
use std::panic::AssertUnwindSafe;
use std::rc::Rc;
use std::sync::mpsc::{RecvTimeoutError, channel};
use std::time::Duration;

use paritysim_dynamics::CancelFlag;
use paritysim_dynamics::integrate::budget;
use paritysim_error::{Error, Result};

/// Runs `work` on a scoped worker thread; every `every` calls `poll`, and on its first `Err`
/// sets `cancel`, waits for the worker to stop and returns that `Err`. Otherwise returns the
/// work's result (a panic in the work becomes [`Error::Integration`]).
///
/// # Errors
/// The interruption from `poll` (outer), or the work's own error (inner).
pub fn run_watched<T: Send, E>(
    cancel: &CancelFlag,
    every: Duration,
    mut poll: impl FnMut() -> std::result::Result<(), E>,
    work: impl FnOnce() -> Result<T> + Send,
) -> std::result::Result<Result<T>, E> {
    std::thread::scope(|scope| {
        let (done_tx, done_rx) = channel::<()>();
        let worker = scope.spawn(move || {
            let out = work();
            let _ = done_tx.send(());
            out
        });
        let mut interrupted = None;
        loop {
            match done_rx.recv_timeout(every) {
                Err(RecvTimeoutError::Timeout) if interrupted.is_none() => {
                    if let Err(e) = poll() {
                        cancel.cancel();
                        interrupted = Some(e);
                    }
                }
                Err(RecvTimeoutError::Timeout) => {}
                _ => break,
            }
        }
        let out = worker.join().unwrap_or_else(|_| Err(panicked()));
        match interrupted {
            Some(e) => Err(e),
            None => Ok(out),
        }
    })
}

/// A panic in the work, as an error (no panic crosses into a binding).
fn panicked() -> Error {
    Error::Integration {
        time: f64::NAN,
        state: Vec::new(),
        reason: "internal error (panic) in the simulation".into(),
    }
}

/// [`run_watched`] without a worker thread: `work` runs on this thread and `poll` is called
/// from its budget checks ([`budget::watched`]), at most once per `every`; on its first `Err`
/// `cancel` is set, the work stops at its next check and that `Err` is returned. For a call
/// whose work stays on the calling thread (one simulation): spawning and joining a thread
/// costs more than a short trial's set-up (20-400 µs measured on a 2-core machine). Work
/// handed to other threads sees `cancel` but never polls.
///
/// # Errors
/// The interruption from `poll` (outer), or the work's own error (inner; a panic becomes
/// [`Error::Integration`]).
pub fn run_inline<T, E: 'static>(
    cancel: &CancelFlag,
    every: Duration,
    mut poll: impl FnMut() -> std::result::Result<(), E> + 'static,
    work: impl FnOnce() -> Result<T>,
) -> std::result::Result<Result<T>, E> {
    let interruption = Rc::new(RefCell::new(None));
    let slot = Rc::clone(&interruption);
    let polled = move || match poll() {
        Ok(()) => false,
        Err(e) => {
            slot.borrow_mut().get_or_insert(e);
            true
        }
    };
    let out = std::panic::catch_unwind(AssertUnwindSafe(|| {
        budget::watched(cancel, every, polled, work)
    }))
    .unwrap_or_else(|_| Err(panicked()));
    match interruption.borrow_mut().take() {
        Some(e) => Err(e),
        None => Ok(out),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_interruption_cancels_the_work_and_is_returned() {
        let cancel = CancelFlag::new();
        let flag = cancel.clone();
        let mut polls = 0;
        let out = run_watched(
            &cancel,
            Duration::from_millis(1),
            || {
                polls += 1;
                if polls >= 3 {
                    Err("interrupted")
                } else {
                    Ok(())
                }
            },
            move || {
                while !flag.is_cancelled() {
                    std::thread::sleep(Duration::from_millis(1));
                }
                Err::<(), _>(Error::Cancelled)
            },
        );
        assert_eq!(out.unwrap_err(), "interrupted");
        assert!(cancel.is_cancelled());
    }

    #[test]
    fn without_an_interruption_the_work_result_is_returned() {
        let cancel = CancelFlag::new();
        let out = run_watched(
            &cancel,
            Duration::from_millis(1),
            || Ok::<(), ()>(()),
            || Ok(7),
        );
        assert_eq!(out.unwrap().unwrap(), 7);
        assert!(!cancel.is_cancelled());
    }

    #[test]
    fn inline_polls_from_the_budget_checks_and_returns_the_interruption() {
        use paritysim_dynamics::integrate::budget::check;
        let cancel = CancelFlag::new();
        let polls = Rc::new(RefCell::new(0));
        let counted = Rc::clone(&polls);
        let out = run_inline(
            &cancel,
            Duration::ZERO,
            move || {
                *counted.borrow_mut() += 1;
                if *counted.borrow() >= 3 {
                    Err("interrupted")
                } else {
                    Ok(())
                }
            },
            // A "integration" checking its budget until it is stopped.
            move || loop {
                check(0.0)?;
            },
        );
        assert_eq!(out.map(|_: Result<()>| ()).unwrap_err(), "interrupted");
        assert!(cancel.is_cancelled());
    }

    #[test]
    fn inline_returns_the_work_result_and_turns_a_panic_into_an_error() {
        let cancel = CancelFlag::new();
        let ok = run_inline(&cancel, Duration::ZERO, || Ok::<(), ()>(()), || Ok(7));
        assert_eq!(ok.unwrap().unwrap(), 7);
        let panicked = run_inline(
            &cancel,
            Duration::ZERO,
            || Ok::<(), ()>(()),
            || -> Result<()> { panic!("a bug") },
        );
        assert!(matches!(panicked.unwrap(), Err(Error::Integration { .. })));
        assert!(!cancel.is_cancelled());
        // The watch is gone after the call: a budget check outside polls nothing.
        assert!(paritysim_dynamics::integrate::budget::check(0.0).is_ok());
    }
}
