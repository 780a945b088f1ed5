//! `sepval goals`: J_pos and J_att of one trajectory against another.

use anyhow::{Context, Result};
use sepval_common::goals::goals_between;
use sepval_common::telemetry::Trajectory;

use crate::cli::GoalsArgs;

/// Runs `sepval goals`.
pub fn run(args: GoalsArgs) -> Result<()> {
    let data = Trajectory::read(&args.data)?;
    let sim = Trajectory::read(&args.sim)?;
    let g = goals_between(&data, &sim).with_context(|| {
        format!(
            "cannot compare {} with {}",
            args.data.display(),
            args.sim.display()
        )
    })?;
    println!("J_pos = {:.9} m", g.j_pos_m);
    println!("J_att = {:.9} deg", g.j_att_deg);
    Ok(())
}
