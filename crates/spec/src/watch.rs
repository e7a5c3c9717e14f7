//! Running work on a worker thread while the calling thread polls for an interruption (a
//! language binding polls for Ctrl-C): on an interruption the work's [`CancelFlag`] is set, the
//! work stops at its next budget check, and the interruption is returned.

use std::sync::mpsc::{RecvTimeoutError, channel};
use std::time::Duration;

use paritysim_dynamics::CancelFlag;
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
        let out = worker.join().unwrap_or_else(|_| {
            Err(Error::Integration {
                time: f64::NAN,
                state: Vec::new(),
                reason: "internal error (panic) in the simulation thread".into(),
            })
        });
        match interrupted {
            Some(e) => Err(e),
            None => Ok(out),
        }
    })
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
}
