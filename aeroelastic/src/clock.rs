//! The calling thread's CPU time, for the analyses' timing columns.

/// CPU time of the calling thread, s (`None` where the platform has no per-thread clock).
#[cfg(target_os = "linux")]
pub fn thread_cpu_s() -> Option<f64> {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; the call only writes to it.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    (rc == 0).then_some(ts.tv_sec as f64 + 1e-9 * ts.tv_nsec as f64)
}

/// CPU time of the calling thread, s (`None` where the platform has no per-thread clock).
#[cfg(not(target_os = "linux"))]
pub fn thread_cpu_s() -> Option<f64> {
    None
}
