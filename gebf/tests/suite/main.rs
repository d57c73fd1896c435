//! The gebf crate's integration tests, one module per file, built as one test binary (one
//! link instead of one per file). The binary installs the counting allocator for the allocation
//! tests: it counts only the calling thread's allocations inside `alloc_count::count`, so the
//! other tests running beside them do not disturb the counts.

mod common;
mod energy;
mod frame_retraction;
mod generic_analysis;
mod inertia;
mod memory;
mod modes;
mod momentum_projection;
mod no_alloc;
mod paper_cases;
mod paper_reference;
mod properties;
mod sharpy_regression;
mod spring;
mod stabilization;
mod statics;
mod twist;
mod validation;

#[global_allocator]
static GLOBAL: alloc_count::Counting = alloc_count::Counting;
