//! `sepval simulate`: one release, written as a trajectory file.

use anyhow::{Context, Result};
use sepval_common::simulation::{Simulator, sample_times};
use sepval_common::synthetic::synthetic_flight_test_logged;
use sepval_core::limits::{check_sampling, check_steps};
use sepval_core::number_text::Shown;
use sepval_fit::inputs;
use sepval_fit::out_dir::Input;
use sepval_predict::releases;

use super::{clearance, positive};
use crate::cli::SimulateArgs;

/// Runs `sepval simulate`.
pub fn run(args: SimulateArgs) -> Result<()> {
    let t_end = args.t_end.map(|t| positive("--t-end", t)).transpose()?;
    let rate = args.rate.map(|r| positive("--rate", r)).transpose()?;
    // Nothing the run reads may be written over: its scenario, the tables the scenario names,
    // its extension, factors and geometry.
    let mut read =
        super::scenario_inputs(args.model.scenario.as_ref(), args.model.extension.as_ref());
    if let Some(path) = inputs::factors_file(&args.factors) {
        read.push(Input::file("--factors", path));
    }
    read.extend(super::geometry_inputs(&args.geometry));
    super::out_file_apart(&args.out, &read)?;
    let effects = inputs::effects(&args.effects)?;
    let scenario = inputs::scenario(
        args.model.scenario.as_deref(),
        args.model.extension.as_deref(),
    )?;
    let factors = inputs::factors(&args.factors, &scenario.factors)?;
    let clearance = clearance::settings(&args.geometry, &scenario)?;
    let t_end = t_end.unwrap_or(scenario.integrator.t_end_s);
    let rate = rate.unwrap_or(scenario.integrator.rate_hz);
    // The work of the run, refused before the sample times are made.
    let (t_shown, rate_shown) = (Shown(t_end), Shown(rate));
    check_steps(t_end, scenario.integrator.dt_s).with_context(|| format!("--t-end {t_shown}"))?;
    check_sampling(t_end, rate)
        .with_context(|| format!("--t-end {t_shown} with --rate {rate_shown}"))?;
    let sim = Simulator::new(&scenario);
    let times = sample_times(t_end, rate);
    let (mut traj, log) =
        synthetic_flight_test_logged(&sim, &factors, &effects, &times, args.noise_seed)
            .context("simulation failed")?;
    // Tables left: held at the edge and reported, or refused (docs/model.md section 3).
    let left = sim.table_excursions(&log);
    if args.tables.strict_tables && !left.is_empty() {
        let lines: Vec<String> = left.iter().map(|e| e.to_string()).collect();
        anyhow::bail!(
            "--strict-tables: the run {} (nothing written)",
            lines.join("; and ")
        );
    }
    traj.comments
        .insert(0, format!("sepval simulate --factors {}", args.factors));
    if let Some(path) = &args.model.extension {
        // The extension's terms as the model held them (the scenario's own terms included),
        // so that the file says what made it.
        traj.push_metadata("extension", &path.display().to_string());
        let terms: Vec<String> = sim
            .model()
            .extension
            .iter()
            .map(|t| format!("{} {} = {}", t.axis.name(), t.formula(), t.coefficient))
            .collect();
        traj.push_metadata("extension_terms", &terms.join("; "));
    }
    match &clearance {
        Some(c) => {
            // The clearance of the trajectory written (its noise included, with --noise-seed).
            let trace = releases::trace(c, &traj).context("the clearance of the trajectory")?;
            let line = releases::words(c, &trace);
            traj.push_metadata("clearance", &line);
            traj.write_with_columns(&args.out, &[("clearance_m", &trace.distance_m)])?;
            note!("clearance: {line}");
        }
        None => traj.write(&args.out)?,
    }
    note!(
        "wrote {} ({} samples, t = 0 to {} s)",
        args.out.display(),
        traj.len(),
        traj.times_s.last().copied().unwrap_or(0.0)
    );
    for e in &left {
        note!("warning: {e}");
    }
    Ok(())
}
