//! `sepval fit` as asked, configured: the releases read (the flags', or the checkpoint's when
//! resuming without them), the method and the searches (the checkpoint's when resuming, only
//! its generations may grow; else the flags'), the noise levels and the truth shown beside the
//! factors. Nothing runs and nothing is written here.

use std::path::{Path, PathBuf};

use sepval_common::evaluation::Job;
use sepval_common::telemetry::outliers::Policy;
use sepval_core::factors::Factors;
use sepval_solve::ga::GaSettings;
use sepval_solve::hill::HillSettings;
use sepval_solve::lm::LmSettings;

use crate::checkpoint::Checkpoint;
use crate::resume::{self, InputPaths};
use crate::sigma::Sigma;
use crate::{FitError, FitOptions, Method};
use sepval_run::inputs::{self, Tell};

/// The flags of `sepval fit`, as given.
#[derive(Debug, Clone)]
pub struct FitRequest<'a> {
    /// `--data`, `--scenario`, `--extension`.
    pub inputs: InputPaths,
    /// `--outliers`, if given.
    pub outliers: Option<Policy>,
    /// `--method`, if given.
    pub method: Option<Method>,
    /// `--resume`: the checkpoint's path and the checkpoint.
    pub resume: Option<(&'a Path, Checkpoint)>,
    /// The GA's settings of the flags (its generations: `--generations` or 500); a resumed
    /// run takes the checkpoint's.
    pub ga: GaSettings,
    /// `--generations`, if given (a resumed run may only grow it).
    pub generations: Option<usize>,
    /// `--hill-budget`.
    pub hill_budget: usize,
    /// `--lm-budget`.
    pub lm_budget: u64,
    /// `--sigma-pos-m`, `--sigma-att-deg`.
    pub sigma: (Option<f64>, Option<f64>),
    /// `--truth-factors`.
    pub truth_factors: Option<&'a Path>,
    /// `--out`.
    pub out: PathBuf,
}

/// The fit `request` asks for: the job of its releases (what their screening leaves out told
/// to `tell`) and the options of the run.
pub fn configure(request: FitRequest, tell: Tell) -> Result<(Job, FitOptions), FitError> {
    let r = request;
    let resume = r.resume.as_ref().map(|(_, c)| c);
    let paths = r.inputs.or_recorded(resume);
    let recorded = resume.map(|c| c.inputs.outliers).unwrap_or_default();
    let input = |e| FitError::Inputs(Box::new(e));
    let (job, record) = inputs::job(
        &paths.data,
        paths.scenario.as_deref(),
        paths.extension.as_deref(),
        r.outliers.unwrap_or(recorded),
        tell,
    )
    .map_err(input)?;
    let resumed = r.resume.as_ref().map(|(p, c)| (*p, c));
    let method = resume::method(r.method, resumed)?;
    let (ga, hill, sigma) = match resumed {
        Some((path, c)) => resume::searches(c, path, &job, r.generations)?,
        None => {
            let hill = HillSettings {
                budget: r.hill_budget,
                ..HillSettings::default()
            };
            let sigma = Sigma::resolve(&job, r.sigma.0, r.sigma.1).map_err(FitError::Sigma)?;
            (r.ga, hill, sigma)
        }
    };
    ga.validate()?;
    let truth = match r.truth_factors {
        Some(p) => {
            Some(inputs::factors(&p.display().to_string(), job.factor_table()).map_err(input)?)
        }
        None if paths.data.is_empty() => Some(Factors::TRUTH),
        None => None,
    };
    let options = FitOptions {
        method,
        ga,
        hill,
        sigma,
        truth,
        out: r.out,
        resume: r.resume.map(|(_, c)| c),
        inputs: record,
        lm: LmSettings {
            budget: r.lm_budget,
            ..LmSettings::default()
        },
        lm_probe: LmSettings {
            budget: r.lm_budget.min(800),
            ..LmSettings::default()
        },
        clearance: None,
        strict_tables: false,
    };
    Ok((job, options))
}
