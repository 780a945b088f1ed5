//! `sepval diagnose`: what the simulation still gets wrong after a fit, why, and what the best
//! extension of the model gains.
//!
//! 1. The baseline model is fitted by the fit pipeline (genetic search, then refinement to
//!    the optimum) and its residuals are analysed per channel and over time: RMS against the
//!    noise, where in time the misfit sits (ejector stroke, interference zone, free flight),
//!    and whiteness (autocorrelation against its 95 % band, Ljung-Box portmanteau test).
//! 2. Every effect of the catalogue (MODEL.md section 7) extends the model in turn and is
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
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result};
use sepval_common::atomic_file::write_atomically;
use sepval_common::effects::{CATALOGUE, EffectSet, MAX_ACTIVE_EFFECTS};
use sepval_common::evaluation::{Evaluator, Job};
use sepval_common::factors::FACTOR_COUNT;
use serde::{Deserialize, Serialize};

use crate::fit::{FitOptions, Method, run_fit};
use crate::identifiability::identifiability;
use crate::refine::{LmResult, LmRun, LmSettings, Noise, ParamSpace, refine_together};
use crate::results::ChannelRms;
use crate::stats::{autocorrelation, f_test, ljung_box};

mod report;

/// Format tag of diagnosis files.
pub const DIAGNOSIS_FORMAT: &str = "sepval-diagnosis/1";
/// Family-wise significance level of the candidate tests.
pub const ALPHA: f64 = 0.01;
/// Per-channel Ljung-Box p-value below which residuals are not white.
pub const WHITENESS_P: f64 = 0.001;
/// Lags of the whiteness tests.
pub const LAGS: usize = 20;
/// Channel names and units.
pub const CHANNELS: [(&str, &str); 6] = [
    ("x", "m"),
    ("y", "m"),
    ("z", "m"),
    ("roll", "deg"),
    ("pitch", "deg"),
    ("yaw", "deg"),
];

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

/// Residual time segment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SegmentRms {
    /// Segment name.
    pub name: String,
    /// Start \[s\] (first event).
    pub t_start_s: f64,
    /// End \[s\] (first event).
    pub t_end_s: f64,
    /// RMS residual in the segment, pooled over events (channel unit).
    pub rms: f64,
}

/// Residual analysis of one channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelReport {
    /// Channel.
    pub channel: String,
    /// Unit.
    pub unit: String,
    /// RMS residual.
    pub rms: f64,
    /// Noise sigma.
    pub sigma: f64,
    /// RMS / sigma.
    pub rms_over_sigma: f64,
    /// RMS per time segment.
    pub segments: Vec<SegmentRms>,
    /// Fraction of autocorrelations at lags 1..20 outside the 95 % band +-1.96/sqrt(N).
    pub autocorr_outside_band: f64,
    /// Ljung-Box statistic (summed over events).
    pub ljung_box_q: f64,
    /// Its p-value.
    pub ljung_box_p: f64,
    /// Whether the residuals are white (p >= 0.001).
    pub white: bool,
}

/// Residual analysis of one model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResidualReport {
    /// Per channel.
    pub channels: Vec<ChannelReport>,
    /// Whether every channel is white.
    pub white: bool,
    /// Whether both goals are within 1.1 sigma.
    pub at_noise_floor: bool,
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

/// Residuals in physical units per event, per sample: (x, y, z \[m\], roll, pitch, yaw \[deg\]).
fn physical_residuals(r: &[f64], noise: Noise, events: &[usize]) -> Vec<Vec<[f64; 6]>> {
    let mut out = Vec::new();
    let mut pos = 0;
    for &n in events {
        out.push(
            (0..n)
                .map(|i| {
                    let s = &r[pos + 6 * i..pos + 6 * i + 6];
                    [
                        s[0] * noise.pos_m,
                        s[1] * noise.pos_m,
                        s[2] * noise.pos_m,
                        s[3] * noise.att_deg,
                        s[4] * noise.att_deg,
                        s[5] * noise.att_deg,
                    ]
                })
                .collect(),
        );
        pos += 6 * n;
    }
    out
}

fn rms_channels(res: &[Vec<[f64; 6]>]) -> ChannelRms {
    crate::results::channel_rms(res)
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

/// Time segments of the first event: ejector stroke, interference zone (until the decay factor
/// falls below 0.1), free flight.
fn segments(job: &Job, lm: &LmResult) -> Vec<(String, f64, f64)> {
    let e = &job.events()[0];
    let times = &e.data.times_s;
    let t_end = *times.last().unwrap_or(&0.0);
    let scenario = e.simulator.scenario();
    let decay = sepval_common::model::InterferenceDecay::new(
        scenario.interference.lambda_m,
        scenario.interference.s_end_m,
    );
    // Stroke end: the later foot of the baseline fit's own run.
    let factors = sepval_common::factors::Factors(std::array::from_fn(|i| lm.x[i]));
    let stroke = e
        .simulator
        .simulate_logged(&factors, &EffectSet::NONE, &[times[0].max(0.0)])
        .ok()
        .and_then(|(_, log)| {
            log.foot_off_s
                .iter()
                .flatten()
                .cloned()
                .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.max(t))))
        })
        .unwrap_or(0.06);
    let zone_end = lm.samples[0]
        .iter()
        .zip(times)
        .find(|(o, t)| {
            **t > stroke
                && decay
                    .factor((o.pos_m[0].powi(2) + o.pos_m[1].powi(2) + o.pos_m[2].powi(2)).sqrt())
                    < 0.1
        })
        .map_or(t_end, |(_, t)| *t);
    vec![
        ("ejector stroke".into(), times[0], stroke.min(t_end)),
        ("interference zone".into(), stroke.min(t_end), zone_end),
        ("free flight".into(), zone_end, t_end),
    ]
}

fn residual_report(job: &Job, lm: &LmResult, noise: Noise, floor: [f64; 2]) -> ResidualReport {
    let events: Vec<usize> = job.events().iter().map(|e| e.data.len()).collect();
    let res = physical_residuals(&lm.residuals, noise, &events);
    let segs = segments(job, lm);
    let mut channels = Vec::new();
    for (c, (name, unit)) in CHANNELS.iter().enumerate() {
        let sigma = if c < 3 { noise.pos_m } else { noise.att_deg };
        let all: Vec<f64> = res.iter().flatten().map(|s| s[c]).collect();
        let rms = (all.iter().map(|v| v * v).sum::<f64>() / all.len().max(1) as f64).sqrt();
        let segments = segs
            .iter()
            .map(|(n, t0, t1)| {
                let mut acc = (0.0, 0usize);
                for (ev, r) in job.events().iter().zip(&res) {
                    for (t, s) in ev.data.times_s.iter().zip(r) {
                        if *t >= *t0
                            && (*t < *t1 || (*t1 >= *ev.data.times_s.last().unwrap() && *t <= *t1))
                        {
                            acc.0 += s[c] * s[c];
                            acc.1 += 1;
                        }
                    }
                }
                SegmentRms {
                    name: n.clone(),
                    t_start_s: *t0,
                    t_end_s: *t1,
                    rms: if acc.1 > 0 {
                        (acc.0 / acc.1 as f64).sqrt()
                    } else {
                        0.0
                    },
                }
            })
            .collect();
        let (mut q, mut dof, mut outside, mut lags) = (0.0, 0usize, 0usize, 0usize);
        for r in &res {
            let x: Vec<f64> = r.iter().map(|s| s[c]).collect();
            let h = LAGS.min(x.len().saturating_sub(2)).max(1);
            let (qk, _) = ljung_box(&x, h);
            q += qk;
            dof += h;
            let band = 1.96 / (x.len() as f64).sqrt();
            let rho = autocorrelation(&x, h);
            outside += rho.iter().filter(|r| r.abs() > band).count();
            lags += h;
        }
        let p = crate::stats::chi2_sf(q, dof as f64);
        channels.push(ChannelReport {
            channel: name.to_string(),
            unit: unit.to_string(),
            rms,
            sigma,
            rms_over_sigma: rms / sigma,
            segments,
            autocorr_outside_band: outside as f64 / lags.max(1) as f64,
            ljung_box_q: q,
            ljung_box_p: p,
            white: p >= WHITENESS_P,
        });
    }
    let white = channels.iter().all(|c| c.white);
    ResidualReport {
        channels,
        white,
        at_noise_floor: lm.goals.j_pos_m <= floor[0] && lm.goals.j_att_deg <= floor[1],
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
        set.push(index, &neutral)?;
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
pub fn diagnose(options: &DiagnoseOptions, evaluator: &mut dyn Evaluator) -> Result<Diagnosis> {
    let t0 = Instant::now();
    std::fs::create_dir_all(options.out.join("figures"))
        .with_context(|| format!("cannot create {}", options.out.display()))?;
    let noise = noise_of(&options.fit);
    let floor = [1.1 * noise.pos_m, 1.1 * noise.att_deg];
    let job = Arc::new(evaluator.job().clone());
    let events: Vec<usize> = job.events().iter().map(|e| e.data.len()).collect();
    let m = 6 * job.sample_count();

    // 1. The baseline fit.
    let fit = FitOptions {
        method: Method::GaLm,
        out: options.out.join("baseline"),
        resume: None,
        ..options.fit.clone()
    };
    let baseline_out = run_fit(&fit, evaluator).context("the baseline fit failed")?;
    let baseline_lm = baseline_out
        .refined
        .context("the baseline fit produced no refined optimum")?;
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
    let json = serde_json::to_vec_pretty(&diagnosis).context("serialising the diagnosis")?;
    write_atomically(&options.out.join("diagnosis.json"), &json)?;
    write_atomically(
        &options.out.join("report.html"),
        report::report_html(&diagnosis, &figures).as_bytes(),
    )?;
    Ok(diagnosis)
}

fn fmt_value(v: &ParamValue) -> String {
    match v.std_error {
        Some(se) => format!(
            "{} = {:.4} ± {:.2} {}",
            v.name,
            v.value,
            se,
            per_unit(&v.unit)
        ),
        None => format!(
            "{} = {:.4} {} (undetermined)",
            v.name,
            v.value,
            per_unit(&v.unit)
        ),
    }
}

fn per_unit(unit: &str) -> String {
    match unit.strip_prefix("1/") {
        Some(u) => format!("per {u}"),
        None => unit.to_string(),
    }
}

fn verdict(
    causes: &[String],
    explained: bool,
    parameters: &BTreeMap<String, Vec<ParamValue>>,
    base: &ModelSummary,
    ext: &ModelSummary,
    noise: Noise,
) -> String {
    let rms = |s: &ModelSummary| (s.j_pos_m, s.j_att_deg);
    let (bp, ba) = rms(base);
    let (ep, ea) = rms(ext);
    if causes.is_empty() {
        return if explained {
            format!(
                "the baseline model explains the data to the noise level (position RMS {bp:.4} m, sigma {:.4} m; attitude RMS {ba:.3} deg, sigma {:.3} deg)",
                noise.pos_m, noise.att_deg
            )
        } else {
            format!(
                "not explained: the residuals keep structure beyond the noise (position RMS {bp:.4} m, attitude RMS {ba:.3} deg) and no effect of the catalogue accounts for it: the cause lies outside the catalogue"
            )
        };
    }
    let named: Vec<String> = causes
        .iter()
        .map(|id| {
            let adds = CATALOGUE
                .iter()
                .find(|e| e.id() == id)
                .map_or(id.as_str(), |e| e.adds());
            let values = parameters
                .get(id)
                .map(|v| v.iter().map(fmt_value).collect::<Vec<_>>().join(", "))
                .unwrap_or_default();
            format!(
                "missing {} ({id}), {values}",
                adds.split(':').next().unwrap_or(adds)
            )
        })
        .collect();
    let gains =
        format!("position RMS {bp:.4} m -> {ep:.4} m, attitude RMS {ba:.3} deg -> {ea:.3} deg");
    if explained {
        format!("{}; {gains}", named.join("; and "))
    } else {
        format!(
            "not explained: the closest extension of the catalogue, {}, improves the fit ({gains}) but leaves structure beyond the noise: part of the cause lies outside the catalogue",
            named.join(" with ")
        )
    }
}

fn residual_figures(
    dir: &Path,
    job: &Job,
    base: &LmResult,
    ext: &LmResult,
    noise: Noise,
    events: &[usize],
) -> Result<Vec<String>> {
    let b = physical_residuals(&base.residuals, noise, events);
    let e = physical_residuals(&ext.residuals, noise, events);
    let mut names = Vec::new();
    for (k, event) in job.events().iter().enumerate() {
        let name = format!("figures/residuals_event{}.png", k + 1);
        crate::figures::residual_figure(
            &dir.join(&name),
            &event.data.times_s,
            &[("baseline", &b[k]), ("extended", &e[k])],
            (noise.pos_m, noise.att_deg),
            &format!("Residuals (simulated - measured), {}", event.name),
        )?;
        names.push(name);
    }
    Ok(names)
}
