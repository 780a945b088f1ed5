//! `sepval goals`: J_pos and J_att of one trajectory against another.

use anyhow::{Context, Result};
use sepval_common::goals::{Goals, goals_between};
use sepval_common::telemetry::Trajectory;

use crate::cli::GoalsArgs;

/// Runs `sepval goals`.
pub fn run(args: GoalsArgs) -> Result<()> {
    let data = Trajectory::read(&args.data)?;
    let sim = Trajectory::read(&args.sim)?;
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
