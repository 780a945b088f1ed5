//! The iceoryx2 transport (shared memory, one host): the coordinator's [`IpcLink`] and the
//! worker's [`IpcWorker`], and what both ends share: the per-run configuration (one prefix per
//! run id, so that two runs on one host never see each other), the service names, and liveness
//! queries and cleanup.
//!
//! Service names say what they carry. Within a run's prefix:
//!
//! | service | pattern | carries |
//! |---|---|---|
//! | `sepval/run/setup` | publish-subscribe `[u8]` + [`SetupHeader`] (history 1) | the job setup |
//! | `sepval/run/hello` | publish-subscribe [`Hello`] | workers announcing themselves |
//! | `sepval/run/coordinator-wake` | event | "answers are waiting" (workers to coordinator) |
//! | `sepval/worker/<node id>/requests` | publish-subscribe `[WireRequest]` + [`ChunkHeader`] | chunks of candidates |
//! | `sepval/worker/<node id>/responses` | publish-subscribe `[WireResponse]` + [`ChunkHeader`] | their outcomes |
//! | `sepval/worker/<node id>/samples` | publish-subscribe `[WireObservation]` + [`ChunkHeader`] | simulated samples (residual fits) |
//! | `sepval/worker/<node id>/wake` | event | "requests are waiting" (coordinator to worker) |
//!
//! Every node is built with iceoryx2's own signal handling off: SIGINT and SIGTERM set sepval's
//! cancellation flag ([`sepval_core::cancel`]), which both ends check at every wake-up.
//!
//! [`SetupHeader`]: crate::wire::SetupHeader
//! [`Hello`]: crate::wire::Hello
//! [`ChunkHeader`]: crate::wire::ChunkHeader
//! [`WireRequest`]: crate::wire::WireRequest
//! [`WireResponse`]: crate::wire::WireResponse
//! [`WireObservation`]: crate::wire::WireObservation

mod cleanup;
mod coordinator;
mod worker;

pub(crate) use cleanup::RunCleanup;
pub use cleanup::{
    Cleaned, LEFTOVER_GRACE, STALE_AFTER, clean_run_if_stale, clean_stale_runs, files_of_run,
    nodes_dir, resource_files, runs_with_resources,
};
pub use coordinator::{IpcLink, IpcOptions, Launch};
pub use worker::IpcWorker;

use iceoryx2::config::Config;
use iceoryx2::node::NodeView;
use iceoryx2::prelude::*;

use crate::{RunId, TransportError, iox};

/// Node name of a coordinator.
pub const COORDINATOR_NODE: &str = "sepval-coordinator";
/// Node name of a worker.
pub const WORKER_NODE: &str = "sepval-worker";
/// Chunks a worker's request buffer holds (the coordinator never has more in flight).
pub const REQUEST_BUFFER: usize = 8;
/// Chunks kept in flight per worker.
pub const IN_FLIGHT_PER_WORKER: usize = 2;
/// Most workers one run accepts.
pub const MAX_WORKERS: usize = 64;

/// One of a worker's chunk services (requests, responses, samples): slices of `T` behind a
/// [`ChunkHeader`](crate::wire::ChunkHeader).
pub(crate) type ChunkService<T> = iceoryx2::service::port_factory::publish_subscribe::PortFactory<
    ipc::Service,
    [T],
    crate::wire::ChunkHeader,
>;

/// Creates a worker's chunk service `name` (the worker does): one publisher, one subscriber,
/// [`REQUEST_BUFFER`] chunks, no silent overwriting, no history.
pub(crate) fn create_chunk_service<T: std::fmt::Debug + ZeroCopySend>(
    node: &Node<ipc::Service>,
    name: &str,
) -> Result<ChunkService<T>, TransportError> {
    node.service_builder(&service_name(name)?)
        .publish_subscribe::<[T]>()
        .user_header::<crate::wire::ChunkHeader>()
        .max_publishers(1)
        .max_subscribers(1)
        .subscriber_max_buffer_size(REQUEST_BUFFER)
        .enable_safe_overflow(false)
        .history_size(0)
        .create()
        .map_err(iox(format!("creating {name}")))
}

/// Opens a worker's chunk service `name` (the coordinator does).
pub(crate) fn open_chunk_service<T: std::fmt::Debug + ZeroCopySend>(
    node: &Node<ipc::Service>,
    name: &str,
) -> Result<ChunkService<T>, TransportError> {
    node.service_builder(&service_name(name)?)
        .publish_subscribe::<[T]>()
        .user_header::<crate::wire::ChunkHeader>()
        .open()
        .map_err(iox(format!("opening {name}")))
}

/// The file-name prefix of a run's iceoryx2 resources.
pub fn run_prefix(run_id: &RunId) -> String {
    format!("sepval_{run_id}_")
}

/// The iceoryx2 configuration of a run: the global configuration with the run's own prefix.
pub fn run_config(run_id: &RunId) -> Result<Config, TransportError> {
    quiet_logs();
    let mut cfg = Config::global_config().clone();
    cfg.global.prefix = FileName::new(run_prefix(run_id).as_bytes())
        .map_err(iox(format!("run id {run_id} as a file-name prefix")))?;
    Ok(cfg)
}

/// iceoryx2 reports only errors (its warnings about a missing configuration file are noise
/// for sepval's users). Called by every process before its first node.
pub fn quiet_logs() {
    iceoryx2::prelude::set_log_level(LogLevel::Error);
}

/// A node of a run, with iceoryx2's signal handling off (see the module docs).
pub fn node(cfg: &Config, name: &str) -> Result<Node<ipc::Service>, TransportError> {
    quiet_logs();
    NodeBuilder::new()
        .config(cfg)
        .name(&NodeName::new(name).map_err(iox("node name"))?)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(iox(format!("creating the {name} node")))
}

/// Service names of a run.
pub mod names {
    /// The job setup.
    pub const SETUP: &str = "sepval/run/setup";
    /// Worker announcements.
    pub const HELLO: &str = "sepval/run/hello";
    /// Coordinator wake-ups.
    pub const COORDINATOR_WAKE: &str = "sepval/run/coordinator-wake";

    /// Requests to the worker whose node id is `id`.
    pub fn requests(id: u128) -> String {
        format!("sepval/worker/{id:032x}/requests")
    }

    /// Responses of worker `id`.
    pub fn responses(id: u128) -> String {
        format!("sepval/worker/{id:032x}/responses")
    }

    /// Simulated samples from worker `id`.
    pub fn samples(id: u128) -> String {
        format!("sepval/worker/{id:032x}/samples")
    }

    /// Wake-ups of worker `id`.
    pub fn wake(id: u128) -> String {
        format!("sepval/worker/{id:032x}/wake")
    }
}

/// A service name from text.
pub fn service_name(name: &str) -> Result<ServiceName, TransportError> {
    ServiceName::new(name).map_err(iox(format!("service name {name}")))
}

/// Presence of the nodes of one name in a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Presence {
    /// Nodes alive.
    pub alive: usize,
    /// Nodes whose process died without cleaning up.
    pub dead: usize,
}

/// How many nodes named `name` are alive or dead in the run of `cfg`.
pub fn presence(cfg: &Config, name: &str) -> Result<Presence, TransportError> {
    let mut p = Presence::default();
    Node::<ipc::Service>::list(cfg, |state| {
        let named = |details: &Option<iceoryx2::node::NodeDetails>| {
            details.as_ref().is_some_and(|d| d.name().as_str() == name)
        };
        match &state {
            NodeState::Alive(v) if named(v.details()) => p.alive += 1,
            NodeState::Dead(v) if named(v.details()) => p.dead += 1,
            _ => {}
        }
        CallbackProgression::Continue
    })
    .map_err(iox("listing the run's nodes"))?;
    Ok(p)
}

/// Node ids of the alive and the dead nodes of a run.
pub fn node_states(cfg: &Config) -> Result<(Vec<u128>, Vec<u128>), TransportError> {
    let (mut alive, mut dead) = (Vec::new(), Vec::new());
    Node::<ipc::Service>::list(cfg, |state| {
        match &state {
            NodeState::Alive(v) => alive.push(v.id().value()),
            NodeState::Dead(v) => dead.push(v.id().value()),
            _ => {}
        }
        CallbackProgression::Continue
    })
    .map_err(iox("listing the run's nodes"))?;
    Ok((alive, dead))
}
