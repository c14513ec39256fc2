//! Ctrl-C for long calls. [`interruptible`] runs the work without the GIL on a worker
//! thread while the calling thread waits for it and, every [`POLL`], runs Python's signal
//! handlers: when one raises (Ctrl-C's `KeyboardInterrupt`), the stop flag handed to the
//! work is raised, the worker is joined and the exception is raised in Python. The work
//! ends early by checking the flag: [`par_rows`] checks it before every chunk of rows,
//! so a batch stops within one chunk's time. Calls too small to be worth a thread
//! ([`detached`] with `long = false`) just release the GIL.
//!
//! The batch functions (`fk_batch`, `jacobian_batch`, `gravity_batch`, `ik_batch`,
//! `sample_poses`), `workspace` (through `WorkspaceOptions::stop`), `run_scenario`
//! (through `RunOptions::stop`) and the planner use it; any other loop can, with
//! `stop.load(Relaxed)` where it can stop.

use crate::errors::err;
use armsim::{Data, Model};
use pyo3::prelude::*;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

/// How often the waiting thread runs Python's signal handlers.
pub const POLL: Duration = Duration::from_millis(20);

/// Rows per rayon task in [`par_rows`] (one `Data` each; the stop flag is read per task).
const CHUNK: usize = 32;

/// The error of work that saw the stop flag (never reaches Python: [`interruptible`]
/// raises the signal handler's exception instead).
pub const CANCELLED: &str = "cancelled by a signal";

/// Work units (rows × bodies, or rows × output values when more) above which a batch
/// runs interruptibly: below, it takes milliseconds and a worker thread would only add
/// its start-up time. Bodies, not coordinates: mimic joints are bodies without one.
pub const LONG_WORK: usize = 1 << 15;

/// Whether `rows` rows of `width` output values on `model` are [`LONG_WORK`] or more.
pub fn is_long(model: &Model, rows: usize, width: usize) -> bool {
    rows.saturating_mul(model.nbodies().max(width).max(1)) >= LONG_WORK
}

/// Whether the stop flag is raised.
pub fn stopped(stop: &AtomicBool) -> bool {
    stop.load(Ordering::Relaxed)
}

/// Runs `work` on a worker thread without the GIL; this thread runs Python's signal
/// handlers every [`POLL`] until the work ends. When a handler raises (Ctrl-C), the flag
/// given to `work` is raised, the worker is joined and the handler's exception returned.
pub fn interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(Arc<AtomicBool>) -> T + Send,
) -> PyResult<T> {
    let stop = Arc::new(AtomicBool::new(false));
    let done = Done::default();
    std::thread::scope(|sc| {
        let flag = stop.clone();
        let handle = sc.spawn(|| {
            // Signalled even when `work` panics (the guard's drop), so no wait hangs.
            let _guard = DoneGuard(&done);
            work(flag)
        });
        while !py.detach(|| done.wait(POLL)) {
            if let Err(e) = py.check_signals() {
                stop.store(true, Ordering::Relaxed);
                let _ = py.detach(|| handle.join());
                return Err(e);
            }
        }
        py.detach(|| handle.join())
            .map_err(|_| err("the worker thread panicked"))
    })
}

/// The worker's end, waited for with a timeout.
#[derive(Default)]
struct Done {
    ended: Mutex<bool>,
    cv: Condvar,
}

impl Done {
    /// Whether the worker has ended, waiting up to `timeout` for it.
    fn wait(&self, timeout: Duration) -> bool {
        let ended = self.ended.lock().unwrap_or_else(|e| e.into_inner());
        let (ended, _) = self
            .cv
            .wait_timeout_while(ended, timeout, |e| !*e)
            .unwrap_or_else(|e| e.into_inner());
        *ended
    }
}

/// Marks [`Done`] when dropped (at the end of the work, or when it panics).
struct DoneGuard<'a>(&'a Done);

impl Drop for DoneGuard<'_> {
    fn drop(&mut self) {
        *self.0.ended.lock().unwrap_or_else(|e| e.into_inner()) = true;
        self.0.cv.notify_all();
    }
}

/// [`interruptible`] when `long`; otherwise `work` runs on this thread with the GIL
/// released (its flag is never raised).
pub fn detached<T: Send>(
    py: Python<'_>,
    long: bool,
    work: impl FnOnce(Arc<AtomicBool>) -> T + Send,
) -> PyResult<T> {
    if long {
        interruptible(py, work)
    } else {
        let never = Arc::new(AtomicBool::new(false));
        Ok(py.detach(|| work(never)))
    }
}

/// Runs `f(data, row, out_row)` on every row in parallel (`out` has `width` values per
/// row), one `Data` per chunk of rows; ends with [`CANCELLED`] once `stop` is raised.
pub fn par_rows<F>(
    model: &Model,
    n: usize,
    width: usize,
    stop: &AtomicBool,
    f: F,
) -> Result<Vec<f64>, String>
where
    F: Fn(&mut Data, usize, &mut [f64]) -> Result<(), String> + Sync,
{
    let mut out = crate::batch::zeros(n, width)?;
    if width == 0 {
        return Ok(out);
    }
    out.par_chunks_mut(width * CHUNK)
        .enumerate()
        .try_for_each(|(c, chunk)| {
            if stopped(stop) {
                return Err(CANCELLED.to_string());
            }
            let mut d = Data::new(model);
            for (r, row) in chunk.chunks_mut(width).enumerate() {
                f(&mut d, c * CHUNK + r, row)?;
            }
            Ok(())
        })?;
    Ok(out)
}

/// [`par_rows`] under [`detached`]: interruptible when [`is_long`]. Errors (a row's, or an allocation's) are `ArmsimError`s.
pub fn batch_rows<F>(
    py: Python<'_>,
    model: &Model,
    n: usize,
    width: usize,
    f: F,
) -> PyResult<Vec<f64>>
where
    F: Fn(&mut Data, usize, &mut [f64]) -> Result<(), String> + Sync + Send,
{
    detached(py, is_long(model, n, width), |stop| {
        par_rows(model, n, width, &stop, f)
    })?
    .map_err(err)
}
