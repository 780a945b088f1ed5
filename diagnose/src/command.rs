//! `sepval diagnose` as a run of the one sequence ([`sepval_run::sequence`]): the configured
//! diagnosis ([`DiagnoseOptions::configure`]) run, and what it says. The diagnosis writes its
//! files as it goes (the baseline fit's checkpoints, the figures, diagnosis.json).

use std::path::Path;
use std::sync::Arc;

use sepval_common::evaluation::Job;
use sepval_run::sequence::{Evaluators, Run, RunError, Said};
use sepval_solve::run::ProgressObserver;

use crate::{DiagnoseOptions, Diagnosis, diagnose};

/// A diagnosis configured: the releases fitted and its options.
pub struct DiagnoseRun {
    /// The releases fitted.
    pub job: Arc<Job>,
    /// The diagnosis's options.
    pub options: DiagnoseOptions,
}

impl Run for DiagnoseRun {
    type Found = Diagnosis;

    fn job(&self) -> Option<Arc<Job>> {
        Some(Arc::clone(&self.job))
    }

    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<Diagnosis, RunError> {
        Ok(diagnose(&self.options, evaluators.one()?, progress)?)
    }

    /// The tables left by its fitted runs told as simulate and fit tell them
    /// (`--strict-tables` refused them after the baseline fit, before any other work).
    fn write(&self, d: Diagnosis, out: &Path, _wall_s: f64) -> Result<Said, RunError> {
        let mut summary = sepval_run::clearance::lines(d.clearance.as_ref());
        summary.push_str(&crate::summary(&d, out));
        let warnings = d.tables_left;
        Ok(Said { summary, warnings })
    }
}
