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
use sepval_common::factors::FACTOR_COUNT;

use sepval_fit::space::{FreeTerm, Noise, ParamSpace};
use sepval_fit::{FitError, FitOptions, Method, run_fit};
use sepval_report::figures::FigureError;
use sepval_solve::lm::{LmResult, LmSettings};
use sepval_solve::run::{ProgressObserver, RunError};

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
mod diagnosis;
mod discover;
mod found;
mod library;
mod probe;
pub mod readings;
mod reconstruct;
mod report;
mod residuals;
mod stepwise;
mod validation;
mod verify;

pub use diagnosis::{
    Alternative, CandidateReport, Diagnosis, ExtensionReport, ModelSummary, ParamValue,
};
pub use found::{DiscoveredTerm, DiscoveryStep, Gain, GroupMember, Screened, Verified};
pub use reconstruct::{IncrementSeries, Reconstruction};
pub use report::fmt_discovered;
pub use residuals::{
    CHANNELS, ChannelReport, LAGS, ResidualReport, SegmentRms, WHITENESS_P, physical_residuals,
    residual_report,
};
use residuals::{residual_figures, rms_channels};
pub use validation::{AlternativePrediction, ValidationReport};
use validation::{prediction_caveat, validate};

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
    let cat_report = residual_report(
        &job,
        &cat.fitted.lm,
        &cat.fitted.candidate(&job)?,
        noise,
        floor,
    );
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
        let report = residual_report(&job, &f.lm, &f.candidate(&job)?, noise, floor);
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
    let final_report = residual_report(
        &job,
        &answer_fit.lm,
        &answer_fit.candidate(&job)?,
        noise,
        floor,
    );
    let base_report = residual_report(&job, &baseline.lm, &baseline.candidate(&job)?, noise, floor);
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
    let caution = prediction_caveat(&validation, noise);
    if let Some(c) = &caution {
        verdict.push_str(&format!("; caution: {c}"));
    }

    let mut residuals = BTreeMap::new();
    residuals.insert("baseline".to_string(), base_report);
    residuals.insert("extended".to_string(), final_report);
    let diagnosis = Diagnosis {
        format: DIAGNOSIS_FORMAT.to_string(),
        causes,
        explained,
        verdict,
        caution,
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
        Some((f, _, _)) => verify::model_increments(&job, f)?,
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
