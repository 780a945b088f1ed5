//! sepval's coordinator-worker protocol and its transports, both ends of each side by side.
//!
//! - [`wire`]: the fixed-layout messages (zero copy over shared memory), the one validation of a
//!   request and the one [`wire::serve_chunks`];
//! - [`codec`]: their byte form for byte transports; [`setup`]: the job setup;
//! - [`link`]: what a transport is ([`link::Link`] for the coordinator, [`link::WorkerLink`]
//!   for a worker) and the [`link::Notice`]s it reports;
//! - [`dispatch`]: the coordinator's dispatcher over any link (chunk plan, credit windows,
//!   results by candidate index, deadlines, re-dispatch), an
//!   [`Evaluator`](sepval_common::evaluation::Evaluator);
//! - [`serve`]: a worker's serve loop over any link;
//! - the transports, each only a link: [`ipc`] (iceoryx2 shared memory, one host), [`uds`] (Unix
//!   sockets, the benchmark's conventional baseline), `zenoh` (other hosts, feature `zenoh`,
//!   with the gateway that serves a zenoh run with a host's iceoryx2 workers);
//! - [`spec`]: which evaluator to start, as a validated configuration;
//! - [`bench`](mod@bench): simulations per second against worker count, per transport (`sepval bench`).
//!
//! Nothing here prints: what the user should hear goes out as [`link::Notice`]s.

#![deny(clippy::float_cmp)]

pub mod bench;
pub mod codec;
pub mod dispatch;
pub mod flags;
pub mod ipc;
pub mod link;
pub mod run_id;
pub mod serve;
pub mod setup;
pub mod spec;
pub mod uds;
pub mod wire;
#[cfg(feature = "zenoh")]
pub mod zenoh;

#[cfg(test)]
mod fuzz_tests;

pub use run_id::RunId;

use sepval_common::evaluation::EvalError;

/// Errors of the transports.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TransportError {
    /// Too few workers joined in time.
    #[error("only {joined} of {wanted} worker(s) joined run {run} within {seconds} s")]
    TooFewWorkers {
        /// Workers that joined.
        joined: usize,
        /// Workers wanted.
        wanted: usize,
        /// The run.
        run: String,
        /// The wait \[s\].
        seconds: f64,
    },
    /// No worker is left and none can come.
    #[error(
        "every worker of run {run} is lost ({lost}); {unfinished} of {total} evaluations unfinished"
    )]
    AllLost {
        /// The run.
        run: String,
        /// What happened to them.
        lost: String,
        /// Evaluations not done.
        unfinished: usize,
        /// Evaluations of the batch.
        total: usize,
    },
    /// Spawned workers exit before they join (a refused setup, a bad executable).
    #[error("workers keep exiting before joining run {run} ({status})")]
    WorkersExit {
        /// The run.
        run: String,
        /// The last exit status.
        status: String,
    },
    /// A worker count out of range.
    #[error("{0} workers: expected 1 to {max}", max = ipc::MAX_WORKERS)]
    WorkerCount(usize),
    /// A signal asked the process to stop.
    #[error("interrupted by a signal")]
    Interrupted,
    /// A run id that cannot name a run.
    #[error(transparent)]
    RunId(#[from] run_id::RunIdError),
    /// Another coordinator serves this run id.
    #[error("run {run} already has a coordinator: choose another run id")]
    RunTaken {
        /// The run.
        run: String,
    },
    /// An iceoryx2 operation failed.
    #[error("{what}: {detail}")]
    Iceoryx {
        /// What was attempted.
        what: String,
        /// iceoryx2's error.
        detail: String,
    },
    /// An operating-system operation failed.
    #[error("{what}")]
    Io {
        /// What was attempted.
        what: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A job setup that cannot be used.
    #[error(transparent)]
    Setup(#[from] setup::SetupError),
    /// A setup refused by a worker.
    #[error("refusing the setup of run {run}: {reason}")]
    SetupRefused {
        /// The run it joined.
        run: String,
        /// Why.
        reason: String,
    },
    /// A message that does not decode.
    #[error("{what}")]
    Codec {
        /// Which message.
        what: String,
        /// Why.
        #[source]
        source: codec::CodecError,
    },
    /// The coordinator sent a frame coordinators do not send.
    #[error("the coordinator sent {frame}, which coordinators do not send")]
    NotACoordinatorFrame {
        /// What it sent ([`codec::Frame::name_of`]).
        frame: &'static str,
    },
    /// A worker's first frame was not the job setup.
    #[error("expected the job setup first, received {frame}")]
    SetupNotFirst {
        /// What arrived ([`codec::Frame::name_of`]).
        frame: &'static str,
    },
    /// A frame announced longer than a frame may be.
    #[error("frame of {len} bytes exceeds the {limit}-byte limit")]
    FrameTooLong {
        /// The length announced.
        len: usize,
        /// The limit.
        limit: usize,
    },
    /// A second evaluator of a zenoh run while the first is in use.
    #[error(
        "an evaluator of this zenoh run is still in use: a command evaluates one job at a time"
    )]
    ZenohRunInUse,
    /// The zenoh session closed under the coordinator.
    #[error("the zenoh session closed")]
    ZenohClosed,
    /// The coordinator refused this worker.
    #[error("the coordinator dropped this worker: {reason}")]
    Dropped {
        /// The coordinator's words (free text from the other process, as it sent them).
        reason: String,
    },
    /// No coordinator answered a worker.
    #[error(
        "no coordinator of run {run} answered {place} within {seconds} s: is it running, and is \
         the run id right?"
    )]
    NoCoordinator {
        /// The run.
        run: String,
        /// Where it looked ("on this host", "at tcp/...").
        place: String,
        /// The wait \[s\].
        seconds: f64,
    },
    /// A transport this build does not have.
    #[error(
        "transport {transport}: this sepval was built without the {transport} feature (cargo build --release --features {transport})"
    )]
    NotBuilt {
        /// The transport (and its cargo feature).
        transport: &'static str,
    },
    /// zenoh refused or failed.
    #[error("zenoh: {context}: {message}")]
    Zenoh {
        /// What was attempted.
        context: String,
        /// zenoh's error.
        message: String,
    },
    /// An endpoint that is not `PROTOCOL/HOST:PORT`.
    #[error(
        "endpoint {endpoint:?}: expected PROTOCOL/HOST:PORT with an explicit port, e.g. tcp/192.0.2.7:7447"
    )]
    Endpoint {
        /// The endpoint given.
        endpoint: String,
    },
    /// A server that answered another number of chunks than it was given.
    #[error("serving a chunk: {answers} answers for {chunks} chunks")]
    ServedCount {
        /// The answers.
        answers: usize,
        /// The chunks served.
        chunks: usize,
    },
    /// A gateway whose local iceoryx2 workers are gone.
    #[error("serving a chunk: the host's iceoryx2 workers are gone")]
    LocalGone,
    /// A gateway whose local iceoryx2 workers failed (the message shows the failure's chain).
    #[error("serving a chunk: the host's iceoryx2 workers failed: {}", error_chain(.cause.as_ref()))]
    LocalFailed {
        /// The failure of the local run (not a `source`: the message holds its chain).
        cause: Box<sepval_common::evaluation::EvalError>,
    },
}

impl From<TransportError> for EvalError {
    fn from(e: TransportError) -> Self {
        match e {
            TransportError::Interrupted => EvalError::Interrupted,
            other => EvalError::transport(other),
        }
    }
}

impl From<sepval_core::cancel::Cancelled> for TransportError {
    fn from(_: sepval_core::cancel::Cancelled) -> Self {
        TransportError::Interrupted
    }
}

/// The embedded default job (tests).
#[cfg(test)]
pub(crate) fn default_job() -> sepval_common::evaluation::Job {
    sepval_common::evaluation::Job::single(
        "default",
        &sepval_common::scenario::Scenario::embedded_default(),
        sepval_common::synthetic::default_flight_test(),
    )
}

/// An error and its causes, joined by ": " (what `{:#}` shows for an `anyhow` error).
pub fn error_chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text.push_str(": ");
        text.push_str(&s.to_string());
        source = s.source();
    }
    text
}

/// Wraps an iceoryx2 error with what was attempted.
pub fn iox<E: std::fmt::Debug>(what: impl Into<String>) -> impl FnOnce(E) -> TransportError {
    let what = what.into();
    move |e| TransportError::Iceoryx {
        what,
        detail: format!("{e:?}"),
    }
}

/// Wraps an I/O error with what was attempted.
pub fn io(what: impl Into<String>) -> impl FnOnce(std::io::Error) -> TransportError {
    let what = what.into();
    move |source| TransportError::Io { what, source }
}
