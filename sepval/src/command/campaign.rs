//! `sepval campaign`: a test program as one record (docs/campaign.md). Each subcommand parses
//! its flags, loads the inputs, runs `sepval-campaign` and prints what it found.

use std::path::Path;

use anyhow::{Context, Result, bail};
use sepval_campaign::page;
use sepval_campaign::prior::Prior;
use sepval_campaign::program::{Campaign, Init, NewRelease, input_record};
use sepval_campaign::record::SettingsRecord;
use sepval_fit::inputs;

use super::starter;
use super::{clearance, count, evaluator_spec, tell};
use crate::cli::{
    CampaignAddArgs, CampaignCommand, CampaignInitArgs, CampaignNextArgs, CampaignRehearseArgs,
    CampaignStatusArgs,
};

/// Runs `sepval campaign SUBCOMMAND`.
pub fn run(c: CampaignCommand) -> Result<()> {
    match c {
        CampaignCommand::Init(a) => init(*a),
        CampaignCommand::Next(a) => next(a),
        CampaignCommand::Add(a) => add(a),
        CampaignCommand::Status(a) => status(a),
        CampaignCommand::Rehearse(a) => rehearse(*a),
    }
}

/// A probability flag in (0, 0.5).
fn probability(flag: &str, p: f64) -> Result<f64> {
    if !(p > 0.0 && p < 0.5) {
        bail!("{flag} {p}: expected a probability above 0 and below 0.5");
    }
    Ok(p)
}

fn init(a: CampaignInitArgs) -> Result<()> {
    let spec = evaluator_spec(&a.eval)?;
    let mut start = starter(&spec);
    let c = begin(&a, &mut start)?;
    say!("campaign:  {}", page::headline(&c.file));
    say!("report:    {}", a.out.join("report.html").display());
    Ok(())
}

/// Checks the init flags and begins the campaign in --out.
fn begin(
    a: &CampaignInitArgs,
    start: &mut sepval_campaign::StartEvaluator<'_>,
) -> Result<Campaign> {
    let threads = count("--threads", a.eval.threads)?;
    let allowed = probability("--allowed", a.allowed)?;
    let fly_risk = probability("--fly-risk", a.fly_risk)?;
    if a.samples < 20 {
        bail!("--samples {}: at least 20 samples per condition", a.samples);
    }
    let Some(aircraft) = a.geometry.aircraft.clone() else {
        bail!(
            "--aircraft FILE is required: the aircraft's geometry (e.g. examples/geometry/aircraft.toml)"
        );
    };
    let scenario = inputs::scenario(a.scenario.as_deref(), None)?;
    let axes: Vec<(String, String)> = a
        .grid
        .given()
        .into_iter()
        .map(|(q, a)| (q.flag().to_string(), a.text.clone()))
        .collect();
    if axes.is_empty() {
        bail!(
            "give at least one axis: --mach, --altitude-m, --alpha-deg, --beta-deg or --gamma-deg, each LO:HI:N"
        );
    }
    let prior = match &a.prior {
        Some(p) => Prior::read(p, &scenario.factors)?,
        None => Prior::default_of(&scenario.factors),
    };
    let Some(clearance) = clearance::settings(&a.geometry, &scenario)? else {
        bail!("--aircraft FILE is required");
    };
    let settings = SettingsRecord {
        scenario: a.scenario.as_deref().map(input_record).transpose()?,
        aircraft: input_record(&aircraft)?,
        store_shape: a
            .geometry
            .store_shape
            .as_deref()
            .map(input_record)
            .transpose()?,
        axes,
        clearance_mm: a.geometry.clearance_mm,
        allowed,
        fly_risk,
        samples: a.samples,
        seed: a.seed,
        generations: a.generations,
        prior,
    };
    let init = Init {
        settings,
        scenario,
        clearance,
        threads,
    };
    let c = sepval_campaign::program::init(&a.out, init, start, &mut *crate::front::progress())?;
    Ok(c)
}

fn rehearse(a: CampaignRehearseArgs) -> Result<()> {
    let spec = evaluator_spec(&a.init.eval)?;
    let scenario = inputs::scenario(a.truth_scenario.as_deref(), a.truth_extension.as_deref())
        .context("--truth-scenario")?;
    let factors =
        inputs::factors(&a.truth_factors, &scenario.factors).context("--truth-factors")?;
    let effects = inputs::effects(&a.truth_effect)?;
    let truth = sepval_campaign::rehearse::Truth {
        scenario,
        factors,
        effects,
        noise_seed: a.noise_seed,
    };
    let mut start = starter(&spec);
    let mut c = begin(&a.init, &mut start)?;
    say!("round 0:   {}", page::headline(&c.file));
    let r = sepval_campaign::rehearse::rehearse(
        &mut c,
        &truth,
        a.releases,
        &mut start,
        &mut *crate::front::progress(),
    )?;
    for (k, f) in r.flown.iter().enumerate() {
        say!(
            "release {}: Mach {}, altitude {} m, alpha {} deg (P(fail) planned {:.3}; truly {})",
            k + 1,
            page::number(f.condition.mach),
            page::number(f.condition.altitude_m),
            page::number(f.condition.alpha_deg),
            f.p_fail_planned,
            if f.truly_safe { "safe" } else { "UNSAFE" }
        );
    }
    for round in &r.rounds {
        say!(
            "round {}:   cleared {}, fails {}, undecided {}; false clears {}, false fails {}",
            round.round,
            round.counts.cleared,
            round.counts.fails,
            round.counts.undecided,
            round.false_clears,
            round.false_fails
        );
    }
    say!("rehearsal: {}", r.words);
    say!("report:    {}", a.init.out.join("report.html").display());
    Ok(())
}

fn open(dir: &Path, threads: usize) -> Result<Campaign> {
    Campaign::open(dir, threads).with_context(|| format!("campaign {}", dir.display()))
}

fn next(a: CampaignNextArgs) -> Result<()> {
    if a.count == 0 {
        bail!("--count 0: plan at least one release");
    }
    let c = open(&a.campaign, count("--threads", None)?)?;
    let n = c.next(a.count)?;
    let text = serde_json::to_string_pretty(&n)?;
    println!("{text}");
    note!("next:      {}", a.campaign.join("next.json").display());
    Ok(())
}

fn add(a: CampaignAddArgs) -> Result<()> {
    let spec = evaluator_spec(&a.eval)?;
    let threads = count("--threads", a.eval.threads)?;
    let mut c = open(&a.campaign, threads)?;
    let policy = a.outliers.policy();
    let mut new = Vec::new();
    for p in &a.data {
        let release = NewRelease::read(p, &c.scenario, policy, &mut tell())
            .with_context(|| format!("--data {}", p.display()))?;
        new.push(release);
    }
    let mut start = starter(&spec);
    let checks =
        sepval_campaign::add::add(&mut c, new, &mut start, &mut *crate::front::progress())?;
    for k in &checks {
        say!("check:     {}", k.verdict);
    }
    say!("campaign:  {}", page::headline(&c.file));
    say!("report:    {}", a.campaign.join("report.html").display());
    Ok(())
}

fn status(a: CampaignStatusArgs) -> Result<()> {
    let c = open(&a.campaign, 1)?;
    say!("{}", page::headline(&c.file));
    say!("{}", c.file.words);
    let next = a.campaign.join("next.json");
    if next.is_file() {
        let n: sepval_campaign::NextFile =
            sepval_campaign::record::read_json(&next, sepval_campaign::NEXT_FORMAT)?;
        for r in &n.releases {
            say!(
                "next:      Mach {}, altitude {} m, alpha {} deg: {}",
                page::number(r.mach),
                page::number(r.altitude_m),
                page::number(r.alpha_deg),
                r.why
            );
        }
    }
    Ok(())
}
