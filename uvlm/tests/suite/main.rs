//! The uvlm crate's integration tests, one module per file, built as one test binary (one
//! link instead of one per file). The binary installs the counting allocator for the allocation
//! tests: it counts only the calling thread's allocations inside `alloc_count::count`, so the
//! other tests running beside them do not disturb the counts.

mod common;
mod flap;
mod flow;
mod gust;
mod hinge;
mod linear;
mod linear_baseline;
mod linear_gust;
mod linear_strips;
mod linear_surfaces;
mod load_derivative;
mod multi_surface;
mod multi_surface_baseline;
mod no_alloc;
mod properties;
mod reuse;
mod send_sync;
mod steady;
mod steady_finite_wake;
mod theodorsen;
mod unsteady;

#[global_allocator]
static GLOBAL: alloc_count::Counting = alloc_count::Counting;
