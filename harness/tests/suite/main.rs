//! The harness crate's integration tests, one module per file, built as one test binary (one
//! link instead of one per file).

mod aero;
mod cli;
mod gate;
mod honest;
mod observer;
mod properties;
mod statics;
mod vtk;
mod browser;
mod external;
mod vtk_parse;
