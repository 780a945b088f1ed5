//! The sepval coordinator: everything the `sepval` command does beyond the model itself and
//! the transports: the searches and the one loop that runs them ([`run`]), fits with
//! checkpoints, refinement and identifiability, diagnosis, figures and benchmarks. The binary
//! (`src/main.rs`, `src/cli.rs`, `src/command/`) is only the command line and its rendering;
//! this library returns typed errors and prints nothing (progress reaches the binary through a
//! [`run::ProgressObserver`], transport notices through `sepval_transport::link::Notices`).

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
pub mod out_dir;
pub mod problem;
pub mod refine;
pub mod rerun;
pub mod results;
pub mod rng;
pub mod run;
pub mod search;
pub mod selftest;
pub mod sigma;
pub mod stats;
