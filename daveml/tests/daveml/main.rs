//! The DAVE-ML exchange end to end in process: files as other tools write them read into
//! scenarios, bad files refused with line and element, what sepval writes checked against the
//! DAVE-ML 2.0 element order, and the round trip scenario -> DAVE-ML -> scenario simulated bit
//! for bit.

#![allow(clippy::float_cmp)] // the round trip compares bits on purpose

mod entities;
mod import;
mod refusals;
mod round_trip;
mod schema;

use std::path::PathBuf;

/// A fixture's path.
pub fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

/// A fixture's text.
pub fn fixture_text(name: &str) -> String {
    std::fs::read_to_string(fixture(name)).unwrap()
}
