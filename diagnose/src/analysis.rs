//! The diagnosis record from the decided answer (`docs/model.md` section 7 and 11): the causes
//! and their estimates, whether the catalogue's answer explains the data to the noise, the
//! alternatives, the discovered extension's report, the residuals before and after, the
//! verdict, the prediction of the `--validate` events, and the contents of the files that only
//! a discovered answer writes. Nothing here writes a file (`outputs` does).

use std::collections::BTreeMap;
use std::time::Instant;

use sepval_common::evaluation::Job;
use sepval_common::extension::{Term, TermRecord, extension_toml};
use sepval_core::factors::FACTOR_COUNT;
use sepval_run::model_spec::ModelSpec;

use crate::answer::{Answer, Rival, Setting};
use crate::contender::Contender;
use crate::found::{DiscoveredTerm, DiscoveryStep, Found, Gain};
use crate::increments::{Curves, model_increments};
use crate::reconstruct::Reconstruction;
use crate::residuals::{ResidualReport, physical_residuals, residual_report, rms_channels};
use crate::rivals::same_model;
use crate::validation::{prediction_caveat, validate};
use crate::verdict::{VerdictInput, ambiguity, verdict};
use crate::{
    Alternative, BASELINE_LIMIT_SIGMA, BIC_MARGIN, CandidateReport, DIAGNOSIS_FORMAT,
    DiagnoseError, DiagnoseOptions, Diagnosis, ExtensionReport, Fitted, ModelSummary, ParamValue,
    Result, RivalClass, RivalReport, SkippedRefit, ValidationReport, catalogue, readings, tables,
};
use sepval_fit::space::Noise;
use sepval_solve::identifiability::{Identifiability, identifiability};

/// Everything the stages before the analysis produced.
pub(super) struct Decided {
    /// The converged baseline.
    pub baseline: Fitted,
    /// The answer.
    pub answer: Answer,
    /// The explanations the data cannot tell from the answer, best first.
    pub rivals: Vec<(Contender, RivalReport)>,
    /// The rival classes of discovery's first step.
    pub rival_classes: Vec<RivalClass>,
    /// Every catalogue candidate tried, every round.
    pub candidates: Vec<CandidateReport>,
    /// Discovery's reconstruction of the baseline's misfit, per event.
    pub reconstruction: Vec<Reconstruction>,
    /// Discovery's notes.
    pub notes: Vec<String>,
    /// Discovery's steps.
    pub steps: Vec<DiscoveryStep>,
    /// Why discovery could not run, if it could not.
    pub blocked: Option<String>,
    /// Refits that did not simulate and were left out.
    pub skipped: Vec<SkippedRefit>,
    /// The tables the baseline's runs left.
    pub tables_left: Vec<String>,
    /// Why the first baseline was replaced, when the catalogue showed it in a local optimum.
    pub baseline_restart: Option<String>,
    /// What the releases did to what an earlier diagnosis left open (`--after`).
    pub after: Option<crate::AfterReport>,
    /// The verdict's sentence on it.
    pub after_sentence: Option<String>,
    /// Simulations run.
    pub evaluations: u64,
}

/// The diagnosis and what the outputs need beside it.
pub(super) struct Analysis {
    /// DIR/diagnosis.json.
    pub diagnosis: Diagnosis,
    /// The converged baseline.
    pub baseline: Fitted,
    /// The answer.
    pub answer: Answer,
    /// What the discovered terms give along their trajectory (empty without a discovered
    /// extension).
    pub curves: Curves,
    /// DIR/extension.toml and DIR/factors.json, when a discovered extension is the answer.
    pub extension: Option<ExtensionFiles>,
}

/// The files of a discovered answer.
pub(super) struct ExtensionFiles {
    /// DIR/extension.toml.
    pub toml: String,
    /// DIR/factors.json: the factors fitted with the terms (`--factors DIR/factors.json
    /// --extension DIR/extension.toml` reproduces the answer).
    pub factors_json: Vec<u8>,
}

/// Why the converged baseline counts as a failed fit (a goal beyond
/// [`BASELINE_LIMIT_SIGMA`] sigma), or `None` when it reached near the noise.
fn baseline_failure(baseline: &ModelSummary, noise: Noise) -> Option<String> {
    let (np, na) = (
        baseline.j_pos_m / noise.pos_m,
        baseline.j_att_deg / noise.att_deg,
    );
    (np > BASELINE_LIMIT_SIGMA || na > BASELINE_LIMIT_SIGMA).then(|| {
        format!(
            "the baseline fit did not reach near the noise (J_pos {:.4} m = {np:.0} sigma, J_att {:.3} deg = {na:.0} sigma; the limit is {BASELINE_LIMIT_SIGMA} sigma), so no test against it can name a cause",
            baseline.j_pos_m, baseline.j_att_deg
        )
    })
}

/// Whether `fitted` explains the data to the noise: both goals within the noise floor (1.1
/// sigma) and every channel's residuals white (`residuals`). With a converged baseline, this is
/// what `explained` says of the catalogue's answer.
pub(super) fn explains(setting: &Setting, fitted: &Fitted) -> Result<bool> {
    let report = residuals_of(setting, fitted)?;
    Ok(report.white && report.at_noise_floor)
}

/// The residual report of `fitted` against the setting's noise and noise floor.
fn residuals_of(setting: &Setting, fitted: &Fitted) -> Result<ResidualReport> {
    let job = &*setting.job;
    Ok(residual_report(
        job,
        &fitted.lm,
        &fitted.candidate(job)?,
        setting.noise,
        setting.floor,
    ))
}

/// Whether the converged `baseline` reached near the noise, so that the tests of its
/// extensions mean something (see [`baseline_failure`]).
pub(super) fn baseline_converged(setting: &Setting, baseline: &Fitted) -> bool {
    baseline_failure(&summary(setting, baseline), setting.noise).is_none()
}

/// The diagnosis of `d`; `t0` is when the diagnosis started.
pub(super) fn analyse(
    options: &DiagnoseOptions,
    setting: &Setting,
    d: Decided,
    t0: Instant,
) -> Result<Analysis> {
    let (job, noise) = (&*setting.job, setting.noise);
    let answer_fit = d.answer.model(&d.baseline);
    let base_summary = summary(setting, &d.baseline);
    let unreliable = baseline_failure(&base_summary, noise);
    // The catalogue's model: the baseline when it chose no effect.
    let cat_fit = d.answer.selected().map_or(&d.baseline, |s| &s.fitted);
    let explained = explains(setting, cat_fit)? && unreliable.is_none();
    let (causes, discovered) = d.answer.named();
    let (parameters, identifiability) = answer_estimates(setting, &d.answer, answer_fit);
    let rivals: Vec<RivalReport> = d.rivals.iter().map(|(_, r)| r.clone()).collect();
    let alternatives = if loser_is_rival(job, &d) {
        Vec::new()
    } else {
        alternatives(setting, &d.answer, answer_fit, explained)
    };
    let extension = (d.answer.found())
        .map(|f| extension_report(setting, &d.answer, f, unreliable.is_none()))
        .transpose()?;
    let model = ModelSpec::of(&answer_fit.candidate(job)?);
    let ext_summary = summary(setting, answer_fit);
    let mut verdict = verdict(&VerdictInput {
        causes: &causes,
        explained,
        parameters: &parameters,
        discovered: &discovered,
        extension: extension.as_ref().filter(|e| e.answer),
        alternatives: &alternatives,
        base: &base_summary,
        ext: &ext_summary,
        noise,
        blocked: d.blocked.as_deref(),
    });
    if let Some(a) = ambiguity(&rivals, job.events().len()) {
        verdict.push_str(&format!("; {a}"));
    }
    let open = crate::verdict::open_classes(&d.rival_classes);
    for s in open.iter().chain(&d.after_sentence) {
        verdict.push_str(&format!("; {s}"));
    }
    if let Some(why) = &unreliable {
        verdict = format!("unreliable: {why}; as found: {verdict}");
    }
    let validation = predictions(options, setting, &d.baseline, &d.answer)?;
    let caution = prediction_caveat(&validation, noise);
    if let Some(c) = &caution {
        verdict.push_str(&format!("; caution: {c}"));
    }
    let tables_left = with_answers_tables(job, d.tables_left, &d.answer)?;
    let diagnosis = Diagnosis {
        format: DIAGNOSIS_FORMAT.to_string(),
        causes,
        explained,
        verdict,
        baseline_verdict: crate::BaselineVerdict::of(unreliable),
        baseline_restart: d.baseline_restart,
        caution,
        discovered,
        ambiguous: !rivals.is_empty(),
        rivals,
        rival_classes: d.rival_classes,
        clearance: None,
        after: d.after,
        alternatives,
        extension,
        discovery_notes: d.notes,
        discovery_steps: d.steps,
        skipped: d.skipped,
        tables_left,
        sigma_pos_m: noise.pos_m,
        sigma_att_deg: noise.att_deg,
        sigma_source: options.fit.sigma.source.clone(),
        baseline: base_summary,
        extended: ext_summary,
        model,
        inputs: options.fit.inputs.clone(),
        parameters,
        identifiability: Some(identifiability),
        candidates: d.candidates,
        residuals: before_after(setting, &d.baseline, answer_fit)?,
        reconstruction: d.reconstruction,
        validation,
        evaluations: d.evaluations,
        wall_s: t0.elapsed().as_secs_f64(),
    };
    let (curves, extension) = for_outputs(job, &d.answer, &options.given_terms)?;
    Ok(Analysis {
        diagnosis,
        baseline: d.baseline,
        answer: d.answer,
        curves,
        extension,
    })
}

/// The baseline's tables left, then a catalogue answer's.
fn with_answers_tables(job: &Job, mut left: Vec<String>, answer: &Answer) -> Result<Vec<String>> {
    if let Answer::Catalogue { selected, .. } = answer {
        let answer = tables::tables_left(job, &selected.fitted.candidate(job)?);
        left.extend(answer.iter().map(|l| format!("answer, {l}")));
    }
    Ok(left)
}

/// Whether the model that lost the answer's decision is a rival: it is then listed once, as
/// a rival, not as an alternative.
fn loser_is_rival(job: &Job, d: &Decided) -> bool {
    d.answer.rival().is_some_and(|r| {
        d.rivals
            .iter()
            .any(|(c, _)| same_model(&c.fitted, r.fitted(), job))
    })
}

/// The residual analysis of the baseline and of the answer's model.
fn before_after(
    setting: &Setting,
    baseline: &Fitted,
    answer: &Fitted,
) -> Result<BTreeMap<String, ResidualReport>> {
    let job = &*setting.job;
    let report = |f: &Fitted| -> Result<ResidualReport> {
        Ok(residual_report(
            job,
            &f.lm,
            &f.candidate(job)?,
            setting.noise,
            setting.floor,
        ))
    };
    let mut residuals = BTreeMap::new();
    residuals.insert("baseline".to_string(), report(baseline)?);
    residuals.insert("extended".to_string(), report(answer)?);
    Ok(residuals)
}

/// What the outputs draw and write beside the diagnosis: the discovered terms' increments
/// (the answer or not) and, when they are the answer, their files.
fn for_outputs(
    job: &Job,
    answer: &Answer,
    given: &[Term],
) -> Result<(Curves, Option<ExtensionFiles>)> {
    let curves = match answer.found() {
        Some(f) => model_increments(job, &f.fitted)?,
        None => Vec::new(),
    };
    let files = match answer {
        Answer::Discovered { found, .. } => Some(extension_files(job, found, given)?),
        _ => None,
    };
    Ok((curves, files))
}

/// A fitted model's summary.
fn summary(setting: &Setting, fitted: &Fitted) -> ModelSummary {
    let job = &*setting.job;
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
        channel_rms: rms_channels(&physical_residuals(
            &fitted.lm.residuals,
            setting.noise,
            &setting.events,
        )),
        factors: fitted.candidate(job).ok().map(|c| c.factors),
    }
}

/// The chosen effects' parameters with standard errors (by effect id), and how sure every
/// parameter of the answer's model `answer_fit` is (the covariance `sepval predict` draws from).
fn answer_estimates(
    setting: &Setting,
    answer: &Answer,
    answer_fit: &Fitted,
) -> (BTreeMap<String, Vec<ParamValue>>, Identifiability) {
    let parameters = answer
        .selected()
        .map(|s| effect_parameters(setting, &s.fitted))
        .unwrap_or_default();
    let lm = &answer_fit.lm;
    let space = answer_fit.space(&setting.job);
    let id = identifiability(
        &space.params,
        &lm.x,
        &lm.residuals,
        &lm.jacobian,
        &setting.events,
    );
    (parameters, id)
}

/// Each chosen effect's parameters with standard errors, by effect id.
fn effect_parameters(setting: &Setting, fitted: &Fitted) -> BTreeMap<String, Vec<ParamValue>> {
    let space = fitted.space(&setting.job);
    let all = catalogue::param_values(&space, fitted, &setting.events, FACTOR_COUNT);
    let mut parameters = BTreeMap::new();
    let mut pos = 0;
    for a in fitted.effects.iter() {
        let n = a.effect().params().len();
        parameters.insert(a.effect().id().to_string(), all[pos..pos + n].to_vec());
        pos += n;
    }
    parameters
}

/// The model that lost to the answer, as an alternative; `explained`: whether the catalogue's
/// model explains the data to the noise.
fn alternatives(
    setting: &Setting,
    answer: &Answer,
    answer_fit: &Fitted,
    explained: bool,
) -> Vec<Alternative> {
    let answer_bic = setting.bic(answer_fit);
    let Some(rival) = answer.rival() else {
        return Vec::new();
    };
    let d_bic = setting.bic(rival.fitted()) - answer_bic;
    let (kind, names, note) = match rival {
        Rival::Catalogue(s) => (
            "catalogue",
            s.names(),
            format!(
                "significant on its own, but the discovered terms explain the data better by {d_bic:.1} in BIC (more than {BIC_MARGIN}): a mimic, not the cause{}",
                if explained {
                    " (it even reaches the noise floor: the data alone cannot rule it out)"
                } else {
                    ""
                }
            ),
        ),
        Rival::Discovered(f) => (
            "discovered",
            f.terms
                .iter()
                .map(|t| format!("{}: {}", t.axis, t.term))
                .collect(),
            format!(
                "significant against the baseline, but it does not beat the catalogue's answer by more than {BIC_MARGIN} in BIC (difference {d_bic:+.1}): the catalogue effect stays the cause"
            ),
        ),
    };
    vec![Alternative {
        kind: kind.into(),
        names,
        model: summary(setting, rival.fitted()),
        delta_bic_vs_answer: d_bic,
        note,
    }]
}

/// The report of the discovered extension `f`, the answer or not; `converged`: whether the
/// baseline it is measured against reached near the noise (else it explains nothing).
fn extension_report(
    setting: &Setting,
    answer: &Answer,
    f: &Found,
    converged: bool,
) -> Result<ExtensionReport> {
    let fitted = &f.fitted;
    let report = residuals_of(setting, fitted)?;
    let is_answer = matches!(answer, Answer::Discovered { .. });
    Ok(ExtensionReport {
        answer: is_answer,
        file: is_answer.then(|| "extension.toml".to_string()),
        model: summary(setting, fitted),
        gain: f.gain.clone(),
        white: report.white,
        at_noise_floor: report.at_noise_floor,
        explained: report.white && report.at_noise_floor && converged,
        refinement: format!(
            "{} after {} iterations",
            fitted.lm.stop, fitted.lm.iterations
        ),
    })
}

/// The baseline's, the answer's and its rival's goals on the `--validate` events.
fn predictions(
    options: &DiagnoseOptions,
    setting: &Setting,
    baseline: &Fitted,
    answer: &Answer,
) -> Result<Vec<ValidationReport>> {
    let Some(v) = &options.validation else {
        return Ok(Vec::new());
    };
    let job = &*setting.job;
    let rivals = match answer.rival() {
        Some(r) => vec![r.prediction(job)?],
        None => Vec::new(),
    };
    Ok(validate(
        v,
        &baseline.candidate(job)?,
        &answer.model(baseline).candidate(job)?,
        &rivals,
    ))
}

/// The files of the discovered answer `found`, the terms `given` with `--extension` included.
fn extension_files(job: &Job, found: &Found, given: &[Term]) -> Result<ExtensionFiles> {
    let toml = extension_file(job, &found.fitted, &found.terms, &found.gain, given)?;
    let factors_json = serde_json::to_vec_pretty(&found.fitted.candidate(job)?.factors)
        .expect("factors serialise");
    Ok(ExtensionFiles { toml, factors_json })
}

/// DIR/extension.toml: every term of the answer's model beyond the scenario file's, that is
/// the terms `given` with `--extension` (fixed in every fit, as given) and the discovered terms
/// at their refitted values, with a header that says where they came from; `sepval simulate
/// --factors DIR/factors.json --extension DIR/extension.toml` (with the diagnosis's scenario)
/// reproduces the answer.
fn extension_file(
    job: &Job,
    f: &Fitted,
    found: &[DiscoveredTerm],
    gain: &Gain,
    given: &[Term],
) -> Result<String> {
    let terms = f.space(job).terms_at(&f.lm.x)?;
    let records: Vec<TermRecord> = given
        .iter()
        .map(TermRecord::of)
        .chain(terms.iter().map(|t| {
            let mut r = TermRecord::of(t);
            r.reading = Some(readings::reading(
                t,
                &job.events()[0].simulator.scenario().interference,
            ));
            r
        }))
        .collect();
    let mut text = format!(
        "# Found by `sepval diagnose` beyond the effect catalogue, from: {}\n",
        job.events()
            .iter()
            .map(|e| e.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    for t in given {
        text.push_str(&format!(
            "# {} {}: given with --extension, fixed\n",
            t.axis.name(),
            t.formula()
        ));
    }
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
    sepval_common::extension::parse_extension(&text, "extension.toml")
        .map_err(DiagnoseError::ExtensionReadBack)?;
    Ok(text)
}
