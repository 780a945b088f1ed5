//! The stages of an update, in order ([`update`]), from the baseline fit to the record.

use std::sync::Arc;
use std::time::Instant;

use sepval_common::evaluation::{Evaluator, Job};
use sepval_common::scenario::Scenario;
use sepval_core::factors::{Factor, Factors};
use sepval_fit::refine::{ModelLm, refine_together};
use sepval_fit::space::{Noise, ParamSpace};
use sepval_fit::{BaselineSearch, FitError, FitOptions, Method, run_fit};
use sepval_run::inputs::{self, Releases};
use sepval_solve::lm::{LmSettings, Stall};
use sepval_solve::run::{ProgressObserver, RunError};

use crate::crossval::folds;
use crate::explored::Proposal;
use crate::jobs::{CLOCK, StartEvaluator};
use crate::outcome::{Baseline, Update};
use crate::select::{Selected, Setting, select};
use crate::store::{Store, updated_store};
use crate::uncertainty::Uncertainty;
use crate::{Result, UpdateError};

/// What an update needs.
pub struct UpdateOptions {
    /// The baseline fit (its method is forced to `ga+lm`; its output goes to DIR/baseline).
    pub fit: FitOptions,
    /// The refits' settings.
    pub lm: LmSettings,
    /// Indices of the factors the update fits (the others stay at the baseline's values).
    pub free: Vec<usize>,
    /// Releases predicted but never fitted (`--validate`).
    pub validation: Option<Job>,
    /// The store as given (`--scenario`, or the embedded default), which the update corrects.
    pub scenario: Scenario,
}

impl UpdateOptions {
    /// An update as `sepval update` makes it of the store `scenario`: the baseline `fit`, the
    /// refits with `lm`'s settings within 400 iterations and 20 000 simulations, every factor
    /// free, no release held out.
    pub fn new(fit: FitOptions, lm: &LmSettings, scenario: Scenario) -> Self {
        UpdateOptions {
            fit,
            lm: LmSettings {
                max_iterations: 400,
                budget: 20_000,
                ..lm.clone()
            },
            free: (0..sepval_core::factors::FACTOR_COUNT).collect(),
            validation: None,
            scenario,
        }
    }
}

impl UpdateOptions {
    /// An update as `sepval update` configures it: `releases` read (what the screening leaves
    /// out told to `tell`), the store as given read, the baseline fitted by `search` into
    /// `out/baseline`, the factors named `free` fitted (all 17 when `None`). Returns the job of
    /// the releases fitted and the options.
    pub fn configure(
        releases: &Releases,
        search: &BaselineSearch,
        free: Option<&[String]>,
        out: &std::path::Path,
        tell: sepval_run::inputs::Tell,
    ) -> Result<(Job, UpdateOptions)> {
        let free = free_factors(free)?;
        let input = |e| UpdateError::Inputs(Box::new(e));
        let read = releases.read(tell).map_err(input)?;
        let scenario = inputs::scenario(releases.scenario, releases.extension).map_err(input)?;
        let (fit, lm) = search
            .options(&read.job, &out.join("baseline"), read.record)
            .map_err(UpdateError::Search)?;
        let options = UpdateOptions {
            free,
            validation: read.validation,
            ..UpdateOptions::new(fit, &lm, scenario)
        };
        Ok((read.job, options))
    }
}

/// The factors named (all 17 when `None`), as indices in order; a name that is not a factor's
/// or is given twice is refused.
pub fn free_factors(names: Option<&[String]>) -> Result<Vec<usize>> {
    let Some(names) = names else {
        return Ok((0..Factor::ALL.len()).collect());
    };
    let mut out = Vec::new();
    for name in names {
        let f =
            Factor::from_name(name).ok_or_else(|| UpdateError::FreeName { name: name.clone() })?;
        if out.contains(&f.index()) {
            return Err(UpdateError::FreeTwice { name: name.clone() });
        }
        out.push(f.index());
    }
    out.sort_unstable();
    Ok(out)
}

/// The stall rule of the update's refits: ten iterations that lower the chi-square by less
/// than 1e-5 of itself end a refit (below any difference the selection decides on).
const STALL: Stall = Stall {
    iterations: 10,
    rel_drop: 1e-5,
};

/// Runs the update on the releases of `job` (each with its flight condition), starting its
/// evaluators with `start`; `progress` sees the baseline's searches.
pub fn update(
    options: &UpdateOptions,
    job: Arc<Job>,
    start: &mut StartEvaluator<'_>,
    progress: &mut dyn ProgressObserver,
) -> Result<Update> {
    let factors = Factor::ALL.len();
    if options.free.is_empty() || options.free.iter().any(|&i| i >= factors) {
        return Err(UpdateError::Free(options.free.clone()));
    }
    let t0 = Instant::now();
    CLOCK.start();
    let noise = Noise {
        pos_m: options.fit.sigma.pos_m,
        att_deg: options.fit.sigma.att_deg,
    };
    let lm = LmSettings {
        stall: Some(STALL),
        ..options.lm.clone()
    };
    let mut evaluator = start(Arc::clone(&job)).map_err(UpdateError::Start)?;
    let baseline = baseline(options, &lm, evaluator.as_mut(), progress, noise)?;
    drop(evaluator);
    CLOCK.lap("baseline");
    sepval_core::cancel::check().map_err(RunError::from)?;
    let (folds, _) = folds(&job);
    let setting = Setting {
        job: Arc::clone(&job),
        base: baseline.factors,
        free: options.free.clone(),
        noise,
        lm,
        folds,
    };
    let selected = select(&setting, start)?;
    CLOCK.lap("select");
    let uncertainty = Uncertainty::of(&selected.model.fit, &selected.model.space.shared_factors());
    let validation = crate::validation::validate(options.validation.as_ref(), &selected, noise)?;
    let store = store(options, &job, &selected)?;
    let evaluations = baseline.evaluations + selected.evaluations + validation.1;
    let parts = crate::assemble::Parts {
        job: &job,
        noise,
        baseline: &baseline,
        selected: &selected,
        uncertainty: &uncertainty,
        validation: validation.0,
        store: &store,
        free: &options.free,
        evaluations,
        wall_s: t0.elapsed().as_secs_f64(),
    };
    Ok(crate::assemble::assemble(parts))
}

/// The baseline: the fit pipeline's `ga+lm` into DIR/baseline, then refined on to convergence.
fn baseline(
    options: &UpdateOptions,
    lm: &LmSettings,
    evaluator: &mut dyn Evaluator,
    progress: &mut dyn ProgressObserver,
    noise: Noise,
) -> Result<Baseline> {
    let fit = FitOptions {
        method: Method::GaLm,
        resume: None,
        clearance: None,
        ..options.fit.clone()
    };
    let out = run_fit(&fit, evaluator, progress).map_err(|e| match e {
        FitError::Run(RunError::Interrupted) => UpdateError::Run(RunError::Interrupted),
        other => UpdateError::Baseline(other),
    })?;
    let refined = out.refined.ok_or(UpdateError::NoRefinedOptimum)?;
    let mut evaluations: u64 = out
        .result
        .methods
        .values()
        .map(|m| m.best.evaluations)
        .sum();
    let job = Arc::clone(evaluator.job());
    let space = ParamSpace::new(job.factor_table(), &sepval_common::effects::EffectSet::NONE);
    let mut runs = vec![ModelLm::new(space, job, &refined.x, noise, lm.clone())];
    refine_together(evaluator, &mut runs)?;
    let run = runs.remove(0);
    if let Some(f) = run.failure() {
        return Err(UpdateError::Refinement(f.clone()));
    }
    let lm = run.finish();
    evaluations += lm.evaluations;
    let mut factors = Factors::NOMINAL;
    factors.0.copy_from_slice(&lm.x[..Factor::ALL.len()]);
    Ok(Baseline {
        factors,
        lm,
        evaluations,
    })
}

/// The updated store: the kept corrections merged into the scenario as given.
fn store(options: &UpdateOptions, job: &Job, selected: &Selected) -> Result<Store> {
    let model = &selected.model;
    let values = model.space.values(&model.fit.lm.x);
    let kept: Vec<(sepval_common::correction::Correction, Vec<f64>)> =
        model.space.checked().into_iter().zip(values).collect();
    let names: Vec<String> = model
        .corrections
        .proposals
        .iter()
        .map(Proposal::name)
        .collect();
    let releases = job.events().len();
    let description = if names.is_empty() {
        format!(
            "{} (checked by `sepval update` against {releases} release(s): no correction kept)",
            options.scenario.description
        )
    } else {
        format!(
            "{} (updated by `sepval update` from {releases} release(s): {})",
            options.scenario.description,
            names.join(", ")
        )
    };
    updated_store(&options.scenario, &kept, &description)
}
