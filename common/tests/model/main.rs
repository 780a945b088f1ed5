//! The model library's integration tests, in one test binary (one link instead of five):
//! conformance with docs/model.md section 8, the effect catalogue, the elementary functions
//! against a high-precision reference, verification against known solutions, and property-based
//! hardening of the readers of outside input (telemetry, scenario, factors). Run in release:
//! `cargo test --release -p sepval-common`.

mod conformance;
mod continuity;
mod effects;
mod elementary;
mod flowfield;
mod flowfield_grid;
mod flowfield_shape;
mod fuzz;
mod input_files;
mod lanes;
mod locators;
mod tables;
mod units;
mod verification;
mod wind;
