//! The scenario tables a fitted model's runs leave (docs/model.md section 3: a value beyond a
//! table's range is held at its edge, and the excursion reported), as `sepval simulate` and
//! `sepval fit` report them (`sepval_fit::pipeline`'s `tables_left`): one line per event and
//! table, named by the model that left it.

use sepval_common::evaluation::{Candidate, Job};

/// The tables the runs of `candidate` leave, one line per event and table: `EVENT: left table
/// ...`, as `sepval fit` words them. Empty when the scenario has no table. `candidate` has no
/// terms of its own (see the module's documentation).
pub(super) fn tables_left(job: &Job, candidate: &Candidate) -> Vec<String> {
    job.events()
        .iter()
        .filter(|e| e.simulator.model().tables.any())
        .flat_map(|e| {
            e.simulator
                .simulate_logged(&candidate.factors, &candidate.effects, &e.data.times_s)
                .map(|(_, log)| e.simulator.table_excursions(&log))
                .unwrap_or_default()
                .into_iter()
                .map(move |x| format!("{}: {x}", e.name))
        })
        .collect()
}
