//! Where a diagnosis's wall time goes, stage by stage: when the environment variable
//! `SEPVAL_DIAGNOSE_TIMING` is set (to anything), each stage's wall time since the previous
//! stage ended is printed on stderr as `diagnose timing: STAGE S s` (issue 22;
//! `sepval_core::stage_clock`).

use sepval_core::stage_clock::StageClock;

/// The environment variable that switches the stage times on.
pub const TIMING_VAR: &str = "SEPVAL_DIAGNOSE_TIMING";

static CLOCK: StageClock = StageClock::new(TIMING_VAR, "diagnose");

/// Starts the clock (the diagnosis begins).
pub(crate) fn start() {
    CLOCK.start();
}

/// Prints the wall time of `stage`, which ends now, when the clock is on.
pub(crate) fn lap(stage: &str) {
    CLOCK.lap(stage);
}
