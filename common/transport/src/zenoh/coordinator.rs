//! The coordinator's end of the zenoh transport: [`ZenohLink`].
//!
//! The coordinator listens on one endpoint, serves the job setup from a queryable, watches the
//! workers' liveliness tokens (a worker whose token goes is lost: killed, host down, link cut)
//! and hears their `Ready` and `Answer` frames. A worker of another protocol version, or one that
//! accepted another setup, is told it is dropped and ignored from then on. Workers may join at
//! any time; when none is left, the dispatcher waits up to the join timeout for one.

use std::collections::{BTreeMap, BTreeSet};
use std::time::Duration;

use crossbeam::channel::{Receiver, RecvTimeoutError, unbounded};
use sepval_common::cancel;
use sepval_common::evaluation::Job;
use zenoh::Wait;
use zenoh::qos::CongestionControl;
use zenoh::sample::SampleKind;

use super::{Role, keys, zerr};
use crate::codec::{CodecError, Frame};
use crate::link::{Link, LinkEvent, Notice, WorkerId};
use crate::setup::encode_setup_as;
use crate::wire::{Chunk, PROTOCOL_VERSION};
use crate::{RunId, TransportError};

/// How the zenoh coordinator runs.
#[derive(Debug, Clone)]
pub struct ZenohOptions {
    /// Run id (workers must be told it).
    pub run_id: RunId,
    /// The endpoint to listen on, e.g. `tcp/192.0.2.7:7447`.
    pub listen: String,
    /// Workers the run waits for (for the notice).
    pub workers: usize,
    /// How long to wait for a worker when none is left.
    pub join_timeout: Duration,
    /// A zenoh configuration file to start from (TLS, authentication).
    pub zenoh_config: Option<std::path::PathBuf>,
    /// Announce this protocol version (compatibility tests only).
    pub announce_protocol: Option<u32>,
}

enum Heard {
    Alive(String, bool),
    Message(String, Vec<u8>),
}

struct Remote {
    id: WorkerId,
    publisher: zenoh::pubsub::Publisher<'static>,
}

/// The coordinator's end of the zenoh transport.
pub struct ZenohLink {
    options: ZenohOptions,
    session: zenoh::Session,
    heard: Receiver<Heard>,
    workers: BTreeMap<String, Remote>,
    /// Workers refused or given up on: ignored from then on.
    dropped: BTreeSet<String>,
    next_worker: WorkerId,
    setup_sha256: [u8; 32],
    early: Vec<Notice>,
    _queryable: zenoh::query::Queryable<()>,
    _subscribers: (zenoh::pubsub::Subscriber<()>, zenoh::pubsub::Subscriber<()>),
    _token: zenoh::liveliness::LivelinessToken,
}

impl ZenohLink {
    /// Listens on the endpoint and serves the setup.
    pub fn start(job: &Job, options: ZenohOptions) -> Result<ZenohLink, TransportError> {
        let cfg = super::config(
            Role::Listen,
            &options.listen,
            options.zenoh_config.as_deref(),
        )?;
        let session = super::open(cfg, &options.listen)?;
        let run = options.run_id.to_string();
        let protocol = options.announce_protocol.unwrap_or(PROTOCOL_VERSION);
        let (header, bytes) = encode_setup_as(job, protocol);
        let setup = Frame::Setup {
            run_id: run.clone(),
            header,
            bytes,
        }
        .encode_as(protocol);
        let setup_key = keys::setup(&run);
        let queryable = {
            let key = setup_key.clone();
            session
                .declare_queryable(&setup_key)
                .callback(move |query| {
                    let _ = query.reply(&key, setup.clone()).wait();
                })
                .wait()
                .map_err(zerr("serving the setup"))?
        };
        let (tx, heard) = unbounded();
        let alive = {
            let tx = tx.clone();
            session
                .liveliness()
                .declare_subscriber(keys::workers(&run))
                .history(true)
                .callback(move |s| {
                    let id = keys::last(s.key_expr().as_str()).to_string();
                    let _ = tx.send(Heard::Alive(id, s.kind() == SampleKind::Put));
                })
                .wait()
                .map_err(zerr("watching worker liveliness"))?
        };
        let ups = session
            .declare_subscriber(keys::ups(&run))
            .callback(move |s| {
                let id = keys::last(s.key_expr().as_str()).to_string();
                let _ = tx.send(Heard::Message(id, s.payload().to_bytes().into_owned()));
            })
            .wait()
            .map_err(zerr("listening to workers"))?;
        let token = session
            .liveliness()
            .declare_token(keys::coordinator(&run))
            .wait()
            .map_err(zerr("declaring our liveliness"))?;
        let early = vec![Notice::Waiting {
            run: run.clone(),
            listening: Some(options.listen.clone()),
            workers: options.workers,
            command: format!("sepval-worker --connect {} --run {run}", options.listen),
        }];
        Ok(ZenohLink {
            options,
            session,
            heard,
            workers: BTreeMap::new(),
            dropped: BTreeSet::new(),
            next_worker: 0,
            setup_sha256: header.sha256,
            early,
            _queryable: queryable,
            _subscribers: (alive, ups),
            _token: token,
        })
    }

    /// Tells worker `zid` it is dropped and ignores it from now on.
    fn refuse(&mut self, zid: &str, reason: &str) {
        self.dropped.insert(zid.to_string());
        let message = Frame::Dropped(reason.to_string()).encode();
        match self.workers.remove(zid) {
            Some(w) => {
                let _ = w.publisher.put(message).wait();
            }
            None => {
                let _ = self
                    .session
                    .put(keys::down(self.options.run_id.as_str(), zid), message)
                    .congestion_control(CongestionControl::Block)
                    .wait();
            }
        }
    }

    fn heard(&mut self, h: Heard, events: &mut Vec<LinkEvent>) -> Result<(), TransportError> {
        match h {
            // A worker registers with its Ready frame; its token only tells us it left.
            Heard::Alive(_, true) => {}
            Heard::Alive(zid, false) => {
                if let Some(w) = self.workers.remove(&zid) {
                    events.push(LinkEvent::Lost {
                        worker: w.id,
                        reason: "its liveliness token is gone".into(),
                    });
                }
            }
            Heard::Message(zid, bytes) => {
                if self.dropped.contains(&zid) {
                    return Ok(());
                }
                match Frame::decode(&bytes) {
                    Ok(Frame::Ready {
                        pid,
                        credits,
                        setup_sha256,
                        host,
                    }) => self.ready(zid, pid, credits, setup_sha256, host, events)?,
                    Ok(Frame::Answer(answer)) => {
                        if let Some(w) = self.workers.get(&zid) {
                            events.push(LinkEvent::Answer {
                                worker: w.id,
                                answer,
                            });
                        }
                    }
                    Ok(other) => {
                        let reason = format!(
                            "it sent {}, which workers do not send",
                            Frame::name_of(Some(&other))
                        );
                        self.misbehaved(&zid, &reason, events);
                    }
                    Err(e @ CodecError::Protocol { .. }) => {
                        self.misbehaved(&zid, &e.to_string(), events)
                    }
                    Err(e) => self.misbehaved(&zid, &format!("malformed message: {e}"), events),
                }
            }
        }
        Ok(())
    }

    fn misbehaved(&mut self, zid: &str, reason: &str, events: &mut Vec<LinkEvent>) {
        match self.workers.get(zid).map(|w| w.id) {
            Some(id) => events.push(LinkEvent::Lost {
                worker: id,
                reason: reason.to_string(),
            }),
            None => events.push(LinkEvent::Notice(Notice::Refused {
                label: zid.to_string(),
                reason: reason.to_string(),
            })),
        }
        self.refuse(zid, reason);
    }

    fn ready(
        &mut self,
        zid: String,
        pid: u32,
        credits: u32,
        setup_sha256: [u8; 32],
        host: String,
        events: &mut Vec<LinkEvent>,
    ) -> Result<(), TransportError> {
        let label = format!("{host} pid {pid} ({zid})");
        if setup_sha256 != self.setup_sha256 {
            events.push(LinkEvent::Notice(Notice::Refused {
                label,
                reason: "it accepted another setup".into(),
            }));
            self.refuse(&zid, "it accepted another setup");
            return Ok(());
        }
        let id = match self.workers.get(&zid) {
            Some(w) => w.id,
            None => {
                let publisher = self
                    .session
                    .declare_publisher(keys::down(self.options.run_id.as_str(), &zid))
                    .congestion_control(CongestionControl::Block)
                    .wait()
                    .map_err(zerr(format!("publishing to worker {label}")))?;
                let id = self.next_worker;
                self.next_worker += 1;
                self.workers.insert(zid, Remote { id, publisher });
                id
            }
        };
        events.push(LinkEvent::Joined {
            worker: id,
            label,
            credits: credits as usize,
        });
        Ok(())
    }

    fn zid_of(&self, worker: WorkerId) -> Option<String> {
        self.workers
            .iter()
            .find(|(_, w)| w.id == worker)
            .map(|(z, _)| z.clone())
    }
}

impl Link for ZenohLink {
    fn send(&mut self, worker: WorkerId, chunk: &Chunk) -> Result<(), String> {
        let w = self
            .workers
            .values()
            .find(|w| w.id == worker)
            .ok_or_else(|| format!("no worker {worker}"))?;
        w.publisher
            .put(Frame::Chunk(chunk.clone()).encode())
            .wait()
            .map_err(|e| e.to_string())
    }

    fn poll(
        &mut self,
        timeout: Duration,
        events: &mut Vec<LinkEvent>,
    ) -> Result<(), TransportError> {
        cancel::check()?;
        events.extend(self.early.drain(..).map(LinkEvent::Notice));
        match self.heard.recv_timeout(timeout) {
            Ok(h) => self.heard(h, events)?,
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => {
                return Err(TransportError::Protocol("the zenoh session closed".into()));
            }
        }
        while let Ok(h) = self.heard.try_recv() {
            self.heard(h, events)?;
        }
        Ok(())
    }

    fn drop_worker(&mut self, worker: WorkerId, reason: &str) -> &'static str {
        if let Some(zid) = self.zid_of(worker) {
            self.refuse(&zid, reason);
        }
        "told to quit"
    }

    fn replacement_wait(&self) -> Duration {
        self.options.join_timeout
    }

    fn run_id(&self) -> &str {
        self.options.run_id.as_str()
    }

    fn describe(&self) -> String {
        format!("zenoh at {}", self.options.listen)
    }
}

impl Drop for ZenohLink {
    fn drop(&mut self) {
        for w in self.workers.values() {
            let _ = w
                .publisher
                .put(Frame::Quit("the run is finished".into()).encode())
                .wait();
        }
        let _ = self.session.close().wait();
    }
}
