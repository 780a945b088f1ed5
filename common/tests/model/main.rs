//! The model library's integration tests, in one test binary (one link instead of three):
//! conformance with docs/model.md section 8, the effect catalogue, and verification against known
//! solutions, and the elementary functions against a high-precision reference. Run in release: `cargo test --release -p sepval-common`.

mod conformance;
mod effects;
mod elementary;
mod verification;
