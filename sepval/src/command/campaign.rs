//! `sepval campaign`: a test program as one record (docs/campaign.md). Each subcommand parses
//! its flags, loads the inputs, runs `sepval-campaign` and prints what it found.

use std::path::Path;

use anyhow::{Context, Result, bail};
use sepval_campaign::page;
use sepval_campaign::program::{self, Campaign, Init};
use sepval_campaign::release::NewRelease;
use sepval_campaign::request::InitRequest;

use super::starter;
use super::{count, evaluator_spec, tell};
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

fn init(a: CampaignInitArgs) -> Result<()> {
    let spec = evaluator_spec(&a.eval)?;
    let init = request(&a)?;
    let mut start = starter(&spec);
    let c = program::init(&a.out, init, &mut start, &mut *crate::front::progress())?;
    for l in c.file.settings.prior.lines() {
        say!("prior:     {l}");
    }
    say!("campaign:  {}", page::headline(&c.file));
    say!("report:    {}", a.out.join("report.html").display());
    Ok(())
}

/// Checks the init flags and reads what they name: what `init` begins from.
fn request(a: &CampaignInitArgs) -> Result<Init> {
    let request = InitRequest {
        scenario: a.scenario.as_deref(),
        aircraft: a.geometry.aircraft.as_deref(),
        store_shape: a.geometry.store_shape.as_deref(),
        axes: a
            .grid
            .given()
            .into_iter()
            .map(|(q, a)| (q.flag().to_string(), a.text.clone()))
            .collect(),
        clearance_mm: a.geometry.clearance_mm,
        allowed: a.allowed,
        fly_risk: a.fly_risk,
        samples: a.samples,
        seed: a.seed,
        generations: a.generations,
        prior: a.prior.as_deref(),
        prior_daveml: a.prior_daveml.as_deref(),
        prior_from_shape: a.prior_from_shape.as_deref(),
        preflight: &a.preflight,
        preflight_allowance: (a.preflight_allowance_m, a.preflight_allowance_deg),
        threads: count("--threads", a.eval.threads)?,
    };
    Ok(request.read()?)
}

fn rehearse(a: CampaignRehearseArgs) -> Result<()> {
    let spec = evaluator_spec(&a.init.eval)?;
    let truth = sepval_campaign::rehearse::Truth::read(
        a.truth_scenario.as_deref(),
        a.truth_extension.as_deref(),
        &a.truth_factors,
        &a.truth_effect,
        a.noise_seed,
    )?;
    let init = request(&a.init)?;
    // The truth over the grid before anything is written: one that does not fly is refused.
    let truth_at = sepval_campaign::rehearse::truth_envelope(&init.grid, &init.clearance, &truth)?;
    let mut start = starter(&spec);
    let mut c = program::init(
        &a.init.out,
        init,
        &mut start,
        &mut *crate::front::progress(),
    )?;
    say!("round 0:   {}", page::headline(&c.file));
    let r = sepval_campaign::rehearse::rehearse(
        &mut c,
        &truth,
        truth_at,
        sepval_campaign::rehearse::Schedule {
            max_releases: a.releases,
            check_settled: a.check_settled,
        },
        &mut start,
        &mut *crate::front::progress(),
    )?;
    for l in r.lines() {
        say!("{l}");
    }
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
    // Through the front end, as every command's words (Python collects them).
    say!("{}", serde_json::to_string_pretty(&n)?);
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
        let release = NewRelease::read(p, c.against(), policy, a.other_scenario, &mut tell())
            .with_context(|| format!("--data {}", p.display()))?;
        for n in &release.notes {
            say!("note:      {n}");
        }
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
    crate::front::out(&c.status_lines()?);
    Ok(())
}
