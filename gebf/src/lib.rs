//! gebf (work in progress)
#![warn(missing_docs)]

pub mod crv;
pub mod quaternion;
