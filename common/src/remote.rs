//! Workers on other hosts: the zenoh transport (cargo feature `zenoh`).
//!
//! iceoryx2 is shared memory on one host, so scale-out across hosts uses Eclipse zenoh 1.10
//! (<https://zenoh.io>) under the same [`crate::evaluation::Evaluator`] interface. The
//! coordinator listens on one explicit endpoint (`tcp/ADDR:PORT`); every worker connects to it.
//! Both run zenoh in peer mode with multicast scouting and gossip switched off, so a session
//! talks only to the endpoints it is given (see the README, "Workers on other hosts").
//!
//! Key expressions of run `R` (a run id is `[A-Za-z0-9-]`, so it is one key chunk):
//!
//! | key                          | what                                                      |
//! |------------------------------|-----------------------------------------------------------|
//! | `sepval/R/setup`             | queryable of the coordinator: the job setup ([`SetupFrame`]) |
//! | `sepval/R/coordinator`       | liveliness token of the coordinator                       |
//! | `sepval/R/worker/W`          | liveliness token of worker `W` (its zenoh session id)     |
//! | `sepval/R/up/W`              | worker `W` to the coordinator ([`Up`])                    |
//! | `sepval/R/down/W`            | the coordinator to worker `W` ([`Down`])                  |
//!
//! Work is pulled: a worker announces how many chunks it can hold ([`Up::Ready`]) and every
//! answer hands one credit back, so the coordinator sends a chunk only to a worker that asked
//! for one and fast hosts take more chunks than slow ones. A worker whose liveliness token
//! disappears (process killed, host or link down) loses its in-flight chunks to the others.
//!
//! Every message is postcard behind an envelope of [`MAGIC`] and [`PROTOCOL_VERSION`], checked
//! before the body is decoded, so two versions refuse each other by name instead of misreading
//! each other's bytes. Chunk items and answers are the socket transport's frames
//! ([`crate::uds`]): the same candidates and outcomes, bit for bit.

use std::collections::VecDeque;
use std::sync::Arc;
use std::time::{Duration, Instant};

use crossbeam::channel::{Receiver, RecvTimeoutError, Sender, unbounded};
use serde::{Deserialize, Serialize};
use zenoh::Wait;
use zenoh::qos::CongestionControl;
use zenoh::sample::SampleKind;

use crate::evaluation::{Evaluation, Job, Outcome};
use crate::messages::{MAGIC, PROTOCOL_VERSION, decode_setup};
use crate::uds::{self, AnswerFrame, FromWorker, ItemFrame};

/// Errors of the zenoh transport.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RemoteError {
    /// An endpoint that is not `PROTOCOL/HOST:PORT`.
    #[error(
        "endpoint {0:?}: expected PROTOCOL/HOST:PORT with an explicit port, e.g. tcp/192.0.2.7:7447"
    )]
    Endpoint(String),
    /// A run id that cannot name a run.
    #[error("run id {0:?}: expected 1 to 48 characters of A-Z, a-z, 0-9 and -")]
    RunId(String),
    /// zenoh refused or failed.
    #[error("zenoh: {context}: {message}")]
    Zenoh {
        /// What we were doing.
        context: String,
        /// zenoh's error.
        message: String,
    },
    /// A message that is not ours or not our version.
    #[error("{0}")]
    Message(String),
    /// A setup we refuse.
    #[error("refusing the setup of run {run}: {reason}")]
    Setup {
        /// The run we joined.
        run: String,
        /// Why.
        reason: String,
    },
    /// No coordinator answered.
    #[error(
        "no coordinator of run {run} answered at {endpoint} within {seconds} s (is it running, \
         is the run id right, can this host reach the endpoint?)"
    )]
    NoCoordinator {
        /// The run.
        run: String,
        /// The endpoint.
        endpoint: String,
        /// The wait \[s\].
        seconds: f64,
    },
    /// The chunk server failed.
    #[error("serving a chunk: {0}")]
    Serve(String),
    /// The coordinator refused this worker.
    #[error("the coordinator dropped this worker: {0}")]
    Dropped(String),
}

/// Maps a zenoh error into [`RemoteError::Zenoh`] with what we were doing.
pub fn zerr(context: impl Into<String>) -> impl FnOnce(zenoh::Error) -> RemoteError {
    let context = context.into();
    move |e| RemoteError::Zenoh {
        context,
        message: e.to_string(),
    }
}

/// Checks an endpoint given on the command line: `PROTOCOL/HOST:PORT`, port not 0 (workers must
/// know where to connect).
pub fn validate_endpoint(endpoint: &str) -> Result<(), RemoteError> {
    let bad = || RemoteError::Endpoint(endpoint.to_string());
    let (proto, addr) = endpoint.split_once('/').ok_or_else(bad)?;
    if proto.is_empty() || !proto.chars().all(|c| c.is_ascii_alphanumeric()) {
        return Err(bad());
    }
    let addr = addr.split('#').next().unwrap_or_default();
    let (host, port) = addr.rsplit_once(':').ok_or_else(bad)?;
    match port.parse::<u16>() {
        Ok(p) if p > 0 && !host.is_empty() => Ok(()),
        _ => Err(bad()),
    }
}

/// Checks a run id (the same rule as the shared-memory transport's).
pub fn validate_run_id(run_id: &str) -> Result<(), RemoteError> {
    crate::ipc::validate_run_id(run_id).map_err(|_| RemoteError::RunId(run_id.to_string()))
}

/// Key expressions of a run.
pub mod keys {
    /// The setup queryable.
    pub fn setup(run: &str) -> String {
        format!("sepval/{run}/setup")
    }
    /// The coordinator's liveliness token.
    pub fn coordinator(run: &str) -> String {
        format!("sepval/{run}/coordinator")
    }
    /// A worker's liveliness token.
    pub fn worker(run: &str, worker: &str) -> String {
        format!("sepval/{run}/worker/{worker}")
    }
    /// Every worker's liveliness token.
    pub fn workers(run: &str) -> String {
        format!("sepval/{run}/worker/*")
    }
    /// Messages from a worker.
    pub fn up(run: &str, worker: &str) -> String {
        format!("sepval/{run}/up/{worker}")
    }
    /// Messages from every worker.
    pub fn ups(run: &str) -> String {
        format!("sepval/{run}/up/*")
    }
    /// Messages to a worker.
    pub fn down(run: &str, worker: &str) -> String {
        format!("sepval/{run}/down/{worker}")
    }
    /// The last chunk of a key (the worker id of a worker key).
    pub fn last(key: &str) -> &str {
        key.rsplit('/').next().unwrap_or(key)
    }
}

/// Which side of the transport a session is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The coordinator: listens on the endpoint.
    Listen,
    /// A worker: connects to the endpoint.
    Connect,
}

/// The zenoh configuration of a session: `base` (a zenoh JSON5 configuration file, e.g. with
/// TLS certificates, or zenoh's defaults), then peer mode, multicast scouting and gossip off,
/// and exactly one endpoint to listen on or connect to. A worker listens on nothing.
pub fn config(
    role: Role,
    endpoint: &str,
    base: Option<&std::path::Path>,
) -> Result<zenoh::Config, RemoteError> {
    validate_endpoint(endpoint)?;
    let mut cfg = match base {
        Some(path) => zenoh::Config::from_file(path).map_err(zerr(format!(
            "reading the zenoh configuration {}",
            path.display()
        )))?,
        None => zenoh::Config::default(),
    };
    let endpoint_json = serde_json::to_string(&[endpoint]).expect("a string list serialises");
    let (listen, connect) = match role {
        Role::Listen => (endpoint_json.as_str(), "[]"),
        Role::Connect => ("[]", endpoint_json.as_str()),
    };
    let settings = [
        ("mode", "\"peer\""),
        ("scouting/multicast/enabled", "false"),
        ("scouting/gossip/enabled", "false"),
        ("listen/endpoints", listen),
        ("connect/endpoints", connect),
        // A worker started before its coordinator keeps trying to connect.
        ("connect/timeout_ms", "-1"),
        ("connect/exit_on_failure", "false"),
        // The listening endpoint is the one given, or nothing: fail loudly if it is taken.
        ("listen/exit_on_failure", "true"),
    ];
    for (key, value) in settings {
        cfg.insert_json5(key, value)
            .map_err(zerr(format!("setting {key} = {value}")))?;
    }
    Ok(cfg)
}

/// Opens a zenoh session.
pub fn open(cfg: zenoh::Config, endpoint: &str) -> Result<zenoh::Session, RemoteError> {
    zenoh::open(cfg)
        .wait()
        .map_err(zerr(format!("opening a session on {endpoint}")))
}

/// The job setup as the coordinator's queryable serves it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SetupFrame {
    /// The run id the setup belongs to.
    pub run_id: String,
    /// SHA-256 of `bytes`.
    pub sha256: [u8; 32],
    /// The effect catalogue's fingerprint.
    pub catalogue: [u8; 32],
    /// The setup bytes ([`crate::messages::encode_setup`]).
    pub bytes: Vec<u8>,
}

/// Worker to coordinator, on `sepval/R/up/W`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Up {
    /// Accepted the setup; can hold `credits` chunks at once.
    Ready {
        /// Chunks the worker can hold.
        credits: u32,
        /// Host name, for messages.
        host: String,
        /// Process id, for messages.
        pid: u32,
        /// SHA-256 of the setup accepted.
        setup_sha256: [u8; 32],
    },
    /// The answers of one chunk (and one credit back).
    Answer(FromWorker),
}

/// Coordinator to worker, on `sepval/R/down/W`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Down {
    /// A chunk of candidates.
    Chunk {
        /// Chunk id (echoed).
        chunk_id: u64,
        /// Whether samples are wanted.
        with_samples: bool,
        /// The candidates.
        items: Vec<ItemFrame>,
    },
    /// Stop serving: the run is finished.
    Quit {
        /// Why.
        reason: String,
    },
    /// The coordinator refuses this worker (another protocol version, a chunk held past the
    /// deadline, a malformed answer) and ignores it from now on.
    Dropped {
        /// Why.
        reason: String,
    },
}

/// Encodes a message behind the envelope (magic, protocol version).
pub fn encode<T: Serialize>(body: &T) -> Vec<u8> {
    encode_as(PROTOCOL_VERSION, body)
}

/// Encodes a message announcing `protocol` (compatibility tests announce other versions).
pub fn encode_as<T: Serialize>(protocol: u32, body: &T) -> Vec<u8> {
    postcard::to_stdvec(&(MAGIC, protocol, body)).expect("messages serialise")
}

/// Decodes a message, refusing another magic or protocol version before reading the body.
pub fn decode<T: for<'de> Deserialize<'de>>(bytes: &[u8], what: &str) -> Result<T, RemoteError> {
    let ((magic, protocol), rest) = postcard::take_from_bytes::<(u64, u32)>(bytes)
        .map_err(|e| RemoteError::Message(format!("{what}: not a sepval message ({e})")))?;
    if magic != MAGIC {
        return Err(RemoteError::Message(format!(
            "{what}: magic {magic:#x}, expected {MAGIC:#x}: not a sepval message"
        )));
    }
    if protocol != PROTOCOL_VERSION {
        return Err(RemoteError::Message(format!(
            "{what}: protocol version {protocol}, ours is {PROTOCOL_VERSION}"
        )));
    }
    postcard::from_bytes(rest)
        .map_err(|e| RemoteError::Message(format!("{what}: does not decode ({e})")))
}

/// Checks a setup frame against the run we were told to join and decodes its job.
pub fn accept_setup(run: &str, bytes: &[u8]) -> Result<(SetupFrame, Job), RemoteError> {
    let refuse = |reason: String| RemoteError::Setup {
        run: run.to_string(),
        reason,
    };
    let frame: SetupFrame = decode(bytes, "setup").map_err(|e| refuse(e.to_string()))?;
    if frame.run_id != run {
        return Err(refuse(format!(
            "it belongs to run {:?}; this worker was told to join run {run:?}",
            frame.run_id
        )));
    }
    let header = uds::setup_header(
        PROTOCOL_VERSION,
        frame.sha256,
        frame.catalogue,
        frame.bytes.len(),
    );
    let job = decode_setup(&header, &frame.bytes).map_err(|e| refuse(e.to_string()))?;
    Ok((frame, job))
}

/// Evaluates the chunks a worker receives: one simulation at a time in this process
/// ([`Local`]), or a host's iceoryx2 workers behind a gateway.
pub trait ChunkServer {
    /// Chunks this server can hold at once (its credits).
    fn credits(&self) -> u32;
    /// Chunks evaluated together as one batch; the rest of what it holds waits its turn, so
    /// every answered chunk frees a credit, and a new chunk arrives, while the others run.
    fn parallelism(&self) -> usize {
        1
    }
    /// Evaluates candidates; `out[i]` answers `candidates[i]`. A malformed candidate becomes a
    /// failed outcome; `Err` is for a server that can no longer serve at all.
    fn evaluate(
        &mut self,
        candidates: &[&ItemFrame],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, String>;
}

/// The plain worker: simulates each candidate itself.
pub struct Local(pub Arc<Job>);

impl ChunkServer for Local {
    fn credits(&self) -> u32 {
        2
    }

    fn evaluate(
        &mut self,
        candidates: &[&ItemFrame],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, String> {
        Ok(candidates
            .iter()
            .map(
                |(_, factors, effects)| match uds::candidate(factors, effects) {
                    Ok(c) if with_samples => self.0.evaluate_with_samples(&c),
                    Ok(c) => self.0.evaluate(&c),
                    Err(reason) => Evaluation::from(Outcome::Failed {
                        reason: format!("malformed request: {reason}"),
                    }),
                },
            )
            .collect())
    }
}

/// How a worker joins a run.
#[derive(Debug, Clone)]
pub struct JoinOptions {
    /// The coordinator's endpoint.
    pub endpoint: String,
    /// The run to join.
    pub run_id: String,
    /// How long to wait for the setup \[s\].
    pub setup_timeout: Duration,
    /// A zenoh configuration file to start from (TLS, authentication).
    pub zenoh_config: Option<std::path::PathBuf>,
    /// Announce this protocol version instead of ours (compatibility tests only).
    pub announce_protocol: Option<u32>,
}

/// Why a worker stopped serving (normal ends; failures are errors).
#[derive(Debug, Clone, PartialEq)]
pub enum Stopped {
    /// The coordinator told us to stop.
    Quit(String),
    /// The coordinator's liveliness token went away.
    CoordinatorGone,
}

impl std::fmt::Display for Stopped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Stopped::Quit(reason) => write!(f, "the coordinator ended our work: {reason}"),
            Stopped::CoordinatorGone => write!(f, "the coordinator is gone; exiting"),
        }
    }
}

enum Inbox {
    Down(Vec<u8>),
    CoordinatorAlive(bool),
}

/// A worker's session in a run: joined, setup accepted, ready to serve.
pub struct Joined {
    session: zenoh::Session,
    options: JoinOptions,
    worker_id: String,
    frame: SetupFrame,
    job: Job,
    inbox: Receiver<Inbox>,
    _subscribers: (zenoh::pubsub::Subscriber<()>, zenoh::pubsub::Subscriber<()>),
    _token: zenoh::liveliness::LivelinessToken,
}

/// Joins a run: connects, declares our liveliness, asks the coordinator for the setup until
/// `setup_timeout` and checks it (run id, protocol version, hash).
pub fn join(options: JoinOptions) -> Result<Joined, RemoteError> {
    validate_run_id(&options.run_id)?;
    let cfg = config(
        Role::Connect,
        &options.endpoint,
        options.zenoh_config.as_deref(),
    )?;
    let session = open(cfg, &options.endpoint)?;
    let run = options.run_id.clone();
    let worker_id = session.zid().to_string();
    let (tx, inbox) = unbounded();
    let down = {
        let tx: Sender<Inbox> = tx.clone();
        session
            .declare_subscriber(keys::down(&run, &worker_id))
            .callback(move |s| {
                let _ = tx.send(Inbox::Down(s.payload().to_bytes().into_owned()));
            })
            .wait()
            .map_err(zerr("subscribing to our chunks"))?
    };
    let alive = session
        .liveliness()
        .declare_subscriber(keys::coordinator(&run))
        .history(true)
        .callback(move |s| {
            let _ = tx.send(Inbox::CoordinatorAlive(s.kind() == SampleKind::Put));
        })
        .wait()
        .map_err(zerr("watching the coordinator's liveliness"))?;
    let token = session
        .liveliness()
        .declare_token(keys::worker(&run, &worker_id))
        .wait()
        .map_err(zerr("declaring our liveliness"))?;
    let deadline = Instant::now() + options.setup_timeout;
    let (frame, job) = loop {
        let replies = session
            .get(keys::setup(&run))
            .timeout(Duration::from_secs(2))
            .wait()
            .map_err(zerr("asking for the setup"))?;
        if let Ok(reply) = replies.recv() {
            match reply.into_result() {
                Ok(sample) => break accept_setup(&run, &sample.payload().to_bytes())?,
                Err(e) => {
                    return Err(RemoteError::Setup {
                        run,
                        reason: format!(
                            "the coordinator answered with an error: {}",
                            String::from_utf8_lossy(&e.payload().to_bytes())
                        ),
                    });
                }
            }
        }
        if Instant::now() >= deadline {
            return Err(RemoteError::NoCoordinator {
                run,
                endpoint: options.endpoint.clone(),
                seconds: options.setup_timeout.as_secs_f64(),
            });
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    Ok(Joined {
        session,
        options,
        worker_id,
        frame,
        job,
        inbox,
        _subscribers: (down, alive),
        _token: token,
    })
}

impl Joined {
    /// The job of the accepted setup.
    pub fn job(&self) -> &Job {
        &self.job
    }

    /// Our worker id (the zenoh session id).
    pub fn worker_id(&self) -> &str {
        &self.worker_id
    }

    /// Announces our credits and serves chunks until the coordinator ends the run or goes.
    pub fn serve(self, server: &mut dyn ChunkServer) -> Result<Stopped, RemoteError> {
        let run = &self.options.run_id;
        let publisher = self
            .session
            .declare_publisher(keys::up(run, &self.worker_id))
            .congestion_control(CongestionControl::Block)
            .wait()
            .map_err(zerr("publishing to the coordinator"))?;
        let protocol = self.options.announce_protocol.unwrap_or(PROTOCOL_VERSION);
        let ready = Up::Ready {
            credits: server.credits().max(1),
            host: host_name(),
            pid: std::process::id(),
            setup_sha256: self.frame.sha256,
        };
        publisher
            .put(encode_as(protocol, &ready))
            .wait()
            .map_err(zerr("announcing ourselves"))?;
        let mut queue: VecDeque<(u64, bool, Vec<ItemFrame>)> = VecDeque::new();
        loop {
            // Block only when nothing is queued; control messages act at once.
            let mut inbox: Vec<Inbox> = Vec::new();
            if queue.is_empty() {
                match self.inbox.recv_timeout(Duration::from_millis(500)) {
                    Ok(m) => inbox.push(m),
                    Err(RecvTimeoutError::Timeout) => continue,
                    Err(RecvTimeoutError::Disconnected) => return Ok(Stopped::CoordinatorGone),
                }
            }
            inbox.extend(self.inbox.try_iter());
            for message in inbox {
                match message {
                    Inbox::CoordinatorAlive(true) => {}
                    Inbox::CoordinatorAlive(false) => return Ok(Stopped::CoordinatorGone),
                    Inbox::Down(bytes) => {
                        match decode::<Down>(&bytes, "message from the coordinator")? {
                            Down::Quit { reason } => return Ok(Stopped::Quit(reason)),
                            Down::Dropped { reason } => return Err(RemoteError::Dropped(reason)),
                            Down::Chunk {
                                chunk_id,
                                with_samples,
                                items,
                            } => queue.push_back((chunk_id, with_samples, items)),
                        }
                    }
                }
            }
            // The next chunks of one kind, up to the server's parallelism (a gateway spreads
            // them over its workers), in the order they came.
            let Some(with_samples) = queue.front().map(|c| c.1) else {
                continue;
            };
            let mut group = Vec::new();
            while group.len() < server.parallelism().max(1)
                && queue.front().is_some_and(|c| c.1 == with_samples)
            {
                group.extend(queue.pop_front());
            }
            let items: Vec<&ItemFrame> = group.iter().flat_map(|c| c.2.iter()).collect();
            let evaluations = server
                .evaluate(&items, with_samples)
                .map_err(RemoteError::Serve)?;
            if evaluations.len() != items.len() {
                return Err(RemoteError::Serve(format!(
                    "{} evaluations for {} candidates",
                    evaluations.len(),
                    items.len()
                )));
            }
            let mut evaluations = evaluations.into_iter();
            for (chunk_id, _, chunk_items) in &group {
                let answers: Vec<AnswerFrame> = chunk_items
                    .iter()
                    .zip(evaluations.by_ref())
                    .map(|((index, _, _), e)| {
                        (
                            *index,
                            uds::OutcomeFrame::from(&e.outcome),
                            e.samples.as_deref().map(uds::samples_out),
                        )
                    })
                    .collect();
                let answer = Up::Answer(FromWorker {
                    chunk_id: *chunk_id,
                    items: answers,
                });
                publisher
                    .put(encode_as(protocol, &answer))
                    .wait()
                    .map_err(zerr("answering a chunk"))?;
            }
        }
    }
}

/// This host's name, for messages.
pub fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|s| s.trim().to_string())
        .ok()
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown-host".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endpoints_are_checked() {
        validate_endpoint("tcp/127.0.0.1:7447").unwrap();
        validate_endpoint("tcp/[::1]:7447").unwrap();
        validate_endpoint("tls/host.example:7447").unwrap();
        for bad in [
            "127.0.0.1:7447",
            "tcp/127.0.0.1",
            "tcp/127.0.0.1:0",
            "tcp/:7447",
            "tcp/h:70000",
            "/h:1",
        ] {
            assert!(validate_endpoint(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn envelopes_refuse_other_versions_by_name() {
        let m = Down::Quit { reason: "x".into() };
        assert_eq!(decode::<Down>(&encode(&m), "m").unwrap(), m);
        let e = decode::<Down>(&encode_as(PROTOCOL_VERSION + 1, &m), "m").unwrap_err();
        assert!(e.to_string().contains("protocol version"), "{e}");
        let e = decode::<Down>(b"hello", "m").unwrap_err();
        assert!(e.to_string().contains("not a sepval message"), "{e}");
    }

    #[test]
    fn a_setup_of_another_run_is_refused() {
        let job = Job::single(
            "default",
            &crate::scenario::Scenario::embedded_default(),
            crate::synthetic::default_flight_test(),
        );
        let (header, bytes) = crate::messages::encode_setup(&job);
        let frame = SetupFrame {
            run_id: "run-a".into(),
            sha256: header.sha256,
            catalogue: header.catalogue,
            bytes,
        };
        let wire = encode(&frame);
        accept_setup("run-a", &wire).unwrap();
        let e = accept_setup("run-b", &wire).unwrap_err().to_string();
        assert!(e.contains("belongs to run \"run-a\""), "{e}");
        let e = accept_setup("run-a", &encode_as(PROTOCOL_VERSION + 1, &frame))
            .unwrap_err()
            .to_string();
        assert!(e.contains("protocol version"), "{e}");
        let mut tampered = frame.clone();
        tampered.bytes[0] ^= 1;
        let e = accept_setup("run-a", &encode(&tampered))
            .unwrap_err()
            .to_string();
        assert!(e.contains("run-a"), "{e}");
    }
}
