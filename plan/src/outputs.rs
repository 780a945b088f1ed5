//! The plan's outputs: DIR/plan.json (its record, [`crate::record`]), DIR/plan.html (the
//! recommendation first, the private module `page`) and two figures,
//! DIR/figures/separation.png (the ranking's score over the two axes that vary it most) and
//! DIR/figures/rivals.png (every model's predicted trajectory at the recommended condition).
//! Each file is written atomically, the cancellation flag asked before each
//! ([`sepval_report::Written`]): a failed or interrupted plan leaves no partial file.

use std::path::{Path, PathBuf};

use sepval_report::figures::{MapAxis, channel_figure, condition_map};

use crate::conditions::Quantity;
use crate::ranking::{RankedCondition, Standing};
use crate::record::PlanFile;
use crate::{Plan, Prepared};

pub use sepval_report::OutputError;
use sepval_report::Written;

/// Writes the figures, the page and plan.json into `out` (plan.json last), the cancellation
/// flag asked before each ([`Written`]); returns the files written.
pub fn write_outputs(
    prepared: &Prepared,
    plan: &Plan,
    file: &PlanFile,
    out: &Path,
) -> Result<Vec<PathBuf>, OutputError> {
    let mut w = Written::into(out);
    let figures = w.figures()?;
    w.maybe(|| separation_map(prepared, plan, &figures.join("separation.png")).map(Some))?;
    w.maybe(|| rivals_figure(prepared, plan, &figures.join("rivals.png")))?;
    let html = crate::page::render(file, w.files(), out)?;
    w.file("plan.html", html.as_bytes())?;
    w.json("plan.json", file)?;
    Ok(w.done())
}

/// The score that ranks a condition: its separation with rivals, its information gain
/// without; NaN where it is missing or the condition diverged.
fn score(prepared: &Prepared, c: &RankedCondition) -> f64 {
    if matches!(c.standing, Standing::Diverged(_)) {
        return f64::NAN;
    }
    let v = if prepared.models.has_rivals() {
        c.separation
    } else {
        c.information_gain
    };
    v.unwrap_or(f64::NAN)
}

/// The position of condition `k` on each varied axis (the grid's last axis fastest).
fn coordinates(prepared: &Prepared, mut k: usize) -> Vec<usize> {
    let axes = &prepared.conditions.axes;
    let mut at = vec![0; axes.len()];
    for (a, (_, values)) in axes.iter().enumerate().rev() {
        at[a] = k % values.len();
        k /= values.len();
    }
    at
}

/// DIR/figures/separation.png: the score over the two varied axes along which its best value
/// changes most (the best over the other axes in each cell), the recommended cell outlined.
fn separation_map(prepared: &Prepared, plan: &Plan, path: &Path) -> Result<PathBuf, OutputError> {
    let axes = &prepared.conditions.axes;
    let scores: Vec<(Vec<usize>, f64)> = plan
        .ranking
        .conditions
        .iter()
        .map(|c| (coordinates(prepared, c.index), score(prepared, c)))
        .collect();
    // How much the best score changes along each axis.
    let spread = |a: usize| {
        let best: Vec<f64> = (0..axes[a].1.len())
            .map(|i| {
                scores
                    .iter()
                    .filter(|(at, v)| at[a] == i && v.is_finite())
                    .map(|(_, v)| *v)
                    .fold(f64::NEG_INFINITY, f64::max)
            })
            .filter(|v| v.is_finite())
            .collect();
        best.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            - best.iter().copied().fold(f64::INFINITY, f64::min)
    };
    let mut order: Vec<usize> = (0..axes.len()).collect();
    order.sort_by(|&a, &b| spread(b).total_cmp(&spread(a)).then(a.cmp(&b)));
    let mut shown: Vec<usize> = order.into_iter().take(2).collect();
    shown.sort_unstable();
    let base = [prepared.conditions.base.mach];
    let (xq, xv): (Quantity, &[f64]) = match shown.first() {
        Some(&a) => (axes[a].0, &axes[a].1),
        None => (Quantity::Mach, &base),
    };
    let y = shown.get(1).map(|&a| (axes[a].0, &axes[a].1));
    let rows = y.map_or(1, |(_, v)| v.len());
    let mut cells = vec![vec![f64::NAN; xv.len()]; rows];
    for (at, v) in &scores {
        let ix = shown.first().map_or(0, |&a| at[a]);
        let iy = shown.get(1).map_or(0, |&a| at[a]);
        let cell = &mut cells[iy][ix];
        if v.is_finite() && !(cell.is_finite() && *cell >= *v) {
            *cell = *v;
        }
    }
    let best = plan.ranking.recommended().map(|c| {
        let at = coordinates(prepared, c.index);
        (
            shown.first().map_or(0, |&a| at[a]),
            shown.get(1).map_or(0, |&a| at[a]),
        )
    });
    let (title, label) = if prepared.models.has_rivals() {
        (
            "Separation of the rival models (smallest BIC margin over the pairs)",
            "separation (BIC margin)",
        )
    } else {
        (
            "Information gain of the answer's parameters",
            "gain in ln det",
        )
    };
    condition_map(
        path,
        title,
        MapAxis {
            label: xq.label(),
            values: xv,
        },
        y.map(|(q, v)| MapAxis {
            label: q.label(),
            values: v,
        }),
        &cells,
        label,
        best,
    )?;
    Ok(path.to_path_buf())
}

/// DIR/figures/rivals.png: every model's trajectory at the recommended condition (none when
/// no condition is recommended).
fn rivals_figure(
    prepared: &Prepared,
    plan: &Plan,
    path: &Path,
) -> Result<Option<PathBuf>, OutputError> {
    let Some(best) = plan.ranking.recommended() else {
        return Ok(None);
    };
    let e = prepared.flown + best.index;
    let times = &prepared.job.events()[e].data.times_s;
    let rows: Vec<(String, Vec<[f64; 6]>)> = prepared
        .models
        .list
        .iter()
        .zip(&plan.simulated.runs)
        .filter_map(|(m, r)| {
            let obs = r.nominal[e].as_ref().ok()?;
            let label = if m.answer {
                format!("answer: {}", m.name)
            } else {
                m.name.clone()
            };
            let values = obs
                .iter()
                .map(|o| {
                    let (p, a) = (o.pos_m, o.att_deg);
                    [p[0], p[1], p[2], a[0], a[1], a[2]]
                })
                .collect();
            Some((label, values))
        })
        .collect();
    let sets: Vec<(&str, &[[f64; 6]])> = rows
        .iter()
        .map(|(l, v)| (l.as_str(), v.as_slice()))
        .collect();
    let f = &prepared.conditions.list[best.index].flight;
    let n = crate::page::number;
    let title = format!(
        "The models at the recommended condition (Mach {}, {} m, alpha {} deg, beta {} deg, gamma {} deg)",
        n(f.mach),
        n(f.altitude_m),
        n(f.alpha_deg),
        n(f.beta_deg),
        n(f.gamma_deg)
    );
    channel_figure(path, times, &sets, &title)?;
    Ok(Some(path.to_path_buf()))
}
