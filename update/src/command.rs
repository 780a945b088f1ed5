//! `sepval update` as a run of the one sequence ([`sepval_run::sequence`]): the configured
//! update ([`UpdateOptions::configure`]) run round by round, each round's evaluator started in
//! turn, its files written (with `--daveml`, the updated store as DAVE-ML) and what it says.

use std::path::Path;
use std::sync::Arc;

use sepval_common::evaluation::Job;
use sepval_run::sequence::{Evaluators, Run, RunError, Said};
use sepval_solve::run::ProgressObserver;

use crate::{Update, UpdateOptions, update, write_outputs};

/// An update configured: the releases, the options, and whether DAVE-ML is written.
pub struct UpdateRun {
    /// The releases fitted.
    pub job: Arc<Job>,
    /// The update's options.
    pub options: UpdateOptions,
    /// `--daveml`: the updated store written as DAVE-ML too, naming these releases.
    pub daveml: Option<Vec<String>>,
}

impl Run for UpdateRun {
    type Found = Update;

    fn job(&self) -> Option<Arc<Job>> {
        None
    }

    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<Update, RunError> {
        let job = Arc::clone(&self.job);
        Ok(update(&self.options, job, evaluators.each()?, progress)?)
    }

    fn write(&self, update: Update, out: &Path, _wall_s: f64) -> Result<Said, RunError> {
        write_outputs(&update, out)?;
        let mut summary = String::new();
        if let Some(releases) = &self.daveml {
            let command = format!("sepval update --out {}", out.display());
            let path = crate::daveml::write_daveml(&update, out, command, releases.clone())?;
            summary.push_str(&format!("daveml:    {}\n", path.display()));
        }
        summary.push_str(&update.summary(out));
        Ok(Said::summary(summary))
    }
}
