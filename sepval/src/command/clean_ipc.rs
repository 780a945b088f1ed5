//! `sepval clean-ipc`: removes what dead runs left in shared memory and iceoryx2's directories.

use sepval_transport::ipc::clean_stale_runs;

/// Runs `sepval clean-ipc`: names each run of which something was removed, once (a run whose
/// resources are gone is not found again), and what could not be removed.
pub fn run() {
    // Explicitly asked for: any run without a live process, whatever its age.
    let runs = clean_stale_runs(None, std::time::Duration::ZERO);
    let cleaned: Vec<&str> = runs
        .iter()
        .filter(|(_, c)| c.removed_anything())
        .map(|(r, _)| r.as_str())
        .collect();
    say!(
        "cleaned {} stale run(s) {}",
        cleaned.len(),
        cleaned.join(" ")
    );
    for (run, c) in runs.iter().filter(|(_, c)| c.failed > 0) {
        say!(
            "run {run}: {} node(s) not removed (another process is removing them, or they are \
             not this user's)",
            c.failed
        );
    }
}
