//! The end-to-end tests across processes, in one test binary: the iceoryx2 transport, and the
//! zenoh transport when built with `--features zenoh` (so that the binaries have it too).

mod transport;
#[cfg(feature = "zenoh")]
mod zenoh;
