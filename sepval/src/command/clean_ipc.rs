//! `sepval clean-ipc`: removes what dead runs left in shared memory.

use sepval_transport::ipc::clean_stale_runs;

/// Runs `sepval clean-ipc`.
pub fn run() {
    // Explicitly asked for: any run without a live process, whatever its age.
    let cleaned = clean_stale_runs(None, std::time::Duration::ZERO);
    say!(
        "cleaned {} stale run(s) {}",
        cleaned.len(),
        cleaned
            .iter()
            .map(|r| r.as_str())
            .collect::<Vec<_>>()
            .join(" ")
    );
}
