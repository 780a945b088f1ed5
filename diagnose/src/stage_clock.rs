//! Where a diagnosis's wall time goes, stage by stage: when the environment variable
//! `SEPVAL_DIAGNOSE_TIMING` is set (to anything), each stage's wall time since the previous
//! stage ended is printed on stderr as `diagnose timing: STAGE S s`. For finding what to make
//! faster (issue 22); nothing of it reaches the outputs, and without the variable it costs one
//! lookup per stage.

use std::sync::Mutex;
use std::time::Instant;

/// The environment variable that switches the stage times on.
pub const TIMING_VAR: &str = "SEPVAL_DIAGNOSE_TIMING";

/// When the previous stage ended (`None` before the first).
static LAST: Mutex<Option<Instant>> = Mutex::new(None);

/// Starts the clock (the diagnosis begins).
pub(crate) fn start() {
    if std::env::var_os(TIMING_VAR).is_some() {
        *LAST.lock().unwrap_or_else(|e| e.into_inner()) = Some(Instant::now());
    }
}

/// Prints the wall time of `stage`, which ends now, when the clock is on.
pub(crate) fn lap(stage: &str) {
    if std::env::var_os(TIMING_VAR).is_none() {
        return;
    }
    let now = Instant::now();
    let mut last = LAST.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(before) = last.replace(now) {
        eprintln!(
            "diagnose timing: {stage} {:.2} s",
            now.duration_since(before).as_secs_f64()
        );
    }
}
