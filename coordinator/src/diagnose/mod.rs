//! `sepval diagnose`: what the simulation still gets wrong after a fit, why, and what the best
//! extension of the model gains.
//!
//! 1. The baseline model is fitted by the fit pipeline (genetic search, then refinement to
//!    the optimum) and its residuals are analysed per channel and over time: RMS against the
//!    noise, where in time the misfit sits (ejector stroke, interference zone, free flight),
//!    and whiteness (autocorrelation against its 95 % band, Ljung-Box portmanteau test).
//! 2. Every effect of the catalogue (docs/model.md section 7) extends the model in turn and is
//!    refitted from the baseline optimum; all candidate refits share each batch sent to the
//!    workers. Each is judged by the statistics of nested least squares: the chi-square drop,
//!    the F test of the extra parameters (Bonferroni-corrected over the candidates tried), and
//!    the Bayesian information criterion, which charges the extra parameters
//!    (BIC = m ln(RSS / m) + k ln m, G. Schwarz 1978). An extension is significant when its F
//!    test passes at 1 % family-wise and its BIC is lower; among significant ones the lowest BIC
//!    is chosen, not the largest raw drop.
//! 3. Forward selection: further effects are added to the chosen ones while each addition is
//!    itself significant, so that effects hidden together are all named.
//! 4. The verdict: `causes` are the chosen effects; `explained` says whether the final model
//!    leaves nothing but noise (both goals within 1.1 sigma and every channel's residuals white
//!    by the Ljung-Box test at 0.1 %). When structure remains, the report says the catalogue does
//!    not hold the cause rather than naming one with confidence.
//!
//! The analysis lives here; the HTML page that presents it (DIR/report.html) is written by the
//! `report` submodule.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use sepval_common::atomic_file::{WriteError, write_atomically};
use sepval_common::effects::{CATALOGUE, EffectSet, MAX_ACTIVE_EFFECTS};
use sepval_common::evaluation::{Evaluator, Job};
use sepval_common::factors::FACTOR_COUNT;
use serde::{Deserialize, Serialize};

use crate::figures::FigureError;
use crate::fit::{FitError, FitOptions, Method, run_fit};
use crate::identifiability::identifiability;
use crate::refine::{LmResult, LmRun, LmSettings, Noise, ParamSpace, refine_together};
use crate::results::ChannelRms;
use crate::run::{ProgressObserver, RunError};
use crate::stats::f_test;

/// Errors of a diagnosis.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DiagnoseError {
    /// The output directory cannot be created.
    #[error("cannot create {path}")]
    Dir {
        /// The directory.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The baseline fit failed.
    #[error("the baseline fit failed")]
    Baseline(#[source] FitError),
    /// A refinement failed.
    #[error(transparent)]
    Run(#[from] RunError),
    /// A file that cannot be written.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// A figure that cannot be drawn.
    #[error(transparent)]
    Figure(#[from] FigureError),
    /// A model extension that cannot be made.
    #[error("{0}")]
    Model(String),
}

type Result<T> = std::result::Result<T, DiagnoseError>;

mod report;
use report::verdict;
mod residuals;

pub use residuals::{
    CHANNELS, ChannelReport, LAGS, ResidualReport, SegmentRms, WHITENESS_P, physical_residuals,
    residual_report,
};
use residuals::{residual_figures, rms_channels};

/// Format tag of diagnosis files.
pub const DIAGNOSIS_FORMAT: &str = "sepval-diagnosis/1";
/// Family-wise significance level of the candidate tests.
pub const ALPHA: f64 = 0.01;
/// Settings of a diagnosis.
pub struct DiagnoseOptions {
    /// The baseline fit (its method is forced to `ga+lm`; its output goes to DIR/baseline).
    pub fit: FitOptions,
    /// Output directory.
    pub out: PathBuf,
    /// Refinement settings of each candidate.
    pub candidate_lm: LmSettings,
}

/// One parameter's estimate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamValue {
    /// Parameter name.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Estimate.
    pub value: f64,
    /// Standard error (null when the data do not determine it).
    pub std_error: Option<f64>,
}

/// Summary of one model's fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelSummary {
    /// Its effects (empty: the baseline).
    pub effects: Vec<String>,
    /// Free parameters.
    pub parameters: usize,
    /// RMS position error \[m\].
    pub j_pos_m: f64,
    /// RMS attitude error \[deg\].
    pub j_att_deg: f64,
    /// Sum of squared normalised residuals.
    pub chi2: f64,
    /// RMS residual per channel.
    pub channel_rms: ChannelRms,
}

/// One candidate extension, tried against the model of its round.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateReport {
    /// Effect id.
    pub id: String,
    /// What it adds.
    pub adds: String,
    /// Forward-selection round (1: against the baseline).
    pub round: usize,
    /// Its parameters' estimates.
    pub parameters: Vec<ParamValue>,
    /// Chi-square of the extended fit.
    pub chi2: f64,
    /// Chi-square drop from the round's model.
    pub chi2_drop: f64,
    /// F statistic of the extra parameters.
    pub f: f64,
    /// Its p-value.
    pub p_value: f64,
    /// The Bonferroni-corrected threshold of the round.
    pub p_threshold: f64,
    /// BIC change (negative: better even after charging the parameters).
    pub delta_bic: f64,
    /// Whether the extension is significant.
    pub significant: bool,
    /// Goals after the extension: J_pos \[m\], J_att \[deg\].
    pub goals: [f64; 2],
    /// RMS residual per channel after the extension.
    pub channel_rms: ChannelRms,
    /// A remark (for example a weak effect's bound).
    pub note: String,
    /// Why its refinement stopped, and after how many iterations.
    pub refinement: String,
}

/// DIR/diagnosis.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Diagnosis {
    /// [`DIAGNOSIS_FORMAT`].
    pub format: String,
    /// The effects named as causes, in the order chosen (empty when the baseline explains the
    /// data).
    pub causes: Vec<String>,
    /// False when structure beyond noise remains after the best extension.
    pub explained: bool,
    /// The verdict in one sentence.
    pub verdict: String,
    /// Position noise \[m\].
    pub sigma_pos_m: f64,
    /// Attitude noise \[deg\].
    pub sigma_att_deg: f64,
    /// Where the sigmas came from.
    pub sigma_source: String,
    /// The baseline fit.
    pub baseline: ModelSummary,
    /// The final (extended) model; the baseline when no cause is named.
    pub extended: ModelSummary,
    /// Each named effect's parameters with standard errors.
    pub parameters: BTreeMap<String, Vec<ParamValue>>,
    /// Every candidate tried, every round.
    pub candidates: Vec<CandidateReport>,
    /// Residual analysis before and after.
    pub residuals: BTreeMap<String, ResidualReport>,
    /// Simulations run (baseline fit included).
    pub evaluations: u64,
    /// Wall time \[s\].
    pub wall_s: f64,
}

/// A fitted model: its effects and refinement.
struct Fitted {
    effects: EffectSet,
    lm: LmResult,
}

fn noise_of(options: &FitOptions) -> Noise {
    Noise {
        pos_m: options.sigma.pos_m,
        att_deg: options.sigma.att_deg,
    }
}

fn summary(fitted: &Fitted, noise: Noise, events: &[usize]) -> ModelSummary {
    ModelSummary {
        effects: fitted
            .effects
            .iter()
            .map(|a| a.effect().id().to_string())
            .collect(),
        parameters: FACTOR_COUNT + fitted.effects.param_count(),
        j_pos_m: fitted.lm.goals.j_pos_m,
        j_att_deg: fitted.lm.goals.j_att_deg,
        chi2: fitted.lm.cost,
        channel_rms: rms_channels(&physical_residuals(&fitted.lm.residuals, noise, events)),
    }
}

/// Refines a model again from its optimum until it converges (a reference model must be
/// converged for the drops of its extensions to measure them); keeps the better of the two.
fn converge(
    evaluator: &mut dyn Evaluator,
    job: &Arc<Job>,
    fitted: Fitted,
    noise: Noise,
    settings: &LmSettings,
    evaluations: &mut u64,
) -> Result<Fitted> {
    let space = ParamSpace::new(job.factor_table(), &fitted.effects);
    let mut run = [LmRun::new(
        space,
        Arc::clone(job),
        &fitted.lm.x,
        noise,
        settings.clone(),
    )];
    refine_together(evaluator, &mut run)?;
    let [run] = run;
    let lm = run.finish();
    *evaluations += lm.evaluations;
    Ok(if lm.cost < fitted.lm.cost {
        Fitted {
            effects: fitted.effects,
            lm,
        }
    } else {
        fitted
    })
}

/// The extensions of `base` by each effect of `ids`, refitted together from `base`'s optimum.
fn try_extensions(
    evaluator: &mut dyn Evaluator,
    job: &Arc<Job>,
    base: &Fitted,
    ids: &[usize],
    noise: Noise,
    settings: &LmSettings,
) -> Result<Vec<(usize, Fitted)>> {
    let table = *job.factor_table();
    let mut runs = Vec::new();
    let mut sets = Vec::new();
    for &index in ids {
        let mut set = base.effects;
        let neutral: Vec<f64> = CATALOGUE[index]
            .params()
            .iter()
            .map(|p| p.neutral)
            .collect();
        set.push(index, &neutral)
            .map_err(|e| DiagnoseError::Model(e.to_string()))?;
        let space = ParamSpace::new(&table, &set);
        let mut x0 = base.lm.x.clone();
        x0.extend(neutral);
        runs.push(LmRun::new(
            space,
            Arc::clone(job),
            &x0,
            noise,
            settings.clone(),
        ));
        sets.push((index, set));
    }
    refine_together(evaluator, &mut runs)?;
    Ok(sets
        .into_iter()
        .zip(runs)
        .map(|((index, effects), run)| {
            (
                index,
                Fitted {
                    effects,
                    lm: run.finish(),
                },
            )
        })
        .collect())
}

fn param_values(
    space: &ParamSpace,
    fitted: &Fitted,
    events: &[usize],
    from: usize,
) -> Vec<ParamValue> {
    let id = identifiability(
        space,
        &fitted.lm.x,
        &fitted.lm.residuals,
        &fitted.lm.jacobian,
        events,
    );
    id.parameters[from..]
        .iter()
        .map(|p| ParamValue {
            name: p.name.clone(),
            unit: p.unit.clone(),
            value: p.value,
            std_error: p.std_error,
        })
        .collect()
}

/// Runs the diagnosis and writes DIR/diagnosis.json, DIR/report.html and the figures.
pub fn diagnose(
    options: &DiagnoseOptions,
    evaluator: &mut dyn Evaluator,
    progress: &mut dyn ProgressObserver,
) -> Result<Diagnosis> {
    let t0 = Instant::now();
    std::fs::create_dir_all(options.out.join("figures")).map_err(|source| DiagnoseError::Dir {
        path: options.out.join("figures"),
        source,
    })?;
    let noise = noise_of(&options.fit);
    let floor = [1.1 * noise.pos_m, 1.1 * noise.att_deg];
    let job = Arc::clone(evaluator.job());
    let events: Vec<usize> = job.events().iter().map(|e| e.data.len()).collect();
    let m = 6 * job.sample_count();

    // 1. The baseline fit.
    let fit = FitOptions {
        method: Method::GaLm,
        out: options.out.join("baseline"),
        resume: None,
        ..options.fit.clone()
    };
    let baseline_out = run_fit(&fit, evaluator, progress).map_err(|e| match e {
        FitError::Run(RunError::Interrupted) => DiagnoseError::Run(RunError::Interrupted),
        other => DiagnoseError::Baseline(other),
    })?;
    let baseline_lm = baseline_out.refined.ok_or_else(|| {
        DiagnoseError::Model("the baseline fit produced no refined optimum".into())
    })?;
    let mut evaluations: u64 = baseline_out
        .result
        .methods
        .values()
        .map(|m| m.best.evaluations)
        .sum();
    let baseline = converge(
        evaluator,
        &job,
        Fitted {
            effects: EffectSet::NONE,
            lm: baseline_lm,
        },
        noise,
        &options.candidate_lm,
        &mut evaluations,
    )?;

    // 2-3. Candidates and forward selection.
    let mut current = Fitted {
        effects: EffectSet::NONE,
        lm: baseline.lm.clone(),
    };
    let mut chosen: Vec<usize> = Vec::new();
    let mut candidates = Vec::new();
    for round in 1..=MAX_ACTIVE_EFFECTS {
        let remaining: Vec<usize> = (0..CATALOGUE.len())
            .filter(|i| !chosen.contains(i))
            .collect();
        if remaining.is_empty() {
            break;
        }
        let threshold = ALPHA / remaining.len() as f64;
        let tried = try_extensions(
            evaluator,
            &job,
            &current,
            &remaining,
            noise,
            &options.candidate_lm,
        )?;
        let mut best: Option<(usize, f64)> = None;
        let mut fitted_by_index = BTreeMap::new();
        for (index, fitted) in tried {
            evaluations += fitted.lm.evaluations;
            let effect = CATALOGUE[index];
            let q = effect.params().len();
            let p1 = FACTOR_COUNT + fitted.effects.param_count();
            let (f, p) = f_test(current.lm.cost, fitted.lm.cost, q, m, p1);
            let delta_bic =
                m as f64 * (fitted.lm.cost / current.lm.cost).ln() + q as f64 * (m as f64).ln();
            let space = ParamSpace::new(job.factor_table(), &fitted.effects);
            let from = space.len() - q;
            let parameters = param_values(&space, &fitted, &events, from);
            let significant = p < threshold && delta_bic < 0.0;
            let note = if significant {
                String::new()
            } else {
                format!(
                    "not significant (p = {p:.2e}, threshold {threshold:.1e}; BIC change {delta_bic:+.1}); the data bound it to {}",
                    parameters
                        .iter()
                        .map(|v| match v.std_error {
                            Some(se) => format!(
                                "|{}| <~ {:.3e} {} (2 SE)",
                                v.name,
                                v.value.abs() + 2.0 * se,
                                v.unit
                            ),
                            None => format!("{}: undetermined", v.name),
                        })
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            };
            if significant && best.is_none_or(|(_, b)| delta_bic < b) {
                best = Some((index, delta_bic));
            }
            candidates.push(CandidateReport {
                id: effect.id().to_string(),
                adds: effect.adds().to_string(),
                round,
                parameters,
                chi2: fitted.lm.cost,
                chi2_drop: current.lm.cost - fitted.lm.cost,
                f,
                p_value: p,
                p_threshold: threshold,
                delta_bic,
                significant,
                goals: fitted.lm.goals.as_array(),
                channel_rms: rms_channels(&physical_residuals(
                    &fitted.lm.residuals,
                    noise,
                    &events,
                )),
                note,
                refinement: format!(
                    "{} after {} iterations",
                    fitted.lm.stop, fitted.lm.iterations
                ),
            });
            fitted_by_index.insert(index, fitted);
        }
        match best {
            Some((index, _)) => {
                chosen.push(index);
                let picked = fitted_by_index.remove(&index).expect("tried");
                current = converge(
                    evaluator,
                    &job,
                    picked,
                    noise,
                    &options.candidate_lm,
                    &mut evaluations,
                )?;
            }
            None => break,
        }
    }

    // 4. The verdict.
    let final_report = residual_report(&job, &current.lm, noise, floor);
    let base_report = residual_report(&job, &baseline.lm, noise, floor);
    let explained = final_report.white && final_report.at_noise_floor;
    let causes: Vec<String> = chosen
        .iter()
        .map(|&i| CATALOGUE[i].id().to_string())
        .collect();
    let mut parameters = BTreeMap::new();
    if !chosen.is_empty() {
        let space = ParamSpace::new(job.factor_table(), &current.effects);
        let all = param_values(&space, &current, &events, FACTOR_COUNT);
        let mut pos = 0;
        for a in current.effects.iter() {
            let n = a.effect().params().len();
            parameters.insert(a.effect().id().to_string(), all[pos..pos + n].to_vec());
            pos += n;
        }
    }
    let base_summary = summary(&baseline, noise, &events);
    let ext_summary = summary(&current, noise, &events);
    let verdict = verdict(
        &causes,
        explained,
        &parameters,
        &base_summary,
        &ext_summary,
        noise,
    );
    let mut residuals = BTreeMap::new();
    residuals.insert("baseline".to_string(), base_report);
    residuals.insert("extended".to_string(), final_report);
    let diagnosis = Diagnosis {
        format: DIAGNOSIS_FORMAT.to_string(),
        causes,
        explained,
        verdict,
        sigma_pos_m: noise.pos_m,
        sigma_att_deg: noise.att_deg,
        sigma_source: options.fit.sigma.source.clone(),
        baseline: base_summary,
        extended: ext_summary,
        parameters,
        candidates,
        residuals,
        evaluations,
        wall_s: t0.elapsed().as_secs_f64(),
    };
    let figures = residual_figures(
        &options.out,
        &job,
        &baseline.lm,
        &current.lm,
        noise,
        &events,
    )?;
    let json = serde_json::to_vec_pretty(&diagnosis).expect("a diagnosis serialises");
    write_atomically(&options.out.join("diagnosis.json"), &json)?;
    write_atomically(
        &options.out.join("report.html"),
        report::report_html(&diagnosis, &figures).as_bytes(),
    )?;
    Ok(diagnosis)
}
