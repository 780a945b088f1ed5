//! `sepval diagnose`: what the simulation still gets wrong after a fit, and why.

use std::sync::Arc;

use anyhow::{Context, Result};
use sepval_coordinator::diagnose::{DiagnoseOptions, diagnose};
use sepval_coordinator::fit::{FitOptions, Method};
use sepval_coordinator::out_dir::{Claim, RunDir};
use sepval_coordinator::refine::LmSettings;
use sepval_coordinator::search::ga::GaSettings;
use sepval_coordinator::search::hill::HillSettings;
use sepval_coordinator::sigma::Sigma;

use super::{Bar, evaluator_spec, inputs, notices};
use crate::cli::DiagnoseArgs;

/// Runs `sepval diagnose`.
pub fn run(args: DiagnoseArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    // The output directory, before anything runs (no worker is started for a refused --out).
    let claim = if args.overwrite {
        Claim::Overwrite
    } else {
        Claim::Fresh
    };
    let run_dir = RunDir::claim(&args.out, claim, "diagnose").with_context(|| {
        format!(
            "--out {} (--overwrite clears an earlier run)",
            args.out.display()
        )
    })?;
    let ga = GaSettings {
        population: args.population,
        generations: args.generations,
        seed: args.seed,
        ..GaSettings::default()
    };
    ga.validate()?;
    let (job, inputs) = inputs::job(
        &args.data,
        args.scenario.as_deref(),
        args.extension.as_deref(),
    )?;
    let sigma = Sigma::resolve(&job, args.noise.sigma_pos_m, args.noise.sigma_att_deg)
        .context("the noise levels that weight the goals (--sigma-pos-m, --sigma-att-deg)")?;
    let lm = LmSettings {
        budget: args.lm_budget,
        ..LmSettings::default()
    };
    let fit = FitOptions {
        method: Method::GaLm,
        ga,
        hill: HillSettings::default(),
        sigma,
        truth: None,
        out: args.out.join("baseline"),
        resume: None,
        inputs,
        lm: lm.clone(),
        lm_probe: LmSettings {
            budget: args.lm_budget.min(800),
            ..LmSettings::default()
        },
    };
    let options = DiagnoseOptions {
        fit,
        out: args.out.clone(),
        candidate_lm: LmSettings {
            max_iterations: 400,
            budget: 10_000,
            ..lm
        },
    };
    let mut evaluator = spec.start(Arc::new(job), notices())?;
    let d = diagnose(&options, evaluator.as_mut(), &mut Bar::new())?;
    println!("{}", d.verdict);
    println!(
        "causes: [{}]  explained: {}  ({} simulations, {:.1} s)",
        d.causes.join(", "),
        d.explained,
        d.evaluations,
        d.wall_s
    );
    println!(
        "report: {}  data: {}",
        args.out.join("report.html").display(),
        args.out.join("diagnosis.json").display()
    );
    drop(run_dir);
    Ok(())
}
