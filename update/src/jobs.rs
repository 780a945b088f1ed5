//! The jobs of an update and how their evaluators start: the releases as given, and with the
//! corrections of a round in every scenario (docs/update.md section 15.1), whose values each
//! candidate carries; and the clock of its stages.

use sepval_common::correction::CorrectionRecord;
use sepval_common::evaluation::{Event, Job};
use sepval_common::simulation::Simulator;

use crate::explored::Proposal;
use crate::{Result, UpdateError};

/// Starts an evaluator for a job (the update needs two: the releases as given for the
/// baseline, then with the corrections proposed).
pub use sepval_common::evaluation::StartEvaluator;

/// Each stage's wall time on stderr when `SEPVAL_UPDATE_TIMING` is set (never in the outputs).
pub static CLOCK: sepval_core::stage_clock::StageClock =
    sepval_core::stage_clock::StageClock::new("SEPVAL_UPDATE_TIMING", "update");

/// The releases of `job` with `proposals` in every scenario, so that candidates carry their
/// values.
pub fn with_corrections(job: &Job, proposals: &[Proposal]) -> Result<Job> {
    let records: Vec<CorrectionRecord> = proposals
        .iter()
        .map(|p| CorrectionRecord {
            field: p.target.field(),
            variable: p.variable.key().to_string(),
            breakpoints: p.breakpoints.clone(),
        })
        .collect();
    let events = job
        .events()
        .iter()
        .map(|e| {
            let mut s = e.simulator.scenario().clone();
            s.correction = records.clone();
            s.validate(&e.name)
                .map_err(|source| UpdateError::Corrected {
                    release: e.name.clone(),
                    source,
                })?;
            Ok(Event {
                name: e.name.clone(),
                simulator: Simulator::new(&s),
                data: e.data.clone(),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Job::new(events).map_err(UpdateError::Releases)
}
