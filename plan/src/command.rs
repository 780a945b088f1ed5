//! `sepval plan` as a run of the one sequence ([`sepval_run::sequence`]): the diagnosis planned
//! from and its releases read ([`request`]), the plan prepared over the ranges given, then run,
//! its files written and what it says.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use sepval_common::evaluation::Job;
use sepval_run::inputs::Tell;
use sepval_run::out_dir::{Claim, recorded_inputs};
use sepval_run::sequence::{Evaluators, Run, RunError, Said, Writes};
use sepval_solve::run::ProgressObserver;

use crate::{Plan, PlanError, Prepared, Range, plan, plan_file, prepare, read_from};

/// A plan as the flags ask for it: paths and numbers, nothing read yet.
pub struct PlanRequest {
    /// The diagnosis planned from (`--from`).
    pub from: PathBuf,
    /// The ranges of the conditions given, in the order of `[flight]`.
    pub ranges: Vec<Range>,
    /// Points per axis.
    pub points: usize,
    /// `--out`.
    pub out: PathBuf,
    /// Fresh or `--overwrite`.
    pub claim: Claim,
}

/// A plan prepared, with the diagnosis it is made from.
pub struct PlanRun {
    /// Everything the plan needs.
    pub prepared: Prepared,
    /// `--from`, as the record names it.
    pub from: PathBuf,
}

/// The request read and checked: the diagnosis, its releases and the ranges against its
/// scenario; where the plan writes.
pub fn request(r: PlanRequest, tell: Tell) -> Result<(Writes, PlanRun), PlanError> {
    let (diagnosis, flown) = read_from(&r.from, tell)?;
    let read = recorded_inputs(&r.from, &diagnosis.inputs, &[]);
    let prepared = prepare(diagnosis, &flown, &r.ranges, r.points)?;
    let writes = Writes::new(r.out, "plan", r.claim, read);
    let from = r.from;
    Ok((writes, PlanRun { prepared, from }))
}

impl Run for PlanRun {
    type Found = Plan;

    fn job(&self) -> Option<Arc<Job>> {
        Some(Arc::new(self.prepared.job.clone()))
    }

    fn run(
        &mut self,
        evaluators: &mut Evaluators<'_>,
        progress: &mut dyn ProgressObserver,
    ) -> Result<Plan, RunError> {
        Ok(plan(&self.prepared, evaluators.one()?, progress)?)
    }

    fn write(&self, found: Plan, out: &Path, wall_s: f64) -> Result<Said, RunError> {
        let file = plan_file(&self.prepared, &found, &self.from, wall_s);
        crate::write_outputs(&self.prepared, &found, &file, out)?;
        Ok(Said::summary(crate::summary(&file, out)))
    }
}
