//! The separation envelope (`sepval envelope`, docs/envelope.md section 14.4): the store's
//! clearance to the aircraft predicted at every condition of a grid, from a fit or a diagnosis,
//! each a prediction of `sepval predict` (its factor draws, model form and discrepancy) with
//! the clearance of every sample, mapped over the two axes that matter. A condition is cleared
//! when at most 5 % of its samples fail to keep the criterion (MIL-STD-1289D: 25.4 mm) or
//! diverge.
//!
//! The sweep is a pipeline of named stages:
//! 0. [`mod@prepare`]: the sweep asked for read and checked ([`Prepared`]): the source, the
//!    grid, the geometry and the digest of its inputs;
//! 1. [`grid`]: the axes `LO:HI:N` and the conditions, checked before anything runs
//!    ([`Grid`]);
//! 2. [`mod@sweep`]: the held-out evidence of the model form computed once ([`Evidence`]), then
//!    every condition predicted through any evaluator with its clearance, one row each
//!    ([`Row`]), the rows saved after each condition so an interrupted sweep resumes
//!    ([`progress`]);
//! 3. [`summary`]: the conditions cleared and not, in words, per row of the map;
//! 4. [`record`] ([`EnvelopeFile::of`]: the sweep's record with its summary and where it came
//!    from, [`Provenance`]) and [`outputs`]: DIR/envelope.csv, DIR/envelope.json, DIR/figures/envelope.png and
//!    DIR/report.html, written atomically.
//!
//! Every condition uses the same seed: sample s draws the same factors at every condition
//! (common random numbers, so the map is smooth where the physics is), and a condition's row
//! is the same bits whatever the worker count, and whether the sweep was interrupted and
//! resumed or not.
//!
//! [`Evidence`]: sepval_predict::discrepancy::Evidence

#![deny(clippy::float_cmp)]

pub mod command;
pub mod grid;
pub mod outputs;
mod page;
pub mod prepare;
pub mod progress;
pub mod record;
pub mod row;
pub mod summary;
pub mod sweep;

pub use grid::{Axis, Grid, GridError};
pub use outputs::write_outputs;
pub use prepare::{PrepareError, Prepared, prepare};
pub use progress::{Progress, ProgressError};
pub use record::{ENVELOPE_FORMAT, EnvelopeFile, Provenance};
pub use row::Row;
pub use sweep::{Sweep, SweepError, Swept, sweep};
