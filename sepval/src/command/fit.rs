//! `sepval fit`: the factors fitted to measured data by the study's searches (and refinement).

use std::sync::Arc;

use anyhow::Result;
use sepval_common::evaluation::Job;
use sepval_fit::checkpoint::Checkpoint;
use sepval_fit::command::FitRun;
use sepval_fit::configure::FitRequest;
use sepval_fit::resume::{self, InputPaths};
use sepval_fit::{FitOptions, Method};
use sepval_predict::releases::Stage;
use sepval_run::out_dir::Input;
use sepval_run::sequence::Writes;
use sepval_solve::ga::GaSettings;

use super::{evaluator_spec, execute, tell};
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

/// Runs `sepval fit`: the flags made a request (the checkpoint resumed from, the releases,
/// the settings and the geometry read and checked), then the command's sequence, whose
/// confirmation re-evaluates and replays a resumed checkpoint before the directory changes.
pub fn run(args: FitArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let resume = args.resume.as_deref().map(Checkpoint::load).transpose()?;
    let writes = writes(&args, resume.as_ref());
    let (job, mut options) = configure(&args, resume)?;
    let base = job.events()[0].simulator.scenario();
    let threads = super::count("--threads", args.eval.threads)?;
    options.clearance = Stage::of(&super::geometry(&args.geometry), base, threads)?;
    options.strict_tables = args.tables.strict_tables;
    let run = FitRun {
        job: Arc::new(job),
        options,
        resume_path: args.resume,
        figures: !args.no_figures,
    };
    execute(&spec, writes, run)
}

/// Where the fit writes and what it reads ([`resume::writes`]).
fn writes(args: &FitArgs, resume: Option<&Checkpoint>) -> Writes {
    let mut read = super::model_inputs(&args.inputs);
    read.extend(Input::files("--truth-factors", &args.truth_factors));
    read.extend(super::geometry(&args.geometry).inputs());
    let resumed = args.resume.as_deref().zip(resume);
    resume::writes(&args.out, resumed, args.overwrite.overwrite, read)
}

/// The flags (and the checkpoint resumed from) as a validated configuration
/// ([`sepval_fit::configure`]).
fn configure(args: &FitArgs, resume: Option<Checkpoint>) -> Result<(Job, FitOptions)> {
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
    Ok(sepval_fit::configure::configure(request, &mut tell())?)
}
