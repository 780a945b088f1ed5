//! `sepval diagnose`: what the simulation still gets wrong after a fit, and why.

use std::sync::Arc;

use anyhow::{Context, Result};
use sepval_common::evaluation::Job;
use sepval_diagnose::{DiagnoseOptions, Diagnosis, diagnose, fmt_discovered};
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
    crate::front::out(&summary_lines(&d, &args.out));
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

/// The terminal summary: a few short lines.
fn summary_lines(d: &Diagnosis, out: &std::path::Path) -> String {
    let mut s = String::new();
    if !d.baseline_verdict.converged() {
        s.push_str(&format!(
            "UNRELIABLE: the baseline fit failed (J_pos {:.0}, J_att {:.0} sigma): no cause below is reliable\n",
            d.baseline.j_pos_m / d.sigma_pos_m,
            d.baseline.j_att_deg / d.sigma_att_deg
        ));
    }
    let answer = if !d.discovered.is_empty() {
        "terms found beyond the catalogue"
    } else if !d.causes.is_empty() {
        "catalogue effects"
    } else {
        "nothing named"
    };
    s.push_str(&format!("answer:    {answer}\n"));
    for c in &d.causes {
        let values: Vec<String> = d
            .parameters
            .get(c)
            .map(|v| {
                v.iter()
                    .map(|p| match p.std_error {
                        Some(se) => format!("{} = {:.4} ± {:.2}", p.name, p.value, se),
                        None => format!("{} = {:.4}", p.name, p.value),
                    })
                    .collect()
            })
            .unwrap_or_default();
        s.push_str(&format!("cause:     {c} ({})\n", values.join(", ")));
    }
    for t in &d.discovered {
        s.push_str(&format!("found:     {}\n", fmt_discovered(t)));
        s.push_str(&format!("           {}\n", t.reading));
    }
    s.push_str(&format!(
        "fit:       J_pos {:.4} -> {:.4} m, J_att {:.3} -> {:.3} deg (noise {:.4} m, {:.3} deg)\n",
        d.baseline.j_pos_m,
        d.extended.j_pos_m,
        d.baseline.j_att_deg,
        d.extended.j_att_deg,
        d.sigma_pos_m,
        d.sigma_att_deg
    ));
    let explained = match &d.extension {
        Some(x) if x.answer => x.explained,
        _ => d.explained,
    };
    s.push_str(&format!(
        "explained: {} ({} simulations, {:.1} s)\n",
        if explained {
            "yes, to the noise"
        } else {
            "no, structure remains"
        },
        d.evaluations,
        d.wall_s
    ));
    if !d.rivals.is_empty() {
        s.push_str(&rivals_line(d));
    }
    for v in &d.validation {
        let f = |v: Option<f64>, p: usize| {
            v.map_or("-".to_string(), |v| format!("{v:.prec$}", prec = p))
        };
        s.push_str(&format!(
            "predicts:  {}: J_pos {} -> {} m, J_att {} -> {} deg\n",
            v.event,
            f(v.baseline_j_pos_m, 4),
            f(v.extended_j_pos_m, 4),
            f(v.baseline_j_att_deg, 3),
            f(v.extended_j_att_deg, 3)
        ));
        for a in &v.alternatives {
            let kind = a.model.split(':').next().unwrap_or("alternative");
            s.push_str(&format!(
                "           the {kind} alternative would give J_pos {:.4} m, J_att {:.3} deg\n",
                a.j_pos_m, a.j_att_deg
            ));
        }
    }
    if let Some(caution) = &d.caution {
        s.push_str(&format!("caution:   {caution}\n"));
    }
    if d.extension.as_ref().is_some_and(|x| x.answer) {
        s.push_str(&format!(
            "extension: {} with factors {}\n",
            out.join("extension.toml").display(),
            out.join("factors.json").display()
        ));
    }
    s.push_str(&format!(
        "report:    {}\n",
        out.join("report.html").display()
    ));
    s
}

/// The line that says what the data cannot tell from the answer, at most 160 characters.
fn rivals_line(d: &sepval_diagnose::Diagnosis) -> String {
    const WIDTH: usize = 160;
    let mut line = "rivals:    the data cannot tell it from".to_string();
    for (k, r) in d.rivals.iter().enumerate() {
        let item = format!(
            "{} {} (BIC {:+.1})",
            if k == 0 { "" } else { "," },
            sepval_diagnose::rival_name(r),
            r.delta_bic
        );
        let rest = format!(" ... ({} in all, see diagnosis.json)", d.rivals.len());
        if line.chars().count() + item.chars().count() + rest.chars().count() > WIDTH {
            line.push_str(&rest);
            break;
        }
        line.push_str(&item);
    }
    line.push('\n');
    line
}
