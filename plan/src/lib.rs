//! The next release to fly (`sepval plan`): given a diagnosis whose releases cannot tell its
//! answer from its rivals, the release condition that would best separate them, and with no
//! rivals the one that would most shrink the uncertainty of the answer's parameters. What is
//! computed is specified in docs/planning.md; the design follows M. B. Anderson's
//! observation that "many parameter combinations are capable of producing reasonable
//! trajectories", settled, as engineers settle it, by flying another release.
//!
//! The plan is a pipeline of named stages ([`plan`] shows it whole):
//! 1. [`models`]: the answer and each rival rebuilt from DIR/diagnosis.json, with the free
//!    parameters a refit would move;
//! 2. [`conditions`]: the candidate conditions, a grid over the ranges given;
//! 3. [`simulate`]: every model and its parameter steps at the releases flown and at every
//!    condition, in batches through any [`Evaluator`] (never knowing the transport), long
//!    batches in parts, reduced to normal equations;
//! 4. [`separation`] and [`information`]: the separation of every pair of models at each
//!    condition (a linearised refit, [`refit`]) and the D-optimal information gain;
//! 5. [`tables`]: the tables a release there would leave;
//! 6. [`ranking`]: the conditions best first;
//! 7. [`record`] and [`outputs`]: DIR/plan.json, DIR/plan.html and the figures, written
//!    atomically.

#![deny(clippy::float_cmp)]

pub use sepval_run::conditions;
pub mod command;
pub mod information;
pub mod models;
pub mod outputs;
mod page;
pub mod ranking;
pub mod record;
pub mod refit;
pub mod separation;
pub mod simulate;
mod summary;
pub mod tables;

use std::path::{Path, PathBuf};

use sepval_common::evaluation::{Evaluator, Job};
use sepval_diagnose::Diagnosis;
use sepval_fit::space::Noise;
use sepval_solve::run::ProgressObserver;

pub use conditions::{Conditions, DEFAULT_POINTS, Quantity, Range};
pub use models::Models;
pub use outputs::write_outputs;
pub use ranking::Ranking;
pub use record::{PLAN_FORMAT, PlanFile, plan_file};
pub use summary::summary;

/// A plan that cannot be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlanError {
    /// A `--from` directory that does not hold a diagnosis.
    #[error("--from {}: {message}", path.display())]
    NotADiagnosis {
        /// The directory.
        path: PathBuf,
        /// What is missing or wrong.
        message: String,
    },
    /// A diagnosis.json that cannot be used (not JSON, another format, edited, a value out of
    /// range).
    #[error("--from {}", path.display())]
    Record {
        /// The directory.
        path: PathBuf,
        /// Why.
        source: sepval_run::sealed::RecordError,
    },
    /// The releases the diagnosis was made from, which do not read again.
    #[error("--from {}: the releases the diagnosis was made from", path.display())]
    Releases {
        /// The directory.
        path: PathBuf,
        /// Why.
        source: Box<sepval_run::inputs::InputError>,
    },
    /// A model of the diagnosis that cannot be rebuilt.
    #[error("the models of the diagnosis")]
    Models(#[from] models::ModelsError),
    /// A range that cannot be planned over.
    #[error(transparent)]
    Conditions(#[from] conditions::ConditionError),
    /// The simulations.
    #[error(transparent)]
    Simulate(#[from] simulate::SimulateError),
    /// The outputs.
    #[error(transparent)]
    Outputs(#[from] outputs::OutputError),
}

/// The diagnosis in `dir` (DIR/diagnosis.json of `sepval diagnose`, format
/// [`sepval_diagnose::DIAGNOSIS_FORMAT`]), read and checked by the records' one reader
/// ([`sepval_run::sealed::read_record`]: parse errors with line and column, format, digest,
/// ranges).
pub fn read_diagnosis(dir: &Path) -> Result<Diagnosis, PlanError> {
    let bad = |message: String| PlanError::NotADiagnosis {
        path: dir.to_path_buf(),
        message,
    };
    if !dir.is_dir() {
        return Err(bad(
            "not a directory (give the --out directory of `sepval diagnose`)".into(),
        ));
    }
    let path = dir.join("diagnosis.json");
    if !path.exists() {
        return Err(bad(
            "holds no diagnosis.json: not the output of `sepval diagnose`".into(),
        ));
    }
    sepval_run::sealed::read_record(&path, "diagnosis").map_err(|source| PlanError::Record {
        path: dir.to_path_buf(),
        source,
    })
}

/// The diagnosis in `dir` ([`read_diagnosis`]) and the job of the releases it was made from,
/// read again as it read them (what the screening leaves out told to `tell`).
pub fn read_from(
    dir: &Path,
    tell: sepval_run::inputs::Tell,
) -> Result<(Diagnosis, Job), PlanError> {
    let diagnosis = read_diagnosis(dir)?;
    let flown = sepval_run::inputs::recorded_job(&diagnosis.inputs, tell).map_err(|e| {
        PlanError::Releases {
            path: dir.to_path_buf(),
            source: Box::new(e),
        }
    })?;
    Ok((diagnosis, flown))
}

/// A plan's inputs, checked, before anything is simulated.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The diagnosis planned from.
    pub diagnosis: Diagnosis,
    /// Its answer and rivals.
    pub models: Models,
    /// The candidate conditions.
    pub conditions: Conditions,
    /// The evaluator's job: the releases flown, then one event per condition.
    pub job: Job,
    /// Releases flown (the first events of `job`).
    pub flown: usize,
}

/// Rebuilds the models of `diagnosis`, whose releases flown are `flown` (the job of its
/// `inputs`), and makes the grid over `ranges`: everything checked before any simulation.
pub fn prepare(
    diagnosis: Diagnosis,
    flown: &Job,
    ranges: &[Range],
    points: usize,
) -> Result<Prepared, PlanError> {
    let models = Models::of(&diagnosis, flown.factor_table())?;
    let base = flown.events()[0].simulator.scenario();
    let conditions = Conditions::grid(base, ranges, points)?;
    let job = simulate::plan_job(flown, &conditions)?;
    simulate::check_size(&models, &job)?;
    Ok(Prepared {
        diagnosis,
        models,
        conditions,
        job,
        flown: flown.events().len(),
    })
}

/// What a plan found.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The simulations, reduced (each model's trajectories at every event included).
    pub simulated: simulate::Simulated,
    /// The separations.
    pub separations: separation::Separations,
    /// The information gains.
    pub information: information::Information,
    /// The conditions, best first.
    pub ranking: Ranking,
}

/// The plan's stages from the simulations on. `evaluator` must have been started with
/// `prepared.job`.
pub fn plan(
    prepared: &Prepared,
    evaluator: &mut dyn Evaluator,
    progress: &mut dyn ProgressObserver,
) -> Result<Plan, PlanError> {
    let d = &prepared.diagnosis;
    let noise = Noise {
        pos_m: d.sigma_pos_m,
        att_deg: d.sigma_att_deg,
    };
    let simulated =
        simulate::simulate(&prepared.models, prepared.flown, noise, evaluator, progress)?;
    let separations = separation::separations(&prepared.models, &simulated);
    let information = information::information(&simulated);
    let tables_left = tables::tables_left(&prepared.job, prepared.flown, &prepared.models);
    let ranking = ranking::rank(
        &prepared.conditions,
        &separations,
        &information,
        &tables_left,
        prepared.models.has_rivals(),
    );
    Ok(Plan {
        simulated,
        separations,
        information,
        ranking,
    })
}

#[cfg(test)]
mod tests;
