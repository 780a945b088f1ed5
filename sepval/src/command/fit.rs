//! `sepval fit`: the factors fitted to measured data by the study's searches (and refinement).

use std::sync::Arc;

use anyhow::Result;
use sepval_common::evaluation::Job;
use sepval_fit::checkpoint::Checkpoint;
use sepval_fit::configure::FitRequest;
use sepval_fit::out_dir::{Claim, Request, RunDir};
use sepval_fit::pipeline::{FitOutput, write_fit_figures};
use sepval_fit::resume::{self, InputPaths};
use sepval_fit::{FitOptions, Method, run_fit};
use sepval_solve::ga::GaSettings;

use super::{clearance, evaluator_spec, notices, tell};
use crate::cli::{FitArgs, MethodArg};

/// The library's method of `--method`.
pub fn method(m: MethodArg) -> Method {
    match m {
        MethodArg::Ga => Method::Ga,
        MethodArg::Hill => Method::Hill,
        MethodArg::Both => Method::Both,
        MethodArg::GaLm => Method::GaLm,
        MethodArg::HillLm => Method::HillLm,
    }
}

/// Runs `sepval fit`: the flags to a validated configuration, the run, the rendering. The run
/// directory is claimed (locked and checked) first, so that no worker starts for a refused
/// `--out`, but changed only once everything is checked, a resumed checkpoint re-evaluated and
/// replayed included: a refusal deletes and rewrites nothing.
pub fn run(args: FitArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let resume = args.resume.as_deref().map(Checkpoint::load).transpose()?;
    let run_dir = claim(&args, resume.as_ref())?;
    let FitConfig { job, options } = configure(&args, resume)?;
    let base = job.events()[0].simulator.scenario().clone();
    let geometry = clearance::settings(&args.geometry, &base)?;
    let mut evaluator = spec.start(Arc::new(job), notices())?;
    if let (Some(c), Some(path)) = (&options.resume, args.resume.as_deref()) {
        // Its members re-evaluated and its generation replayed before going on from it.
        let report = sepval_fit::rerun::confirm(c, path, evaluator.as_mut())?;
        note!(
            "sepval: resuming from {}: {}",
            path.display(),
            report.checked()
        );
    }
    for removed in run_dir.prepare()? {
        note!(
            "sepval: removed {} (a later generation of the continuation being replaced)",
            removed.display()
        );
    }
    let mut output = run_fit(&options, evaluator.as_mut(), &mut *crate::front::progress())?;
    if let Some(c) = &geometry {
        best_clearance(c, &args, evaluator.job(), &mut output)?;
    }
    render(&args, evaluator.job(), &output)?;
    run_dir.commit();
    // Tables left by the best fit: reported, or an error with --strict-tables.
    let left = output.result.tables_left();
    if args.tables.strict_tables && !left.is_empty() {
        anyhow::bail!(
            "--strict-tables: the best fit {} (result.json records it)",
            left.join("; and ")
        );
    }
    for l in &left {
        note!("warning: {l}");
    }
    Ok(())
}

/// A fit as the flags ask for it, validated: the job to run and the options of the run.
struct FitConfig {
    job: Job,
    options: FitOptions,
}

/// The run directory, claimed before anything runs (no worker is started for a refused --out)
/// and changed by nothing yet. It may be none of the run's inputs: with `--resume`, the
/// checkpoint and its run directory too, unless the run goes on in that directory (so
/// `--resume DIR/generations/gen-0005.json --overwrite --out DIR` is refused: it would clear
/// the checkpoint it resumes from).
fn claim(args: &FitArgs, resume: Option<&Checkpoint>) -> Result<RunDir> {
    let claim = match (&args.resume, resume, args.overwrite.overwrite) {
        (_, _, true) => Claim::Overwrite,
        (Some(path), Some(c), false) => Claim::Resume {
            checkpoint: path.clone(),
            generation: c.state.generation,
        },
        _ => Claim::Fresh,
    };
    let mut read = super::model_inputs(&args.inputs);
    read.extend(super::input_files("--truth-factors", &args.truth_factors));
    read.extend(super::geometry_inputs(&args.geometry));
    if let (Some(path), Some(c)) = (&args.resume, resume) {
        read.extend(resume::inputs_read(path, c));
    }
    let resume_hint = format!(
        "resume from one of its checkpoints (--resume {})",
        args.out.join("generations/gen-NNNN.json").display()
    );
    super::claim_out(
        &args.out,
        Request {
            command: "fit",
            claim,
            inputs: &read,
            resume: Some(resume_hint),
        },
    )
}

/// The flags (and the checkpoint resumed from) as a validated configuration
/// ([`sepval_fit::configure`]).
fn configure(args: &FitArgs, resume: Option<Checkpoint>) -> Result<FitConfig> {
    let given = &args.inputs;
    let request = FitRequest {
        inputs: InputPaths {
            data: given.data.clone(),
            scenario: given.model.scenario.clone(),
            extension: given.model.extension.clone(),
        },
        outliers: given.outliers.given(),
        method: args.method.map(method),
        resume: args.resume.as_deref().zip(resume),
        ga: GaSettings {
            population: args.population,
            generations: args.generations.unwrap_or(500),
            p_crossover: args.p_crossover,
            p_jump: args.p_jump,
            p_creep: args.p_creep,
            seed: args.seed,
        },
        generations: args.generations,
        hill_budget: args.hill_budget,
        lm_budget: args.lm_budget,
        sigma: (args.noise.sigma_pos_m, args.noise.sigma_att_deg),
        truth_factors: args.truth_factors.as_deref(),
        out: args.out.clone(),
    };
    let (job, options) = sepval_fit::configure::configure(request, &mut tell())?;
    Ok(FitConfig { job, options })
}

/// The clearance of the best fit's trajectories (`--aircraft`): clearance.csv, the figure and
/// result.json's `clearance`.
fn best_clearance(
    c: &sepval_predict::ClearanceSettings,
    args: &FitArgs,
    job: &Arc<Job>,
    output: &mut FitOutput,
) -> Result<()> {
    let Some(best) = output
        .result
        .methods
        .values()
        .min_by(|a, b| a.best.weighted.total_cmp(&b.best.weighted))
    else {
        return Ok(());
    };
    let candidate = sepval_common::evaluation::Candidate::baseline(best.best.factors);
    let threads = super::count("--threads", args.eval.threads)?;
    clearance::record_releases(
        c,
        (job, candidate, threads),
        &args.out,
        "result.json",
        &mut output.result,
        |r, v| r.clearance = Some(v),
    )
}

/// The summary on stdout, the figures (unless --no-figures), and where the result is.
fn render(args: &FitArgs, job: &Job, output: &FitOutput) -> Result<()> {
    crate::front::out(&output.result.summary());
    if !args.no_figures {
        figures(&args.out, job, output)?;
    }
    say!("results in {}", args.out.join("result.json").display());
    Ok(())
}

fn figures(dir: &std::path::Path, job: &Job, output: &FitOutput) -> Result<()> {
    let written = write_fit_figures(dir, job, output)?;
    say!(
        "{} figures in {}",
        written.len(),
        dir.join("figures").display()
    );
    Ok(())
}
