//! `sepval plan`: the next release to fly, from a diagnosis.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result};
use sepval_fit::out_dir::Request;
use sepval_plan::{PlanFile, Range, plan, plan_file, prepare, read_diagnosis, write_outputs};

use super::{evaluator_spec, notices, tell};
use crate::cli::PlanArgs;

/// Runs `sepval plan`. Every input (the flags, the diagnosis, its releases, the ranges against
/// its scenario) is checked before the output directory is claimed or a worker started, so a
/// refusal writes nothing; the directory is cleared (`--overwrite`) only once the plan is made.
pub fn run(args: PlanArgs) -> Result<()> {
    let spec = evaluator_spec(&args.eval)?;
    let ranges = ranges(&args);
    let diagnosis = read_diagnosis(&args.from)?;
    let record = diagnosis.inputs.clone();
    let (flown, _) = sepval_fit::inputs::job(
        &record.data,
        record.scenario.as_deref(),
        record.extension.as_deref(),
        record.outliers,
        &mut tell(),
    )
    .with_context(|| {
        format!(
            "--from {}: the releases the diagnosis was made from",
            args.from.display()
        )
    })?;
    let read = super::recorded_inputs(&args.from, &record, &[]);
    let prepared = prepare(diagnosis, &flown, &ranges, args.points)?;
    let run_dir = super::claim_out(
        &args.out,
        Request {
            command: "plan",
            claim: super::fresh_or_overwrite(&args.overwrite),
            inputs: &read,
            resume: None,
        },
    )?;
    let start = Instant::now();
    let mut evaluator = spec.start(Arc::new(prepared.job.clone()), notices())?;
    let found = plan(
        &prepared,
        evaluator.as_mut(),
        &mut *crate::front::progress(),
    )?;
    drop(evaluator);
    let file = plan_file(&prepared, &found, &args.from, start.elapsed().as_secs_f64());
    // Cleared (--overwrite) only now: a run stopped while it computed leaves the earlier one.
    run_dir.prepare()?;
    write_outputs(&prepared, &found, &file, &args.out)?;
    crate::front::out(&summary_lines(&file, &args.out));
    drop(run_dir);
    Ok(())
}

/// The ranges of the five condition flags given (parsed by clap), in the order of `[flight]`.
fn ranges(args: &PlanArgs) -> Vec<Range> {
    [
        &args.mach,
        &args.altitude_m,
        &args.alpha_deg,
        &args.beta_deg,
        &args.gamma_deg,
    ]
    .into_iter()
    .flatten()
    .cloned()
    .collect()
}

/// The terminal summary: a few short lines.
fn summary_lines(file: &PlanFile, out: &Path) -> String {
    let mut s = String::new();
    match file.conditions.first() {
        Some(c) => {
            s.push_str(&format!(
                "recommend: Mach {}, altitude {} m, alpha {} deg, beta {} deg, gamma {} deg\n",
                c.mach, c.altitude_m, c.alpha_deg, c.beta_deg, c.gamma_deg
            ));
            if file.ranked_by == "separation" {
                s.push_str(&format!(
                    "separates: {} of {} pair(s) (separation {:.1}, threshold {})\n",
                    c.separates.len(),
                    c.pairs.len(),
                    c.separation.unwrap_or(f64::NAN),
                    file.threshold
                ));
            } else {
                s.push_str("rivals:    none: planned for information alone\n");
            }
            s.push_str(&format!(
                "gain:      {:.3} in ln det of the answer's information\n",
                c.information_gain.unwrap_or(f64::NAN)
            ));
        }
        None => s.push_str("recommend: nothing (no condition)\n"),
    }
    s.push_str(&format!(
        "plan:      {} conditions, {} simulations, {:.1} s\n",
        file.conditions.len(),
        file.evaluations,
        file.wall_s
    ));
    s.push_str(&format!("report:    {}\n", out.join("plan.html").display()));
    s
}
