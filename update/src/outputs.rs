//! The update's outputs, in this order: DIR/figures/corrections.png (when a correction is
//! kept), the updated store (DIR/tables/*.csv, then DIR/scenario.toml, read back and compared
//! with the store fitted), DIR/factors.json, DIR/report.html and DIR/update.json last. Each
//! file is written atomically and the cancellation flag is checked before each
//! ([`sepval_report::Written`]): a failed or interrupted update leaves no partial file.

use std::path::{Path, PathBuf};

use sepval_common::scenario::Scenario;
use sepval_report::figures::{CorrectionPanel, correction_figure};

pub use sepval_report::OutputError;
use sepval_report::Written;

use crate::outcome::Update;

/// Outputs that could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutputsError {
    /// A file, the figure or the page.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// The store written does not read back as it was fitted.
    #[error("the updated store written to {} does not read back as it was fitted: {reason}", path.display())]
    ReadBack {
        /// The scenario file.
        path: PathBuf,
        /// What differs, or why it does not read.
        reason: String,
    },
}

/// Writes every output into `out` ([`Written`]: the cancellation flag asked before each file,
/// each written atomically); returns the files written.
pub fn write_outputs(update: &Update, out: &Path) -> Result<Vec<PathBuf>, OutputsError> {
    let mut w = Written::into(out);
    let figures = w.figures()?;
    if !update.panels.is_empty() {
        let panels: Vec<CorrectionPanel> = update
            .panels
            .iter()
            .map(|p| CorrectionPanel {
                caption: &p.caption,
                x_label: &p.x_label,
                x: &p.x,
                value: &p.value,
                std: &p.std,
                explored: p.explored,
                knots: (&p.knots.0, &p.knots.1),
                evidence: p.evidence.clone(),
            })
            .collect();
        w.figure(figures.join("corrections.png"), |path| {
            correction_figure(
                path,
                &panels,
                "The store's data updated: each correction with its ±2σ band",
            )
        })?;
    }
    write_store(update, &mut w)?;
    w.json("factors.json", &update.factors)?;
    let figure = (!update.panels.is_empty()).then_some("figures/corrections.png");
    let html = crate::page::render(&update.file, figure).map_err(OutputError::from)?;
    w.file("report.html", html.as_bytes())?;
    w.json("update.json", &update.file)?;
    Ok(w.done())
}

/// The header of the scenario written.
const HEADER: &str = "# sepval scenario written by `sepval update` (SI units, angles in degrees; docs/model.md section 1).\n# Its tables are the CSV files under tables/, relative to this file; update.json says what was corrected and how sure it is.\n";

/// DIR/tables/*.csv, then DIR/scenario.toml, then the check that it reads back as fitted.
fn write_store(update: &Update, w: &mut Written) -> Result<(), OutputsError> {
    let store = &update.store;
    if !store.files.is_empty() {
        w.dir("tables")?;
    }
    for (rel, text) in &store.files {
        w.file(rel, text.as_bytes())?;
    }
    let text = format!("{HEADER}{}", store.file_form.to_toml_string());
    let path = w.file("scenario.toml", text.as_bytes())?;
    let back = Scenario::load(&path).map_err(|e| OutputsError::ReadBack {
        path: path.clone(),
        reason: format!("{e:#}"),
    })?;
    if back != store.scenario {
        return Err(OutputsError::ReadBack {
            path,
            reason: "its content differs from the store fitted".into(),
        });
    }
    Ok(())
}
