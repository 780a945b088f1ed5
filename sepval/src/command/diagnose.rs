//! `sepval diagnose`: what the simulation still gets wrong after a fit, and why.

use std::sync::Arc;

use anyhow::{Context, Result};
use sepval_common::evaluation::Job;
use sepval_diagnose::{DiagnoseOptions, diagnose};
use sepval_fit::FitOptions;
use sepval_fit::inputs::{self, HeldOut};
use sepval_fit::out_dir::Request;
use sepval_fit::sigma::Sigma;
use sepval_solve::ga::GaSettings;
use sepval_solve::lm::LmSettings;

use super::{clearance, evaluator_spec, notices, tell};
use crate::cli::DiagnoseArgs;

/// Runs `sepval diagnose`. The output directory is claimed (locked and checked) before anything
/// runs, so that no worker starts for a refused `--out`, and cleared (`--overwrite`) only once
/// every input is checked and the workers run: a refusal deletes nothing.
pub fn run(args: DiagnoseArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    // The output directory, before anything runs (no worker is started for a refused --out).
    let mut read = super::model_inputs(&args.inputs);
    read.extend(super::input_files("--validate", &args.validate));
    read.extend(super::geometry_inputs(&args.geometry));
    let run_dir = super::claim_out(
        &args.out,
        Request {
            command: "diagnose",
            claim: super::fresh_or_overwrite(&args.overwrite),
            inputs: &read,
            resume: None,
        },
    )?;
    let DiagnoseConfig { job, options } = configure(&args)?;
    let base = job.events()[0].simulator.scenario().clone();
    let geometry = clearance::settings(&args.geometry, &base)?;
    let mut evaluator = spec.start(Arc::new(job), notices())?;
    run_dir.prepare()?;
    let mut d = diagnose(&options, evaluator.as_mut(), &mut *crate::front::progress())?;
    if let Some(c) = &geometry {
        // The answer's trajectories: its model rebuilt as predict rebuilds it.
        let job = evaluator.job();
        let answer = sepval_predict::releases::diagnosis_answer(&d, &args.out, job)?;
        let threads = super::count("--threads", args.eval.threads)?;
        let flown = (job, answer, threads);
        clearance::record_releases(c, flown, &args.out, "diagnosis.json", &mut d, |d, v| {
            d.clearance = Some(v)
        })?;
    }
    crate::front::out(&sepval_diagnose::summary(&d, &args.out));
    drop(run_dir);
    // Tables left by the fitted runs, as simulate and fit report them (--strict-tables refused
    // them after the baseline fit, before any other work).
    for l in &d.tables_left {
        note!("warning: {l}");
    }
    Ok(())
}

/// A diagnosis as the flags ask for it, validated.
struct DiagnoseConfig {
    /// The job of the `--data` files.
    job: Job,
    /// The options of the diagnosis: its baseline fit, refinements and `--validate` releases.
    options: DiagnoseOptions,
}

/// The flags as a validated configuration.
fn configure(args: &DiagnoseArgs) -> Result<DiagnoseConfig> {
    let ga = GaSettings {
        population: args.population,
        generations: args.generations,
        seed: args.seed,
        ..GaSettings::default()
    };
    ga.validate()?;
    let given = &args.inputs;
    let policy = given.outliers.policy();
    let (job, inputs) = inputs::job(
        &given.data,
        given.model.scenario.as_deref(),
        given.model.extension.as_deref(),
        policy,
        &mut tell(),
    )?;
    // The --extension terms, written again with the discovered ones to DIR/extension.toml.
    let given_terms = match given.model.extension.as_deref() {
        Some(path) => sepval_common::extension::load_extension(path)?,
        None => Vec::new(),
    };
    let held = inputs::with_policy(&args.validate, policy);
    let held_out = HeldOut {
        held: &held,
        data_paths: &given.data,
        fitted: &job,
        scenario_path: given.model.scenario.as_deref(),
        extension_path: given.model.extension.as_deref(),
    };
    let validation = inputs::validation_job(&held_out, &mut tell())?;
    let sigma = Sigma::resolve(&job, args.noise.sigma_pos_m, args.noise.sigma_att_deg)
        .context("the noise levels that weight the goals (--sigma-pos-m, --sigma-att-deg)")?;
    let lm = LmSettings {
        budget: args.lm_budget,
        ..LmSettings::default()
    };
    let fit = FitOptions::baseline(ga, sigma, &lm, &args.out.join("baseline"), inputs);
    let options = DiagnoseOptions {
        validation,
        given_terms,
        strict_tables: args.tables.strict_tables,
        ..DiagnoseOptions::new(fit, &lm, args.out.clone())
    };
    Ok(DiagnoseConfig { job, options })
}
