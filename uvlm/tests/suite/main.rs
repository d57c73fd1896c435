//! The uvlm crate's integration tests, one module per file, built as one test binary (one
//! link instead of one per file); the allocation tests stay separate binaries because they install a counting global allocator.

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
mod properties;
mod reuse;
mod send_sync;
mod steady;
mod steady_finite_wake;
mod theodorsen;
mod unsteady;
