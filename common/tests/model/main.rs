//! The model library's integration tests, in one test binary (one link instead of four):
//! conformance with docs/model.md section 8, the effect catalogue, verification against known
//! solutions, and property-based hardening of the readers of outside input (telemetry, scenario,
//! factors). Run in release: `cargo test --release -p sepval-common`.

mod conformance;
mod effects;
mod fuzz;
mod tables;
mod verification;
