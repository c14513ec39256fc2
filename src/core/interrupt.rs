//! Ctrl-C (SIGINT) as a flag, so a long run can stop cleanly and still finish its
//! recording.
//!
//! Owned here: [`install`], [`requested`], [`flag`], [`request`] and [`reset`]. A simulation loop
//! calls [`install`] once, polls [`requested`] between steps and, when it is set, stops
//! stepping and calls `McapWriter::finish`, leaving a complete MCAP with the frames so far.
//! A second Ctrl-C while the first is being handled exits at once with status 130 (the
//! recording's temporary file is then left behind, the target untouched).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();
static INSTALLED: OnceLock<Result<(), InterruptError>> = OnceLock::new();

/// The SIGINT handler could not be installed (e.g. another crate installed one first).
#[derive(Debug, Clone, thiserror::Error)]
#[error("cannot install the Ctrl-C handler: {0}")]
pub struct InterruptError(pub String);

/// Installs the SIGINT handler (idempotent: later calls return the first call's result).
pub fn install() -> Result<(), InterruptError> {
    INSTALLED
        .get_or_init(|| {
            ctrlc::set_handler(|| {
                if flag().swap(true, Ordering::SeqCst) {
                    eprintln!("interrupted again: exiting without finishing the output");
                    std::process::exit(130);
                }
                eprintln!("interrupted: finishing the output (Ctrl-C again to abort)");
            })
            .map_err(|e| InterruptError(e.to_string()))
        })
        .clone()
}

/// Whether an interrupt was received (or [`request`]ed) since the start or the last
/// [`reset`].
pub fn requested() -> bool {
    flag().load(Ordering::SeqCst)
}

/// The flag itself, for loops that poll an `Arc<AtomicBool>` (the planner's
/// [`crate::planning::PlanOptions::stop`]).
pub fn flag() -> Arc<AtomicBool> {
    FLAG.get_or_init(|| Arc::new(AtomicBool::new(false)))
        .clone()
}

/// Sets the flag as SIGINT does (for callers with their own stop conditions, and tests).
pub fn request() {
    flag().store(true, Ordering::SeqCst);
}

/// Clears the flag (e.g. between runs in one process).
pub fn reset() {
    flag().store(false, Ordering::SeqCst);
}
