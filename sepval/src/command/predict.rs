//! `sepval predict`: a release not flown, with its bands, from a fit or a diagnosis; with
//! `--data`, the post-flight check of a flown release against them.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use sepval_fit::inputs;
use sepval_fit::out_dir::Request;
use sepval_predict::{
    Flown, PredictionFile, Settings, SourceInputs, predict, prediction_file, prepare,
    source_inputs, write_outputs,
};

use super::{clearance, count, evaluator_spec, input_files, notices, tell};
use crate::cli::PredictArgs;

/// Runs `sepval predict`. Every input (the flags, the source, its releases, the condition, the
/// flown release) is checked before the output directory is claimed or a worker started, so a
/// refusal writes nothing; the directory is cleared (`--overwrite`) only once the prediction
/// is made, just before its files are written.
pub fn run(args: PredictArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let settings = Settings {
        samples: args.samples,
        level: args.level,
        seed: args.seed,
        with_noise: args.with_noise,
        threads: count("--threads", args.eval.threads)?,
    };
    settings.check()?;
    let policy = args.outliers.policy();
    let SourceInputs {
        source,
        fitted,
        held_out,
    } = source_inputs(
        &args.from,
        args.extension.as_deref(),
        &args.validate,
        policy,
        &mut tell(),
    )?;
    let mut read = super::recorded_inputs(&args.from, &source.inputs, &source.held_out);
    read.extend(input_files("--scenario", [&args.scenario]));
    read.extend(input_files("--extension", &args.extension));
    read.extend(input_files("--data", &args.data));
    read.extend(input_files("--validate", &args.validate));
    read.extend(super::geometry_inputs(&args.geometry));
    let extension = args.extension.clone().or(source.inputs.extension.clone());
    let condition = inputs::scenario(Some(&args.scenario), extension.as_deref())
        .with_context(|| format!("--scenario {}", args.scenario.display()))?;
    sepval_predict::check_condition(fitted.events()[0].simulator.scenario(), &condition)
        .with_context(|| format!("--scenario {}", args.scenario.display()))?;
    let flown = match &args.data {
        Some(path) => Some(flown(path, (args.scenario.as_path(), &condition), policy)?),
        None => None,
    };
    let clearance = clearance::settings(&args.geometry, &condition)?;
    let prepared = prepare(source, fitted, condition, held_out, flown, settings)?;
    let prepared = match clearance {
        Some(c) => prepared.with_clearance(c),
        None => prepared,
    };
    let run_dir = super::claim_out(
        &args.out,
        Request {
            command: "predict",
            claim: super::fresh_or_overwrite(&args.overwrite),
            inputs: &read,
            resume: None,
        },
    )?;
    let start = Instant::now();
    let mut evaluator = spec.start(Arc::new(prepared.job.clone()), notices())?;
    let found = predict(
        &prepared,
        evaluator.as_mut(),
        &mut *crate::front::progress(),
    )?;
    drop(evaluator);
    let file = prediction_file(&prepared, &found, &args.from, start.elapsed().as_secs_f64());
    // Cleared (--overwrite) only now: a run stopped while it computed leaves the earlier one.
    run_dir.prepare()?;
    write_outputs(&found, &file, &args.out)?;
    crate::front::out(&summary_lines(&file, &args.out));
    drop(run_dir);
    Ok(())
}

/// The flown release of `--data`, whose metadata (when it names one) must give the condition
/// of `--scenario`.
fn flown(
    path: &Path,
    (scenario_path, condition): (&Path, &sepval_common::scenario::Scenario),
    policy: sepval_common::telemetry::outliers::Policy,
) -> Result<Flown> {
    let name = path.display().to_string();
    let data = inputs::read(path, policy, &mut tell()).with_context(|| format!("--data {name}"))?;
    let named = inputs::event_scenario(condition, &data, &name)?;
    let scenario_name = format!("--scenario {}", scenario_path.display());
    inputs::check_store(condition, &data, &name, &scenario_name)?;
    let (a, b) = (&named.flight, &condition.flight);
    let same = |x: f64, y: f64| (x - y).abs() <= 1e-9 * (1.0 + x.abs().max(y.abs()));
    if !(same(a.mach, b.mach)
        && same(a.altitude_m, b.altitude_m)
        && same(a.alpha_deg, b.alpha_deg)
        && same(a.beta_deg, b.beta_deg)
        && same(a.gamma_deg, b.gamma_deg))
    {
        bail!(
            "--data {name}: its metadata says it was flown at Mach {}, altitude {} m, alpha {} deg, beta {} deg, gamma {} deg, not at the condition of --scenario (Mach {}, altitude {} m, alpha {} deg, beta {} deg, gamma {} deg)",
            a.mach,
            a.altitude_m,
            a.alpha_deg,
            a.beta_deg,
            a.gamma_deg,
            b.mach,
            b.altitude_m,
            b.alpha_deg,
            b.beta_deg,
            b.gamma_deg
        );
    }
    Ok(Flown { name, data })
}

/// The terminal summary: a few short lines.
fn summary_lines(file: &PredictionFile, out: &Path) -> String {
    let k = file.t_s.len().saturating_sub(1);
    let ch = file.channels();
    let mut s = file
        .extrapolation
        .as_ref()
        .map_or(String::new(), |w| format!("warning:   {w}\n"));
    s.push_str(&format!(
        "predict:   t = {:.3} s: x {:.3} m [{:.3}, {:.3}], z {:.3} m [{:.3}, {:.3}], pitch {:.2} deg [{:.2}, {:.2}] ({:.0} % bands)\n",
        file.t_s.get(k).copied().unwrap_or(f64::NAN),
        ch[0].mid[k],
        ch[0].lo[k],
        ch[0].hi[k],
        ch[2].mid[k],
        ch[2].lo[k],
        ch[2].hi[k],
        ch[4].mid[k],
        ch[4].lo[k],
        ch[4].hi[k],
        100.0 * file.level
    ));
    let src = &file.sources;
    s.push_str(&format!(
        "sources:   factors {:.0} %, model form {:.0} %, measurement {:.0} % (most: {})\n",
        100.0 * src.factors.share,
        100.0 * src.model_form.share,
        100.0 * src.measurement.share,
        src.dominant.replace('_', " ")
    ));
    if let Some(c) = &file.check {
        s.push_str(&format!("check:     {}\n", c.verdict));
    }
    if let Some(c) = &file.clearance {
        s.push_str(&format!(
            "clearance: {}\n",
            sepval_predict::clearance::words(c)
        ));
    }
    s.push_str(&format!(
        "samples:   {} ({} ran), {} simulations, {:.1} s\n",
        file.samples, file.samples_used, file.evaluations, file.wall_s
    ));
    s.push_str(&format!(
        "report:    {}\n",
        out.join("report.html").display()
    ));
    s
}
