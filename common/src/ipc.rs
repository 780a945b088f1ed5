//! What the coordinator and the workers share about the iceoryx2 transport: the per-run
//! configuration (one prefix per run id, so that two runs on one host never see each other),
//! the service and node names, and liveness queries.
//!
//! Service names say what they carry. Within a run's prefix:
//!
//! | service | pattern | carries |
//! |---|---|---|
//! | `sepval/run/setup` | publish-subscribe `[u8]` + [`SetupHeader`] (history 1) | the job setup |
//! | `sepval/run/hello` | publish-subscribe [`Hello`] | workers announcing themselves |
//! | `sepval/run/coordinator-wake` | event | "responses are waiting" (workers to coordinator) |
//! | `sepval/worker/<node id>/requests` | publish-subscribe `[WireRequest]` + [`ChunkHeader`] | chunks of candidates |
//! | `sepval/worker/<node id>/responses` | publish-subscribe `[WireResponse]` + [`ChunkHeader`] | their outcomes |
//! | `sepval/worker/<node id>/samples` | publish-subscribe `[WireObservation]` + [`ChunkHeader`] | simulated samples (residual fits) |
//! | `sepval/worker/<node id>/wake` | event | "requests are waiting" (coordinator to worker) |
//!
//! [`SetupHeader`]: crate::messages::SetupHeader
//! [`Hello`]: crate::messages::Hello
//! [`ChunkHeader`]: crate::messages::ChunkHeader

use iceoryx2::config::Config;
use iceoryx2::node::NodeView;
use iceoryx2::prelude::*;

/// Node name of a coordinator.
pub const COORDINATOR_NODE: &str = "sepval-coordinator";
/// Node name of a worker.
pub const WORKER_NODE: &str = "sepval-worker";
/// Chunks a worker's request buffer holds (the coordinator never has more in flight).
pub const REQUEST_BUFFER: usize = 8;

/// Errors of the shared transport helpers.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum IpcError {
    /// A run id with characters a file name cannot hold.
    #[error("run id `{0}`: expected 1 to 48 characters from A-Z, a-z, 0-9 and '-'")]
    RunId(String),
    /// An iceoryx2 operation failed.
    #[error("{what}: {detail}")]
    Iceoryx {
        /// What was attempted.
        what: String,
        /// iceoryx2's error.
        detail: String,
    },
}

/// Wraps an iceoryx2 error with what was attempted.
pub fn iox<E: std::fmt::Debug>(what: impl Into<String>) -> impl FnOnce(E) -> IpcError {
    let what = what.into();
    move |e| IpcError::Iceoryx {
        what,
        detail: format!("{e:?}"),
    }
}

/// Checks a run id.
pub fn validate_run_id(run_id: &str) -> Result<(), IpcError> {
    let ok = !run_id.is_empty()
        && run_id.len() <= 48
        && run_id
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-');
    if ok {
        Ok(())
    } else {
        Err(IpcError::RunId(run_id.to_string()))
    }
}

/// The file-name prefix of a run's iceoryx2 resources.
pub fn run_prefix(run_id: &str) -> String {
    format!("sepval_{run_id}_")
}

/// The iceoryx2 configuration of a run: the global configuration with the run's own prefix.
pub fn run_config(run_id: &str) -> Result<Config, IpcError> {
    validate_run_id(run_id)?;
    let mut cfg = Config::global_config().clone();
    cfg.global.prefix = FileName::new(run_prefix(run_id).as_bytes())
        .map_err(iox(format!("run id {run_id} as a file-name prefix")))?;
    Ok(cfg)
}

/// A fresh run id: the process id and the time, in hex (unique on a host; not random).
pub fn new_run_id() -> String {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    format!("r{:x}{:x}", std::process::id(), nanos & 0xffff_ffff_ffff)
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
pub fn service_name(name: &str) -> Result<ServiceName, IpcError> {
    ServiceName::new(name).map_err(iox(format!("service name {name}")))
}

/// Run ids that have iceoryx2 resources on this host (shared memory or files under the
/// iceoryx2 root), found by their `sepval_<run id>_` prefix, with the age of each run's newest
/// resource.
pub fn runs_with_resources() -> Vec<(String, std::time::Duration)> {
    let mut ids: std::collections::BTreeMap<String, std::time::Duration> =
        std::collections::BTreeMap::new();
    let root = Config::global_config().global.root_path().to_string();
    let mut dirs = vec![std::path::PathBuf::from("/dev/shm")];
    let root = std::path::PathBuf::from(root);
    dirs.push(root.join("services"));
    if let Ok(nodes) = std::fs::read_dir(root.join("nodes")) {
        dirs.extend(nodes.flatten().map(|e| e.path()));
    }
    for dir in dirs {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if let Some(rest) = name.strip_prefix("sepval_") {
                if let Some((id, _)) = rest.split_once('_') {
                    if validate_run_id(id).is_ok() {
                        let age = e
                            .metadata()
                            .and_then(|m| m.modified())
                            .ok()
                            .and_then(|t| t.elapsed().ok())
                            .unwrap_or_default();
                        let entry = ids.entry(id.to_string()).or_insert(age);
                        *entry = (*entry).min(age);
                    }
                }
            }
        }
    }
    ids.into_iter().collect()
}

/// Runs younger than this are never cleaned by another run: their processes may be starting.
pub const STALE_AFTER: std::time::Duration = std::time::Duration::from_secs(30);

/// Removes the iceoryx2 resources of run `run_id` if none of its nodes is alive: the dead
/// nodes' resources (through iceoryx2's own cleanup) and the run's management segment.
/// Returns whether the run was stale (and cleaned).
pub fn clean_run_if_stale(run_id: &str) -> Result<bool, IpcError> {
    let cfg = run_config(run_id)?;
    let (alive, _) = node_states(&cfg)?;
    if !alive.is_empty() {
        return Ok(false);
    }
    {
        let janitor = NodeBuilder::new()
            .config(&cfg)
            .name(&NodeName::new("sepval-janitor").map_err(iox("node name"))?)
            .create::<ipc::Service>()
            .map_err(iox(format!("joining stale run {run_id} to clean it")))?;
        janitor.try_cleanup_dead_nodes();
    }
    // SAFETY: no node of this run is alive (checked above); the management segment only
    // counts node creations and is recreated by the next node of the run.
    let _ = unsafe { iceoryx2::testing::remove_global_mgmt_segment::<ipc::Service>(&cfg) };
    Ok(true)
}

/// Cleans every stale sepval run on this host except `except`: runs whose newest resource is
/// older than `min_age` and none of whose nodes is alive (returns the runs cleaned).
pub fn clean_stale_runs(except: &str, min_age: std::time::Duration) -> Vec<String> {
    runs_with_resources()
        .into_iter()
        .filter(|(id, age)| id != except && *age >= min_age)
        .map(|(id, _)| id)
        .filter(|id| clean_run_if_stale(id).unwrap_or(false))
        .collect()
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
pub fn presence(cfg: &Config, name: &str) -> Result<Presence, IpcError> {
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
pub fn node_states(cfg: &Config) -> Result<(Vec<u128>, Vec<u128>), IpcError> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_ids_are_checked() {
        validate_run_id("run-1-A").unwrap();
        assert!(validate_run_id("run_1").is_err());
        assert!(validate_run_id("").is_err());
        assert!(validate_run_id("a/b").is_err());
        assert!(validate_run_id(&"x".repeat(49)).is_err());
        assert_eq!(
            validate_run_id("a b").unwrap_err().to_string(),
            "run id `a b`: expected 1 to 48 characters from A-Z, a-z, 0-9 and '-'"
        );
        assert!(run_config(&new_run_id()).is_ok());
    }
}
