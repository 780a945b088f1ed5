//! The scenario's tables a planned release would leave (docs/model.md section 3: a value is
//! held at its table's edge and the excursion recorded): each model's run at each condition,
//! logged in this process (the evaluators return samples, not logs). A condition where a model
//! leaves a table is reported and ranked after the conditions that stay inside them.

use sepval_common::evaluation::Job;
use sepval_common::propagator::{Observation, propagate};

use crate::models::Models;

/// Per condition (the events after the `flown` first ones of `job`), the tables left by any
/// model, in words (empty: none, or a scenario without tables).
pub fn tables_left(job: &Job, flown: usize, models: &Models) -> Vec<Vec<String>> {
    job.events()[flown..]
        .iter()
        .map(|e| {
            let sim = &e.simulator;
            if !sim.model().tables.any() {
                return Vec::new();
            }
            let mut left: Vec<String> = Vec::new();
            for m in &models.list {
                let c = &m.candidate;
                let Ok(run) = c.run_setup(sim) else {
                    continue;
                };
                let mut sink: Vec<Observation> = Vec::with_capacity(e.data.len());
                let Ok(log) = propagate(sim.model(), &run, &e.data.times_s, &mut sink) else {
                    continue;
                };
                for x in sim.table_excursions(&log) {
                    let text = format!("{}: {x}", m.name);
                    if !left.contains(&text) {
                        left.push(text);
                    }
                }
            }
            left
        })
        .collect()
}
