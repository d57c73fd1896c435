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
//! The library itself is empty.
