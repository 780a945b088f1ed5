//! `sepval campaign add`: releases flown, recorded (docs/campaign.md, "Adding releases"). Each
//! is first checked against what the campaign predicted at its condition (the post-flight
//! check of `sepval predict --data`, [`sepval_predict::check`]); then every release flown is
//! diagnosed again (`sepval diagnose`: the baseline fit, the effect catalogue, discovery beyond
//! it; its answer and rivals), and the envelope is predicted again from that diagnosis (round
//! N). A
//! release already in the campaign (the same bytes, or half or more of the same samples:
//! [`crate::release::overlap`]) is refused with nothing changed.

use std::path::Path;
use std::sync::Arc;

use sepval_common::evaluation::Job;
use sepval_common::scenario::Scenario;
use sepval_common::telemetry::Trajectory;
use sepval_diagnose::DiagnoseOptions;
use sepval_fit::FitOptions;
use sepval_fit::sigma::Sigma;
use sepval_predict::bands::{BandInputs, bands};
use sepval_predict::check::{Check, check};
use sepval_predict::record::ConditionRecord;
use sepval_predict::simulate::{self, GridTrajectory, data_on_grid};
use sepval_run::inputs::InputsRecord;
use sepval_solve::ga::GaSettings;
use sepval_solve::lm::LmSettings;
use sepval_solve::run::ProgressObserver;

use crate::assess::{AssessSettings, FormBand, Model, StartEvaluator};
use crate::journal;
use crate::program::{Campaign, STAGING, fitted_model};
use crate::record::{CAMPAIGN_FORMAT, ReleaseRecord, record_error};
use crate::release::{NewRelease, overlap};
use crate::seal::read_sealed;
use crate::{CampaignError, Refusal};

/// The noise of a prediction's bands before any release was fitted: the synthetic flight
/// tests' (docs/model.md section 6).
fn prior_noise() -> sepval_fit::space::Noise {
    sepval_fit::space::Noise {
        pos_m: sepval_common::noise::SIGMA_POS_M,
        att_deg: sepval_common::noise::SIGMA_ATT_DEG,
    }
}

/// Adds `releases` to the campaign (module docs); returns each one's check. On an error (a
/// signal's included) the campaign is left as it was: campaign.json untouched, and what was
/// written for the releases removed.
pub fn add(
    c: &mut Campaign,
    releases: Vec<NewRelease>,
    start: &mut StartEvaluator<'_>,
    observer: &mut dyn ProgressObserver,
) -> Result<Vec<Check>, CampaignError> {
    let done = add_all(c, releases, start, observer);
    if done.is_err() {
        // campaign.json on disk says what was committed (an error after the commit, in the
        // derived files, keeps the round); what it does not name is removed, best effort: the
        // next command that opens the campaign removes what is left.
        let path = c.dir.join("campaign.json");
        if let Ok(on_disk) = read_sealed(&path, CAMPAIGN_FORMAT) {
            c.file = on_disk;
            let _ = c.tidy();
        }
    }
    done
}

fn add_all(
    c: &mut Campaign,
    releases: Vec<NewRelease>,
    start: &mut StartEvaluator<'_>,
    observer: &mut dyn ProgressObserver,
) -> Result<Vec<Check>, CampaignError> {
    let flown = c.job()?;
    refuse_known(c, flown.as_ref(), &releases)?;
    // Where the copies and the round will go, refused before any work if taken.
    for i in 0..releases.len() {
        journal::claim(&c.dir, &copy_name(c.file.releases.len() + i + 1))?;
    }
    journal::claim(&c.dir, &format!("rounds/{:02}", c.file.rounds.len()))?;
    let model = c.model_of(flown)?;
    let settings = c.assess_settings();
    // One band for every release checked: its held-out evidence (a refit per release flown)
    // is computed once.
    let mut form = FormBand::of(&model);
    let mut checks = Vec::new();
    for r in &releases {
        let name = r.given.display().to_string();
        let flown = (&r.scenario, &r.data, name.as_str());
        checks.push(check_release(&model, &mut form, flown, &settings, start)?);
    }
    let round = c.file.rounds.len();
    std::fs::create_dir_all(c.dir.join("releases")).map_err(|e| record_error(&c.dir, e))?;
    for (r, k) in releases.iter().zip(&checks) {
        let file = copy_name(c.file.releases.len() + 1);
        let path = c.dir.join(&file);
        journal::record(&c.dir, &file)?;
        r.data.write(&path).map_err(|e| record_error(&path, e))?;
        let copy = std::fs::read(&path).map_err(|e| record_error(&path, e))?;
        c.file.releases.push(ReleaseRecord {
            file,
            given: r.given.display().to_string(),
            sha256: r.sha256.clone(),
            copy_sha256: sepval_common::scenario::hex_sha256(&copy),
            condition: ConditionRecord::of(&r.scenario.flight),
            round,
            inside: k.inside,
            check: k.verdict.clone(),
            notes: r.notes.clone(),
        });
    }
    let job = c.job()?.expect("releases were added");
    let dir = c.dir.join(STAGING).join("diagnosis");
    diagnose(c, &job, &dir, start, observer)?;
    let model = fitted_model(&dir, job)?;
    c.round(&model, start, observer)?;
    Ok(checks)
}

/// The campaign's copy of its `n`-th release (from 1).
fn copy_name(n: usize) -> String {
    format!("releases/{n:02}.csv")
}

/// Refuses a release the campaign holds (`known`: its releases flown), or one given twice: the
/// same bytes, or half or more of the same samples ([`overlap`]: a copy, thinned or not).
fn refuse_known(
    c: &Campaign,
    known: Option<&Job>,
    releases: &[NewRelease],
) -> Result<(), CampaignError> {
    let same_flight = |name: &str, other: String, flown: bool, shared: usize, d: &Trajectory| {
        CampaignError::from(Refusal::SameFlight {
            name: name.to_string(),
            other,
            flown,
            shared,
            samples: d.len(),
        })
    };
    for (i, r) in releases.iter().enumerate() {
        let name = r.given.display().to_string();
        if let Some(k) = c.file.releases.iter().find(|k| k.sha256 == r.sha256) {
            return Err(Refusal::AlreadyIn {
                name,
                file: k.file.clone(),
                given: k.given.clone(),
            }
            .into());
        }
        let flown = known.map_or(&[][..], |j| j.events());
        for (k, e) in flown.iter().enumerate() {
            if let Some(shared) = overlap(&e.data, &r.data) {
                let other = c.file.releases[k].file.clone();
                return Err(same_flight(&name, other, true, shared, &r.data));
            }
        }
        for o in &releases[..i] {
            if o.sha256 == r.sha256 {
                return Err(Refusal::GivenTwice {
                    name,
                    other: o.given.display().to_string(),
                }
                .into());
            }
            if let Some(shared) = overlap(&o.data, &r.data) {
                let other = o.given.display().to_string();
                return Err(same_flight(&name, other, false, shared, &r.data));
            }
        }
    }
    Ok(())
}

/// The diagnosis of every release flown into `out` (DIR/diagnosis.json, its baseline fit in
/// DIR/baseline): the study's GA for the campaign's generations then Levenberg-Marquardt, the
/// effect catalogue and discovery beyond it, as `sepval diagnose` runs them.
fn diagnose(
    c: &Campaign,
    job: &Job,
    out: &Path,
    start: &mut StartEvaluator<'_>,
    observer: &mut dyn ProgressObserver,
) -> Result<(), CampaignError> {
    let s = &c.file.settings;
    let sigma =
        Sigma::resolve(job, None, None).map_err(|reason| Refusal::ReleasesNoise { reason })?;
    let inputs = InputsRecord {
        data: c
            .file
            .releases
            .iter()
            .map(|r| c.dir.join(&r.file))
            .collect(),
        scenario: s.scenario.as_ref().map(|r| r.path.clone().into()),
        extension: None,
        outliers: Default::default(),
    };
    let ga = GaSettings {
        generations: s.generations,
        seed: s.seed,
        ..GaSettings::default()
    };
    let lm = LmSettings::default();
    let options = DiagnoseOptions {
        fit: FitOptions::baseline(ga, sigma, &lm, &out.join("baseline"), inputs),
        out: out.to_path_buf(),
        candidate_lm: LmSettings {
            max_iterations: 400,
            budget: 10_000,
            ..lm
        },
        validation: None,
        given_terms: Vec::new(),
        strict_tables: false,
        clearance: None,
        after: previous_diagnosis(c),
        plan: None,
    };
    let mut evaluator = start(Arc::new(job.clone())).map_err(CampaignError::from_eval)?;
    sepval_diagnose::diagnose(&options, evaluator.as_mut(), observer).map_err(|e| {
        if sepval_core::cancel::requested() {
            CampaignError::Interrupted
        } else {
            CampaignError::Diagnose(Box::new(e))
        }
    })?;
    Ok(())
}

/// The diagnosis of the previous round, when it diagnosed releases: what it left open is
/// refitted on every release flown and competes for the answer (`sepval diagnose --after`).
/// The campaign's next release comes from its own planner (`next.json`), not from `sepval
/// plan`, so no plan is set against the diagnosis here.
fn previous_diagnosis(c: &Campaign) -> Option<std::path::PathBuf> {
    let last = c.file.rounds.last().filter(|r| r.releases_flown > 0)?;
    let dir = c.dir.join(&last.dir).join("diagnosis");
    dir.join("diagnosis.json").is_file().then_some(dir)
}

/// The post-flight check of release `name` (its `data`, flown at `scenario`) against the
/// bands `model` predicts there at the 95 % level, with the measurement noise: the same
/// model-form band as the round's envelope (`form`: the discrepancy at the releases, the reach
/// beyond them).
pub(crate) fn check_release(
    model: &Model,
    form: &mut FormBand<'_>,
    (scenario, data, name): (&Scenario, &Trajectory, &str),
    settings: &AssessSettings,
    start: &mut StartEvaluator<'_>,
) -> Result<Check, CampaignError> {
    let points = simulate::Grid::of(&data.times_s);
    let (candidates, _) = crate::assess::draws(model, settings)?;
    let (job, runs) = crate::assess::fly(scenario, &data.times_s, &points, &candidates, start)?;
    let ran: Vec<&GridTrajectory> = runs.trajectories.iter().flatten().collect();
    let (sd, _) = form.at(&job, &points, &ran, settings)?;
    let noise = model
        .fitted
        .as_ref()
        .map_or_else(prior_noise, |f| f.source.noise);
    let per_sample = runs.trajectories.into_iter().map(|t| (0, t.ok())).collect();
    let b = bands(
        &BandInputs {
            weights: &[1.0],
            discrepancy: &sd,
            noise: Some(noise),
            level: 0.95,
            seed: settings.seed,
            points: points.len(),
        },
        per_sample,
    );
    let flown = data_on_grid(data, &points);
    Ok(check(name, &flown, &points.t_s, &b.channels))
}
