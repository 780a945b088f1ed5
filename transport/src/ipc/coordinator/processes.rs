//! The worker processes a coordinator spawns (`Launch::Spawn`): starting one for a run, and
//! stopping them all when the link goes: SIGTERM first (it sets a worker's cancellation flag,
//! [`sepval_core::cancel`], so it leaves as after Ctrl-C), then SIGKILL for any still running
//! after [`STOP_DEADLINE`].

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::{RunId, TransportError};

/// How long stopped workers have to exit before they are killed.
const STOP_DEADLINE: Duration = Duration::from_secs(2);

/// How often a stopping worker is checked.
const STOP_POLL: Duration = Duration::from_millis(5);

/// Starts `executable --run RUN_ID` (no input; its output to nothing, its errors to ours).
pub(super) fn spawn_worker(executable: &Path, run_id: &RunId) -> Result<Child, TransportError> {
    Command::new(executable)
        .args(["--run", run_id.as_str()])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .spawn()
        .map_err(crate::io(format!(
            "cannot start worker {}",
            executable.display()
        )))
}

/// Asks every child to stop (SIGTERM), then makes sure it did: waits until [`STOP_DEADLINE`],
/// then kills and reaps those still running.
pub(super) fn stop_all(mut children: Vec<Child>) {
    for c in &children {
        // SAFETY: plain kill(2) on a process id we spawned and have not reaped.
        unsafe {
            libc::kill(c.id() as libc::pid_t, libc::SIGTERM);
        }
    }
    let deadline = Instant::now() + STOP_DEADLINE;
    for c in children.iter_mut() {
        while matches!(c.try_wait(), Ok(None)) && Instant::now() < deadline {
            std::thread::sleep(STOP_POLL);
        }
        if matches!(c.try_wait(), Ok(None)) {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}
