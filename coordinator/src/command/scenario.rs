//! `sepval scenario`: a scenario written as TOML (the embedded default to start your own).

use anyhow::Result;

use super::inputs;
use crate::cli::ScenarioArgs;

/// Runs `sepval scenario`.
pub fn run(args: ScenarioArgs) -> Result<()> {
    let scenario = inputs::scenario(args.scenario.as_deref(), None)?;
    let text = format!(
        "# sepval scenario (SI units, angles in degrees); docs/model.md section 1 describes each field.\n{}",
        scenario.to_toml_string()
    );
    sepval_common::atomic_file::write_atomically(&args.out, text.as_bytes())?;
    eprintln!("wrote {}", args.out.display());
    Ok(())
}
