//! Timing tools of the flexmb workspace, kept out of the libraries so that their dependency
//! (criterion) does not change the features of the libraries' own dependencies:
//!
//! * criterion benches (`cargo bench -p perf --bench NAME`): `ancf_pendulum`, `gebf_pendulum`
//!   (the paper's pendulum), `uvlm_step`, `uvlm_wake_scaling` and `uvlm_kernel` (one UVLM step,
//!   its cost against wake length, the Biot–Savart kernel);
//! * timing and tracing examples (`cargo run --release -p perf --example NAME`), named after the
//!   crate they time: `ancf_*`, `gebf_*`, `uvlm_*`, and `newton_trace` (the Newton iterations of a
//!   case's run).
//!
//! The library holds what several examples share: [`reuse_radius`], the probes' measure of how
//! well an earlier iteration matrix serves the current one, and [`thread_cpu_ns`], their clock.

use nalgebra::{DMatrix, DVector};

/// CPU time of the calling thread, ns, to the nanosecond (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`;
/// wall time since the first call where the platform has no per-thread clock).
///
/// Not `/proc/thread-self/schedstat`: on a kernel with tick-based accounting its figure moves
/// only at the scheduler's ticks (4 ms steps at 250 Hz), so a timed interval of tens of
/// milliseconds came out as a whole number of ticks.
pub fn thread_cpu_ns() -> u64 {
    static START: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
    match aeroelastic::clock::thread_cpu_s() {
        Some(s) => (s * 1e9) as u64,
        None => START.get_or_init(std::time::Instant::now).elapsed().as_nanos() as u64,
    }
}

/// The spectral radius of `I − A_old⁻¹ A_new` (the linear contraction of Newton's iteration with
/// the matrix `A_old` on a problem whose matrix is `A_new`), by `iterations` steps of power
/// iteration from a fixed start.
pub fn reuse_radius(a_old: &DMatrix<f64>, a_new: &DMatrix<f64>, iterations: usize) -> f64 {
    let lu = a_old.clone().lu();
    let n = a_old.nrows();
    let mut x = DVector::from_fn(n, |i, _| ((i * 7 + 3) as f64).sin());
    let mut rho = 0.0;
    for _ in 0..iterations {
        let y = &x - lu.solve(&(a_new * &x)).expect("the old matrix is invertible");
        rho = y.norm() / x.norm();
        x = y / rho.max(1e-300);
    }
    rho
}
