//! What a discovered extension's terms give along its fitted trajectory (`docs/discovery.md`
//! section 11.7): per event and axis, the coefficient increments the figure of the
//! reconstruction draws beside the reconstructed ones, and that figure.

use std::path::Path;

use sepval_common::evaluation::Job;
use sepval_common::extension::Axis;
use sepval_report::figures::{
    IncrementPanel, IncrementSeries, increment_figure as draw_increments,
};

use super::library::{self, Sample};
use super::reconstruct::Reconstruction;
use super::{Fitted, Result};

/// Per event, per axis: (times \[s\], values).
pub(super) type Curves = Vec<Vec<(Vec<f64>, Vec<f64>)>>;

/// Per event and axis, the increment the extension's terms give along its fitted trajectory:
/// (times \[s\], values), the ejector's while the forward foot strokes.
pub(super) fn model_increments(job: &Job, fitted: &Fitted) -> Result<Curves> {
    let c = fitted.candidate(job)?;
    let history = library::flow_history(job, &c);
    Ok(history
        .iter()
        .map(|samples| {
            Axis::FORCE_AND_MOMENT
                .iter()
                .map(|&axis| {
                    let pick = |s: &Sample| -> Option<f64> {
                        if axis == Axis::Ejector {
                            (s.sigma[0] < 1.0).then(|| {
                                c.terms
                                    .iter()
                                    .filter(|t| t.axis == axis)
                                    .map(|t| {
                                        t.coefficient * t.ejector_value(s.input.t_s, s.sigma[0])
                                    })
                                    .sum()
                            })
                        } else {
                            Some(c.terms.aero_increments(&s.input)[axis.index()])
                        }
                    };
                    samples
                        .iter()
                        .filter_map(|s| pick(s).map(|v| (s.input.t_s, v)))
                        .unzip()
                })
                .collect()
        })
        .collect())
}

/// Names of the increment axes in the figure.
fn axis_caption(axis: &str) -> String {
    let what = match axis {
        "CA" => "axial force",
        "CY" => "side force",
        "CZ" => "normal force",
        "Cl" => "roll moment",
        "Cm" => "pitch moment",
        "Cn" => "yaw moment",
        _ => "ejector force, fraction",
    };
    if axis == "ejector" {
        format!("d ejector ({what})")
    } else {
        format!("d{axis} ({what})")
    }
}

/// DIR/figures/increments.png: the reconstructed increments per axis with their bands, and
/// what the discovered terms give (`model[event][axis]`, axes in `Axis::FORCE_AND_MOMENT`
/// order: a wind is no increment, it acts through the flow).
pub(super) fn increment_figure(
    path: &Path,
    reconstruction: &[Reconstruction],
    model: &Curves,
) -> Result<()> {
    let axes = ["CA", "CY", "CZ", "Cl", "Cm", "Cn", "ejector"];
    let captions: Vec<String> = axes.iter().map(|a| axis_caption(a)).collect();
    let panels: Vec<IncrementPanel> = axes
        .iter()
        .enumerate()
        .map(|(k, axis)| IncrementPanel {
            axis: &captions[k],
            series: reconstruction
                .iter()
                .filter_map(|r| {
                    r.increments
                        .iter()
                        .find(|s| s.axis == *axis)
                        .map(|s| IncrementSeries {
                            label: &r.event,
                            t_s: &s.t_s,
                            value: &s.value,
                            std: &s.std,
                        })
                })
                .collect(),
            model: model
                .iter()
                .filter_map(|e| e.get(k).map(|(t, v)| (t.as_slice(), v.as_slice())))
                .filter(|(t, v)| !t.is_empty() && v.iter().any(|x| *x != 0.0))
                .collect(),
        })
        .collect();
    draw_increments(
        path,
        &panels,
        "What the model lacks: reconstructed coefficient increments (±2σ) and the discovered terms",
    )?;
    Ok(())
}
