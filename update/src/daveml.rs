//! `sepval update --daveml`: the updated store as DIR/store.dml (DAVE-ML 2.0, docs/daveml.md),
//! each correction's standard deviation as its table's uncertainty, the releases it was
//! updated from named in its provenance.

use std::path::{Path, PathBuf};

use sepval_common::scenario::Scenario;
use sepval_daveml::{CorrectionSpread, DavemlError, Provenance};

use crate::Update;

/// Writes the store of `u`, written in `out` (out/scenario.toml), as out/store.dml; `command`
/// and `releases` are its provenance. Returns the file written.
pub fn write_daveml(
    u: &Update,
    out: &Path,
    command: String,
    releases: Vec<String>,
) -> Result<PathBuf, DavemlError> {
    let toml = out.join("scenario.toml");
    let store = Scenario::load(&toml).map_err(|source| DavemlError::Scenario {
        file: toml.display().to_string(),
        source,
    })?;
    let spreads: Vec<CorrectionSpread> = u
        .file
        .corrections
        .iter()
        .map(|c| CorrectionSpread {
            field: c.field.clone(),
            variable: c.variable.clone(),
            breakpoints: c.breakpoints.clone(),
            std: c.std.clone(),
        })
        .collect();
    let bands = sepval_daveml::bands(&store, &spreads)?;
    let path = out.join("store.dml");
    sepval_daveml::write_model(&path, &store, &bands, &Provenance::now(command, releases))?;
    Ok(path)
}
