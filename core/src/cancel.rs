//! Cancellation: one process-wide flag that SIGINT and SIGTERM set, observed by every long loop
//! (evaluations, searches, refinements, transports, worker loops), so that any command stops
//! within a second of a signal and cleans up on its way out (shared memory, worker processes,
//! temporary files) instead of being killed mid-write.
//!
//! The binaries call [`install_signal_handlers`] once at start; library loops call
//! [`check`] (or [`requested`]) at least every few hundred milliseconds.

use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// The process was asked to stop (SIGINT or SIGTERM, or [`request`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("interrupted by a signal")]
pub struct Cancelled;

/// Asks every loop of this process to stop.
pub fn request() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Withdraws the request, for a process that goes on after a cancelled command (the Python
/// package: a call stopped by KeyboardInterrupt, then the next call). Only once every loop
/// that may have seen the request has returned.
pub fn reset() {
    REQUESTED.store(false, Ordering::SeqCst);
}

/// Whether the process was asked to stop.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// `Err(Cancelled)` once the process was asked to stop.
pub fn check() -> Result<(), Cancelled> {
    if requested() { Err(Cancelled) } else { Ok(()) }
}

#[cfg(unix)]
extern "C" fn on_signal(_: libc::c_int) {
    // Only an atomic store: async-signal-safe.
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Makes SIGINT and SIGTERM set the flag instead of ending the process at once. Blocking system
/// calls are restarted (`SA_RESTART`), so waits return at their own timeouts, which every loop
/// keeps short.
pub fn install_signal_handlers() {
    #[cfg(unix)]
    for signal in [libc::SIGINT, libc::SIGTERM] {
        // SAFETY: a plain sigaction with a handler that only stores to an atomic.
        unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = on_signal as extern "C" fn(libc::c_int) as usize;
            action.sa_flags = libc::SA_RESTART;
            libc::sigemptyset(&mut action.sa_mask);
            libc::sigaction(signal, &action, std::ptr::null_mut());
        }
    }
}
