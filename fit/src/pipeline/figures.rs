//! The fit's figures, DIR/figures: the study's Figures 1-6 (trajectories), Figure 7 (factors),
//! the Pareto fronts, the convergence histories and, for refined fits, the correlation of the
//! estimates; drawn by `sepval_report::figures` from the result and the plotted samples.

use std::path::{Path, PathBuf};

use sepval_common::evaluation::Job;
use sepval_common::telemetry::Trajectory;
use sepval_core::factors::Factor;
use sepval_report::Written;
use sepval_report::figures::{
    FigureError, Series, Track, convergence_figure, correlation_figure, factor_figure,
    pareto_figure, trajectory_figures,
};

use super::outputs::plot_stride;
use super::{FitError, FitOutput};
use crate::results::{FitResult, MethodResult};

/// Writes the fit's figures into DIR/figures: the study's Figures 1-6 (trajectories of the
/// first event against each method's best), Figure 7 (factors beside the truth, when known),
/// the Pareto fronts and the convergence histories, through [`Written`] (each atomically, the
/// cancellation flag asked before each). Returns the files written.
pub fn write_fit_figures(
    dir: &Path,
    job: &Job,
    output: &FitOutput,
) -> Result<Vec<PathBuf>, FitError> {
    let mut w = Written::into(dir);
    let fig_dir = w.figures()?;
    let r = &output.result;
    w.several(|| write_trajectories(&fig_dir, job, output))?;
    w.figure(fig_dir.join("fig7_factors.png"), |path| {
        write_factors(path, job, r)
    })?;
    w.figure(fig_dir.join("pareto_front.png"), |path| {
        write_fronts(path, r)
    })?;
    w.figure(fig_dir.join("convergence.png"), |path| {
        write_convergence(path, r)
    })?;
    if let Some(id) = &r.identifiability {
        let names: Vec<&str> = id.names.iter().map(String::as_str).collect();
        w.figure(fig_dir.join("correlation.png"), |path| {
            correlation_figure(
                path,
                &names,
                &id.correlation,
                "Correlation of the refined estimates (|rho| > 0.9: compensating)",
            )
        })?;
    }
    Ok(w.done())
}

/// A method's name as the legends write it.
fn label(m: &str) -> String {
    match m {
        "ga" => "genetic algorithm".to_string(),
        "hill" => "hill climber".to_string(),
        other => other.to_string(),
    }
}

/// Per method, its legend label and `values` of its result.
fn per_method<T>(r: &FitResult, values: impl Fn(&MethodResult) -> Vec<T>) -> Vec<(String, Vec<T>)> {
    r.methods
        .iter()
        .map(|(m, v)| (label(m), values(v)))
        .collect()
}

/// The borrowed form the figures take of [`per_method`]'s.
fn borrowed<T>(owned: &[(String, Vec<T>)]) -> Vec<(&str, &[T])> {
    owned
        .iter()
        .map(|(l, v)| (l.as_str(), v.as_slice()))
        .collect()
}

/// Figures 1-6: the first event's data against each method's best trajectory. A long record
/// is drawn from every k-th sample (a figure has about a thousand pixels across; the plotted
/// copies stay small).
fn write_trajectories(
    fig_dir: &Path,
    job: &Job,
    output: &FitOutput,
) -> Result<Vec<PathBuf>, FigureError> {
    let first = &job.events()[0];
    let stride = plot_stride(job);
    let pick = |n: usize| (0..n).step_by(stride);
    let data = Trajectory {
        times_s: pick(first.data.len())
            .map(|k| first.data.times_s[k])
            .collect(),
        pos_m: pick(first.data.len())
            .map(|k| first.data.pos_m[k])
            .collect(),
        att_deg: pick(first.data.len())
            .map(|k| first.data.att_deg[k])
            .collect(),
        ..Default::default()
    };
    let fits: Vec<(String, Trajectory)> = output
        .best_plotted
        .iter()
        .map(|(m, plotted)| {
            let traj = Trajectory {
                times_s: data.times_s.clone(),
                pos_m: plotted.iter().map(|o| o.pos_m).collect(),
                att_deg: plotted.iter().map(|o| o.att_deg).collect(),
                ..Default::default()
            };
            (label(m), traj)
        })
        .collect();
    let series: Vec<Series> = fits
        .iter()
        .map(|(l, t)| Series {
            label: l,
            traj: track(t),
        })
        .collect();
    trajectory_figures(fig_dir, track(&data), &series)
}

/// A trajectory as the figures draw it.
fn track(t: &Trajectory) -> Track<'_> {
    Track {
        times_s: &t.times_s,
        pos_m: &t.pos_m,
        att_deg: &t.att_deg,
    }
}

/// Figure 7: each method's factors beside the truth, when known.
fn write_factors(path: &Path, job: &Job, r: &FitResult) -> Result<(), FigureError> {
    let ranges: Vec<(f64, f64)> = job
        .factor_table()
        .0
        .iter()
        .map(|s| (s.min, s.max))
        .collect();
    let values = per_method(r, |v| v.best.factors.0.to_vec());
    let truth = r.truth.map(|t| t.0.to_vec());
    factor_figure(
        path,
        &Factor::NAMES,
        &ranges,
        &borrowed(&values),
        truth.as_deref(),
    )
}

/// Each method's Pareto front, with the noise levels.
fn write_fronts(path: &Path, r: &FitResult) -> Result<(), FigureError> {
    let fronts = per_method(r, |v| {
        v.pareto_front
            .iter()
            .map(|p| [p.j_pos_m, p.j_att_deg])
            .collect()
    });
    pareto_figure(
        path,
        &borrowed(&fronts),
        Some((r.sigma_pos_m, r.sigma_att_deg)),
    )
}

/// Each method's best weighted goal against its simulations.
fn write_convergence(path: &Path, r: &FitResult) -> Result<(), FigureError> {
    let histories = per_method(r, |v| {
        v.history
            .iter()
            .map(|h| (h.best.evaluations, h.best.best_weighted))
            .collect()
    });
    convergence_figure(path, &borrowed(&histories), Some(2.0))
}
