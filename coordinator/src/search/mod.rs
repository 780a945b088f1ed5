//! Searches over the model factors: the study's genetic algorithm and hill climber.
//!
//! The searches see simulations only through a problem's batch evaluation, so the transport
//! that runs them (threads, worker processes) is invisible here.

pub mod ga;
pub mod hill;
pub mod operators;
pub mod pareto;
