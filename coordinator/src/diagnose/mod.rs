//! `sepval diagnose`: what the simulation still gets wrong after a fit, why, and what the best
//! extension of the model gains.
//!
//! 1. **Baseline.** The 17 factors are fitted by the fit pipeline (genetic search, then
//!    refinement to the optimum) and the residuals analysed per channel and over time: RMS
//!    against the noise, where in time the misfit sits (ejector stroke, interference zone, free
//!    flight), and whiteness (autocorrelation against its 95 % band, Ljung-Box test).
//! 2. **Catalogue** (`catalogue`): every effect of the catalogue (docs/model.md section 7)
//!    extends the model in turn and is refitted; an extension is significant when its F test
//!    passes at 1 % family-wise (Bonferroni over the round) and it lowers the Bayesian
//!    information criterion (BIC = m ln(RSS / m) + k ln m, G. Schwarz 1978); the lowest BIC
//!    among significant ones is chosen, and further effects are added while each addition is
//!    itself significant (forward selection).
//! 3. **Discovery** (`discover`): beyond the catalogue, the missing force and moment are
//!    reconstructed as time histories, and terms of a documented library (docs/model.md
//!    section 11) are selected by stepwise regression and verified by an output-error refit.
//! 4. **The answer.** The catalogue's effects (`causes`) stay the answer unless the discovered
//!    extension beats them by more than [`BIC_MARGIN`] in BIC (R. E. Kass and A. E. Raftery,
//!    JASA 90, 1995: a difference above 6 is strong evidence), in which case the catalogue's
//!    effects are listed as `alternatives`, mimics of the better explanation. With no
//!    catalogue effect significant, a significant discovered extension is the answer. Null
//!    data name nothing. `explained` says whether the catalogue's answer (the baseline when it
//!    names no effect) leaves nothing but noise (both goals within 1.1 sigma and every
//!    channel's residuals white by the Ljung-Box test at 0.1 %); whether a discovered extension
//!    does is `extension.explained`.
//! 5. **Prediction.** Events given with `--validate` take no part in any fit: the baseline's
//!    and the answer's goals on them are reported.
//!
//! The analysis lives here; the HTML page that presents it (DIR/report.html) is written by the
//! `report` submodule.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use sepval_common::atomic_file::{WriteError, write_atomically};
use sepval_common::effects::{CATALOGUE, EffectSet};
use sepval_common::evaluation::{Candidate, EvalError, Evaluator, Job};
use sepval_common::extension::{TermRecord, extension_toml};
use sepval_common::factors::{FACTOR_COUNT, Factors};
use serde::{Deserialize, Serialize};

use crate::figures::FigureError;
use crate::fit::{FitError, FitOptions, Method, run_fit};
use crate::refine::{FreeTerm, LmResult, LmSettings, Noise, ParamSpace};
use crate::results::ChannelRms;
use crate::run::{ProgressObserver, RunError};

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

impl From<EvalError> for DiagnoseError {
    fn from(e: EvalError) -> Self {
        DiagnoseError::Run(RunError::from(e))
    }
}

type Result<T> = std::result::Result<T, DiagnoseError>;

mod catalogue;
mod discover;
mod library;
mod probe;
pub mod readings;
mod reconstruct;
mod report;
mod residuals;
mod stepwise;

pub use discover::{DiscoveredTerm, DiscoveryStep, Gain, GroupMember, Screened, Verified};
pub use reconstruct::{IncrementSeries, Reconstruction};
pub use report::fmt_discovered;
pub use residuals::{
    CHANNELS, ChannelReport, LAGS, ResidualReport, SegmentRms, WHITENESS_P, physical_residuals,
    residual_report,
};
use residuals::{residual_figures, rms_channels};

/// Format tag of diagnosis files.
pub const DIAGNOSIS_FORMAT: &str = "sepval-diagnosis/2";
/// Family-wise significance level of the candidate tests.
pub const ALPHA: f64 = 0.01;
/// The BIC lead by which a discovered extension must beat the catalogue's answer to replace it.
pub const BIC_MARGIN: f64 = 6.0;

/// Settings of a diagnosis.
pub struct DiagnoseOptions {
    /// The baseline fit (its method is forced to `ga+lm`; its output goes to DIR/baseline).
    pub fit: FitOptions,
    /// Output directory.
    pub out: PathBuf,
    /// Refinement settings of each candidate.
    pub candidate_lm: LmSettings,
    /// Events not used for fitting, on which the baseline and the answer predict.
    pub validation: Option<Job>,
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
    /// Its extension terms (`axis: formula`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub terms: Vec<String>,
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
    /// The 17 factors as fitted with it (absent in files written before they were recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factors: Option<Factors>,
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

/// The discovered extension: the model with the discovered terms, refitted, and its gain.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExtensionReport {
    /// Whether it is the answer (else the catalogue's effects are, and it is an alternative).
    pub answer: bool,
    /// The extension file written (relative to DIR), when it is the answer.
    pub file: Option<String>,
    /// The extended model's fit.
    pub model: ModelSummary,
    /// Its gain over the baseline (chi-square drop, F test, BIC).
    pub gain: Gain,
    /// Whether every channel's residuals are white.
    pub white: bool,
    /// Whether both goals are within 1.1 sigma.
    pub at_noise_floor: bool,
    /// Whether it explains the data to the noise (white and at the floor).
    pub explained: bool,
    /// Why its refinement stopped.
    pub refinement: String,
}

/// A model that explains part of the data but is not the answer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Alternative {
    /// `catalogue` (effects) or `discovered` (terms).
    pub kind: String,
    /// Its effects or terms.
    pub names: Vec<String>,
    /// Its fit.
    pub model: ModelSummary,
    /// Its BIC minus the answer's (positive: worse).
    pub delta_bic_vs_answer: f64,
    /// Why it is not the answer.
    pub note: String,
}

/// Prediction of one event that took no part in the fits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ValidationReport {
    /// The event.
    pub event: String,
    /// The baseline's RMS position error on it \[m\].
    pub baseline_j_pos_m: Option<f64>,
    /// The baseline's RMS attitude error \[deg\].
    pub baseline_j_att_deg: Option<f64>,
    /// The answer's RMS position error \[m\].
    pub extended_j_pos_m: Option<f64>,
    /// The answer's RMS attitude error \[deg\].
    pub extended_j_att_deg: Option<f64>,
    /// The alternatives' predictions.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub alternatives: Vec<AlternativePrediction>,
    /// Why a model did not simulate it, if one did not.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
}

/// An alternative's prediction of a validation event.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AlternativePrediction {
    /// The alternative (`catalogue: ...` or `discovered: ...`).
    pub model: String,
    /// RMS position error \[m\].
    pub j_pos_m: f64,
    /// RMS attitude error \[deg\].
    pub j_att_deg: f64,
}

/// DIR/diagnosis.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Diagnosis {
    /// [`DIAGNOSIS_FORMAT`].
    pub format: String,
    /// The catalogue effects named as causes, in the order chosen (empty when the baseline
    /// explains the data, or when a discovered extension explains it better).
    pub causes: Vec<String>,
    /// Whether the catalogue's answer leaves nothing but noise: the model with the effects it
    /// chose (the baseline when it chose none), even when those effects are not the answer
    /// (`causes` is then empty because a discovered extension explains better). A discovered
    /// extension's own verdict is `extension.explained`; the terminal summary shows the
    /// answer's.
    pub explained: bool,
    /// The verdict in one sentence.
    pub verdict: String,
    /// Terms found beyond the catalogue, most important first, when they are the answer.
    pub discovered: Vec<DiscoveredTerm>,
    /// Models that explain part of the data but not as well as the answer (mimics).
    pub alternatives: Vec<Alternative>,
    /// The discovered extension and its gain, when discovery verified one.
    pub extension: Option<ExtensionReport>,
    /// What discovery did beyond its findings (why nothing was named, terms dropped).
    pub discovery_notes: Vec<String>,
    /// Each step of discovery's selection: the entries ranked, the refits, what entered.
    pub discovery_steps: Vec<DiscoveryStep>,
    /// Position noise \[m\].
    pub sigma_pos_m: f64,
    /// Attitude noise \[deg\].
    pub sigma_att_deg: f64,
    /// Where the sigmas came from.
    pub sigma_source: String,
    /// The baseline fit.
    pub baseline: ModelSummary,
    /// The answer's model; the baseline when nothing is named.
    pub extended: ModelSummary,
    /// Each named effect's parameters with standard errors.
    pub parameters: BTreeMap<String, Vec<ParamValue>>,
    /// Every candidate tried, every round.
    pub candidates: Vec<CandidateReport>,
    /// Residual analysis before and after.
    pub residuals: BTreeMap<String, ResidualReport>,
    /// Per event, the reconstructed coefficient increments with their bands.
    pub reconstruction: Vec<Reconstruction>,
    /// Prediction of the `--validate` events.
    pub validation: Vec<ValidationReport>,
    /// Simulations run (baseline fit included).
    pub evaluations: u64,
    /// Wall time \[s\].
    pub wall_s: f64,
}

/// A fitted model: its effects, its free extension terms and its refinement.
#[derive(Clone)]
struct Fitted {
    effects: EffectSet,
    terms: Vec<FreeTerm>,
    lm: LmResult,
}

impl Fitted {
    /// Its parameter space.
    fn space(&self, job: &Job) -> ParamSpace {
        ParamSpace::with_terms(job.factor_table(), &self.effects, &self.terms)
    }

    /// Its candidate at the optimum.
    fn candidate(&self, job: &Job) -> Result<Candidate> {
        Ok(self.space(job).candidate(&self.lm.x)?)
    }
}

/// BIC = m ln(chi2 / m) + k ln m of a fit of `k` parameters to `m` residuals.
fn bic(chi2: f64, k: usize, m: usize) -> f64 {
    let m = m as f64;
    m * (chi2.max(1e-300) / m).ln() + k as f64 * m.ln()
}

fn noise_of(options: &FitOptions) -> Noise {
    Noise {
        pos_m: options.sigma.pos_m,
        att_deg: options.sigma.att_deg,
    }
}

fn summary(job: &Job, fitted: &Fitted, noise: Noise, events: &[usize]) -> ModelSummary {
    let terms = fitted
        .space(job)
        .terms_at(&fitted.lm.x)
        .unwrap_or_default()
        .iter()
        .map(|t| format!("{}: {}", t.axis.name(), t.formula()))
        .collect();
    ModelSummary {
        effects: fitted
            .effects
            .iter()
            .map(|a| a.effect().id().to_string())
            .collect(),
        terms,
        parameters: fitted.space(job).len(),
        j_pos_m: fitted.lm.goals.j_pos_m,
        j_att_deg: fitted.lm.goals.j_att_deg,
        chi2: fitted.lm.cost,
        channel_rms: rms_channels(&physical_residuals(&fitted.lm.residuals, noise, events)),
        factors: fitted.candidate(job).ok().map(|c| c.factors),
    }
}

/// Which model answers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Answer {
    Baseline,
    Catalogue,
    Discovered,
}

/// Runs the diagnosis and writes DIR/diagnosis.json, DIR/report.html, the figures and (when
/// the answer is a discovered extension) DIR/extension.toml.
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
    let baseline = catalogue::converge(
        evaluator,
        &job,
        Fitted {
            effects: EffectSet::NONE,
            terms: Vec::new(),
            lm: baseline_lm,
        },
        noise,
        &options.candidate_lm,
        &mut evaluations,
    )?;

    // 2. The catalogue.
    let cat = catalogue::select(
        evaluator,
        &job,
        &baseline,
        noise,
        &options.candidate_lm,
        &mut evaluations,
    )?;

    // 3. Discovery.
    let disc = discover::discover(evaluator, &job, &baseline, noise, &options.candidate_lm)?;
    evaluations += disc.evaluations;

    // 4. The answer.
    let k_of = |f: &Fitted| f.space(&job).len();
    let cat_bic = bic(cat.fitted.lm.cost, k_of(&cat.fitted), m);
    let answer = match (&disc.found, cat.chosen.is_empty()) {
        (None, true) => Answer::Baseline,
        (None, false) => Answer::Catalogue,
        (Some(_), true) => Answer::Discovered,
        (Some((f, _, _)), false) => {
            if bic(f.lm.cost, k_of(f), m) < cat_bic - BIC_MARGIN {
                Answer::Discovered
            } else {
                Answer::Catalogue
            }
        }
    };
    let answer_fit: &Fitted = match (answer, &disc.found) {
        (Answer::Discovered, Some((f, _, _))) => f,
        (Answer::Catalogue, _) => &cat.fitted,
        _ => &baseline,
    };
    let answer_bic = bic(answer_fit.lm.cost, k_of(answer_fit), m);
    let cat_report = residual_report(&job, &cat.fitted.lm, noise, floor);
    let explained = cat_report.white && cat_report.at_noise_floor;
    let causes: Vec<String> = if answer == Answer::Catalogue {
        cat.chosen
            .iter()
            .map(|&i| CATALOGUE[i].id().to_string())
            .collect()
    } else {
        Vec::new()
    };
    let mut parameters = BTreeMap::new();
    if !cat.chosen.is_empty() {
        let space = cat.fitted.space(&job);
        let all = catalogue::param_values(&space, &cat.fitted, &events, FACTOR_COUNT);
        let mut pos = 0;
        for a in cat.fitted.effects.iter() {
            let n = a.effect().params().len();
            parameters.insert(a.effect().id().to_string(), all[pos..pos + n].to_vec());
            pos += n;
        }
    }
    let cat_names: Vec<String> = cat
        .chosen
        .iter()
        .map(|&i| CATALOGUE[i].id().to_string())
        .collect();
    let mut alternatives = Vec::new();
    let mut extension = None;
    let mut discovered = Vec::new();
    if answer == Answer::Discovered && !cat.chosen.is_empty() {
        alternatives.push(Alternative {
            kind: "catalogue".into(),
            names: cat
                .chosen
                .iter()
                .map(|&i| CATALOGUE[i].id().to_string())
                .collect(),
            model: summary(&job, &cat.fitted, noise, &events),
            delta_bic_vs_answer: cat_bic - answer_bic,
            note: format!(
                "significant on its own, but the discovered terms explain the data better by {:.1} in BIC (more than {BIC_MARGIN}): a mimic, not the cause{}",
                cat_bic - answer_bic,
                if explained {
                    " (it even reaches the noise floor: the data alone cannot rule it out)"
                } else {
                    ""
                }
            ),
        });
    }
    if let Some((f, terms, gain)) = &disc.found {
        let report = residual_report(&job, &f.lm, noise, floor);
        let is_answer = answer == Answer::Discovered;
        if is_answer {
            discovered = terms.clone();
        } else {
            let d_bic = bic(f.lm.cost, k_of(f), m) - answer_bic;
            alternatives.push(Alternative {
                kind: "discovered".into(),
                names: terms
                    .iter()
                    .map(|t| format!("{}: {}", t.axis, t.term))
                    .collect(),
                model: summary(&job, f, noise, &events),
                delta_bic_vs_answer: d_bic,
                note: format!(
                    "significant against the baseline, but it does not beat the catalogue's answer by more than {BIC_MARGIN} in BIC (difference {d_bic:+.1}): the catalogue effect stays the cause"
                ),
            });
        }
        extension = Some(ExtensionReport {
            answer: is_answer,
            file: is_answer.then(|| "extension.toml".to_string()),
            model: summary(&job, f, noise, &events),
            gain: gain.clone(),
            white: report.white,
            at_noise_floor: report.at_noise_floor,
            explained: report.white && report.at_noise_floor,
            refinement: format!("{} after {} iterations", f.lm.stop, f.lm.iterations),
        });
    }
    let final_report = residual_report(&job, &answer_fit.lm, noise, floor);
    let base_report = residual_report(&job, &baseline.lm, noise, floor);
    let base_summary = summary(&job, &baseline, noise, &events);
    let ext_summary = summary(&job, answer_fit, noise, &events);
    let mut verdict = report::verdict(&report::VerdictInput {
        causes: &causes,
        explained,
        parameters: &parameters,
        discovered: &discovered,
        extension: extension.as_ref().filter(|e| e.answer),
        alternatives: &alternatives,
        base: &base_summary,
        ext: &ext_summary,
        noise,
    });

    // 5. Prediction of the validation events.
    let validation = match &options.validation {
        Some(v) => {
            let mut alts = Vec::new();
            if answer != Answer::Catalogue && !cat.chosen.is_empty() {
                alts.push((
                    format!("catalogue: {}", cat_names.join(" + ")),
                    cat.fitted.candidate(&job)?,
                ));
            }
            if let (false, Some((f, terms, _))) = (answer == Answer::Discovered, &disc.found) {
                alts.push((
                    format!(
                        "discovered: {}",
                        terms
                            .iter()
                            .map(|t| format!("{} {}", t.axis, t.term))
                            .collect::<Vec<_>>()
                            .join(" + ")
                    ),
                    f.candidate(&job)?,
                ));
            }
            validate(
                v,
                &baseline.candidate(&job)?,
                &answer_fit.candidate(&job)?,
                &alts,
            )
        }
        None => Vec::new(),
    };
    if let Some(note) = prediction_caveat(&validation, noise) {
        verdict.push_str(&note);
    }

    let mut residuals = BTreeMap::new();
    residuals.insert("baseline".to_string(), base_report);
    residuals.insert("extended".to_string(), final_report);
    let diagnosis = Diagnosis {
        format: DIAGNOSIS_FORMAT.to_string(),
        causes,
        explained,
        verdict,
        discovered,
        alternatives,
        extension,
        discovery_notes: disc.notes.clone(),
        discovery_steps: disc.steps.clone(),
        sigma_pos_m: noise.pos_m,
        sigma_att_deg: noise.att_deg,
        sigma_source: options.fit.sigma.source.clone(),
        baseline: base_summary,
        extended: ext_summary,
        parameters,
        candidates: cat.candidates,
        residuals,
        reconstruction: disc.reconstruction.clone(),
        validation,
        evaluations,
        wall_s: t0.elapsed().as_secs_f64(),
    };
    let mut figures = residual_figures(
        &options.out,
        &job,
        &baseline.lm,
        &answer_fit.lm,
        noise,
        &events,
    )?;
    let model_curves = match &disc.found {
        Some((f, _, _)) => discover::model_increments(&job, f)?,
        None => Vec::new(),
    };
    if !diagnosis.reconstruction.is_empty() {
        let name = "figures/increments.png";
        report::increment_figure(
            &options.out.join(name),
            &diagnosis.reconstruction,
            &model_curves,
        )?;
        figures.insert(0, name.to_string());
    }
    if let (Answer::Discovered, Some((f, terms, gain))) = (answer, &disc.found) {
        let text = extension_file(&job, f, terms, gain)?;
        write_atomically(&options.out.join("extension.toml"), text.as_bytes())?;
        // The factors fitted with the terms: `--factors DIR/factors.json --extension
        // DIR/extension.toml` reproduces the answer.
        let factors =
            serde_json::to_vec_pretty(&f.candidate(&job)?.factors).expect("factors serialise");
        write_atomically(&options.out.join("factors.json"), &factors)?;
    }
    let json = serde_json::to_vec_pretty(&diagnosis).expect("a diagnosis serialises");
    write_atomically(&options.out.join("diagnosis.json"), &json)?;
    write_atomically(
        &options.out.join("report.html"),
        report::report_html(&diagnosis, &figures).as_bytes(),
    )?;
    Ok(diagnosis)
}

/// DIR/extension.toml: the discovered terms at their refitted values, with a header that says
/// where they came from.
fn extension_file(job: &Job, f: &Fitted, found: &[DiscoveredTerm], gain: &Gain) -> Result<String> {
    let terms = f.space(job).terms_at(&f.lm.x)?;
    let records: Vec<TermRecord> = terms
        .iter()
        .map(|t| {
            let mut r = TermRecord::of(t);
            r.reading = Some(readings::reading(
                t,
                &job.events()[0].simulator.scenario().interference,
            ));
            r
        })
        .collect();
    let mut text = format!(
        "# Found by `sepval diagnose` beyond the effect catalogue, from: {}\n",
        job.events()
            .iter()
            .map(|e| e.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    for d in found {
        text.push_str(&format!(
            "# {} {} ({}): {}\n",
            d.axis, d.term, d.family, d.reading
        ));
    }
    text.push_str(&format!(
        "# Gain over the baseline: chi-square drop {:.1}, F = {:.1}, p = {:.2e}, BIC change {:+.1}\n",
        gain.chi2_drop, gain.f, gain.p_value, gain.delta_bic
    ));
    text.push_str(&extension_toml(&records));
    // What is written must read back.
    sepval_common::extension::parse_extension(&text, "extension.toml").map_err(|e| {
        DiagnoseError::Model(format!("the extension written does not read back: {e}"))
    })?;
    Ok(text)
}

/// Goals of the baseline, the answer and the alternatives (named) on each validation event.
fn validate(
    v: &Job,
    base: &Candidate,
    answer: &Candidate,
    alternatives: &[(String, Candidate)],
) -> Vec<ValidationReport> {
    v.events()
        .iter()
        .map(|e| {
            let one = Job::new(vec![e.clone()]);
            let goals = |c: &Candidate| -> Prediction {
                let job = one.as_ref().map_err(|e| e.to_string())?;
                let ev = job.evaluate(c);
                ev.outcome
                    .goals()
                    .map(|g| (g.j_pos_m, g.j_att_deg))
                    .ok_or_else(|| format!("{:?}", ev.outcome))
            };
            let (b, a) = (goals(base), goals(answer));
            let others: Vec<(String, Prediction)> = alternatives
                .iter()
                .map(|(n, c)| (n.clone(), goals(c)))
                .collect();
            let mut note: Vec<String> = [("baseline", &b), ("extended model", &a)]
                .iter()
                .filter_map(|(n, r)| r.as_ref().err().map(|e| format!("{n}: {e}")))
                .collect();
            note.extend(
                others
                    .iter()
                    .filter_map(|(n, r)| r.as_ref().err().map(|e| format!("{n}: {e}"))),
            );
            ValidationReport {
                event: e.name.clone(),
                baseline_j_pos_m: b.as_ref().ok().map(|g| g.0),
                baseline_j_att_deg: b.as_ref().ok().map(|g| g.1),
                extended_j_pos_m: a.as_ref().ok().map(|g| g.0),
                extended_j_att_deg: a.as_ref().ok().map(|g| g.1),
                alternatives: others
                    .iter()
                    .filter_map(|(n, r)| {
                        r.as_ref().ok().map(|g| AlternativePrediction {
                            model: n.clone(),
                            j_pos_m: g.0,
                            j_att_deg: g.1,
                        })
                    })
                    .collect(),
                note: note.join("; "),
            }
        })
        .collect()
}

/// A model's goals on a validation event (J_pos \[m\], J_att \[deg\]), or why it did not simulate.
type Prediction = std::result::Result<(f64, f64), String>;

/// A caveat for the verdict when an alternative predicts the events not fitted clearly better
/// than the answer (its sum over events of `(J_pos/sigma_pos)^2 + (J_att/sigma_att)^2` below
/// 0.8 of the answer's): the answer may fit its own data by mimicry.
fn prediction_caveat(validation: &[ValidationReport], noise: Noise) -> Option<String> {
    let score = |p: f64, a: f64| (p / noise.pos_m).powi(2) + (a / noise.att_deg).powi(2);
    let mut answer = 0.0;
    let mut alts: Vec<(String, f64, f64, f64)> = Vec::new();
    for v in validation {
        let (Some(p), Some(a)) = (v.extended_j_pos_m, v.extended_j_att_deg) else {
            return None;
        };
        answer += score(p, a);
        for (i, alt) in v.alternatives.iter().enumerate() {
            if alts.len() <= i {
                alts.push((alt.model.clone(), 0.0, 0.0, 0.0));
            }
            alts[i].1 += score(alt.j_pos_m, alt.j_att_deg);
            alts[i].2 += alt.j_pos_m.powi(2);
            alts[i].3 += alt.j_att_deg.powi(2);
        }
    }
    let n = validation.len() as f64;
    let (model, s, p2, a2) = alts
        .into_iter()
        .filter(|a| a.1.is_finite())
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    if n == 0.0 || s >= 0.8 * answer || !s.is_finite() {
        return None;
    }
    let kind = model.split(':').next().unwrap_or("an");
    Some(format!(
        "; caution: on the events not fitted the {kind} alternative predicts better (RMS over events J_pos {:.4} m, J_att {:.3} deg): the answer may fit these data without naming their cause",
        (p2 / n).sqrt(),
        (a2 / n).sqrt()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn event(answer: (f64, f64), alt: (f64, f64)) -> ValidationReport {
        ValidationReport {
            event: "e".into(),
            baseline_j_pos_m: Some(0.1),
            baseline_j_att_deg: Some(1.0),
            extended_j_pos_m: Some(answer.0),
            extended_j_att_deg: Some(answer.1),
            alternatives: vec![AlternativePrediction {
                model: "catalogue: cg_offset".into(),
                j_pos_m: alt.0,
                j_att_deg: alt.1,
            }],
            note: String::new(),
        }
    }

    #[test]
    fn an_alternative_that_predicts_clearly_better_is_a_caveat() {
        let noise = Noise {
            pos_m: 0.001,
            att_deg: 0.1,
        };
        // Answer 0.012 m / 0.75 deg against the alternative's 0.008 m / 0.26 deg: caveat.
        let better = [event((0.012, 0.75), (0.008, 0.26))];
        let note = prediction_caveat(&better, noise).expect("a caveat");
        assert!(
            note.contains("catalogue alternative predicts better"),
            "{note}"
        );
        assert!(note.contains("0.0080 m"), "{note}");
        // Within 20 % of the answer's score: no caveat.
        let close = [event((0.010, 0.5), (0.0095, 0.48))];
        assert_eq!(prediction_caveat(&close, noise), None);
        // The answer predicts better: no caveat.
        let worse = [event((0.008, 0.26), (0.012, 0.75))];
        assert_eq!(prediction_caveat(&worse, noise), None);
    }
}
