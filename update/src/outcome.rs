//! What an update produces before anything is written: its baseline, and the update itself
//! (its record, the store, the factors and what the figure draws).

use sepval_core::factors::Factors;
use sepval_solve::lm::LmResult;

use crate::record::UpdateFile;
use crate::store::Store;

/// The baseline: the 17 factors fitted to every release, converged.
#[derive(Debug, Clone)]
pub struct Baseline {
    /// The factors.
    pub factors: Factors,
    /// Its refinement (17 parameters, every sample's residuals).
    pub lm: LmResult,
    /// Simulations run.
    pub evaluations: u64,
}

/// A finished update.
#[derive(Debug, Clone)]
pub struct Update {
    /// DIR/update.json.
    pub file: UpdateFile,
    /// The updated store.
    pub store: Store,
    /// The factors fitted with it.
    pub factors: Factors,
    /// What the figure draws, per correction kept.
    pub panels: Vec<PanelData>,
}

/// What the figure draws of one correction.
#[derive(Debug, Clone)]
pub struct PanelData {
    /// Caption.
    pub caption: String,
    /// The variable with its unit.
    pub x_label: String,
    /// The curve: variable, value, standard deviation.
    pub x: Vec<f64>,
    /// See `x`.
    pub value: Vec<f64>,
    /// See `x`.
    pub std: Vec<f64>,
    /// The explored range.
    pub explored: (f64, f64),
    /// Breakpoints and values.
    pub knots: (Vec<f64>, Vec<f64>),
    /// The reconstruction's windows as evidence: (variable, value, standard deviation).
    pub evidence: Vec<(f64, f64, f64)>,
}

impl Update {
    /// What `sepval update` says on the terminal of the update written in `out`: the verdict,
    /// what the releases cannot tell, where the store, the factors and the report are.
    pub fn summary(&self, out: &std::path::Path) -> String {
        let mut s = format!("update:    {}\n", self.file.verdict);
        for c in &self.file.cannot_tell {
            s.push_str(&format!("open:      {c}\n"));
        }
        s.push_str(&format!(
            "store:     {} ({} table files), factors {}\n",
            out.join("scenario.toml").display(),
            self.store.files.len(),
            out.join("factors.json").display()
        ));
        s.push_str(&format!(
            "report:    {} ({} simulations, {:.1} s)\n",
            out.join("report.html").display(),
            self.file.evaluations,
            self.file.wall_s
        ));
        s
    }
}
