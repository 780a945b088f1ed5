//! `sepval predict` as a run of the one sequence ([`sepval_run::sequence`]): the request as
//! the flags give it ([`PredictRequest`]), read and checked into a prepared prediction with
//! where it writes ([`request`]: the source and its releases, the condition, the flown
//! release, the geometry), then run, its files written and what it says.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use sepval_common::evaluation::Job;
use sepval_common::telemetry::outliers::Policy;
use sepval_run::clearance::GeometryPaths;
use sepval_run::inputs::{self, Tell};
use sepval_run::out_dir::{Claim, Input, recorded_inputs};
use sepval_run::sequence::{Evaluators, Named, Run, RunError, Said, Writes};
use sepval_solve::run::ProgressObserver;

use crate::{
    ClearanceSettings, Flown, Prediction, Prepared, Settings, SourceInputs, check_condition,
    predict, prediction_file, prepare, source_inputs, write_outputs,
};

/// A prediction as the flags ask for it: paths and numbers, nothing read yet.
pub struct PredictRequest {
    /// The fit or diagnosis predicted from (`--from`).
    pub from: PathBuf,
    /// The condition to predict (`--scenario`).
    pub scenario: PathBuf,
    /// The extension terms (`--extension`), else the source's.
    pub extension: Option<PathBuf>,
    /// A flown release to check against the bands (`--data`).
    pub data: Option<PathBuf>,
    /// Held-out releases that calibrate the model-form band (`--validate`).
    pub validate: Vec<PathBuf>,
    /// How the releases' outliers are treated.
    pub policy: Policy,
    /// The geometry of the clearance.
    pub geometry: GeometryPaths,
    /// Samples, level, seed, noise, threads.
    pub settings: Settings,
    /// `--out`, and how it is claimed.
    pub out: PathBuf,
    /// Fresh or `--overwrite`.
    pub claim: Claim,
}

/// A prediction prepared, with the source it is made from.
pub struct PredictRun {
    /// Everything the prediction needs.
    pub prepared: Prepared,
    /// `--from`, as the record names it.
    pub from: PathBuf,
}

/// The request read and checked: the source and its releases, the condition against the
/// fitted store and the flight domain, the flown release, the geometry; where it writes.
pub fn request(r: PredictRequest, tell: Tell) -> Result<(Writes, PredictRun), RunError> {
    r.settings.check()?;
    let SourceInputs {
        source,
        fitted,
        held_out,
    } = source_inputs(
        &r.from,
        r.extension.as_deref(),
        &r.validate,
        r.policy,
        &mut *tell,
    )?;
    let mut read = recorded_inputs(&r.from, &source.inputs, &source.held_out);
    read.extend(Input::files("--scenario", [&r.scenario]));
    read.extend(Input::files("--extension", &r.extension));
    read.extend(Input::files("--data", &r.data));
    read.extend(Input::files("--validate", &r.validate));
    read.extend(r.geometry.inputs());
    let extension = r.extension.clone().or(source.inputs.extension.clone());
    let at_scenario = |e: RunError| Named::error("--scenario", &r.scenario, e);
    let condition = inputs::scenario(Some(&r.scenario), extension.as_deref())
        .map_err(|e| at_scenario(e.into()))?;
    check_condition(fitted.events()[0].simulator.scenario(), &condition)
        .map_err(|e| at_scenario(e.into()))?;
    let flown = match &r.data {
        Some(path) => {
            let scenario_name = format!("--scenario {}", r.scenario.display());
            let at = (scenario_name.as_str(), &condition);
            Some(Flown::read(path, at, r.policy, tell)?)
        }
        None => None,
    };
    let clearance = ClearanceSettings::of(&r.geometry, &condition)?;
    let prepared = prepare(source, fitted, condition, held_out, flown, r.settings)?;
    let prepared = match clearance {
        Some(c) => prepared.with_clearance(c),
        None => prepared,
    };
    let writes = Writes::new(r.out, "predict", r.claim, read);
    let from = r.from;
    Ok((writes, PredictRun { prepared, from }))
}

impl Run for PredictRun {
    type Found = Prediction;

    fn job(&self) -> Option<Arc<Job>> {
        Some(Arc::new(self.prepared.job.clone()))
    }

    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<Prediction, RunError> {
        Ok(predict(&self.prepared, evaluators.one()?, progress)?)
    }

    fn write(&self, found: Prediction, out: &Path, wall_s: f64) -> Result<Said, RunError> {
        let file = prediction_file(&self.prepared, &found, &self.from, wall_s);
        write_outputs(&found, &file, out)?;
        Ok(Said::summary(crate::summary(&file, out)))
    }
}
