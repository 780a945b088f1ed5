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
//! - [`results`]: DIR/result.json; [`record`]: the one writer (sealed with a digest) and
//!   reader (parse errors, format, digest, ranges) of records other commands read; [`out_dir`]: output directories, locked and protected;
//! - [`refine`]: a model refined to the optimum by Levenberg-Marquardt, several sharing each
//!   batch;
//! - [`model_spec`]: a fitted model as files hold it, rebuilt exactly by other commands;
//! - [`domain`]: where a fitted model may be flown (refused outside, said when far from the
//!   releases), for every command that flies one at a new condition;
//! - [`inputs`]: what a run reads (scenario, factors, effects, releases screened and
//!   checked) read into a job;
//! - [`sigma`]: the noise that weights the goals; [`method`]: which searches to run.
//!
//! The library returns typed errors and prints nothing: progress reaches the caller through a
//! [`ProgressObserver`](sepval_solve::run::ProgressObserver).

#![deny(clippy::float_cmp)]
// Matrix and array code indexes by (row, column) as the equations it implements do.
#![allow(clippy::needless_range_loop)]

pub mod checkpoint;
pub mod conditions;
pub mod configure;
pub mod domain;
pub mod inputs;
pub mod method;
pub mod model_spec;
pub mod out_dir;
pub mod pipeline;
pub mod problem;
pub mod rebuild;
pub mod record;
pub mod refine;
pub mod rerun;
pub mod results;
pub mod resume;
pub mod sigma;
pub mod space;

pub use method::Method;
pub use pipeline::{BaselineSearch, FitError, FitOptions, FitOutput, run_fit};
