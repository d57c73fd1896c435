//! The gebf crate's integration tests, one module per file, built as one test binary (one
//! link instead of one per file); the allocation tests stay separate binaries because they install a counting global allocator.

mod common;
mod energy;
mod frame_retraction;
mod generic_analysis;
mod inertia;
mod memory;
mod modes;
mod momentum_projection;
mod paper_cases;
mod paper_reference;
mod properties;
mod sharpy_regression;
mod spring;
mod stabilization;
mod statics;
mod twist;
mod validation;
