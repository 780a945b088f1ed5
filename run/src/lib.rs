//! What every run shares, below the pipelines that compute: where it writes and what it
//! reads, and the records one command writes and another reads.
//!
//! - [`out_dir`]: output directories (`--out` of every command), locked for a run's whole
//!   life, protected from being cleared unless sepval wrote all they hold, with their marker
//!   and manifest;
//! - [`inputs`]: what a run reads (scenario, factors, effects, releases screened and checked)
//!   read into a job, and the [`InputsRecord`](inputs::InputsRecord) a record keeps of where
//!   they came from;
//! - [`sealed`]: the one writer (sealed with a digest) and reader (parse errors, format,
//!   digest, ranges) of the records other commands read (result.json, diagnosis.json);
//! - [`clearance`]: the clearance of a record's releases, as records hold it, and the stage
//!   the fit and the diagnosis ask for it before they seal their record;
//! - [`model_spec`]: a fitted model as files hold it, rebuilt exactly by other commands;
//! - [`domain`]: where a fitted model may be flown (refused outside, said when far from the
//!   releases), for every command that flies one at a new condition;
//! - [`conditions`]: the grids of flight conditions a prediction, a plan or an envelope
//!   covers;
//! - [`sequence`]: the one order of every command that writes an output directory (its
//!   directory claimed, its evaluator started, the run, its files, the commit), each
//!   command's run a [`sequence::Run`] of its library.
//!
//! The library returns typed errors and prints nothing.

#![deny(clippy::float_cmp)]

pub mod clearance;
pub mod conditions;
pub mod domain;
pub mod inputs;
pub mod model_spec;
pub mod out_dir;
pub mod sealed;
pub mod sequence;
