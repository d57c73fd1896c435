//! A stop request the time loops read before each step: a front end sets it from a signal
//! handler (the harness on SIGINT/SIGTERM) or from its own code; the runs under way end after
//! their current step with the rows so far.

use std::sync::atomic::{AtomicBool, Ordering};

static STOP: AtomicBool = AtomicBool::new(false);

/// Whether a stop was requested.
#[inline]
pub fn interrupted() -> bool {
    STOP.load(Ordering::Relaxed)
}

/// Ask the time loops to stop. Returns whether a stop had been requested already. Only touches
/// an atomic, so a signal handler may call it.
pub fn request_stop() -> bool {
    STOP.swap(true, Ordering::SeqCst)
}

/// Clear a stop request once the runs it stopped have returned.
pub fn clear_stop() {
    STOP.store(false, Ordering::SeqCst);
}
