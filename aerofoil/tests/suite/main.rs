//! The aerofoil crate's integration tests, one module per file, built as one test binary (one
//! link instead of one per file).

mod dynamic_stall;
mod lattice_strips;
mod naca0015_neuralfoil;
