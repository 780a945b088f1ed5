//! The end-to-end tests across processes, in one test binary: every transport's outcomes
//! against the in-process evaluator, the iceoryx2 transport's faults, and the zenoh transport
//! when built with `--features zenoh` (so that the binaries have it too).

mod cleanup;
mod outcomes;
mod transport;
#[cfg(feature = "zenoh")]
mod zenoh;
#[cfg(feature = "zenoh")]
mod zenoh_commands;
