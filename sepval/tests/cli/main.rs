//! The `sepval` command line end to end, in one test binary: the commands as a user runs them,
//! `fit` and `rerun`, edited checkpoints, refinement and identifiability, `diagnose`, `plan`,
//! `predict`, `update`, and property-based hardening of the checkpoint reader on arbitrary and mutated files. The binary
//! is run through the shared support of the end-to-end tests (`sepval-tests`). Keep this the
//! package's only integration test: it is also what makes `cargo test --workspace` build
//! `sepval`.

mod aero;
mod campaign;
mod campaign_begin;
mod campaign_wall;
mod checkpoint;
mod cli;
mod daveml;
mod diagnose;
mod discover;
mod envelope;
mod fit;
mod flowfield;
mod from_shape;
mod fuzz;
// The tests' own generator of releases with a hidden cause, shared with the in-process tests
// of the diagnosis and the plan.
#[path = "../../../diagnose/tests/support/generator.rs"]
mod generator;
mod guide;
mod gust;
mod hardening;
mod hardening3_geometry;
mod hardening3_out;
mod hardening3_records;
mod hardening3_releases;
mod hardening5_campaign;
mod hardening5_inputs;
mod hardening_on_disk;
mod jobs;
mod plan;
mod predict;
mod refine;
mod tables;
mod update;
