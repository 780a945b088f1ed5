//! Where a run's inputs came from, as its checkpoints and records keep it.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

/// Where the fit's inputs came from (so that `rerun` and `--resume` can find them again, and
/// `sepval predict` the releases fitted); checkpoints, result.json and diagnosis.json hold it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InputsRecord {
    /// Data files (absolute paths); empty for the embedded default flight test.
    pub data: Vec<PathBuf>,
    /// Scenario file (absolute path); none for the embedded default.
    pub scenario: Option<PathBuf>,
    /// Model-extension file (absolute path), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extension: Option<PathBuf>,
    /// What was done with outliers in the data (docs/model.md section 6); written only when
    /// they were dropped, so that a record of the default reads and hashes as before.
    #[serde(
        default,
        skip_serializing_if = "sepval_common::telemetry::outliers::Policy::is_refuse"
    )]
    pub outliers: sepval_common::telemetry::outliers::Policy,
}
