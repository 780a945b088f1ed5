//! `sepval goals`: J_pos and J_att of one trajectory against another.

use anyhow::{Context, Result};
use sepval_common::goals::{Goals, goals_between};
use sepval_common::telemetry::Trajectory;
use sepval_run::inputs::screen::{read_screened, screen};

use super::tell;
use crate::cli::GoalsArgs;

/// Runs `sepval goals`. Both files are screened for outliers; `--outliers drop` leaves out the
/// rows of either's outliers from both, so that their times still pair.
pub fn run(args: GoalsArgs) -> Result<()> {
    let policy = args.outliers.policy();
    let (data, in_data) = read_screened(&args.data)?;
    let (sim, in_sim) = read_screened(&args.sim)?;
    let either: Vec<_> = in_data.iter().chain(&in_sim).copied().collect();
    let data = screen(&args.data, data, &in_data, &either, policy)?.told(&mut tell());
    let sim = screen(&args.sim, sim, &in_sim, &either, policy)?.told(&mut tell());
    let g = between(
        (&args.data.display().to_string(), &data),
        (&args.sim.display().to_string(), &sim),
    )?;
    say!("J_pos = {:.9} m", g.j_pos_m);
    say!("J_att = {:.9} deg", g.j_att_deg);
    Ok(())
}

/// The goals of `sim` against `data`, each given with the name that errors use (a file's path).
pub fn between(data: (&str, &Trajectory), sim: (&str, &Trajectory)) -> Result<Goals> {
    goals_between(data.1, sim.1)
        .with_context(|| format!("cannot compare {} with {}", data.0, sim.0))
}
