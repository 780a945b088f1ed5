//! What a run leaves on the host, and its removal once no process of the run is left.
//!
//! A run's iceoryx2 resources carry its prefix (`sepval_<run id>_`): the node files under
//! iceoryx2's node directory, the services' static configurations under its service directory,
//! event sockets under its root, and shared memory in `/dev/shm` (the services' dynamic
//! configurations and data segments, and the run's node counter). A process killed with SIGKILL
//! leaves its node "dead": iceoryx2 removes a dead node's resources through
//! [`DeadNodeView::try_remove_stale_resources`](iceoryx2::node::DeadNodeView), the supported
//! way, which is tried first. What it cannot reach stays otherwise: a node killed while it was
//! being made (its details written, its monitor not yet; or its monitor without details, which
//! iceoryx2 then looks for under another prefix), the files of its services, and the node
//! counter (iceoryx2's management segment of the run's domain, which iceoryx2 never removes, a
//! domain being meant to live as long as its host). Once no node of the run is left, alive or
//! dead, those files are removed by their prefix ([`remove_leftovers`]): the prefix is the run's
//! own, no process of the run holds a node, and a file made after the listing, or within
//! [`LEFTOVER_GRACE`] (a node being made by a process that is starting), is left alone. A
//! clean-up counts what it removed, so that a run is reported cleaned once, when something of it
//! went, and never again for resources that stay.

use std::time::Duration;

use iceoryx2::config::Config;
use iceoryx2::node::{DeadNodeView, NodeState};
use iceoryx2::prelude::*;

use super::{quiet_logs, run_config};
use crate::{RunId, TransportError, iox};

/// Runs younger than this are never cleaned by another run: their processes may be starting.
pub const STALE_AFTER: Duration = Duration::from_secs(30);

/// Removes a run's iceoryx2 resources when dropped, if no process of the run is left: the last
/// field of whatever owns a run's node, so that it drops after the node.
pub(crate) struct RunCleanup(pub(crate) RunId);

impl Drop for RunCleanup {
    fn drop(&mut self) {
        let _ = clean_run_if_stale(&self.0);
    }
}

/// Leftover files younger than this are not removed: they may be those of a node that a
/// starting process of the run is making.
pub const LEFTOVER_GRACE: Duration = Duration::from_millis(500);

/// What cleaning a run removed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Cleaned {
    /// Dead nodes whose resources iceoryx2 removed.
    pub dead_nodes: usize,
    /// Files removed that no iceoryx2 call reaches (see the module's documentation).
    pub files: usize,
    /// Nodes of the run still there after the clean-up (another process is removing them, or
    /// they are not this user's to remove).
    pub failed: usize,
}

impl Cleaned {
    /// Whether anything was removed.
    pub fn removed_anything(&self) -> bool {
        self.dead_nodes > 0 || self.files > 0
    }
}

/// Removes the iceoryx2 resources of run `run_id` if none of its nodes is alive: every dead
/// node's (iceoryx2's own clean-up), then, once no node of the run is left, the files that
/// remain (`remove_leftovers`). Returns `None` when a node of the run is alive (nothing is
/// touched), else what was removed.
pub fn clean_run_if_stale(run_id: &RunId) -> Result<Option<Cleaned>, TransportError> {
    let cfg = run_config(run_id)?;
    let mut cleaned = Cleaned::default();
    let Some(dead) = dead_nodes(&cfg, &mut cleaned)? else {
        return Ok(None);
    };
    for view in dead {
        if view.try_remove_stale_resources().is_ok() {
            cleaned.dead_nodes += 1;
        }
    }
    // Listed again: whatever is left now is beyond iceoryx2's clean-up (or being made).
    let mut unreadable = Cleaned::default();
    let listed = std::time::SystemTime::now();
    match dead_nodes(&cfg, &mut unreadable)? {
        Some(_) if unreadable.failed == 0 => cleaned.files = remove_leftovers(run_id, listed),
        None => return Ok(Some(cleaned)),
        Some(_) => {}
    }
    let mut left = 0;
    Node::<ipc::Service>::list(&cfg, |_| {
        left += 1;
        CallbackProgression::Continue
    })
    .map_err(iox("listing the run's nodes"))?;
    cleaned.failed = left;
    Ok(Some(cleaned))
}

/// The dead nodes of the run of `cfg`, or `None` if one is alive; nodes that cannot be read
/// (permissions) are counted in `cleaned.failed` (their files are not touched). A node listed as undefined (half made or
/// half removed) is not alive: its files are leftovers.
fn dead_nodes(
    cfg: &Config,
    cleaned: &mut Cleaned,
) -> Result<Option<Vec<DeadNodeView<ipc::Service>>>, TransportError> {
    let mut alive = false;
    let mut dead = Vec::new();
    Node::<ipc::Service>::list(cfg, |state| {
        match state {
            NodeState::Alive(_) => alive = true,
            NodeState::Dead(view) => dead.push(view),
            NodeState::Inaccessible(_) => cleaned.failed += 1,
            NodeState::Undefined(_) => {}
        }
        CallbackProgression::Continue
    })
    .map_err(iox("listing the run's nodes"))?;
    Ok((!alive).then_some(dead))
}

/// Removes the files of run `run_id` last modified before `listed` (when no node of the run
/// was found alive) and at least [`LEFTOVER_GRACE`] ago, and the node directories they leave
/// empty; returns how many files went. The node counter goes whatever its age: it only numbers
/// the run's nodes, and a process that maps it keeps its mapping.
fn remove_leftovers(run_id: &RunId, listed: std::time::SystemTime) -> usize {
    let mut removed = 0;
    let nodes = nodes_dir();
    for path in files_of_run(run_id) {
        let counter = path.to_string_lossy().ends_with(".global_mgmt");
        let modified = std::fs::symlink_metadata(&path).and_then(|m| m.modified());
        let old = modified
            .is_ok_and(|t| t < listed && t.elapsed().is_ok_and(|age| age >= LEFTOVER_GRACE));
        if (counter || old) && std::fs::remove_file(&path).is_ok() {
            removed += 1;
            // A node's own directory (named by its id), once empty.
            if let Some(dir) = path
                .parent()
                .filter(|d| d.parent() == Some(nodes.as_path()))
            {
                let _ = std::fs::remove_dir(dir);
            }
        }
    }
    removed
}

/// Cleans every stale sepval run on this host except `except`: runs whose newest resource is
/// older than `min_age` and none of whose nodes is alive. Returns the runs of which something
/// was removed or could not be, with what.
pub fn clean_stale_runs(except: Option<&RunId>, min_age: Duration) -> Vec<(RunId, Cleaned)> {
    runs_with_resources()
        .into_iter()
        .filter(|(id, age)| except.is_none_or(|e| e.as_str() != id) && *age >= min_age)
        .filter_map(|(id, _)| RunId::new(&id).ok())
        .filter_map(|id| match clean_run_if_stale(&id) {
            Ok(Some(c)) if c.removed_anything() || c.failed > 0 => Some((id, c)),
            _ => None,
        })
        .collect()
}

/// Run ids that have iceoryx2 resources on this host (shared memory or files under the
/// iceoryx2 root), found by their `sepval_<run id>_` prefix, with the age of each run's newest
/// resource.
pub fn runs_with_resources() -> Vec<(String, Duration)> {
    let mut ids: std::collections::BTreeMap<String, Duration> = std::collections::BTreeMap::new();
    for path in resource_files() {
        let Some(name) = path.file_name().map(|n| n.to_string_lossy().into_owned()) else {
            continue;
        };
        let Some((id, _)) = name.strip_prefix("sepval_").and_then(|r| r.split_once('_')) else {
            continue;
        };
        if RunId::new(id).is_err() {
            continue;
        }
        let age = std::fs::symlink_metadata(&path)
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| t.elapsed().ok())
            .unwrap_or_default();
        let entry = ids.entry(id.to_string()).or_insert(age);
        *entry = (*entry).min(age);
    }
    ids.into_iter().collect()
}

/// iceoryx2's root directory.
fn root_dir() -> std::path::PathBuf {
    quiet_logs();
    std::path::PathBuf::from(Config::global_config().global.root_path().to_string())
}

/// iceoryx2's node directory.
pub fn nodes_dir() -> std::path::PathBuf {
    root_dir().join("nodes")
}

/// Every file of a sepval run's iceoryx2 resources on this host: in `/dev/shm`, iceoryx2's
/// root, service and node directories, and each node's own directory.
pub fn resource_files() -> Vec<std::path::PathBuf> {
    let root = root_dir();
    let nodes = nodes_dir();
    let mut dirs = vec![
        std::path::PathBuf::from("/dev/shm"),
        root.join("services"),
        nodes.clone(),
        root,
    ];
    if let Ok(entries) = std::fs::read_dir(&nodes) {
        dirs.extend(entries.flatten().map(|e| e.path()).filter(|p| p.is_dir()));
    }
    dirs.iter()
        .filter_map(|d| std::fs::read_dir(d).ok())
        .flat_map(|entries| entries.flatten().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("sepval_"))
        })
        .collect()
}

/// Every file of run `run_id`'s iceoryx2 resources on this host (what [`clean_run_if_stale`]
/// removes once no process of the run is left).
pub fn files_of_run(run_id: &RunId) -> Vec<std::path::PathBuf> {
    let prefix = super::run_prefix(run_id);
    resource_files()
        .into_iter()
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with(&prefix))
        })
        .collect()
}
