//! The ancf crate's integration tests, one module per file, built as one test binary (one
//! link instead of one per file); the allocation tests stay separate binaries because they install a counting global allocator.

mod bad_input;
mod common;
mod energy;
mod generic_analysis;
mod inertia;
mod invariance;
mod jacobians;
mod memory;
mod modal;
mod near_rigid;
mod pendulum;
mod properties;
mod rigid_limit;
mod spring;
mod statics;
mod thrust;
mod twist;
