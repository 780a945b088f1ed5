//! The zenoh evaluator (cargo feature `zenoh`): workers on other hosts.
//!
//! The coordinator listens on one endpoint, serves the job setup from a queryable, and hands
//! chunks (the same chunk plan as every other transport) to workers that asked for them
//! (credits, see [`sepval_common::remote`]). It watches the workers' liveliness tokens: a worker
//! whose token goes (killed, host down, link cut) has its in-flight chunks re-dispatched; a
//! worker that holds a chunk past the deadline is told to quit and treated the same way. Workers
//! may join at any time. Results are placed by candidate index, so they are the same bit for bit
//! whichever worker ran what.

use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crossbeam::channel::{Receiver, RecvTimeoutError, unbounded};
use sepval_common::evaluation::{Candidate, EvalError, Evaluation, Evaluator, Job};
use sepval_common::messages::{PROTOCOL_VERSION, encode_setup};
use sepval_common::remote::{self, Down, Role, SetupFrame, Up, keys, zerr};
use sepval_common::uds::{self, FromWorker};
use zenoh::Wait;
use zenoh::qos::CongestionControl;
use zenoh::sample::SampleKind;

use crate::ipc::chunk_plan;

fn transport(e: impl std::fmt::Display) -> EvalError {
    EvalError::Transport(e.to_string())
}

/// How the zenoh coordinator runs.
#[derive(Debug, Clone)]
pub struct RemoteOptions {
    /// Run id (workers must be told it).
    pub run_id: String,
    /// The endpoint to listen on, e.g. `tcp/0.0.0.0:7447`.
    pub listen: String,
    /// Workers to wait for before the first batch.
    pub min_workers: usize,
    /// How long to wait for them, and for a replacement when every worker is gone.
    pub join_timeout: Duration,
    /// A worker holding a chunk longer than this is dropped and its work re-dispatched.
    pub chunk_deadline: Duration,
    /// A zenoh configuration file to start from (TLS, authentication).
    pub zenoh_config: Option<std::path::PathBuf>,
    /// Announce this protocol version (compatibility tests only).
    pub announce_protocol: Option<u32>,
}

enum Event {
    Alive(String, bool),
    Message(String, Vec<u8>),
}

struct Remote {
    publisher: zenoh::pubsub::Publisher<'static>,
    credits: u32,
    /// (chunk id, candidate indices, sent at).
    in_flight: Vec<(u64, Vec<usize>, Instant)>,
    label: String,
}

/// The zenoh evaluator.
pub struct RemoteEvaluator {
    job: Arc<Job>,
    options: RemoteOptions,
    session: zenoh::Session,
    events: Receiver<Event>,
    workers: BTreeMap<String, Remote>,
    /// Workers we dropped (hung, misbehaving, protocol mismatch): ignored from then on.
    dropped: std::collections::BTreeSet<String>,
    next_chunk: u64,
    _queryable: zenoh::query::Queryable<()>,
    _subscribers: (zenoh::pubsub::Subscriber<()>, zenoh::pubsub::Subscriber<()>),
    _token: zenoh::liveliness::LivelinessToken,
}

impl RemoteEvaluator {
    /// Listens, serves the setup and waits for `min_workers` workers.
    pub fn start(job: Arc<Job>, options: RemoteOptions) -> Result<Self, EvalError> {
        remote::validate_run_id(&options.run_id).map_err(transport)?;
        let cfg = remote::config(
            Role::Listen,
            &options.listen,
            options.zenoh_config.as_deref(),
        )
        .map_err(transport)?;
        let session = remote::open(cfg, &options.listen).map_err(transport)?;
        let run = options.run_id.clone();
        let (header, bytes) = encode_setup(&job);
        let frame = SetupFrame {
            run_id: run.clone(),
            sha256: header.sha256,
            catalogue: header.catalogue,
            bytes,
        };
        let setup = remote::encode_as(
            options.announce_protocol.unwrap_or(PROTOCOL_VERSION),
            &frame,
        );
        let setup_key = keys::setup(&run);
        let queryable = {
            let key = setup_key.clone();
            session
                .declare_queryable(&setup_key)
                .callback(move |query| {
                    let _ = query.reply(&key, setup.clone()).wait();
                })
                .wait()
                .map_err(zerr("serving the setup"))
                .map_err(transport)?
        };
        let (tx, events) = unbounded();
        let alive = {
            let tx = tx.clone();
            session
                .liveliness()
                .declare_subscriber(keys::workers(&run))
                .history(true)
                .callback(move |s| {
                    let id = keys::last(s.key_expr().as_str()).to_string();
                    let _ = tx.send(Event::Alive(id, s.kind() == SampleKind::Put));
                })
                .wait()
                .map_err(zerr("watching worker liveliness"))
                .map_err(transport)?
        };
        let ups = session
            .declare_subscriber(keys::ups(&run))
            .callback(move |s| {
                let id = keys::last(s.key_expr().as_str()).to_string();
                let _ = tx.send(Event::Message(id, s.payload().to_bytes().into_owned()));
            })
            .wait()
            .map_err(zerr("listening to workers"))
            .map_err(transport)?;
        let token = session
            .liveliness()
            .declare_token(keys::coordinator(&run))
            .wait()
            .map_err(zerr("declaring our liveliness"))
            .map_err(transport)?;
        let mut evaluator = RemoteEvaluator {
            job,
            options,
            session,
            events,
            workers: BTreeMap::new(),
            dropped: Default::default(),
            next_chunk: 0,
            _queryable: queryable,
            _subscribers: (alive, ups),
            _token: token,
        };
        eprintln!(
            "sepval: run {run} listening on {}; waiting for {} worker(s): \
             sepval-worker --connect {} --run {run}",
            evaluator.options.listen, evaluator.options.min_workers, evaluator.options.listen
        );
        let until = Instant::now() + evaluator.options.join_timeout;
        while evaluator.workers.len() < evaluator.options.min_workers {
            let left = until.saturating_duration_since(Instant::now());
            match evaluator.events.recv_timeout(left) {
                Ok(e) => evaluator.handle(e, &mut VecDeque::new(), &mut [])?,
                Err(_) => {
                    return Err(transport(format!(
                        "{} of {} worker(s) joined run {run} at {} within {} s",
                        evaluator.workers.len(),
                        evaluator.options.min_workers,
                        evaluator.options.listen,
                        evaluator.options.join_timeout.as_secs_f64()
                    )));
                }
            }
        }
        Ok(evaluator)
    }

    /// The run id.
    pub fn run_id(&self) -> &str {
        &self.options.run_id
    }

    /// Workers currently serving.
    pub fn worker_count(&self) -> usize {
        self.workers.len()
    }

    /// Handles one event. Re-dispatched chunks go to the front of `pending`; answers land in
    /// `results` (only while a batch is running: `batch` non-empty).
    fn handle(
        &mut self,
        event: Event,
        pending: &mut VecDeque<Vec<usize>>,
        results: &mut [Option<Evaluation>],
    ) -> Result<(), EvalError> {
        match event {
            // A worker registers with its Ready message; its token only tells us it left.
            Event::Alive(_, true) => {}
            Event::Alive(id, false) => {
                if let Some(w) = self.workers.remove(&id) {
                    self.requeue(&w, pending, "its liveliness token is gone");
                }
            }
            Event::Message(id, bytes) => {
                if self.dropped.contains(&id) {
                    return Ok(());
                }
                let up = match remote::decode::<Up>(&bytes, &format!("message from worker {id}")) {
                    Ok(up) => up,
                    Err(e) => {
                        self.drop_worker(&id, pending, &e.to_string());
                        return Ok(());
                    }
                };
                match up {
                    Up::Ready {
                        credits,
                        host,
                        pid,
                        setup_sha256,
                    } => {
                        self.ready(id, credits, host, pid, setup_sha256, pending)?;
                    }
                    Up::Answer(answer) => self.answer(&id, answer, pending, results),
                }
            }
        }
        Ok(())
    }

    fn ready(
        &mut self,
        id: String,
        credits: u32,
        host: String,
        pid: u32,
        setup_sha256: [u8; 32],
        pending: &mut VecDeque<Vec<usize>>,
    ) -> Result<(), EvalError> {
        let label = format!("{host} pid {pid} ({id})");
        if let Some(w) = self.workers.remove(&id) {
            self.requeue(&w, pending, "it announced itself again");
        }
        let publisher = self
            .session
            .declare_publisher(keys::down(&self.options.run_id, &id))
            .congestion_control(CongestionControl::Block)
            .wait()
            .map_err(zerr(format!("publishing to worker {label}")))
            .map_err(transport)?;
        let (header, _) = encode_setup(&self.job);
        if setup_sha256 != header.sha256 {
            let _ = publisher
                .put(remote::encode(&Down::Dropped {
                    reason: "it accepted another setup".into(),
                }))
                .wait();
            self.dropped.insert(id);
            eprintln!("sepval: refused worker {label}: it accepted another setup");
            return Ok(());
        }
        eprintln!("sepval: worker {label} joined ({credits} chunk(s) at a time)");
        self.workers.insert(
            id,
            Remote {
                publisher,
                credits: credits.clamp(1, 64),
                in_flight: Vec::new(),
                label,
            },
        );
        Ok(())
    }

    fn answer(
        &mut self,
        id: &str,
        answer: FromWorker,
        pending: &mut VecDeque<Vec<usize>>,
        results: &mut [Option<Evaluation>],
    ) {
        let Some(w) = self.workers.get_mut(id) else {
            return;
        };
        let Some(pos) = w
            .in_flight
            .iter()
            .position(|(c, _, _)| *c == answer.chunk_id)
        else {
            // A chunk we already gave to someone else (or of an earlier batch): ignore.
            return;
        };
        let (_, indices, _) = w.in_flight.remove(pos);
        let ok = answer.items.len() == indices.len()
            && answer
                .items
                .iter()
                .zip(&indices)
                .all(|((i, _, _), &e)| *i as usize == e && e < results.len());
        if !ok {
            let w = self.workers.get_mut(id).expect("present");
            w.in_flight.push((answer.chunk_id, indices, Instant::now()));
            self.drop_worker(id, pending, "it answered a chunk with the wrong candidates");
            return;
        }
        w.credits += 1;
        for ((_, outcome, samples), &i) in answer.items.into_iter().zip(&indices) {
            results[i] = Some(Evaluation {
                outcome: outcome.into(),
                samples: samples.map(uds::samples_in),
            });
        }
    }

    fn requeue(&self, w: &Remote, pending: &mut VecDeque<Vec<usize>>, why: &str) {
        if !w.in_flight.is_empty() {
            eprintln!(
                "sepval: worker {} is gone ({why}); re-dispatching {} chunk(s)",
                w.label,
                w.in_flight.len()
            );
        } else {
            eprintln!("sepval: worker {} is gone ({why})", w.label);
        }
        for (_, indices, _) in w.in_flight.iter().rev() {
            pending.push_front(indices.clone());
        }
    }

    /// Tells a worker to quit, ignores it from now on and re-dispatches its work.
    fn drop_worker(&mut self, id: &str, pending: &mut VecDeque<Vec<usize>>, why: &str) {
        self.dropped.insert(id.to_string());
        let message = remote::encode(&Down::Dropped {
            reason: why.to_string(),
        });
        if let Some(w) = self.workers.remove(id) {
            let _ = w.publisher.put(message).wait();
            self.requeue(&w, pending, why);
        } else {
            let _ = self
                .session
                .put(keys::down(&self.options.run_id, id), message)
                .congestion_control(CongestionControl::Block)
                .wait();
            eprintln!("sepval: refused worker {id}: {why}");
        }
    }
}

/// How often the coordinator checks deadlines while it waits.
const TICK: Duration = Duration::from_millis(100);

impl Evaluator for RemoteEvaluator {
    fn evaluate(
        &mut self,
        batch: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, EvalError> {
        let n = batch.len();
        let mut pending = chunk_plan(n, self.workers.len().max(1));
        let mut results: Vec<Option<Evaluation>> = vec![None; n];
        let mut done = 0;
        let mut workerless_since: Option<Instant> = None;
        while done < n {
            // Hand chunks to workers that have credit, one each in turn.
            let mut progress = true;
            while progress && !pending.is_empty() {
                progress = false;
                let mut failed = Vec::new();
                for (id, w) in self.workers.iter_mut() {
                    if w.credits == 0 {
                        continue;
                    }
                    let Some(indices) = pending.pop_front() else {
                        break;
                    };
                    let chunk_id = self.next_chunk;
                    self.next_chunk += 1;
                    let message = Down::Chunk {
                        chunk_id,
                        with_samples,
                        items: indices
                            .iter()
                            .map(|&i| uds::item(i as u64, &batch[i]))
                            .collect(),
                    };
                    w.in_flight.push((chunk_id, indices, Instant::now()));
                    w.credits -= 1;
                    if let Err(e) = w.publisher.put(remote::encode(&message)).wait() {
                        failed.push((id.clone(), e.to_string()));
                    }
                    progress = true;
                }
                for (id, e) in failed {
                    self.drop_worker(&id, &mut pending, &format!("sending failed: {e}"));
                }
            }
            // Deadlines: a worker holding a chunk too long is dropped.
            let late: Vec<String> = self
                .workers
                .iter()
                .filter(|(_, w)| {
                    w.in_flight
                        .iter()
                        .any(|(_, _, t)| t.elapsed() > self.options.chunk_deadline)
                })
                .map(|(id, _)| id.clone())
                .collect();
            for id in late {
                let why = format!(
                    "it held a chunk longer than {} s",
                    self.options.chunk_deadline.as_secs_f64()
                );
                self.drop_worker(&id, &mut pending, &why);
            }
            if self.workers.is_empty() {
                let since = *workerless_since.get_or_insert_with(Instant::now);
                if since.elapsed() > self.options.join_timeout {
                    return Err(transport(format!(
                        "no worker served run {} for {} s",
                        self.options.run_id,
                        self.options.join_timeout.as_secs_f64()
                    )));
                }
            } else {
                workerless_since = None;
            }
            match self.events.recv_timeout(TICK) {
                Ok(event) => {
                    self.handle(event, &mut pending, &mut results)?;
                    for event in self.events.try_iter().collect::<Vec<_>>() {
                        self.handle(event, &mut pending, &mut results)?;
                    }
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(transport("the zenoh session closed"));
                }
            }
            done = results.iter().filter(|r| r.is_some()).count();
        }
        Ok(results
            .into_iter()
            .map(|r| r.expect("every candidate answered"))
            .collect())
    }

    fn job(&self) -> &Job {
        &self.job
    }

    fn describe(&self) -> String {
        format!(
            "zenoh, {} worker(s) at {}",
            self.workers.len(),
            self.options.listen
        )
    }
}

impl Drop for RemoteEvaluator {
    fn drop(&mut self) {
        for w in self.workers.values() {
            let _ = w
                .publisher
                .put(remote::encode(&Down::Quit {
                    reason: "the run is finished".into(),
                }))
                .wait();
        }
        let _ = self.session.close().wait();
    }
}

/// The gateway of a host: one zenoh worker that serves its chunks with the host's iceoryx2
/// workers, so the zero-copy path is kept within the host and the zenoh traffic is one session
/// per host. It holds two chunks per local worker and evaluates one chunk per local worker at a
/// time as one batch (spread over its workers by the shared-memory evaluator), so the next
/// chunks are already here when a batch ends.
pub struct Gateway {
    ipc: crate::ipc::IpcEvaluator,
    workers: usize,
}

impl Gateway {
    /// Starts `options.workers` local iceoryx2 workers for `job`.
    pub fn start(job: Arc<Job>, options: crate::ipc::IpcOptions) -> Result<Self, EvalError> {
        let workers = options.workers;
        Ok(Gateway {
            ipc: crate::ipc::IpcEvaluator::start(job, options)?,
            workers,
        })
    }
}

impl remote::ChunkServer for Gateway {
    fn credits(&self) -> u32 {
        (2 * self.workers).clamp(1, 64) as u32
    }

    fn parallelism(&self) -> usize {
        self.workers
    }

    fn evaluate(
        &mut self,
        candidates: &[&sepval_common::uds::ItemFrame],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, String> {
        let mut out: Vec<Option<Evaluation>> = vec![None; candidates.len()];
        let mut batch = Vec::new();
        let mut at = Vec::new();
        for (i, (_, factors, effects)) in candidates.iter().enumerate() {
            match uds::candidate(factors, effects) {
                Ok(c) => {
                    batch.push(c);
                    at.push(i);
                }
                Err(reason) => {
                    out[i] = Some(Evaluation::from(
                        sepval_common::evaluation::Outcome::Failed {
                            reason: format!("malformed request: {reason}"),
                        },
                    ));
                }
            }
        }
        if !batch.is_empty() {
            let evaluations = self
                .ipc
                .evaluate(&batch, with_samples)
                .map_err(|e| format!("the host's iceoryx2 workers failed: {e}"))?;
            for (e, i) in evaluations.into_iter().zip(at) {
                out[i] = Some(e);
            }
        }
        Ok(out
            .into_iter()
            .map(|e| e.expect("every candidate evaluated"))
            .collect())
    }
}
