//! What a diagnosis writes, once its analysis is done: the figures (residuals of the baseline
//! and the answer, and the reconstructed increments beside what the discovered terms give),
//! DIR/extension.toml and DIR/factors.json when a discovered extension is the answer,
//! DIR/diagnosis.json and DIR/report.html.
//!
//! The files are written through the output kit (`sepval_report::Written`; the figures by
//! their own writers, which do the same): each written atomically, a signal observed before
//! each one (issue 21, item 9). A diagnosis interrupted here ends with `RunError::Interrupted`
//! (exit status 130), the files already written stay whole and the others are not begun. The
//! progress observer sees this stage as `outputs`, one step per file.

use std::path::Path;

use sepval_report::{OutputError, Written};
use sepval_solve::run::{Progress, ProgressObserver};

use crate::Result;
use crate::analysis::Analysis;
use crate::answer::Setting;
use crate::increments::increment_figure;
use crate::page::report_html;
use crate::residuals::residual_figures;

/// The outputs stage as its observer sees it: a signal checked before each file, each file
/// written counted as a step.
struct Steps<'a> {
    progress: &'a mut dyn ProgressObserver,
    done: usize,
    files: usize,
    goals: [f64; 2],
}

impl Steps<'_> {
    /// Before a figure written by its own writer: `Err` once a signal asked the process to
    /// stop.
    fn next(&self) -> Result<()> {
        Ok(OutputError::check_cancel()?)
    }

    /// After a file (or a group of figures).
    fn written(&mut self, files: usize) {
        self.done += files;
        self.progress.progress(&Progress {
            step: self.done,
            steps: Some(self.files),
            evaluations: 0,
            best: self.goals,
        });
    }
}

/// Writes the outputs of `a` into `out`.
pub(super) fn write_outputs(
    out: &Path,
    setting: &Setting,
    a: &Analysis,
    progress: &mut dyn ProgressObserver,
) -> Result<()> {
    let d = &a.diagnosis;
    let events = setting.job.events().len();
    let files = events
        + usize::from(!d.reconstruction.is_empty())
        + 2 * usize::from(a.extension.is_some())
        + 2;
    progress.start("outputs", Some(files));
    let mut steps = Steps {
        progress,
        done: 0,
        files,
        goals: [d.extended.j_pos_m, d.extended.j_att_deg],
    };
    steps.next()?;
    let mut figures = residual_figures(
        out,
        &setting.job,
        &a.baseline.lm,
        &a.answer.model(&a.baseline).lm,
        setting.noise,
        &setting.events,
    )?;
    steps.written(events);
    if !d.reconstruction.is_empty() {
        steps.next()?;
        let name = "figures/increments.png";
        increment_figure(&out.join(name), &d.reconstruction, &a.curves)?;
        figures.insert(0, name.to_string());
        steps.written(1);
    }
    let mut w = Written::into(out);
    if let Some(x) = &a.extension {
        w.file("extension.toml", x.toml.as_bytes())?;
        steps.written(1);
        w.file("factors.json", &x.factors_json)?;
        steps.written(1);
    }
    let html = report_html(d, &figures)?;
    w.file("diagnosis.json", &sepval_run::sealed::sealed(d))?;
    steps.written(1);
    w.file("report.html", html.as_bytes())?;
    steps.written(1);
    steps.progress.finish();
    Ok(())
}
