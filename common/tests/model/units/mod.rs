//! The model library's unit tests, one file per module of `sepval_common` (named by its path).
//! They live here, outside the crate, so that the library compiles once when tested rather than
//! a second time as its own unit-test binary (`test = false` in its Cargo.toml: about a minute
//! of a cold CI); what of the crate's inside they need, they reach through the hidden
//! `sepval_common::internals`.

mod atmosphere;
mod correction;
mod effects;
mod elementary;
mod evaluation;
mod extension;
mod extension_locator;
mod frames;
mod goals;
mod lanes;
mod model_ejector;
mod model_flowfield;
mod model_interference;
mod model_term_lanes;
mod noise;
mod scenario;
mod scenario_same_store;
mod table;
mod telemetry;
mod telemetry_lines;
mod telemetry_outliers;
