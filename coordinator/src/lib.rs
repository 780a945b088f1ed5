//! The sepval coordinator: everything the `sepval` command does beyond the model itself.
//! The binary (`src/main.rs`) is only the command line; the logic lives here.

#![warn(missing_docs)]
#![deny(clippy::float_cmp)]
// Matrix and array code indexes by (row, column) as the equations it implements do.
#![allow(clippy::needless_range_loop)]

pub mod bench;
pub mod checkpoint;
pub mod diagnose;
pub mod figures;
pub mod fit;
pub mod identifiability;
pub mod inputs;
pub mod ipc;
pub mod problem;
pub mod refine;
#[cfg(feature = "zenoh")]
pub mod remote;
pub mod rerun;
pub mod results;
pub mod rng;
pub mod search;
pub mod selftest;
pub mod stats;
pub mod uds;
