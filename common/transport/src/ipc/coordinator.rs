//! The coordinator's end of the iceoryx2 transport: [`IpcLink`].
//!
//! iceoryx2 has no competing-consumer queue, so every worker has its own request, response,
//! sample and wake-up services (named by its node id) and the dispatcher chooses the worker of
//! every chunk. Waits block on the coordinator's wake-up listener (workers notify it after each
//! answer), never spin.
//!
//! Liveness: spawned workers are watched through their process handles at every poll; attached
//! workers (started by hand) through the run's node list, every 500 ms (a listing reads every
//! node's files, about 0.15 ms per node, IPC-NOTES.md). A lost or dropped spawned worker is
//! replaced while replacements are left. Dead nodes' resources are cleaned at start and after
//! every loss; dropping the link stops the workers it spawned (SIGTERM, then SIGKILL after 2 s)
//! and removes the run's resources from the host.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::node::Node;
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use sepval_common::cancel;
use sepval_common::evaluation::Job;

use super::{
    COORDINATOR_NODE, IN_FLIGHT_PER_WORKER, MAX_WORKERS, REQUEST_BUFFER, names, node, node_states,
    open_chunk_service, presence, run_config, service_name,
};
use crate::link::{Link, LinkEvent, Notice, WorkerId};
use crate::setup::encode_setup_as;
use crate::wire::{
    Answer, Chunk, ChunkHeader, Hello, MAGIC, PROTOCOL_VERSION, SetupHeader, WireObservation,
    WireRequest, WireResponse,
};
use crate::{RunId, TransportError, iox};

/// How often the run's nodes are listed to find dead attached workers.
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

/// Settings of the iceoryx2 link.
#[derive(Debug, Clone)]
pub struct IpcOptions {
    /// The run id (the iceoryx2 prefix).
    pub run_id: RunId,
    /// Workers to start (spawned) or expect (attached).
    pub workers: usize,
    /// How they are started.
    pub launch: Launch,
    /// Most replacement workers spawned over the run.
    pub max_respawns: usize,
    /// How long a replacement may take to join.
    pub join_timeout: Duration,
    /// Protocol version to announce in the setup instead of ours (compatibility testing).
    pub announce_protocol: Option<u32>,
}

/// One connected worker's ports.
struct Port {
    node_id: u128,
    pid: u32,
    child: Option<Child>,
    requests: Publisher<ipc::Service, [WireRequest], ChunkHeader>,
    responses: Subscriber<ipc::Service, [WireResponse], ChunkHeader>,
    samples: Subscriber<ipc::Service, [WireObservation], ChunkHeader>,
    wake: Notifier<ipc::Service>,
}

/// The coordinator's end of the iceoryx2 transport.
pub struct IpcLink {
    options: IpcOptions,
    cfg: Config,
    node: Node<ipc::Service>,
    job: Arc<Job>,
    setup_service: iceoryx2::service::port_factory::publish_subscribe::PortFactory<
        ipc::Service,
        [u8],
        SetupHeader,
    >,
    /// The setup's publisher while workers may still join (its sample, in the service's
    /// history, is as large as the data; it is dropped once every worker has joined and made
    /// again for a replacement).
    setup: Option<Publisher<ipc::Service, [u8], SetupHeader>>,
    hello: Subscriber<ipc::Service, Hello, ()>,
    wake: Listener<ipc::Service>,
    ports: BTreeMap<WorkerId, Port>,
    /// Spawned processes that have not said hello yet.
    starting: Vec<Child>,
    next_worker: WorkerId,
    respawns: usize,
    listed: Option<Instant>,
    /// Notices found outside a poll (at start), delivered by the next poll.
    early: Vec<Notice>,
    /// Dropped last, after every port and the node: removes the run's resources.
    _cleanup: super::RunCleanup,
}

impl IpcLink {
    /// Creates the run's services, publishes the job setup, and starts the workers (or
    /// announces that it waits for them). Stale resources of earlier runs whose processes
    /// were killed are cleaned first.
    pub fn start(job: &Arc<Job>, options: IpcOptions) -> Result<IpcLink, TransportError> {
        if options.workers == 0 || options.workers > MAX_WORKERS {
            return Err(TransportError::WorkerCount(options.workers));
        }
        let early: Vec<Notice> = super::clean_stale_runs(Some(&options.run_id), super::STALE_AFTER)
            .into_iter()
            .map(|run| Notice::CleanedStaleRun {
                run: run.to_string(),
            })
            .collect();
        let run_id = options.run_id.clone();
        match Self::create(job, options, early) {
            Ok(link) => Ok(link),
            Err(e) => {
                let _ = super::clean_run_if_stale(&run_id);
                Err(e)
            }
        }
    }

    fn create(
        job: &Arc<Job>,
        options: IpcOptions,
        mut early: Vec<Notice>,
    ) -> Result<IpcLink, TransportError> {
        let run_id = options.run_id.clone();
        let cfg = run_config(&run_id)?;
        let node = node(&cfg, COORDINATOR_NODE)?;
        // Stale resources of processes killed in an earlier run with this id.
        node.try_cleanup_dead_nodes();
        if presence(&cfg, COORDINATOR_NODE)?.alive > 1 {
            return Err(TransportError::RunTaken(options.run_id.to_string()));
        }
        let hello = node
            .service_builder(&service_name(names::HELLO)?)
            .publish_subscribe::<Hello>()
            .max_publishers(MAX_WORKERS + 8)
            .max_subscribers(1)
            .subscriber_max_buffer_size(MAX_WORKERS + 8)
            .history_size(0)
            .create()
            .map_err(iox("creating the hello service"))?
            .subscriber_builder()
            .create()
            .map_err(iox("subscribing to hellos"))?;
        let wake = node
            .service_builder(&service_name(names::COORDINATOR_WAKE)?)
            .event()
            .max_notifiers(MAX_WORKERS + 8)
            .max_listeners(1)
            .create()
            .map_err(iox("creating the coordinator's wake-up service"))?
            .listener_builder()
            .create()
            .map_err(iox("listening for wake-ups"))?;
        // The setup service last: a worker that finds it finds every run service.
        let setup_service = node
            .service_builder(&service_name(names::SETUP)?)
            .publish_subscribe::<[u8]>()
            .user_header::<SetupHeader>()
            .max_publishers(1)
            .max_subscribers(MAX_WORKERS + 8)
            .history_size(1)
            .subscriber_max_buffer_size(1)
            .create()
            .map_err(iox("creating the setup service"))?;
        if options.launch == Launch::Attach {
            early.push(Notice::Waiting {
                run: options.run_id.to_string(),
                listening: None,
                workers: options.workers,
                command: format!("sepval-worker --run {}", options.run_id),
            });
        }
        let mut link = IpcLink {
            options,
            cfg,
            node,
            job: Arc::clone(job),
            setup_service,
            setup: None,
            hello,
            wake,
            ports: BTreeMap::new(),
            starting: Vec::new(),
            next_worker: 0,
            respawns: 0,
            listed: None,
            early,
            _cleanup: super::RunCleanup(run_id),
        };
        link.publish_setup()?;
        if matches!(link.options.launch, Launch::Spawn { .. }) {
            for _ in 0..link.options.workers {
                link.spawn()?;
            }
        }
        Ok(link)
    }

    /// Publishes the job setup (once per publisher: it stays in the service's history).
    fn publish_setup(&mut self) -> Result<(), TransportError> {
        if self.setup.is_some() {
            return Ok(());
        }
        let (header, bytes) = encode_setup_as(
            &self.job,
            self.options.announce_protocol.unwrap_or(PROTOCOL_VERSION),
        );
        let setup = self
            .setup_service
            .publisher_builder()
            .initial_max_slice_len(bytes.len())
            .create()
            .map_err(iox("publishing the setup"))?;
        let mut sample = setup
            .loan_slice_uninit(bytes.len())
            .map_err(iox("loaning the setup"))?;
        *sample.user_header_mut() = header;
        sample
            .write_from_slice(&bytes)
            .send()
            .map_err(iox("sending the setup"))?;
        self.setup = Some(setup);
        Ok(())
    }

    /// Drops the setup's publisher once every spawned worker has joined (attached workers may
    /// come at any time: their setup stays).
    fn retire_setup(&mut self) {
        let spawned = matches!(self.options.launch, Launch::Spawn { .. });
        if spawned && self.starting.is_empty() && self.ports.len() >= self.options.workers {
            self.setup = None;
        }
    }

    /// Process ids of the connected workers.
    pub fn worker_pids(&self) -> Vec<u32> {
        self.ports.values().map(|p| p.pid).collect()
    }

    fn spawn(&mut self) -> Result<(), TransportError> {
        if !matches!(self.options.launch, Launch::Spawn { .. }) {
            return Ok(());
        }
        self.publish_setup()?;
        let Launch::Spawn { executable } = &self.options.launch else {
            return Ok(());
        };
        let child = Command::new(executable)
            .args(["--run", self.options.run_id.as_str()])
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .spawn()
            .map_err(crate::io(format!(
                "cannot start worker {}",
                executable.display()
            )))?;
        self.starting.push(child);
        Ok(())
    }

    /// Starts a replacement if the run allows one.
    fn replace(&mut self, events: &mut Vec<LinkEvent>) -> Result<(), TransportError> {
        if matches!(self.options.launch, Launch::Spawn { .. })
            && self.respawns < self.options.max_respawns
        {
            self.respawns += 1;
            events.push(LinkEvent::Notice(Notice::Respawned {
                count: self.respawns,
            }));
            self.spawn()?;
        }
        Ok(())
    }

    /// Spawned processes that exited before saying hello are reported (a refused setup, a bad
    /// executable) and replaced while replacements are left.
    fn reap_starting(&mut self, events: &mut Vec<LinkEvent>) -> Result<(), TransportError> {
        let mut i = 0;
        while i < self.starting.len() {
            match self.starting[i].try_wait() {
                Ok(Some(status)) => {
                    let mut c = self.starting.remove(i);
                    let _ = c.wait();
                    events.push(LinkEvent::Notice(Notice::ExitedBeforeJoining {
                        pid: c.id(),
                        status: status.to_string(),
                    }));
                    if self.respawns >= self.options.max_respawns {
                        return Err(TransportError::WorkersExit {
                            run: self.options.run_id.to_string(),
                            status: status.to_string(),
                        });
                    }
                    self.replace(events)?;
                }
                Ok(None) => i += 1,
                Err(e) => return Err(crate::io("cannot watch a worker")(e)),
            }
        }
        Ok(())
    }

    /// Delivers the setup to newly subscribed workers (from the service's history) and
    /// connects every worker that announced itself.
    fn accept_hellos(&mut self, events: &mut Vec<LinkEvent>) -> Result<(), TransportError> {
        if let Some(setup) = &self.setup {
            setup
                .update_connections()
                .map_err(iox("delivering the setup"))?;
        }
        while let Some(h) = self.hello.receive().map_err(iox("receiving hellos"))? {
            let h: Hello = *h;
            let label = format!("pid {}", h.pid);
            if h.magic != MAGIC || h.protocol != PROTOCOL_VERSION {
                events.push(LinkEvent::Notice(Notice::Refused {
                    label,
                    reason: format!(
                        "it speaks protocol version {} (magic {:#x}), ours is {PROTOCOL_VERSION}",
                        h.protocol, h.magic
                    ),
                }));
                continue;
            }
            if self.ports.values().any(|p| p.node_id == h.node_id)
                || self.ports.len() >= MAX_WORKERS
            {
                continue;
            }
            let child = self
                .starting
                .iter()
                .position(|c| c.id() == h.pid)
                .map(|i| self.starting.remove(i));
            match self.connect(&h, child) {
                Ok(port) => {
                    let id = self.next_worker;
                    self.next_worker += 1;
                    self.ports.insert(id, port);
                    events.push(LinkEvent::Joined {
                        worker: id,
                        label,
                        credits: IN_FLIGHT_PER_WORKER,
                    });
                }
                Err(e) => events.push(LinkEvent::Notice(Notice::Refused {
                    label,
                    reason: format!("cannot connect to it: {e}"),
                })),
            }
        }
        Ok(())
    }

    fn connect(&self, h: &Hello, child: Option<Child>) -> Result<Port, TransportError> {
        let requests = open_chunk_service::<WireRequest>(&self.node, &names::requests(h.node_id))?
            .publisher_builder()
            .initial_max_slice_len(16)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .max_loaned_samples(2)
            .create()
            .map_err(iox("publishing requests"))?;
        let responses =
            open_chunk_service::<WireResponse>(&self.node, &names::responses(h.node_id))?
                .subscriber_builder()
                .buffer_size(REQUEST_BUFFER)
                .create()
                .map_err(iox("subscribing to responses"))?;
        let samples =
            open_chunk_service::<WireObservation>(&self.node, &names::samples(h.node_id))?
                .subscriber_builder()
                .buffer_size(REQUEST_BUFFER)
                .create()
                .map_err(iox("subscribing to samples"))?;
        let wake = self
            .node
            .service_builder(&service_name(&names::wake(h.node_id))?)
            .event()
            .open()
            .map_err(iox("opening a worker's wake-up"))?
            .notifier_builder()
            .create()
            .map_err(iox("notifying a worker"))?;
        Ok(Port {
            node_id: h.node_id,
            pid: h.pid,
            child,
            requests,
            responses,
            samples,
            wake,
        })
    }

    /// Removes a worker: kills it if we own it and cleans its resources.
    fn remove(&mut self, worker: WorkerId) {
        if let Some(mut p) = self.ports.remove(&worker) {
            if let Some(mut child) = p.child.take() {
                let _ = child.kill();
                let _ = child.wait();
            }
            drop(p);
            self.node.try_cleanup_dead_nodes();
        }
    }

    /// Workers whose process exited or whose node is dead.
    fn check_liveness(&mut self, events: &mut Vec<LinkEvent>) -> Result<(), TransportError> {
        let attached = self.ports.values().any(|p| p.child.is_none());
        let alive = if attached && self.listed.is_none_or(|t| t.elapsed() >= LISTING_PERIOD) {
            self.listed = Some(Instant::now());
            Some(node_states(&self.cfg)?.0)
        } else {
            None
        };
        let mut gone = Vec::new();
        for (&id, p) in self.ports.iter_mut() {
            let reason = match p.child.as_mut().map(Child::try_wait) {
                Some(Ok(Some(status))) => Some(format!("process exited: {status}")),
                _ if p.child.is_none()
                    && alive.as_ref().is_some_and(|a| !a.contains(&p.node_id)) =>
                {
                    Some("its node is dead".to_string())
                }
                _ => None,
            };
            if let Some(r) = reason {
                gone.push((id, r));
            }
        }
        for (id, reason) in gone {
            self.remove(id);
            events.push(LinkEvent::Lost { worker: id, reason });
            self.replace(events)?;
        }
        Ok(())
    }

    /// Takes every answer waiting.
    fn collect(&mut self, events: &mut Vec<LinkEvent>) -> Result<(), TransportError> {
        let mut broken = Vec::new();
        for (&id, p) in self.ports.iter_mut() {
            while let Some(sample) = p.responses.receive().map_err(iox("receiving answers"))? {
                let header = *sample.user_header();
                let samples = if header.with_samples != 0 {
                    match p.samples.receive().map_err(iox("receiving samples"))? {
                        Some(s) => s.payload().to_vec(),
                        None => {
                            broken.push((id, "it sent answers without their samples".to_string()));
                            break;
                        }
                    }
                } else {
                    Vec::new()
                };
                events.push(LinkEvent::Answer {
                    worker: id,
                    answer: Answer {
                        header,
                        responses: sample.payload().to_vec(),
                        samples,
                    },
                });
            }
        }
        for (id, reason) in broken {
            self.remove(id);
            events.push(LinkEvent::Lost { worker: id, reason });
            self.replace(events)?;
        }
        Ok(())
    }

    fn gather(&mut self, events: &mut Vec<LinkEvent>) -> Result<(), TransportError> {
        events.extend(self.early.drain(..).map(LinkEvent::Notice));
        self.accept_hellos(events)?;
        self.reap_starting(events)?;
        self.retire_setup();
        self.collect(events)
    }
}

impl Link for IpcLink {
    fn send(&mut self, worker: WorkerId, chunk: &Chunk) -> Result<(), String> {
        let p = self
            .ports
            .get_mut(&worker)
            .ok_or_else(|| format!("no worker {worker}"))?;
        let mut sample = p
            .requests
            .loan_slice_uninit(chunk.requests.len())
            .map_err(|e| format!("loaning a request chunk: {e:?}"))?;
        *sample.user_header_mut() = chunk.header;
        sample
            .write_from_fn(|k| chunk.requests[k])
            .send()
            .map_err(|e| format!("sending a request chunk: {e:?}"))?;
        let _ = p.wake.notify();
        Ok(())
    }

    fn poll(
        &mut self,
        timeout: Duration,
        events: &mut Vec<LinkEvent>,
    ) -> Result<(), TransportError> {
        cancel::check()?;
        let before = events.len();
        self.gather(events)?;
        self.check_liveness(events)?;
        if events.len() == before {
            // Nothing yet: sleep until a worker notifies us (events are not latched, so the
            // inputs were drained above first), or the timeout.
            // A signal interrupts the wait (sockets with a timeout are not restarted): the flag
            // is checked right after.
            match self.wake.timed_wait(|_| {}, timeout) {
                Ok(_) | Err(ListenerWaitError::InterruptSignal) => {}
                Err(e) => return Err(iox("waiting for answers")(e)),
            }
            cancel::check()?;
            self.gather(events)?;
        }
        Ok(())
    }

    fn drop_worker(&mut self, worker: WorkerId, _reason: &str) -> &'static str {
        self.remove(worker);
        let mut events = Vec::new();
        match self.replace(&mut events) {
            Ok(()) => self
                .early
                .extend(events.into_iter().filter_map(|e| match e {
                    LinkEvent::Notice(n) => Some(n),
                    _ => None,
                })),
            Err(e) => self.early.push(Notice::Refused {
                label: "replacement".into(),
                reason: e.to_string(),
            }),
        }
        "killed"
    }

    fn replacement_wait(&self) -> Duration {
        if self.starting.is_empty() {
            Duration::ZERO
        } else {
            self.options.join_timeout
        }
    }

    fn run_id(&self) -> &str {
        self.options.run_id.as_str()
    }

    fn describe(&self) -> String {
        "ipc".to_string()
    }
}

impl Drop for IpcLink {
    fn drop(&mut self) {
        // Ask our workers to stop (SIGTERM sets their cancellation flag), then make sure they
        // did.
        let mut children: Vec<Child> = self
            .ports
            .values_mut()
            .filter_map(|p| p.child.take())
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
        self.ports.clear();
        self.node.try_cleanup_dead_nodes();
        // Then the fields drop, the node among them, and `_cleanup` last removes what
        // iceoryx2 keeps per run.
    }
}
