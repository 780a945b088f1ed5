//! DIR/report.html: the update as a page for people, the answer first (what was corrected, and
//! how well the updated store predicts what it was not fitted to), then what the data cannot
//! tell apart, the predictions fold by fold, the corrections with their figure, and how they
//! were chosen. The page is `templates/update.html` in sepval-report's layout.

use sepval_common::correction::Target;
use sepval_report::html::{HtmlError, PageTemplate, render_page};
use serde::Serialize;

use crate::record::UpdateFile;
use crate::words::{goals_text, number};

const UPDATE: PageTemplate = PageTemplate {
    name: "update.html",
    source: include_str!("../templates/update.html"),
};

#[derive(Serialize)]
struct Fold {
    held_out: String,
    baseline: String,
    factors_only: String,
    updated: String,
}

#[derive(Serialize)]
struct Validation {
    release: String,
    baseline: String,
    factors_only: String,
    updated: String,
}

#[derive(Serialize)]
struct Correction {
    name: String,
    field: String,
    explored: String,
    lambda: String,
    values: String,
}

#[derive(Serialize)]
struct AxisRow {
    axis: String,
    scored: String,
}

#[derive(Serialize)]
struct Round {
    round: usize,
    correction: String,
    gain: String,
    before: String,
    with: String,
    kept: &'static str,
}

#[derive(Serialize)]
struct Page {
    verdict: String,
    cannot_tell: Vec<String>,
    cv_method: String,
    folds: Vec<Fold>,
    cv_updated: String,
    cv_factors: String,
    noise: String,
    validation: Vec<Validation>,
    corrections: Vec<Correction>,
    figure: String,
    screen_folds: String,
    edf: String,
    residual_scale: String,
    axes: Vec<AxisRow>,
    rounds: Vec<Round>,
    smoothness: String,
    notes: Vec<String>,
    releases: String,
    fit_updated: String,
    fit_factors: String,
    files: String,
    evaluations: u64,
    wall_s: String,
}

/// The page of `file`, with the figure at `figure` (relative to the page) when there is one.
pub fn render(file: &UpdateFile, figure: Option<&str>) -> Result<String, HtmlError> {
    let cv = &file.cross_validation;
    let corrections = correction_rows(file);
    let axes = axis_rows(file);
    let page = Page {
        verdict: file.verdict.clone(),
        cannot_tell: file.cannot_tell.clone(),
        cv_method: capitalised(&cv.method),
        folds: cv
            .folds
            .iter()
            .map(|f| Fold {
                held_out: f.held_out.clone(),
                baseline: goals_text(&f.baseline),
                factors_only: goals_text(&f.factors_only),
                updated: goals_text(&f.updated),
            })
            .collect(),
        cv_updated: number(cv.cv_chi2_updated, 5),
        cv_factors: number(cv.cv_chi2_factors_only, 5),
        noise: format!(
            "{} mm, {} deg",
            number(1000.0 * file.sigma_pos_m, 3),
            number(file.sigma_att_deg, 3)
        ),
        validation: file
            .validation
            .iter()
            .map(|v| Validation {
                release: v.release.clone(),
                baseline: goals_text(&v.baseline),
                factors_only: goals_text(&v.factors_only),
                updated: goals_text(&v.updated),
            })
            .collect(),
        corrections,
        figure: figure.unwrap_or_default().to_string(),
        screen_folds: if file.releases.len() > 1 {
            "a release left out".into()
        } else {
            "a block of the release left out".into()
        },
        edf: number(file.effective_parameters, 3),
        residual_scale: number(file.residual_scale, 3),
        axes,
        smoothness: file
            .smoothness
            .iter()
            .map(|l| format!("lambda {}: {}", number(l.lambda, 2), number(l.cv_chi2, 5)))
            .collect::<Vec<_>>()
            .join("; "),
        rounds: round_rows(file),
        notes: file.notes.clone(),
        releases: file
            .releases
            .iter()
            .map(|r| {
                format!(
                    "{} (Mach {}, alpha {} deg)",
                    r.name,
                    number(r.mach, 3),
                    number(r.alpha_deg, 3)
                )
            })
            .collect::<Vec<_>>()
            .join("; "),
        fit_updated: goals_text(&file.fitted.goals),
        fit_factors: goals_text(&file.fitted.factors_only_goals),
        files: file.files.join(", "),
        evaluations: file.evaluations,
        wall_s: format!("{:.1}", file.wall_s),
    };
    render_page(&UPDATE, &page)
}

fn correction_rows(file: &UpdateFile) -> Vec<Correction> {
    file.corrections
        .iter()
        .map(|c| Correction {
            name: c.name.clone(),
            field: c.field.clone(),
            // The flowfield's parts: one for every release, its shape's values per metre of
            // depth, its slopes with alpha in deg/deg.
            explored: match Target::of_field(&c.field) {
                Some(Target::Field(part)) if part.is_shape() => "every release (per m)".to_string(),
                Some(Target::Field(_)) => "every release (deg/deg)".to_string(),
                _ => format!("{} to {}", number(c.explored.0, 3), number(c.explored.1, 3)),
            },
            lambda: number(c.lambda, 2),
            values: c
                .breakpoints
                .iter()
                .zip(&c.values)
                .zip(&c.std)
                .zip(&c.held)
                .map(|(((b, v), s), h)| {
                    if *h {
                        format!("{}: 0 (held)", number(*b, 3))
                    } else {
                        format!("{}: {} ± {}", number(*b, 3), number(*v, 3), number(*s, 2))
                    }
                })
                .collect::<Vec<_>>()
                .join("; "),
        })
        .collect()
}

fn axis_rows(file: &UpdateFile) -> Vec<AxisRow> {
    file.screening
        .axes
        .iter()
        .map(|a| AxisRow {
            axis: a.axis.clone(),
            scored: a
                .scored
                .iter()
                .take(3)
                .map(|s| format!("{} ({})", s.correction, number(s.gain, 3)))
                .collect::<Vec<_>>()
                .join("; "),
        })
        .collect()
}

fn round_rows(file: &UpdateFile) -> Vec<Round> {
    file.rounds
        .iter()
        .map(|r| Round {
            round: r.round,
            correction: r.correction.clone().unwrap_or_else(|| "none passes".into()),
            gain: r.linear_gain.map_or("-".into(), |g| number(g, 4)),
            before: number(r.cv_chi2_before, 5),
            with: r.cv_chi2_with.map_or("-".into(), |c| number(c, 5)),
            kept: if r.kept { "kept" } else { "not kept" },
        })
        .collect()
}

fn capitalised(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_uppercase().chain(c).collect(),
        None => String::new(),
    }
}
