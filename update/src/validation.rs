//! Releases given with `--validate`: never fitted, predicted by the scenario as given (nominal
//! factors), by the factors alone fitted to every release, and by the updated store. They are
//! few simulations, run in this process.

use std::sync::Arc;

use sepval_common::evaluation::{Candidate, Job};
use sepval_core::factors::Factors;
use sepval_fit::space::{Noise, goals_of};

use crate::jobs::with_corrections;
use crate::record::{GoalsRecord, ValidationRecord};
use crate::refit::Mask;
use crate::select::Selected;
use crate::{Result, UpdateError};

/// The predictions of the `--validate` releases, and the simulations run.
pub fn validate(
    validation: Option<&Job>,
    selected: &Selected,
    noise: Noise,
) -> Result<(Vec<ValidationRecord>, u64)> {
    let Some(job) = validation else {
        return Ok((Vec::new(), 0));
    };
    let model = &selected.model;
    let job = Arc::new(with_corrections(job, &model.corrections.proposals)?);
    let factors_only = &selected.factors_only;
    let candidates: [Candidate; 3] = [
        Candidate::baseline(Factors::NOMINAL),
        factors_only.space.candidate(&factors_only.fit.lm.x),
        model.space.candidate(&model.fit.lm.x),
    ];
    let evaluations = job.evaluate_batch(&candidates, true);
    let n = job.events().len();
    let mut out = Vec::with_capacity(n);
    for (e, event) in job.events().iter().enumerate() {
        let mask = Mask::only(n, e);
        let goals: Vec<GoalsRecord> = evaluations
            .iter()
            .map(|ev| match &ev.samples {
                Some(s) => GoalsRecord::of(goals_of(&mask.residuals(&job, s, noise), noise)),
                None => GoalsRecord {
                    j_pos_m: None,
                    j_att_deg: None,
                },
            })
            .collect();
        out.push(ValidationRecord {
            release: event.name.clone(),
            baseline: goals[0],
            factors_only: goals[1],
            updated: goals[2],
        });
    }
    if out.is_empty() {
        return Err(UpdateError::NoValidation);
    }
    Ok((out, 3 * n as u64))
}
