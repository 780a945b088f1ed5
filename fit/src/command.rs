//! `sepval fit` as a run of the one sequence ([`sepval_run::sequence`]): a configured fit
//! ([`crate::configure`]) confirmed against the checkpoint it resumes from, run
//! ([`run_fit`]), its figures written and what it says of them.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use sepval_common::evaluation::Job;
use sepval_run::sequence::{Evaluators, Run, RunError, Said};
use sepval_solve::run::ProgressObserver;

use crate::pipeline::{FitOutput, write_fit_figures};
use crate::{FitOptions, run_fit};

/// A fit configured: its job, its options, and what is written beside result.json.
pub struct FitRun {
    /// The releases fitted.
    pub job: Arc<Job>,
    /// The run's options (a resumed checkpoint among them).
    pub options: FitOptions,
    /// The checkpoint file resumed from (`--resume`), with `options.resume`.
    pub resume_path: Option<PathBuf>,
    /// Whether the figures are drawn (not with `--no-figures`: result.json is the fit's).
    pub figures: bool,
}

impl Run for FitRun {
    type Found = FitOutput;

    fn job(&self) -> Option<Arc<Job>> {
        Some(Arc::clone(&self.job))
    }

    /// A resumed checkpoint's members re-evaluated and its generation replayed before going
    /// on from it.
    fn confirm(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        tell: &mut dyn FnMut(String),
    ) -> Result<(), RunError> {
        if let (Some(c), Some(path)) = (&self.options.resume, self.resume_path.as_deref()) {
            let report = crate::rerun::confirm(c, path, evaluators.one()?)?;
            tell(format!(
                "sepval: resuming from {}: {}",
                path.display(),
                report.checked()
            ));
        }
        Ok(())
    }

    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<FitOutput, RunError> {
        Ok(run_fit(&self.options, evaluators.one()?, progress)?)
    }

    /// The figures; the tables left by the best fit told (`--strict-tables` refused them
    /// before result.json was written).
    fn write(&self, output: FitOutput, out: &Path, _wall_s: f64) -> Result<Said, RunError> {
        let result = &output.result;
        let mut summary = sepval_run::clearance::lines(result.clearance.as_ref());
        summary.push_str(&result.summary());
        if self.figures {
            let n = write_fit_figures(out, &self.job, &output)?.len();
            let dir = out.join("figures");
            summary.push_str(&format!("{n} figures in {}\n", dir.display()));
        }
        let json = out.join("result.json");
        summary.push_str(&format!("results in {}\n", json.display()));
        let warnings = result.tables_left();
        Ok(Said { summary, warnings })
    }
}
