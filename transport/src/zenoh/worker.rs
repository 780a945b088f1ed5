//! A worker's end of the zenoh transport: [`ZenohWorker`].
//!
//! A worker connects to the coordinator's endpoint, declares its liveliness, asks for the setup
//! until `setup_timeout` and checks it (run id, protocol version, catalogue, hash) before it
//! says `Ready` with its credits. When the coordinator sends another setup of the same run (the
//! next job of an envelope or an update), it checks it alike, serves it from then on and says
//! `Ready` again, so a worker that joined serves the run until the coordinator's command ends.
//! It stops when the coordinator says `Quit`, when the coordinator's liveliness token goes, or
//! on a signal; a `Dropped` message is an error.

use std::sync::Arc;
use std::time::{Duration, Instant};

use crossbeam::channel::{Receiver, RecvTimeoutError, Sender, unbounded};
use sepval_common::evaluation::Job;
use sepval_core::cancel;
use zenoh::Wait;
use zenoh::qos::CongestionControl;
use zenoh::sample::SampleKind;

use super::{Role, host_name, keys, zerr};
use crate::codec::Frame;
use crate::link::{Incoming, Stopped, WorkerLink};
use crate::setup::decode_setup;
use crate::wire::{Answer, PROTOCOL_VERSION};
use crate::{RunId, TransportError};

/// How a worker joins a run.
#[derive(Debug, Clone)]
pub struct JoinOptions {
    /// The coordinator's endpoint.
    pub endpoint: String,
    /// The run to join.
    pub run_id: RunId,
    /// How long to wait for the setup.
    pub setup_timeout: Duration,
    /// A zenoh configuration file to start from (TLS, authentication).
    pub zenoh_config: Option<std::path::PathBuf>,
    /// Announce this protocol version instead of ours (compatibility tests only).
    pub announce_protocol: Option<u32>,
}

enum Inbox {
    Down(Vec<u8>),
    CoordinatorAlive(bool),
}

/// A worker's session in a run: joined, setup accepted.
pub struct ZenohWorker {
    options: JoinOptions,
    worker_id: String,
    setup_sha256: [u8; 32],
    job: Arc<Job>,
    inbox: Receiver<Inbox>,
    publisher: zenoh::pubsub::Publisher<'static>,
    _subscribers: (zenoh::pubsub::Subscriber<()>, zenoh::pubsub::Subscriber<()>),
    _token: zenoh::liveliness::LivelinessToken,
    session: zenoh::Session,
}

/// Checks a setup frame against the run we were told to join and decodes its job.
fn accept_setup(run: &RunId, bytes: &[u8]) -> Result<(Job, [u8; 32]), TransportError> {
    let refuse = |reason: String| TransportError::SetupRefused {
        run: run.to_string(),
        reason,
    };
    match Frame::decode(bytes) {
        Ok(Frame::Setup {
            run_id,
            header,
            bytes,
        }) => {
            if run_id != run.as_str() {
                return Err(refuse(format!(
                    "it belongs to run {run_id:?}; this worker was told to join run {:?}",
                    run.as_str()
                )));
            }
            let job = decode_setup(&header, &bytes).map_err(|e| refuse(crate::error_chain(&e)))?;
            Ok((job, header.sha256))
        }
        Ok(other) => Err(refuse(format!(
            "the coordinator sent {}",
            Frame::name_of(Some(&other))
        ))),
        Err(e) => Err(refuse(format!("setup: {e}"))),
    }
}

impl ZenohWorker {
    /// Joins a run: connects, declares our liveliness, asks the coordinator for the setup until
    /// `setup_timeout` and checks it.
    pub fn join(options: JoinOptions) -> Result<ZenohWorker, TransportError> {
        let cfg = super::config(
            Role::Connect,
            &options.endpoint,
            options.zenoh_config.as_deref(),
        )?;
        let session = super::open(cfg, &options.endpoint)?;
        let run = options.run_id.to_string();
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
        let (job, setup_sha256) = loop {
            cancel::check()?;
            let replies = session
                .get(keys::setup(&run))
                .timeout(Duration::from_secs(2))
                .wait()
                .map_err(zerr("asking for the setup"))?;
            if let Ok(reply) = replies.recv() {
                match reply.into_result() {
                    Ok(sample) => {
                        break accept_setup(&options.run_id, &sample.payload().to_bytes())?;
                    }
                    Err(e) => {
                        return Err(TransportError::SetupRefused {
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
                return Err(TransportError::NoCoordinator {
                    run,
                    place: format!("at {}", options.endpoint),
                    seconds: options.setup_timeout.as_secs_f64(),
                });
            }
            std::thread::sleep(Duration::from_millis(200));
        };
        let publisher = session
            .declare_publisher(keys::up(&run, &worker_id))
            .congestion_control(CongestionControl::Block)
            .wait()
            .map_err(zerr("publishing to the coordinator"))?;
        Ok(ZenohWorker {
            options,
            worker_id,
            setup_sha256,
            job: Arc::new(job),
            inbox,
            publisher,
            _subscribers: (down, alive),
            _token: token,
            session,
        })
    }

    /// The job of the accepted setup.
    pub fn job(&self) -> &Arc<Job> {
        &self.job
    }

    /// Our worker id (the zenoh session id).
    pub fn worker_id(&self) -> &str {
        &self.worker_id
    }

    fn put(&self, frame: &Frame) -> Result<(), TransportError> {
        let protocol = self.options.announce_protocol.unwrap_or(PROTOCOL_VERSION);
        self.publisher
            .put(frame.encode_as(protocol))
            .wait()
            .map_err(zerr("sending to the coordinator"))
    }
}

impl WorkerLink for ZenohWorker {
    fn receive(&mut self, timeout: Duration) -> Result<Incoming, TransportError> {
        if cancel::requested() {
            return Ok(Incoming::Stop(Stopped::Signal));
        }
        let message = match self.inbox.recv_timeout(timeout) {
            Ok(m) => m,
            Err(RecvTimeoutError::Timeout) => return Ok(Incoming::Idle),
            Err(RecvTimeoutError::Disconnected) => {
                return Ok(Incoming::Stop(Stopped::CoordinatorGone(
                    self.options.run_id.to_string(),
                )));
            }
        };
        match message {
            Inbox::CoordinatorAlive(true) => Ok(Incoming::Idle),
            Inbox::CoordinatorAlive(false) => Ok(Incoming::Stop(Stopped::CoordinatorGone(
                self.options.run_id.to_string(),
            ))),
            Inbox::Down(bytes) => {
                let frame = Frame::decode(&bytes).map_err(|source| TransportError::Codec {
                    what: "message from the coordinator".into(),
                    source,
                })?;
                if !matches!(frame, Frame::Setup { .. }) {
                    return frame.into_incoming();
                }
                // The next job of the run: checked as the first setup was.
                let (job, setup_sha256) = accept_setup(&self.options.run_id, &bytes)?;
                self.job = Arc::new(job);
                self.setup_sha256 = setup_sha256;
                Ok(Incoming::Job(Arc::clone(&self.job)))
            }
        }
    }

    fn answer(&mut self, answer: &Answer) -> Result<(), TransportError> {
        self.put(&Frame::Answer(answer.clone()))
    }

    /// Tells the coordinator we accepted its latest setup and can hold `credits` chunks.
    fn ready(&mut self, credits: u32) -> Result<(), TransportError> {
        self.put(&Frame::Ready {
            pid: std::process::id(),
            credits: credits.max(1),
            setup_sha256: self.setup_sha256,
            host: host_name(),
        })
    }
}

impl Drop for ZenohWorker {
    fn drop(&mut self) {
        let _ = self.session.close().wait();
    }
}
