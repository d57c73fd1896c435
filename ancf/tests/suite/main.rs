//! The ancf crate's integration tests, one module per file, built as one test binary (one
//! link instead of one per file). The binary installs the counting allocator for the allocation
//! tests: it counts only the calling thread's allocations inside `alloc_count::count`, so the
//! other tests running beside them do not disturb the counts.

mod allocation;
mod bad_input;
mod common;
mod corotation;
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

#[global_allocator]
static GLOBAL: alloc_count::Counting = alloc_count::Counting;
