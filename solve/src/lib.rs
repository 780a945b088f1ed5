//! sepval's solvers, generic over the problem they solve: the one ask-and-tell loop that runs
//! every search ([`run`]) and the best-so-far record of its history ([`best`]), the study's elitist Pareto genetic algorithm ([`ga`]) and hill
//! climber ([`hill`]), a bounded Levenberg-Marquardt least-squares refinement ([`lm`]), the
//! Pareto machinery ([`pareto`]), how sure a least-squares estimate is ([`identifiability`]),
//! the distribution functions and tests the diagnosis uses ([`stats`]), and the ZDT test
//! problems that check the Pareto machinery against known fronts ([`zdt`]).
//!
//! Nothing here sets up or runs a simulation, reads or writes a file, or prints: a solver asks
//! for points and is told their values (a search's goals, a refinement's residual vector);
//! what a point means, and how it is evaluated, is the caller's (`sepval-fit` maps points to
//! model candidates and sends them to an evaluator). The vocabulary shared with the model
//! library (a gene's bounds and bits, a chromosome, an evaluation's outcome, the cancellation
//! flag) comes from `sepval-common`.

#![deny(clippy::float_cmp)]
// Matrix and array code indexes by (row, column) as the equations it implements do.
#![allow(clippy::needless_range_loop)]

pub mod best;
pub mod ga;
pub mod hill;
pub mod identifiability;
pub mod lm;
pub mod params;
pub mod pareto;
pub mod rng;
pub mod run;
pub mod stats;
pub mod zdt;
