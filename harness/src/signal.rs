//! SIGINT and SIGTERM end runs cleanly: the first signal asks every time loop to stop after its
//! current step (the rows so far are written and the summary is marked `"interrupted"`); a
//! second one ends the process at once. So does a first one that the process has not answered
//! within [`GRACE`]: a computation that never looks at the flag (one static point, one
//! eigen-solve) cannot keep a process alive against a single SIGTERM (`timeout`, a scheduler).

/// Exit status of a run ended by a signal (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: u8 = 130;

/// How long after the first signal the process may take to stop on its own before it is ended
/// (exit status [`EXIT_INTERRUPTED`]). A time loop stops within one step; the grace lets its
/// rows and summary be written.
pub const GRACE: std::time::Duration = std::time::Duration::from_secs(20);

/// Install the handlers and the watchdog that enforces [`GRACE`] (call once, at the start of the
/// binary; an embedding program such as the Python package does not, and keeps its process).
pub fn install() {
    std::thread::spawn(|| {
        while !interrupted() {
            std::thread::sleep(std::time::Duration::from_millis(100));
        }
        std::thread::sleep(GRACE);
        eprintln!("harness: still busy {} s after the interrupt; exiting", GRACE.as_secs());
        std::process::exit(i32::from(EXIT_INTERRUPTED));
    });
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
