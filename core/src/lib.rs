//! sepval's core: what every part of sepval shares and none of it is about store separation.
//! The physics (`sepval-common`), the solvers (`sepval-solve`) and the pages (`sepval-report`)
//! stand on it; it stands on no sepval crate.
//!
//! - [`outcome`]: what one evaluation gives (the two goals, a divergence, a failure) and what
//!   an evaluator's error is;
//! - [`factors`], [`encoding`]: the 17 factors of the study, their bounds and resolutions
//!   (the search space, docs/model.md section 4), and their binary encoding;
//! - [`cancel`]: the one cancellation flag that SIGINT and SIGTERM raise;
//! - [`defect`]: a panic reported as a defect, after everything held is dropped;
//! - [`atomic_file`]: every output written whole to a temporary file and renamed;
//! - [`input_file`], [`limits`]: how every input file is opened and read (regular files only,
//!   within stated byte limits) and the limits on what a file may hold;
//! - [`toml_error`], [`number_text`], [`nonfinite`]: how a TOML error, a number in a message
//!   and a non-finite number in JSON are written;
//! - [`stage_clock`]: the wall time of a pipeline's named stages;
//! - [`units`]: the unit conversions inputs use.

#![deny(clippy::float_cmp)]

pub mod atomic_file;
pub mod cancel;
pub mod defect;
pub mod encoding;
pub mod factors;
pub mod flag_value;
pub mod input_file;
pub mod limits;
pub mod nonfinite;
pub mod number_text;
pub mod outcome;
pub mod stage_clock;
pub mod toml_error;
pub mod units;
