//! The iceoryx2 evaluator: batches of candidates go to `sepval-worker` processes over shared
//! memory, and their goals come back, under the same [`Evaluator`] interface as the in-process
//! thread pool (the searches cannot tell them apart, and every outcome is bit-identical).
//!
//! The coordinator chooses the worker of every chunk itself (iceoryx2 has no competing-consumer
//! queue): each worker has its own request and response services, and the coordinator keeps
//! [`IN_FLIGHT_PER_WORKER`] chunks in flight per worker, so a worker never waits for the
//! coordinator and a fast worker gets more chunks than a slow one. Waits block on a WaitSet
//! (responses wake the coordinator through an event), never spin.
//!
//! Faults: a worker whose process exits (checked every tick for spawned workers) or whose node
//! is dead (attached workers, listed every 500 ms), or that holds a chunk past the
//! deadline (hung; it is then killed), is dropped; its chunks in flight go back to the
//! queue and are sent to the remaining workers, so a batch completes with exactly one result per
//! candidate. Spawned workers are replaced (up to a limit); with no worker left the batch fails
//! with an error instead of hanging. Dead nodes' resources are cleaned at start and after every
//! loss.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::rc::Rc;
use std::sync::Arc;
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use iceoryx2::waitset::WaitSetRunResult;
use sepval_common::evaluation::{Candidate, EvalError, Evaluation, Evaluator, Job};
use sepval_common::ipc::{
    self as sipc, COORDINATOR_NODE, IpcError, REQUEST_BUFFER, iox, names, node_states,
};
use sepval_common::messages::{
    ChunkHeader, Hello, MAGIC, PROTOCOL_VERSION, SetupHeader, WireObservation, WireRequest,
    WireResponse, encode_setup,
};
use sepval_common::propagator::Observation;

/// Chunks kept in flight per worker.
pub const IN_FLIGHT_PER_WORKER: usize = 2;

/// Splits a batch of `n` candidates into chunks of consecutive indices for `workers` workers:
/// about four chunks per worker, so the last chunks balance the load, and at most 16 candidates
/// per chunk, so a lost worker costs little. Shared by every multi-process evaluator, so that
/// `sepval bench` compares transports, not chunkings.
pub(crate) fn chunk_plan(n: usize, workers: usize) -> VecDeque<Vec<usize>> {
    let chunk = n.div_ceil(workers.max(1) * 4).clamp(1, 16);
    (0..n)
        .collect::<Vec<_>>()
        .chunks(chunk)
        .map(<[usize]>::to_vec)
        .collect()
}
/// Most workers one run accepts.
pub const MAX_WORKERS: usize = 64;
/// How often the coordinator checks worker liveness and deadlines while it waits.
const TICK: Duration = Duration::from_millis(50);
/// How often the run's nodes are listed to find dead attached workers. A listing reads every
/// node's files (about 0.15 ms per node, IPC-NOTES.md): at every tick it cost the coordinator
/// 2 % of a core with four workers. Spawned workers are watched through their process handles
/// at every tick instead.
const LISTING_PERIOD: Duration = Duration::from_millis(500);

/// How workers are started.
#[derive(Debug, Clone, PartialEq)]
pub enum Launch {
    /// Spawn local `sepval-worker` processes (and reap them).
    Spawn {
        /// The worker executable.
        executable: PathBuf,
    },
    /// Wait for externally started workers (`sepval-worker --run RUN_ID`).
    Attach,
}

/// Settings of the iceoryx2 evaluator.
#[derive(Debug, Clone)]
pub struct IpcOptions {
    /// The run id (the iceoryx2 prefix).
    pub run_id: String,
    /// Workers to start or wait for.
    pub workers: usize,
    /// How they are started.
    pub launch: Launch,
    /// A worker holding a chunk longer than this is considered hung.
    pub chunk_deadline: Duration,
    /// How long to wait for workers to announce themselves.
    pub join_timeout: Duration,
    /// Most replacement workers spawned over the run.
    pub max_respawns: usize,
    /// Protocol version to announce in the setup instead of ours (compatibility testing).
    pub announce_protocol: Option<u32>,
}

/// One connected worker.
struct WorkerLink {
    node_id: u128,
    pid: u32,
    child: Option<Child>,
    requests: Publisher<ipc::Service, [WireRequest], ChunkHeader>,
    responses: Subscriber<ipc::Service, [WireResponse], ChunkHeader>,
    samples: Subscriber<ipc::Service, [WireObservation], ChunkHeader>,
    wake: Notifier<ipc::Service>,
    in_flight: VecDeque<InFlight>,
    evaluations: u64,
}

/// A chunk sent and not yet answered.
#[derive(Debug, Clone)]
struct InFlight {
    chunk_id: u64,
    indices: Vec<usize>,
    sent: Instant,
}

/// What happened to the workers, for reports.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct IpcStats {
    /// Workers lost (killed, crashed, hung), with the reason.
    pub lost: Vec<String>,
    /// Replacement workers spawned.
    pub respawned: usize,
    /// Evaluations re-dispatched after a loss.
    pub redispatched: u64,
}

/// A run's iceoryx2 ports and workers (the evaluator without its final cleanup).
struct Connection {
    job: Arc<Job>,
    options: IpcOptions,
    cfg: Config,
    node: Node<ipc::Service>,
    setup: Publisher<ipc::Service, [u8], SetupHeader>,
    hello: Subscriber<ipc::Service, Hello, ()>,
    wake: Rc<Listener<ipc::Service>>,
    workers: Vec<WorkerLink>,
    /// Spawned processes that have not said hello yet.
    starting: Vec<Child>,
    next_chunk: u64,
    respawns: usize,
    /// When the run's nodes were last listed (for attached workers' liveness).
    listed: Option<Instant>,
    /// What happened so far.
    pub stats: IpcStats,
}

fn transport(e: impl std::fmt::Display) -> EvalError {
    EvalError::Transport(e.to_string())
}

impl Connection {
    fn start(job: Arc<Job>, options: IpcOptions) -> Result<Self, EvalError> {
        if options.workers == 0 || options.workers > MAX_WORKERS {
            return Err(transport(format!(
                "--workers {}: expected 1 to {MAX_WORKERS}",
                options.workers
            )));
        }
        let cfg = sipc::run_config(&options.run_id).map_err(transport)?;
        let node = NodeBuilder::new()
            .config(&cfg)
            .name(
                &NodeName::new(COORDINATOR_NODE)
                    .map_err(iox("node name"))
                    .map_err(transport)?,
            )
            .create::<ipc::Service>()
            .map_err(iox("creating the coordinator node"))
            .map_err(transport)?;
        // Stale resources of processes killed in an earlier run with this id.
        node.try_cleanup_dead_nodes();
        if sipc::presence(&cfg, COORDINATOR_NODE)
            .map_err(transport)?
            .alive
            > 1
        {
            return Err(transport(format!(
                "run {} already has a coordinator: choose another run id",
                options.run_id
            )));
        }
        let svc = |n: &str| sipc::service_name(n).map_err(transport);
        let hello = node
            .service_builder(&svc(names::HELLO)?)
            .publish_subscribe::<Hello>()
            .max_publishers(MAX_WORKERS + 8)
            .max_subscribers(1)
            .subscriber_max_buffer_size(MAX_WORKERS + 8)
            .history_size(0)
            .create()
            .map_err(iox("creating the hello service"))
            .map_err(transport)?
            .subscriber_builder()
            .create()
            .map_err(iox("subscribing to hellos"))
            .map_err(transport)?;
        let wake = node
            .service_builder(&svc(names::COORDINATOR_WAKE)?)
            .event()
            .max_notifiers(MAX_WORKERS + 8)
            .max_listeners(1)
            .create()
            .map_err(iox("creating the coordinator's wake-up service"))
            .map_err(transport)?
            .listener_builder()
            .create()
            .map_err(iox("listening for wake-ups"))
            .map_err(transport)?;
        // The setup service last: a worker that finds it finds every run service.
        let (mut header, bytes) = encode_setup(&job);
        if let Some(v) = options.announce_protocol {
            header.protocol = v;
        }
        let setup = node
            .service_builder(&svc(names::SETUP)?)
            .publish_subscribe::<[u8]>()
            .user_header::<SetupHeader>()
            .max_publishers(1)
            .max_subscribers(MAX_WORKERS + 8)
            .history_size(1)
            .subscriber_max_buffer_size(1)
            .create()
            .map_err(iox("creating the setup service"))
            .map_err(transport)?
            .publisher_builder()
            .initial_max_slice_len(bytes.len())
            .create()
            .map_err(iox("publishing the setup"))
            .map_err(transport)?;
        let mut sample = setup
            .loan_slice_uninit(bytes.len())
            .map_err(iox("loaning the setup"))
            .map_err(transport)?;
        *sample.user_header_mut() = header;
        sample
            .write_from_slice(&bytes)
            .send()
            .map_err(iox("sending the setup"))
            .map_err(transport)?;
        let mut me = Connection {
            job,
            cfg,
            node,
            setup,
            hello,
            wake: Rc::new(wake),
            workers: Vec::new(),
            starting: Vec::new(),
            next_chunk: 0,
            respawns: 0,
            listed: None,
            stats: IpcStats::default(),
            options,
        };
        match &me.options.launch {
            Launch::Spawn { .. } => {
                for _ in 0..me.options.workers {
                    me.spawn()?;
                }
            }
            Launch::Attach => eprintln!(
                "sepval: run {}: waiting for {} worker(s): start them with `sepval-worker --run {}`",
                me.options.run_id, me.options.workers, me.options.run_id
            ),
        }
        me.wait_for_workers(me.options.workers)?;
        Ok(me)
    }

    /// Process ids of the connected workers.
    fn worker_pids(&self) -> Vec<u32> {
        self.workers.iter().map(|w| w.pid).collect()
    }

    fn spawn(&mut self) -> Result<(), EvalError> {
        let Launch::Spawn { executable } = &self.options.launch else {
            return Ok(());
        };
        let child = Command::new(executable)
            .args(["--run", &self.options.run_id])
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .spawn()
            .map_err(|e| transport(format!("cannot start worker {}: {e}", executable.display())))?;
        self.starting.push(child);
        Ok(())
    }

    /// Waits until `n` workers are connected, or fails after the join timeout.
    fn wait_for_workers(&mut self, n: usize) -> Result<(), EvalError> {
        let deadline = Instant::now() + self.options.join_timeout;
        let waitset = WaitSetBuilder::new()
            .create::<ipc::Service>()
            .map_err(iox("creating a wait set"))
            .map_err(transport)?;
        let wake = Rc::clone(&self.wake);
        let _guard = waitset
            .attach_notification(&*wake)
            .map_err(iox("waiting for workers"))
            .map_err(transport)?;
        loop {
            self.accept_hellos()?;
            self.reap_starting()?;
            if self.workers.len() >= n {
                return Ok(());
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(transport(format!(
                    "only {} of {n} worker(s) joined run {} within {:?}",
                    self.workers.len(),
                    self.options.run_id,
                    self.options.join_timeout
                )));
            }
            let result = waitset
                .wait_and_process_once_with_timeout(
                    |_| CallbackProgression::Stop,
                    (deadline - now).min(TICK),
                )
                .map_err(iox("waiting for workers"))
                .map_err(transport)?;
            interrupted(result)?;
            let _ = self.wake.try_wait(|_| {});
        }
    }

    /// Spawned processes that exited before saying hello are reported (a refused setup, a bad
    /// executable).
    fn reap_starting(&mut self) -> Result<(), EvalError> {
        let mut i = 0;
        while i < self.starting.len() {
            match self.starting[i].try_wait() {
                Ok(Some(status)) => {
                    let mut c = self.starting.remove(i);
                    let _ = c.wait(); // already exited: reap it
                    self.stats.lost.push(format!(
                        "worker pid {} exited before joining ({status})",
                        c.id()
                    ));
                    eprintln!(
                        "sepval: worker pid {} exited before joining ({status}); see its message above",
                        c.id()
                    );
                    if self.respawns >= self.options.max_respawns {
                        return Err(transport(format!(
                            "workers keep exiting before joining run {} ({status})",
                            self.options.run_id
                        )));
                    }
                    self.respawns += 1;
                    self.stats.respawned += 1;
                    self.spawn()?;
                }
                Ok(None) => i += 1,
                Err(e) => return Err(transport(format!("cannot watch a worker: {e}"))),
            }
        }
        Ok(())
    }

    /// Delivers the setup to newly subscribed workers (from the service's history) and
    /// connects every worker that announced itself.
    fn accept_hellos(&mut self) -> Result<(), EvalError> {
        self.setup
            .update_connections()
            .map_err(iox("delivering the setup"))
            .map_err(transport)?;
        while let Some(h) = self
            .hello
            .receive()
            .map_err(iox("receiving hellos"))
            .map_err(transport)?
        {
            let h: Hello = *h;
            if h.magic != MAGIC || h.protocol != PROTOCOL_VERSION {
                let msg = format!(
                    "refusing worker pid {}: it speaks protocol version {} (magic {:#x}), this coordinator speaks version {PROTOCOL_VERSION}",
                    h.pid, h.protocol, h.magic
                );
                eprintln!("sepval: {msg}");
                self.stats.lost.push(msg);
                continue;
            }
            if self.workers.iter().any(|w| w.node_id == h.node_id) {
                continue;
            }
            if self.workers.len() >= MAX_WORKERS {
                continue;
            }
            let child = self
                .starting
                .iter()
                .position(|c| c.id() == h.pid)
                .map(|i| self.starting.remove(i));
            match self.connect(&h, child) {
                Ok(link) => self.workers.push(link),
                Err(e) => eprintln!("sepval: cannot connect worker pid {}: {e}", h.pid),
            }
        }
        Ok(())
    }

    fn connect(&self, h: &Hello, child: Option<Child>) -> Result<WorkerLink, IpcError> {
        let svc = sipc::service_name;
        let requests = self
            .node
            .service_builder(&svc(&names::requests(h.node_id))?)
            .publish_subscribe::<[WireRequest]>()
            .user_header::<ChunkHeader>()
            .open()
            .map_err(iox("opening a worker's requests"))?
            .publisher_builder()
            .initial_max_slice_len(16)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .max_loaned_samples(2)
            .create()
            .map_err(iox("publishing requests"))?;
        let responses = self
            .node
            .service_builder(&svc(&names::responses(h.node_id))?)
            .publish_subscribe::<[WireResponse]>()
            .user_header::<ChunkHeader>()
            .open()
            .map_err(iox("opening a worker's responses"))?
            .subscriber_builder()
            .buffer_size(REQUEST_BUFFER)
            .create()
            .map_err(iox("subscribing to responses"))?;
        let samples = self
            .node
            .service_builder(&svc(&names::samples(h.node_id))?)
            .publish_subscribe::<[WireObservation]>()
            .user_header::<ChunkHeader>()
            .open()
            .map_err(iox("opening a worker's samples"))?
            .subscriber_builder()
            .buffer_size(REQUEST_BUFFER)
            .create()
            .map_err(iox("subscribing to samples"))?;
        let wake = self
            .node
            .service_builder(&svc(&names::wake(h.node_id))?)
            .event()
            .open()
            .map_err(iox("opening a worker's wake-up"))?
            .notifier_builder()
            .create()
            .map_err(iox("notifying a worker"))?;
        Ok(WorkerLink {
            node_id: h.node_id,
            pid: h.pid,
            child,
            requests,
            responses,
            samples,
            wake,
            in_flight: VecDeque::new(),
            evaluations: 0,
        })
    }

    /// Drops worker `i`: kills it if we own it, requeues its chunks, cleans its resources, and
    /// spawns a replacement when allowed.
    fn lose(
        &mut self,
        i: usize,
        reason: &str,
        pending: &mut VecDeque<Vec<usize>>,
    ) -> Result<(), EvalError> {
        let mut w = self.workers.remove(i);
        let requeued: usize = w.in_flight.iter().map(|c| c.indices.len()).sum();
        for c in w.in_flight.drain(..).rev() {
            pending.push_front(c.indices);
        }
        if let Some(mut child) = w.child.take() {
            let _ = child.kill();
            let _ = child.wait();
        }
        drop(w);
        self.node.try_cleanup_dead_nodes();
        let msg = format!("worker lost ({reason}); {requeued} evaluation(s) re-dispatched");
        eprintln!("sepval: {msg}");
        self.stats.lost.push(msg);
        self.stats.redispatched += requeued as u64;
        if matches!(self.options.launch, Launch::Spawn { .. })
            && self.respawns < self.options.max_respawns
        {
            self.respawns += 1;
            self.stats.respawned += 1;
            self.spawn()?;
        }
        Ok(())
    }

    /// Checks every worker: process exited, node dead, chunk past its deadline.
    fn check_workers(&mut self, pending: &mut VecDeque<Vec<usize>>) -> Result<(), EvalError> {
        let attached = self.workers.iter().any(|w| w.child.is_none());
        let alive = if attached && self.listed.is_none_or(|t| t.elapsed() >= LISTING_PERIOD) {
            self.listed = Some(Instant::now());
            Some(node_states(&self.cfg).map_err(transport)?.0)
        } else {
            None
        };
        let mut i = 0;
        while i < self.workers.len() {
            let w = &mut self.workers[i];
            let exited = match w.child.as_mut().map(|c| c.try_wait()) {
                Some(Ok(Some(status))) => Some(format!("process exited: {status}")),
                _ => None,
            };
            let reason = if let Some(r) = exited {
                Some(r)
            } else if w.child.is_none() && alive.as_ref().is_some_and(|a| !a.contains(&w.node_id)) {
                Some("its node is dead".to_string())
            } else if w
                .in_flight
                .front()
                .is_some_and(|c| c.sent.elapsed() > self.options.chunk_deadline)
            {
                Some(format!(
                    "no answer within the {:?} deadline: hung, killed",
                    self.options.chunk_deadline
                ))
            } else {
                None
            };
            match reason {
                Some(r) => {
                    let pid = w.pid;
                    let r = format!("pid {pid}: {r}");
                    self.lose(i, &r, pending)?;
                }
                None => i += 1,
            }
        }
        Ok(())
    }

    fn send(
        &mut self,
        w: usize,
        indices: Vec<usize>,
        batch: &[Candidate],
        with_samples: bool,
    ) -> Result<(), EvalError> {
        let chunk_id = self.next_chunk;
        self.next_chunk += 1;
        let link = &mut self.workers[w];
        let mut sample = link
            .requests
            .loan_slice_uninit(indices.len())
            .map_err(iox("loaning a request chunk"))
            .map_err(transport)?;
        *sample.user_header_mut() = ChunkHeader {
            chunk_id,
            count: indices.len() as u32,
            with_samples: u32::from(with_samples),
        };
        let sample =
            sample.write_from_fn(|k| WireRequest::new(indices[k] as u64, &batch[indices[k]]));
        sample
            .send()
            .map_err(iox("sending a request chunk"))
            .map_err(transport)?;
        let _ = link.wake.notify();
        link.in_flight.push_back(InFlight {
            chunk_id,
            indices,
            sent: Instant::now(),
        });
        Ok(())
    }

    /// Takes every response waiting from worker `w`.
    fn collect(
        &mut self,
        w: usize,
        results: &mut [Option<Evaluation>],
        per_candidate: usize,
    ) -> Result<usize, EvalError> {
        let mut done = 0;
        let link = &mut self.workers[w];
        while let Some(sample) = link
            .responses
            .receive()
            .map_err(iox("receiving responses"))
            .map_err(transport)?
        {
            let header = *sample.user_header();
            let Some(pos) = link
                .in_flight
                .iter()
                .position(|c| c.chunk_id == header.chunk_id)
            else {
                continue; // a chunk already given up on
            };
            let chunk = link.in_flight.remove(pos).expect("position is valid");
            let samples: Option<Vec<Observation>> = if header.with_samples != 0 {
                let s = link
                    .samples
                    .receive()
                    .map_err(iox("receiving samples"))
                    .map_err(transport)?
                    .ok_or_else(|| transport("a worker sent responses without their samples"))?;
                Some(s.payload().iter().map(Observation::from).collect())
            } else {
                None
            };
            let payload = sample.payload();
            if payload.len() != chunk.indices.len() {
                return Err(transport(format!(
                    "worker pid {} answered {} of {} candidates",
                    link.pid,
                    payload.len(),
                    chunk.indices.len()
                )));
            }
            for (k, r) in payload.iter().enumerate() {
                let index = chunk.indices[k];
                if r.index as usize != index {
                    return Err(transport(format!(
                        "worker pid {} answered candidate {} in place of {index}",
                        link.pid, r.index
                    )));
                }
                let outcome = r.outcome().map_err(transport)?;
                let samples_k = samples.as_ref().and_then(|all| {
                    outcome.goals().map(|_| {
                        let flat = &all[k * per_candidate..(k + 1) * per_candidate];
                        split_events(&self.job, flat)
                    })
                });
                results[index] = Some(Evaluation {
                    outcome,
                    samples: samples_k,
                });
                done += 1;
            }
            link.evaluations += payload.len() as u64;
        }
        Ok(done)
    }
}

fn split_events(job: &Job, flat: &[Observation]) -> Vec<Vec<Observation>> {
    let mut out = Vec::with_capacity(job.events().len());
    let mut pos = 0;
    for e in job.events() {
        out.push(flat[pos..pos + e.data.len()].to_vec());
        pos += e.data.len();
    }
    out
}

fn interrupted(result: WaitSetRunResult) -> Result<(), EvalError> {
    match result {
        WaitSetRunResult::TerminationRequest | WaitSetRunResult::Interrupt => {
            Err(transport("interrupted by a signal"))
        }
        _ => Ok(()),
    }
}

impl Connection {
    fn evaluate(
        &mut self,
        batch: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, EvalError> {
        let n = batch.len();
        let mut results: Vec<Option<Evaluation>> = vec![None; n];
        if n == 0 {
            return Ok(Vec::new());
        }
        let per_candidate = self.job.sample_count();
        let mut pending = chunk_plan(n, self.workers.len());
        let mut done = 0usize;
        let waitset = WaitSetBuilder::new()
            .create::<ipc::Service>()
            .map_err(iox("creating a wait set"))
            .map_err(transport)?;
        let wake = Rc::clone(&self.wake);
        let _guard = waitset
            .attach_notification(&*wake)
            .map_err(iox("waiting for responses"))
            .map_err(transport)?;
        let mut last_check = Instant::now();
        while done < n {
            self.accept_hellos()?;
            self.reap_starting()?;
            if self.workers.is_empty() {
                if self.starting.is_empty() {
                    return Err(transport(format!(
                        "every worker of run {} is lost ({}); {} of {n} evaluations unfinished",
                        self.options.run_id,
                        self.stats.lost.join("; "),
                        n - done
                    )));
                }
                self.wait_for_workers(1)?;
                continue;
            }
            // Keep every worker busy: fill its in-flight window.
            for w in 0..self.workers.len() {
                while self.workers[w].in_flight.len() < IN_FLIGHT_PER_WORKER {
                    let Some(indices) = pending.pop_front() else {
                        break;
                    };
                    self.send(w, indices, batch, with_samples)?;
                }
            }
            let before = done;
            for w in 0..self.workers.len() {
                done += self.collect(w, &mut results, per_candidate)?;
            }
            if done >= n {
                break;
            }
            if last_check.elapsed() >= TICK {
                self.check_workers(&mut pending)?;
                last_check = Instant::now();
                continue;
            }
            if done > before && !pending.is_empty() {
                // Answers freed window slots: refill them before blocking. (Waiting here
                // instead cost up to a tick whenever the answers' wake-ups had already been
                // drained, with every worker idle: 50 ms stalls on fast requests.)
                continue;
            }
            let result = waitset
                .wait_and_process_once_with_timeout(|_| CallbackProgression::Stop, TICK)
                .map_err(iox("waiting for responses"))
                .map_err(transport)?;
            interrupted(result)?;
            let _ = self.wake.try_wait(|_| {});
        }
        Ok(results
            .into_iter()
            .map(|r| r.expect("every candidate has exactly one result"))
            .collect())
    }

    fn describe(&self) -> String {
        format!(
            "ipc, {} worker(s), run {}",
            self.workers.len(),
            self.options.run_id
        )
    }
}

impl Drop for Connection {
    fn drop(&mut self) {
        // Ask our workers to stop (SIGTERM ends their wait loop), then make sure they did.
        let mut children: Vec<Child> = self
            .workers
            .iter_mut()
            .filter_map(|w| w.child.take())
            .chain(self.starting.drain(..))
            .collect();
        for c in &children {
            // SAFETY: plain kill(2) on a process id we spawned and have not reaped.
            unsafe {
                libc::kill(c.id() as libc::pid_t, libc::SIGTERM);
            }
        }
        let deadline = Instant::now() + Duration::from_secs(2);
        for c in children.iter_mut() {
            while matches!(c.try_wait(), Ok(None)) && Instant::now() < deadline {
                std::thread::sleep(Duration::from_millis(5));
            }
            if matches!(c.try_wait(), Ok(None)) {
                let _ = c.kill();
                let _ = c.wait();
            }
        }
        self.workers.clear();
        self.node.try_cleanup_dead_nodes();
    }
}

/// The iceoryx2 evaluator: a run's services and workers. Dropping it stops the workers and
/// removes the run's iceoryx2 resources from the host.
pub struct IpcEvaluator {
    connection: Option<Connection>,
    job: Arc<Job>,
    run_id: String,
}

impl IpcEvaluator {
    /// Creates the run's services, publishes the job setup, and starts (or waits for) the
    /// workers. Stale resources of earlier runs whose processes were killed are cleaned first.
    pub fn start(job: Arc<Job>, options: IpcOptions) -> Result<Self, EvalError> {
        sipc::validate_run_id(&options.run_id).map_err(transport)?;
        for id in sipc::clean_stale_runs(&options.run_id, sipc::STALE_AFTER) {
            eprintln!("sepval: cleaned the stale iceoryx2 resources of run {id}");
        }
        let run_id = options.run_id.clone();
        let connection = match Connection::start(Arc::clone(&job), options) {
            Ok(c) => c,
            Err(e) => {
                let _ = sipc::clean_run_if_stale(&run_id);
                return Err(e);
            }
        };
        Ok(IpcEvaluator {
            connection: Some(connection),
            job,
            run_id,
        })
    }

    fn connection(&mut self) -> &mut Connection {
        self.connection
            .as_mut()
            .expect("the connection lives until the evaluator is dropped")
    }

    /// The run id.
    pub fn run_id(&self) -> &str {
        &self.run_id
    }

    /// Process ids of the connected workers.
    pub fn worker_pids(&mut self) -> Vec<u32> {
        self.connection().worker_pids()
    }

    /// What happened to the workers so far.
    pub fn stats(&mut self) -> IpcStats {
        self.connection().stats.clone()
    }
}

impl Evaluator for IpcEvaluator {
    fn evaluate(
        &mut self,
        batch: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, EvalError> {
        self.connection().evaluate(batch, with_samples)
    }

    fn job(&self) -> &Job {
        &self.job
    }

    fn describe(&self) -> String {
        self.connection
            .as_ref()
            .map_or_else(|| "ipc (closed)".to_string(), Connection::describe)
    }
}

impl Drop for IpcEvaluator {
    fn drop(&mut self) {
        drop(self.connection.take());
        // Every process of the run is gone: remove what iceoryx2 keeps per run.
        let _ = sipc::clean_run_if_stale(&self.run_id);
    }
}
