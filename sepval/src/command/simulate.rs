//! `sepval simulate`: one release, written as a trajectory file.

use anyhow::Result;
use sepval_predict::ClearanceSettings;
use sepval_predict::one_release::{ReleaseRequest, SimulatedRelease, simulate_release};
use sepval_run::inputs;
use sepval_run::out_dir::Input;

use super::positive;
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
    let geometry = super::geometry(&args.geometry);
    read.extend(geometry.inputs());
    super::out_file_apart(&args.out, &read)?;
    let effects = inputs::effects(&args.effects)?;
    let scenario = inputs::scenario(
        args.model.scenario.as_deref(),
        args.model.extension.as_deref(),
    )?;
    let factors = inputs::factors(&args.factors, &scenario.factors)?;
    let clearance = ClearanceSettings::of(&geometry, &scenario)?;
    let request = ReleaseRequest {
        scenario: &scenario,
        factors,
        effects: &effects,
        extension: args.model.extension.as_deref(),
        t_end_s: t_end,
        rate_hz: rate,
        noise_seed: args.noise_seed,
        clearance: clearance.as_ref(),
        strict_tables: args.tables.strict_tables,
    };
    let SimulatedRelease {
        trajectory: mut traj,
        clearance,
        tables_left,
    } = simulate_release(&request)?;
    traj.comments
        .insert(0, format!("sepval simulate --factors {}", args.factors));
    match &clearance {
        Some((distance_m, line)) => {
            traj.write_with_columns(&args.out, &[("clearance_m", distance_m)])?;
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
    for l in &tables_left {
        note!("warning: {l}");
    }
    Ok(())
}
