//! The stability module's parameter loops on the sweep engine: one row per parameter value,
//! a failing value a row with its error, on the sweep's own thread pool.

use paritysim_error::{Error, Result};

use crate::integrate::budget;
use crate::sweep::{SweepControl, resolve_threads, run_indexed};

/// One row per parameter value: the value's result or the error that stopped it.
pub type Rows<T> = Vec<Result<T>>;

/// Runs `point(i)` for `i in 0..n` through [`run_indexed`] (the sweep engine: its own rayon
/// pool of [`resolve_threads`]`(threads)` threads, never the global one; a panic is caught as
/// that row's error), under the caller's wall budget and cancel flag. A failing point's error
/// is located as `array[i]` (with `array` given; else left as `point` located it) and kept in
/// its row; the other rows are kept.
///
/// # Errors
/// [`Error::Cancelled`] when the caller's budget is cancelled (no new point starts once a
/// running one saw it); [`Error::InvalidParameter`] for a bad `PARITYSIM_THREADS`.
pub fn run_rows<T, F>(
    n: usize,
    threads: Option<usize>,
    array: Option<&str>,
    point: F,
) -> Result<Rows<T>>
where
    T: Send,
    F: Fn(usize) -> Result<T> + Sync,
{
    let run_budget = budget::current();
    let threads = resolve_threads(threads)?;
    let control = SweepControl::new();
    let slots = run_indexed(n, threads, &control, |i| {
        let out = budget::carry(&run_budget, || point(i));
        match out {
            Err(Error::Cancelled) => {
                // The caller's cancel: the points not yet started do not start.
                control.cancel();
                Err(Error::Cancelled)
            }
            other => other.map_err(|e| match array {
                Some(name) => e.at_index(i, Some(name)),
                None => e,
            }),
        }
    })?;
    let rows: Rows<T> = slots
        .into_iter()
        .map(|slot| slot.unwrap_or(Err(Error::Cancelled)))
        .collect();
    if rows.iter().any(|r| matches!(r, Err(Error::Cancelled))) {
        return Err(Error::Cancelled);
    }
    Ok(rows)
}

/// The independent parts `part(i)`, `i in 0..n`, of one analysis (the two monodromies of
/// [`super::floquet`], the columns of [`super::map_jacobian`], the two signs of
/// [`super::disturbance_response`]), all under the caller's wall budget and cancel flag
/// ([`budget::carry`]).
///
/// Where they run: called from a pool thread (a point of a sweep, or a part of an outer
/// analysis) on that pool, whose threads the sweep already budgets; from a plain call on the
/// sweep engine's own pool ([`run_rows`]), never rayon's global one, unless the engine has one
/// thread ([`resolve_threads`]); a single part, or every part with one engine thread, on the
/// calling thread in index order.
///
/// # Errors
/// The first failing part's error (in index order); [`Error::Cancelled`] as [`run_rows`];
/// [`Error::InvalidParameter`] for a bad `PARITYSIM_THREADS`.
pub(crate) fn run_parts<T, F>(n: usize, part: F) -> Result<Vec<T>>
where
    T: Send,
    F: Fn(usize) -> Result<T> + Sync,
{
    if n == 1 {
        // One part: on this thread, under its own budget (no hand-off to a pool and back).
        return Ok(vec![part(0)?]);
    }
    if rayon::current_thread_index().is_some() {
        return run_parts_on(n, None, part);
    }
    run_parts_on(n, Some(resolve_threads(None)?), part)
}

/// [`run_parts`] from a pool thread (`threads`: `None`) or from a plain call with `threads`
/// engine threads. One thread runs the parts here: the hand-off to the pool's one worker and
/// back cost about 0.3 ms of wall time a sensitivity of three or more parameters
/// (docs/findings.md §30, session 27). A panicking part then unwinds to the caller (as a
/// single part always did), where the bindings catch it.
fn run_parts_on<T, F>(n: usize, threads: Option<usize>, part: F) -> Result<Vec<T>>
where
    T: Send,
    F: Fn(usize) -> Result<T> + Sync,
{
    use rayon::prelude::*;
    match threads {
        None => {
            let run_budget = budget::current();
            (0..n)
                .into_par_iter()
                .map(|i| budget::carry(&run_budget, || part(i)))
                .collect()
        }
        Some(1) => (0..n).map(part).collect(),
        Some(threads) => run_rows(n, Some(threads), None, part)?
            .into_iter()
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::{run_parts, run_parts_on, run_rows};

    #[test]
    fn with_one_engine_thread_the_parts_run_on_the_calling_thread_in_order() {
        let caller = std::thread::current().id();
        let order = std::sync::Mutex::new(Vec::new());
        let ids = run_parts_on(5, Some(1), |i| {
            order.lock().unwrap().push(i);
            Ok(std::thread::current().id())
        })
        .unwrap();
        assert!(ids.iter().all(|id| *id == caller));
        assert_eq!(*order.lock().unwrap(), vec![0, 1, 2, 3, 4]);
        // The first failing part stops the rest, and its error is the call's.
        let seen = std::sync::Mutex::new(Vec::new());
        let err = run_parts_on(4, Some(1), |i| {
            seen.lock().unwrap().push(i);
            if i == 1 {
                Err(paritysim_error::Error::invalid("part", i, "not 1"))
            } else {
                Ok(i)
            }
        })
        .unwrap_err();
        assert_eq!(err.kind(), "InvalidParameter");
        assert_eq!(*seen.lock().unwrap(), vec![0, 1]);
        // With two, they run on the engine's pool, not here.
        let ids = run_parts_on(4, Some(2), |_| Ok(std::thread::current().id())).unwrap();
        assert!(ids.iter().all(|id| *id != caller));
    }

    #[test]
    fn the_parts_of_a_row_run_on_the_rows_threads() {
        // One thread for the rows: each row's parts share it (no pool of every core).
        for threads in [1, 2] {
            let rows = run_rows(3, Some(threads), None, |_| {
                run_parts(4, |_| Ok(rayon::current_num_threads()))
            })
            .unwrap();
            for row in rows {
                assert_eq!(row.unwrap(), vec![threads; 4]);
            }
        }
    }
}
