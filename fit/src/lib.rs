//! The fit: the 17 factors (and, for a diagnosis, effect parameters and extension terms)
//! fitted to flight data, as in M. B. Anderson's study and beyond it.
//!
//! - [`pipeline`]: the fit as stages, the study's hill climber and genetic algorithm, each
//!   optionally refined to the noise floor by Levenberg-Marquardt, then how sure each factor
//!   is and what one grid step of each factor does; [`run_fit`] is the entry point;
//! - [`space`]: the continuous parameters of a model (factors, effect parameters, extension
//!   terms) and the normalised residual vector they are fitted on;
//! - [`problem`]: the solvers of `sepval-solve` asked and told as model candidates, evaluated
//!   by any [`Evaluator`](sepval_common::evaluation::Evaluator) (threads of this process or
//!   worker processes: the fit never knows which);
//! - [`checkpoint`] and [`rerun`]: one checkpoint per generation, resumption and replay;
//! - [`results`]: DIR/result.json, a sealed record (`sepval_run::sealed`) whose ranges
//!   [`result_check`] states;
//! - [`refine`]: a model refined to the optimum by Levenberg-Marquardt, several sharing each
//!   batch;
//! - [`sigma`]: the noise that weights the goals; [`method`]: which searches to run;
//! - [`configure`] and [`command`]: `sepval fit`'s request made a configured run, and that run
//!   in the one sequence of every command (`sepval_run::sequence`).
//!
//! What a run reads and where it writes (the output directory, the input readers, the sealed
//! records, the flight domain) are `sepval-run`'s, which every command shares.
//!
//! The library returns typed errors and prints nothing: progress reaches the caller through a
//! [`ProgressObserver`](sepval_solve::run::ProgressObserver).

#![deny(clippy::float_cmp)]
// Matrix and array code indexes by (row, column) as the equations it implements do.
#![allow(clippy::needless_range_loop)]

pub mod checkpoint;
pub mod command;
pub mod configure;
pub mod method;
pub mod pipeline;
pub mod problem;
pub mod rebuild;
pub mod refine;
pub mod rerun;
pub mod result_check;
pub mod results;
pub mod resume;
pub mod sigma;
pub mod space;

pub use method::Method;
pub use pipeline::{BaselineSearch, FitError, FitOptions, FitOutput, run_fit};
