//! SIGINT and SIGTERM end runs cleanly: the first signal asks every time loop to stop after its
//! current step (the rows so far are written and the summary is marked `"interrupted"`); a
//! second one ends the process at once.

/// Exit status of a run ended by a signal (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: u8 = 130;

/// Install the handlers (call once, at the start of the binary).
pub fn install() {
    #[cfg(target_os = "linux")]
    // SAFETY: the handler only touches an atomic and calls the async-signal-safe `_exit`.
    unsafe {
        let h = handler as extern "C" fn(libc::c_int) as libc::sighandler_t;
        libc::signal(libc::SIGINT, h);
        libc::signal(libc::SIGTERM, h);
    }
}

#[cfg(target_os = "linux")]
extern "C" fn handler(_sig: libc::c_int) {
    if aeroelastic::interrupt::request_stop() {
        // SAFETY: `_exit` is async-signal-safe.
        unsafe { libc::_exit(EXIT_INTERRUPTED as libc::c_int) }
    }
}

/// Whether a stop was requested.
#[inline]
pub fn interrupted() -> bool {
    aeroelastic::interrupt::interrupted()
}

/// Ask the time loops to stop, as a signal does (for tests and embedding programs).
pub fn request_stop() {
    aeroelastic::interrupt::request_stop();
}

/// Clear a stop request once the runs it stopped have returned (an embedding program that goes
/// on after an interrupt: the Python package after a `KeyboardInterrupt`).
pub fn clear_stop() {
    aeroelastic::interrupt::clear_stop();
}
