//! `sepval update`: the store's aerodynamic data updated from its releases, as corrections in
//! the scenario's own table forms kept only as far as they predict (docs/update.md).

use std::sync::Arc;

use anyhow::{Result, bail};
use sepval_common::evaluation::Job;
use sepval_core::factors::Factor;
use sepval_fit::inputs::{self, ReadReleases, Releases};
use sepval_fit::out_dir::Request;
use sepval_update::{UpdateOptions, update, write_outputs};

use super::{baseline_search, evaluator_spec, starter, tell};
use crate::cli::{FactorNames, UpdateArgs};

/// Runs `sepval update`. Every input is checked before the output directory is claimed or a
/// worker started; a refusal deletes nothing.
pub fn run(args: UpdateArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    super::several_jobs(&args.eval, "update", "one per round")?;
    let (options, job) = configure(&args)?;
    let mut read = super::model_inputs(&args.inputs);
    read.extend(super::input_files("--validate", &args.validate));
    let run_dir = super::claim_out(
        &args.out,
        Request {
            command: "update",
            claim: super::fresh_or_overwrite(&args.overwrite),
            inputs: &read,
            resume: None,
        },
    )?;
    run_dir.prepare()?;
    let mut start = starter(&spec);
    let u = update(
        &options,
        Arc::new(job),
        &mut start,
        &mut *crate::front::progress(),
    )?;
    write_outputs(&u, &args.out)?;
    if args.daveml {
        write_daveml(&u, &args)?;
    }
    drop(run_dir);
    say!("update:    {}", u.file.verdict);
    for c in &u.file.cannot_tell {
        say!("open:      {c}");
    }
    say!(
        "store:     {} ({} table files), factors {}",
        args.out.join("scenario.toml").display(),
        u.store.files.len(),
        args.out.join("factors.json").display()
    );
    say!(
        "report:    {} ({} simulations, {:.1} s)",
        args.out.join("report.html").display(),
        u.file.evaluations,
        u.file.wall_s
    );
    Ok(())
}

/// `--daveml`: the updated store as DIR/store.dml, each correction's standard deviation as
/// its table's uncertainty.
fn write_daveml(u: &sepval_update::Update, args: &UpdateArgs) -> Result<()> {
    let store = sepval_common::scenario::Scenario::load(&args.out.join("scenario.toml"))?;
    let spreads: Vec<sepval_daveml::CorrectionSpread> = u
        .file
        .corrections
        .iter()
        .map(|c| sepval_daveml::CorrectionSpread {
            field: c.field.clone(),
            variable: c.variable.clone(),
            breakpoints: c.breakpoints.clone(),
            std: c.std.clone(),
        })
        .collect();
    let bands = sepval_daveml::bands(&store, &spreads)?;
    let prov = sepval_daveml::Provenance::now(
        format!("sepval update --out {}", args.out.display()),
        args.inputs
            .data
            .iter()
            .map(|p| p.display().to_string())
            .collect(),
    );
    let path = args.out.join("store.dml");
    sepval_daveml::write_model(&path, &store, &bands, &prov)?;
    say!("daveml:    {}", path.display());
    Ok(())
}

/// The flags as a validated configuration, and the job of the `--data` releases.
fn configure(args: &UpdateArgs) -> Result<(UpdateOptions, Job)> {
    if args.inputs.data.is_empty() {
        bail!(
            "--data FILE.csv is required (repeat it for each release): the releases that update the store's data"
        );
    }
    let free = free_factors(args.free.as_ref())?;
    let given = &args.inputs;
    let releases = Releases {
        data: &given.data,
        validate: &args.validate,
        scenario: given.model.scenario.as_deref(),
        extension: given.model.extension.as_deref(),
        policy: given.outliers.policy(),
    };
    let ReadReleases {
        job,
        record,
        validation,
    } = releases.read(&mut tell())?;
    let scenario = inputs::scenario(releases.scenario, releases.extension)?;
    let search = baseline_search(
        args.seed,
        args.population,
        args.generations,
        args.lm_budget,
        &args.noise,
    );
    let (fit, lm) = search.options(&job, &args.out.join("baseline"), record)?;
    let options = UpdateOptions {
        free,
        validation,
        ..UpdateOptions::new(fit, &lm, scenario)
    };
    Ok((options, job))
}

/// The factors of `--free NAME,...` (all 17 when absent), as indices; the list holds no empty
/// name (refused as the flags were parsed).
fn free_factors(list: Option<&FactorNames>) -> Result<Vec<usize>> {
    let Some(FactorNames(names)) = list else {
        return Ok((0..Factor::ALL.len()).collect());
    };
    let mut out = Vec::new();
    for name in names {
        let Some(f) = Factor::from_name(name) else {
            bail!(
                "--free {name}: not one of the 17 factors (expected a comma-separated list of {})",
                Factor::NAMES.join(", ")
            );
        };
        if out.contains(&f.index()) {
            bail!("--free {name}: given twice");
        }
        out.push(f.index());
    }
    out.sort_unstable();
    Ok(out)
}
