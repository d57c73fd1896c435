//! The aeroelastic crate's integration tests, one module per file, built as one test binary (one
//! link instead of one per file).

mod cross_formulation;
mod thrust;
