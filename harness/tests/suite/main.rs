//! The harness crate's integration tests, one module per file, built as one test binary (one
//! link instead of one per file).

mod aero;
mod browser;
mod cli;
mod common;
mod control_surfaces;
mod divergence_swept;
mod dynamic_stall;
mod external;
mod flight_gust;
mod fuzz;
mod gate;
mod geometry;
mod gust;
mod healy_readings;
mod honest;
mod loads_lost;
mod observer;
mod planform;
mod polars;
mod polars_flight;
mod polars_linear;
mod properties;
mod roll;
mod send_sync;
mod shard;
mod sideslip;
#[cfg(target_os = "linux")]
mod slurm;
mod stability;
mod statics;
mod statics_bend;
#[cfg(target_os = "linux")]
mod streamed;
mod surfaces;
mod trim;
mod vtk;
mod vtk_parse;
