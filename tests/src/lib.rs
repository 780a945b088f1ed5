//! End-to-end tests of sepval live in `tests/`; this library is empty on purpose: the crate
//! exists to run the `sepval` and `sepval-worker` binaries as a user would.
