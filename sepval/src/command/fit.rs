//! `sepval fit`: the factors fitted to measured data by the study's searches (and refinement).

use std::sync::Arc;

use anyhow::{Context, Result, bail};
use sepval_common::evaluation::Job;
use sepval_fit::checkpoint::Checkpoint;
use sepval_fit::out_dir::{Claim, RunDir};
use sepval_fit::pipeline::{FitOutput, write_fit_figures};
use sepval_fit::sigma::Sigma;
use sepval_fit::{FitOptions, Method, run_fit};
use sepval_solve::ga::GaSettings;
use sepval_solve::hill::HillSettings;
use sepval_solve::lm::LmSettings;

use super::{Bar, evaluator_spec, inputs, notices};
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

/// Runs `sepval fit`.
pub fn run(args: FitArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let resume = args.resume.as_deref().map(Checkpoint::load).transpose()?;
    // The run directory, before anything runs (no worker is started for a refused --out).
    let claim = match (&args.resume, args.overwrite) {
        (_, true) => Claim::Overwrite,
        (Some(c), false) => Claim::Resume {
            checkpoint: c.clone(),
        },
        (None, false) => Claim::Fresh,
    };
    let run_dir = RunDir::claim(&args.out, claim, "fit").with_context(|| {
        format!(
            "--out {} (--overwrite clears an earlier run)",
            args.out.display()
        )
    })?;
    if let (Some(c), false) = (&resume, args.overwrite) {
        for removed in run_dir.discard_generations_after(c.state.generation)? {
            eprintln!(
                "sepval: removed {} (a later generation of the continuation being replaced)",
                removed.display()
            );
        }
    }
    // Inputs: the flags, or (when resuming without them) those recorded in the checkpoint.
    let (data_paths, scenario_path, extension_path) = match (
        &resume,
        args.data.is_empty(),
        &args.scenario,
        &args.extension,
    ) {
        (Some(c), true, None, None) => (
            c.inputs.data.clone(),
            c.inputs.scenario.clone(),
            c.inputs.extension.clone(),
        ),
        _ => (
            args.data.clone(),
            args.scenario.clone(),
            args.extension.clone(),
        ),
    };
    let (job, inputs) = inputs::job(
        &data_paths,
        scenario_path.as_deref(),
        extension_path.as_deref(),
    )?;
    let method = match (args.method, &resume) {
        (Some(m), _) => method(m),
        (None, Some(c)) => Method::from_name(&c.method).ok_or_else(|| {
            anyhow::anyhow!(
                "checkpoint {}: unknown method `{}`",
                args.resume.as_deref().expect("resuming").display(),
                c.method
            )
        })?,
        (None, None) => Method::Both,
    };
    let (ga, hill, sigma) = match &resume {
        Some(c) => {
            let path = args.resume.as_deref().expect("resume path");
            c.check_job(&job, path)?;
            let mut ga = c.settings.clone();
            if let Some(g) = args.generations {
                if g < c.state.generation {
                    bail!(
                        "--generations {g}: the checkpoint is already at generation {}",
                        c.state.generation
                    );
                }
                ga.generations = g;
            }
            (ga, c.hill.clone(), c.sigma.clone())
        }
        None => {
            let ga = GaSettings {
                population: args.population,
                generations: args.generations.unwrap_or(500),
                p_crossover: args.p_crossover,
                p_jump: args.p_jump,
                p_creep: args.p_creep,
                seed: args.seed,
            };
            let hill = HillSettings {
                budget: args.hill_budget,
                ..HillSettings::default()
            };
            let sigma = Sigma::resolve(&job, args.noise.sigma_pos_m, args.noise.sigma_att_deg)
                .context(
                    "the noise levels that weight the goals (--sigma-pos-m, --sigma-att-deg)",
                )?;
            (ga, hill, sigma)
        }
    };
    ga.validate()?;
    let truth = match &args.truth_factors {
        Some(p) => Some(inputs::factors(
            &p.display().to_string(),
            job.factor_table(),
        )?),
        None if data_paths.is_empty() => Some(sepval_common::factors::Factors::TRUTH),
        None => None,
    };
    let options = FitOptions {
        method,
        ga,
        hill,
        sigma,
        truth,
        out: args.out.clone(),
        resume,
        inputs,
        lm: LmSettings {
            budget: args.lm_budget,
            ..LmSettings::default()
        },
        lm_probe: LmSettings {
            budget: args.lm_budget.min(800),
            ..LmSettings::default()
        },
    };
    let mut evaluator = spec.start(Arc::new(job), notices())?;
    if let (Some(c), Some(path)) = (&options.resume, args.resume.as_deref()) {
        // Its members re-evaluated and its generation replayed before going on from it.
        let report = sepval_fit::rerun::confirm(c, path, evaluator.as_mut())?;
        eprintln!(
            "sepval: resuming from {}: {}",
            path.display(),
            report.checked()
        );
    }
    let output = run_fit(&options, evaluator.as_mut(), &mut Bar::new())?;
    print_summary(&output);
    if !args.no_figures {
        figures(&args.out, evaluator.job(), &output)?;
    }
    println!("results in {}", args.out.join("result.json").display());
    drop(run_dir);
    // Tables left by the best fit: reported, or an error with --strict-tables.
    let left: Vec<String> = output
        .result
        .events
        .iter()
        .flat_map(|e| {
            e.tables_left
                .iter()
                .map(move |x| format!("{}: {x}", e.name))
        })
        .collect();
    if args.strict_tables && !left.is_empty() {
        anyhow::bail!(
            "--strict-tables: the best fit {} (result.json records it)",
            left.join("; and ")
        );
    }
    for l in &left {
        eprintln!("warning: {l}");
    }
    Ok(())
}

fn print_summary(output: &FitOutput) {
    let r = &output.result;
    println!(
        "fit of {} ({} samples), sigma_pos {:.4} m, sigma_att {:.4} deg ({})",
        r.events
            .iter()
            .map(|e| e.name.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        r.events.iter().map(|e| e.samples).sum::<usize>(),
        r.sigma_pos_m,
        r.sigma_att_deg,
        r.sigma_source
    );
    println!(
        "{:<6} {:>12} {:>12} {:>10} {:>12} {:>9}",
        "method", "J_pos [m]", "J_att [deg]", "weighted", "simulations", "wall [s]"
    );
    for (name, m) in &r.methods {
        println!(
            "{:<6} {:>12.6} {:>12.5} {:>10.3} {:>12} {:>9.1}",
            name,
            m.best.j_pos_m,
            m.best.j_att_deg,
            m.best.weighted,
            m.best.evaluations,
            m.best.wall_s
        );
    }
}

fn figures(dir: &std::path::Path, job: &Job, output: &FitOutput) -> Result<()> {
    let written = write_fit_figures(dir, job, output)?;
    println!(
        "{} figures in {}",
        written.len(),
        dir.join("figures").display()
    );
    Ok(())
}
