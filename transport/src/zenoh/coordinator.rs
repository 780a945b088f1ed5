//! The coordinator's end of the zenoh transport: [`ZenohLink`].
//!
//! The coordinator listens on one endpoint, serves the job setup from a queryable, watches the
//! workers' liveliness tokens (a worker whose token goes is lost: killed, host down, link cut)
//! and hears their `Ready` and `Answer` frames. A worker of another protocol version, or one that
//! accepted another setup, is told it is dropped and ignored from then on. Workers may join at
//! any time; when none is left, the dispatcher waits up to the join timeout for one.
//!
//! One link serves a whole command: for the next job of the run (an envelope's next condition,
//! an update's next round), [`ZenohLink::next_job`] serves the new setup and sends it to every
//! worker that joined, which says `Ready` again with its hash; until then its answers (to
//! chunks of the job before) are not heard. A worker that said `Ready` to an earlier setup of
//! the run is sent the current one; only `Quit`, when the link is dropped at the command's end,
//! tells the workers that the run is finished.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use crossbeam::channel::{Receiver, RecvTimeoutError, unbounded};
use sepval_common::evaluation::Job;
use sepval_core::cancel;
use zenoh::Wait;
use zenoh::qos::CongestionControl;
use zenoh::sample::SampleKind;

use super::{Role, keys, zerr};
use crate::codec::{CodecError, Frame};
use crate::link::{Link, LinkEvent, NextJob, Notice, SendError, WorkerId};
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
    /// It said `Ready` to the current setup (its answers are heard).
    serving: bool,
}

/// The setup on offer: its frame (what the queryable answers) and its hash.
struct Offer {
    frame: Vec<u8>,
    sha256: [u8; 32],
}

impl Offer {
    fn of(job: &Job, run: &str, protocol: u32) -> Offer {
        let (header, bytes) = encode_setup_as(job, protocol);
        let frame = Frame::Setup {
            run_id: run.to_string(),
            header,
            bytes,
        }
        .encode_as(protocol);
        Offer {
            frame,
            sha256: header.sha256,
        }
    }
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
    /// The current setup, shared with the queryable that serves it.
    offer: Arc<Mutex<Arc<Offer>>>,
    /// Hashes of the earlier setups of this run (jobs done).
    earlier: Vec<[u8; 32]>,
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
        let offer = Arc::new(Mutex::new(Arc::new(Offer::of(job, &run, protocol))));
        let setup_key = keys::setup(&run);
        let queryable = {
            let key = setup_key.clone();
            let offer = Arc::clone(&offer);
            session
                .declare_queryable(&setup_key)
                .callback(move |query| {
                    let current = Arc::clone(&offer.lock().expect("the offer's lock"));
                    let _ = query.reply(&key, current.frame.clone()).wait();
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
            offer,
            earlier: Vec::new(),
            early,
            _queryable: queryable,
            _subscribers: (alive, ups),
            _token: token,
        })
    }

    fn current(&self) -> Arc<Offer> {
        Arc::clone(&self.offer.lock().expect("the offer's lock"))
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
                        // Only a worker serving the current job is heard.
                        if let Some(w) = self.workers.get(&zid).filter(|w| w.serving) {
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
        let current = self.current();
        let serving = setup_sha256 == current.sha256;
        if !serving && !self.earlier.contains(&setup_sha256) {
            events.push(LinkEvent::Notice(Notice::Refused {
                label,
                reason: "it accepted another setup".into(),
            }));
            self.refuse(&zid, "it accepted another setup");
            return Ok(());
        }
        if !self.workers.contains_key(&zid) {
            let publisher = self
                .session
                .declare_publisher(keys::down(self.options.run_id.as_str(), &zid))
                .congestion_control(CongestionControl::Block)
                .wait()
                .map_err(zerr(format!("publishing to worker {label}")))?;
            let id = self.next_worker;
            self.next_worker += 1;
            let remote = Remote {
                id,
                publisher,
                serving: false,
            };
            self.workers.insert(zid.clone(), remote);
        }
        let w = self.workers.get_mut(&zid).expect("inserted above");
        w.serving = serving;
        if !serving {
            // It joined while an earlier job ran: it is sent the current one.
            if let Err(e) = w.publisher.put(current.frame.clone()).wait() {
                let why = format!("sending the current job failed: {e}");
                self.refuse(&zid, &why);
            }
            return Ok(());
        }
        let id = w.id;
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
    fn send(&mut self, worker: WorkerId, chunk: &Chunk) -> Result<(), SendError> {
        let w = self
            .workers
            .values()
            .find(|w| w.id == worker)
            .ok_or(SendError::NoWorker { worker })?;
        w.publisher
            .put(Frame::Chunk(chunk.clone()).encode())
            .wait()
            .map_err(|e| SendError::Refused {
                what: "",
                detail: e.to_string(),
            })
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
                return Err(TransportError::ZenohClosed);
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

impl NextJob for ZenohLink {
    /// Serves `job`'s setup from now on and sends it to every worker that joined, whose answers
    /// are not heard until it says `Ready` to it.
    fn next_job(&mut self, job: &Job) -> Result<Vec<WorkerId>, TransportError> {
        let protocol = self.options.announce_protocol.unwrap_or(PROTOCOL_VERSION);
        let next = Arc::new(Offer::of(job, self.options.run_id.as_str(), protocol));
        let last = std::mem::replace(&mut *self.offer.lock().expect("the offer's lock"), next);
        self.earlier.push(last.sha256);
        let frame = self.current().frame.clone();
        let mut told = Vec::new();
        let mut unreachable = Vec::new();
        for (zid, w) in self.workers.iter_mut() {
            w.serving = false;
            match w.publisher.put(frame.clone()).wait() {
                Ok(()) => told.push(w.id),
                Err(e) => unreachable.push((zid.clone(), e.to_string())),
            }
        }
        for (zid, why) in unreachable {
            self.refuse(&zid, &format!("sending the next job failed: {why}"));
        }
        Ok(told)
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
