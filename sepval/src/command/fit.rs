//! `sepval fit`: the factors fitted to measured data by the study's searches (and refinement).

use std::path::Path;
use std::sync::Arc;

use anyhow::Result;
use sepval_common::evaluation::Job;
use sepval_fit::checkpoint::Checkpoint;
use sepval_fit::configure::FitRequest;
use sepval_fit::pipeline::{FitOutput, write_fit_figures};
use sepval_fit::resume::{self, InputPaths};
use sepval_fit::{FitOptions, Method, run_fit};
use sepval_run::out_dir::Claim;
use sepval_solve::ga::GaSettings;
use sepval_solve::run::ProgressObserver;

use super::sequence::{Evaluators, Run, Said, Writes, execute};
use super::{clearance, evaluator_spec, tell};
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
    let FitConfig { job, mut options } = configure(&args, resume)?;
    let base = job.events()[0].simulator.scenario();
    let threads = super::count("--threads", args.eval.threads)?;
    options.clearance = clearance::stage(&args.geometry, base, threads)?;
    options.strict_tables = args.tables.strict_tables;
    let job = Arc::new(job);
    let request = Request {
        args,
        job: Arc::clone(&job),
        options,
    };
    execute(&spec, writes, Some(job), request)
}

/// A fit asked for by the flags, configured.
struct Request {
    args: FitArgs,
    job: Arc<Job>,
    options: FitOptions,
}

impl Run for Request {
    type Found = FitOutput;

    fn confirm(&mut self, evaluators: &mut Evaluators<'_>) -> Result<()> {
        if let (Some(c), Some(path)) = (&self.options.resume, self.args.resume.as_deref()) {
            // Its members re-evaluated and its generation replayed before going on from it.
            let report = sepval_fit::rerun::confirm(c, path, evaluators.one()?)?;
            note!(
                "sepval: resuming from {}: {}",
                path.display(),
                report.checked()
            );
        }
        Ok(())
    }

    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<FitOutput> {
        Ok(run_fit(&self.options, evaluators.one()?, progress)?)
    }

    /// The figures (unless `--no-figures`: result.json is the fit's); the tables left by the
    /// best fit told (`--strict-tables` refused them before result.json was written).
    fn write(&self, output: FitOutput, out: &Path, _wall_s: f64) -> Result<Said> {
        let result = &output.result;
        let mut summary = clearance::lines(result.clearance.as_ref());
        summary.push_str(&result.summary());
        if !self.args.no_figures {
            let n = write_fit_figures(out, &self.job, &output)?.len();
            let dir = out.join("figures");
            summary.push_str(&format!("{n} figures in {}\n", dir.display()));
        }
        let json = out.join("result.json");
        summary.push_str(&format!("results in {}\n", json.display()));
        let warnings = result.tables_left();
        Ok(Said { summary, warnings })
    }
}

/// Where the fit writes and what it reads. Its directory may be none of the run's inputs: with
/// `--resume`, the checkpoint and its run directory too, unless the run goes on in that
/// directory (so `--resume DIR/generations/gen-0005.json --overwrite --out DIR` is refused: it
/// would clear the checkpoint it resumes from).
fn writes(args: &FitArgs, resume: Option<&Checkpoint>) -> Writes {
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
    Writes {
        out: args.out.clone(),
        command: "fit",
        claim,
        inputs: read,
        resume: Some(resume_hint),
    }
}

/// A fit as the flags ask for it, validated: the job to run and the options of the run.
struct FitConfig {
    job: Job,
    options: FitOptions,
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
