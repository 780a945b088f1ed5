//! What a transport is to the rest of sepval: a [`Link`] on the coordinator's side (send a chunk
//! to a worker, hear what happened) and a [`WorkerLink`] on a worker's side (receive chunks,
//! answer them). Everything else (the chunk plan, credit windows, results placed by candidate
//! index, deadlines, re-dispatch after a loss, the serve loop) is written once, in
//! [`crate::dispatch`] and [`crate::serve`], for every transport.

use std::sync::Arc;
use std::time::Duration;

use sepval_common::evaluation::Job;

use crate::wire::{Answer, Chunk};

/// A worker as its link names it (unique within one link's life).
pub type WorkerId = u64;

/// Something a link observed.
#[derive(Debug)]
pub enum LinkEvent {
    /// A worker is ready and may hold `credits` chunks at once.
    Joined {
        /// The worker.
        worker: WorkerId,
        /// A name for messages ("pid 4242", "host pid 7 (zid)").
        label: String,
        /// Chunks it can hold at once.
        credits: usize,
    },
    /// A worker answered a chunk.
    Answer {
        /// The worker.
        worker: WorkerId,
        /// Its answer.
        answer: Answer,
    },
    /// A worker is gone (process exited, node dead, liveliness lost, malformed message): its
    /// chunks in flight go to the others.
    Lost {
        /// The worker.
        worker: WorkerId,
        /// Why.
        reason: String,
    },
    /// Something the user should hear (a refused worker, a replacement started).
    Notice(Notice),
}

/// Why a chunk could not be sent to a worker (the dispatcher drops the worker).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SendError {
    /// A worker the link does not know.
    #[error("no worker {worker}")]
    NoWorker {
        /// The worker.
        worker: WorkerId,
    },
    /// Writing the frame to the worker's socket failed.
    #[error("{0}")]
    Write(std::io::Error),
    /// The transport library refused the message: its words (free text from zenoh or
    /// iceoryx2, not a type this crate can name).
    #[error("{what}{detail}")]
    Refused {
        /// What was attempted, with ": " when there is one ("sending a request chunk: ").
        what: &'static str,
        /// The library's error text.
        detail: String,
    },
}

/// The coordinator's end of a transport.
pub trait Link {
    /// Sends `chunk` to `worker`. An error means the worker cannot be reached any more: the
    /// dispatcher drops it and re-dispatches its work.
    fn send(&mut self, worker: WorkerId, chunk: &Chunk) -> Result<(), SendError>;

    /// Waits at most `timeout` for something to happen (returning early once anything has),
    /// and appends what happened to `events`. Liveness checks run here. An error ends the
    /// evaluation (the transport itself failed, or a signal asked the process to stop).
    fn poll(
        &mut self,
        timeout: Duration,
        events: &mut Vec<LinkEvent>,
    ) -> Result<(), crate::TransportError>;

    /// Gives up on `worker` (it held a chunk past the deadline, or answered nonsense): stops it
    /// as this transport can (kills it, or tells it to quit) and forgets it. Returns what was
    /// done, for messages ("killed", "told to quit").
    fn drop_worker(&mut self, worker: WorkerId, reason: &str) -> &'static str;

    /// How long to wait for a new worker when none is left: zero when none can come (every
    /// replacement used up, workers attached by hand).
    fn replacement_wait(&self) -> Duration;

    /// The run's name, for messages.
    fn run_id(&self) -> &str;

    /// A short description for reports ("ipc", "zenoh at tcp/...").
    fn describe(&self) -> String;
}

/// A link whose workers stay for the next job of the same run (zenoh: the hosts that joined
/// serve the whole command). Links without it start anew for each job (iceoryx2 spawns its
/// workers for it).
pub trait NextJob: Link {
    /// Moves the run on to `job`: its setup is on offer from now on and sent to every worker
    /// that joined, which joins again (a [`LinkEvent::Joined`]) once it has accepted it.
    /// Returns the workers told.
    fn next_job(&mut self, job: &Job) -> Result<Vec<WorkerId>, crate::TransportError>;
}

/// What a worker's link delivers.
#[derive(Debug)]
pub enum Incoming {
    /// A chunk to evaluate.
    Chunk(Chunk),
    /// Nothing within the timeout.
    Idle,
    /// The coordinator moved on to the next job of the same run (an envelope's next condition,
    /// an update's next round), whose setup the link has accepted: serve it from now on.
    Job(Arc<Job>),
    /// The worker should stop (normally).
    Stop(Stopped),
}

/// Why a worker stopped serving (normal ends; failures are errors).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Stopped {
    /// The coordinator ended the run (zenoh `Quit`, a socket closed).
    Quit(String),
    /// The coordinator is gone.
    CoordinatorGone(String),
    /// SIGINT or SIGTERM (how a coordinator stops the workers it spawned).
    Signal,
}

impl std::fmt::Display for Stopped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Stopped::Quit(reason) => write!(f, "the coordinator ended our work: {reason}"),
            Stopped::CoordinatorGone(run) => {
                write!(f, "the coordinator is gone (run {run}); exiting")
            }
            Stopped::Signal => write!(f, "stopped by a signal"),
        }
    }
}

/// A worker's end of a transport.
pub trait WorkerLink {
    /// The next incoming chunk, waiting at most `timeout` (zero: only what is already here).
    fn receive(&mut self, timeout: Duration) -> Result<Incoming, crate::TransportError>;

    /// Sends the answer to a chunk.
    fn answer(&mut self, answer: &Answer) -> Result<(), crate::TransportError>;

    /// Tells the coordinator that this worker serves the job it accepted last and can hold
    /// `credits` chunks (zenoh's `Ready`); the serve loop calls it before the first chunk and
    /// after every next job. Links whose workers announce themselves as they join (iceoryx2's
    /// hello, a socket's handshake) have nothing to add.
    fn ready(&mut self, _credits: u32) -> Result<(), crate::TransportError> {
        Ok(())
    }
}

/// What the transports tell the user: rendered by the binary (the libraries print nothing).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Notice {
    /// The coordinator waits for workers started by hand.
    Waiting {
        /// The run.
        run: String,
        /// Where the coordinator listens (zenoh), if anywhere.
        listening: Option<String>,
        /// How many.
        workers: usize,
        /// The command that starts one.
        command: String,
    },
    /// A worker joined.
    Joined {
        /// Its name.
        label: String,
        /// Chunks it holds at once.
        credits: usize,
    },
    /// A worker was refused (another protocol, another setup).
    Refused {
        /// Its name.
        label: String,
        /// Why.
        reason: String,
    },
    /// A worker was lost; its work went to the others.
    Lost {
        /// Its name.
        label: String,
        /// Why.
        reason: String,
        /// Evaluations re-dispatched.
        redispatched: usize,
    },
    /// A spawned worker exited before it joined.
    ExitedBeforeJoining {
        /// Its process id.
        pid: u32,
        /// Its exit status.
        status: String,
    },
    /// A replacement worker was started.
    Respawned {
        /// Replacements so far.
        count: usize,
    },
    /// Resources of a dead earlier run were removed.
    CleanedStaleRun {
        /// That run.
        run: String,
    },
}

impl std::fmt::Display for Notice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Notice::Waiting {
                run,
                listening,
                workers,
                command,
            } => {
                write!(f, "run {run}")?;
                if let Some(endpoint) = listening {
                    write!(f, " listening on {endpoint}")?;
                }
                write!(
                    f,
                    ": waiting for {workers} worker(s): start them with `{command}`"
                )
            }
            Notice::Joined { label, credits } => {
                write!(f, "worker {label} joined ({credits} chunk(s) at a time)")
            }
            Notice::Refused { label, reason } => write!(f, "refusing worker {label}: {reason}"),
            Notice::Lost {
                label,
                reason,
                redispatched,
            } => write!(
                f,
                "worker lost: {label} is gone ({reason}); {redispatched} evaluation(s) re-dispatched"
            ),
            Notice::ExitedBeforeJoining { pid, status } => write!(
                f,
                "worker pid {pid} exited before joining ({status}); see its message above"
            ),
            Notice::Respawned { count } => write!(f, "started replacement worker {count}"),
            Notice::CleanedStaleRun { run } => {
                write!(f, "cleaned the stale iceoryx2 resources of run {run}")
            }
        }
    }
}

/// Where notices go: the binary prints them; tests and benchmarks may collect or drop them.
pub type Notices = std::sync::Arc<dyn Fn(Notice) + Send + Sync>;

/// A sink that drops every notice.
pub fn quiet() -> Notices {
    std::sync::Arc::new(|_| {})
}
