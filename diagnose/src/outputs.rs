//! What a diagnosis writes, once its analysis is done: the figures (residuals of the baseline
//! and the answer, and the reconstructed increments beside what the discovered terms give),
//! DIR/extension.toml and DIR/factors.json when a discovered extension is the answer,
//! DIR/diagnosis.json and DIR/report.html.

use std::path::Path;

use sepval_common::atomic_file::write_atomically;

use crate::Result;
use crate::analysis::Analysis;
use crate::answer::Setting;
use crate::increments::increment_figure;
use crate::page::report_html;
use crate::residuals::residual_figures;

/// Writes the outputs of `a` into `out`.
pub(super) fn write_outputs(out: &Path, setting: &Setting, a: &Analysis) -> Result<()> {
    let d = &a.diagnosis;
    let mut figures = residual_figures(
        out,
        &setting.job,
        &a.baseline.lm,
        &a.answer.model(&a.baseline).lm,
        setting.noise,
        &setting.events,
    )?;
    if !d.reconstruction.is_empty() {
        let name = "figures/increments.png";
        increment_figure(&out.join(name), &d.reconstruction, &a.curves)?;
        figures.insert(0, name.to_string());
    }
    if let Some(x) = &a.extension {
        write_atomically(&out.join("extension.toml"), x.toml.as_bytes())?;
        write_atomically(&out.join("factors.json"), &x.factors_json)?;
    }
    let html = report_html(d, &figures)?;
    let json = serde_json::to_vec_pretty(d).expect("a diagnosis serialises");
    write_atomically(&out.join("diagnosis.json"), &json)?;
    write_atomically(&out.join("report.html"), html.as_bytes())?;
    Ok(())
}
