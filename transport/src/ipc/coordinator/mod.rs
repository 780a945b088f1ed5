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
//!
//! The parts: `services` holds the run's services and the job setup on offer, `port` one
//! connected worker (connect, send, read answers, tell whether it is gone), `processes` the
//! spawned workers' processes; this module is the link that ties them together.

mod port;
mod processes;
mod services;

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::Child;
use std::sync::Arc;
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::node::Node;
use iceoryx2::port::listener::ListenerWaitError;
use iceoryx2::prelude::*;
use sepval_common::evaluation::Job;
use sepval_core::cancel;

use super::{
    COORDINATOR_NODE, IN_FLIGHT_PER_WORKER, MAX_WORKERS, node, node_states, presence, run_config,
};
use crate::link::{Link, LinkEvent, Notice, SendError, WorkerId};
use crate::wire::{Chunk, Hello, MAGIC, PROTOCOL_VERSION};
use crate::{RunId, TransportError, iox};
use port::{Port, Received};
use processes::spawn_worker;
use services::RunServices;

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

/// A worker found gone during a poll, and why (its [`LinkEvent::Lost`] to be).
struct Loss {
    worker: WorkerId,
    reason: String,
}

/// The coordinator's end of the iceoryx2 transport.
pub struct IpcLink {
    options: IpcOptions,
    cfg: Config,
    node: Node<ipc::Service>,
    job: Arc<Job>,
    /// The run's own services (hello, wake-up, the setup on offer).
    services: RunServices,
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
            .filter(|(_, cleaned)| cleaned.removed_anything())
            .map(|(run, _)| Notice::CleanedStaleRun {
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
            return Err(TransportError::RunTaken {
                run: options.run_id.to_string(),
            });
        }
        let services = RunServices::create(&node)?;
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
            services,
            ports: BTreeMap::new(),
            starting: Vec::new(),
            next_worker: 0,
            respawns: 0,
            listed: None,
            early,
            _cleanup: super::RunCleanup(run_id),
        };
        let protocol = link.options.announce_protocol.unwrap_or(PROTOCOL_VERSION);
        link.services.setup.publish(&link.job, protocol)?;
        if matches!(link.options.launch, Launch::Spawn { .. }) {
            for _ in 0..link.options.workers {
                link.spawn()?;
            }
        }
        Ok(link)
    }

    /// Drops the setup's publisher once every spawned worker has joined (attached workers may
    /// come at any time: their setup stays).
    fn retire_setup(&mut self) {
        let spawned = matches!(self.options.launch, Launch::Spawn { .. });
        if spawned && self.starting.is_empty() && self.ports.len() >= self.options.workers {
            self.services.setup.retire();
        }
    }

    /// Process ids of the connected workers.
    pub fn worker_pids(&self) -> Vec<u32> {
        self.ports.values().map(|p| p.pid).collect()
    }

    /// Starts a worker process, if workers are spawned, and puts the setup on offer for it.
    fn spawn(&mut self) -> Result<(), TransportError> {
        let Launch::Spawn { executable } = &self.options.launch else {
            return Ok(());
        };
        let protocol = self.options.announce_protocol.unwrap_or(PROTOCOL_VERSION);
        self.services.setup.publish(&self.job, protocol)?;
        self.starting
            .push(spawn_worker(executable, &self.options.run_id)?);
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
        self.services.setup.deliver()?;
        while let Some(h) = self
            .services
            .hello
            .receive()
            .map_err(iox("receiving hellos"))?
        {
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
            match Port::connect(&self.node, &h, child) {
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
        let gone: Vec<Loss> = self
            .ports
            .iter_mut()
            .filter_map(|(&worker, p)| {
                let reason = p.gone(alive.as_deref())?;
                Some(Loss { worker, reason })
            })
            .collect();
        self.lose(gone, events)
    }

    /// Takes every answer waiting.
    fn collect(&mut self, events: &mut Vec<LinkEvent>) -> Result<(), TransportError> {
        let mut broken = Vec::new();
        for (&id, p) in self.ports.iter_mut() {
            while let Some(received) = p.receive()? {
                match received {
                    Received::Answer(answer) => {
                        events.push(LinkEvent::Answer { worker: id, answer })
                    }
                    Received::WithoutSamples => {
                        broken.push(Loss {
                            worker: id,
                            reason: "it sent answers without their samples".to_string(),
                        });
                        break;
                    }
                }
            }
        }
        self.lose(broken, events)
    }

    /// Removes the lost workers, reports them, and starts a replacement for each while the run
    /// allows.
    fn lose(
        &mut self,
        losses: Vec<Loss>,
        events: &mut Vec<LinkEvent>,
    ) -> Result<(), TransportError> {
        for Loss { worker, reason } in losses {
            self.remove(worker);
            events.push(LinkEvent::Lost { worker, reason });
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
    fn send(&mut self, worker: WorkerId, chunk: &Chunk) -> Result<(), SendError> {
        self.ports
            .get_mut(&worker)
            .ok_or(SendError::NoWorker { worker })?
            .send(chunk)
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
            match self.services.wake.timed_wait(|_| {}, timeout) {
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
        processes::stop_all(
            self.ports
                .values_mut()
                .filter_map(|p| p.child.take())
                .chain(self.starting.drain(..))
                .collect(),
        );
        self.ports.clear();
        self.node.try_cleanup_dead_nodes();
        // Then the fields drop, the node among them, and `_cleanup` last removes what
        // iceoryx2 keeps per run.
    }
}
