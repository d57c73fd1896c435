//! The harness crate's integration tests, one module per file, built as one test binary (one
//! link instead of one per file).

mod aero;
mod browser;
mod cli;
mod external;
mod gate;
mod honest;
mod observer;
mod properties;
mod statics;
mod vtk;
mod vtk_parse;
