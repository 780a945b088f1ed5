//! DIR/report.html: the envelope as a page for people, the answer first (how many conditions
//! are cleared and, per row of the map, which), then the map, every condition's row and how it
//! was computed. The page is the template `templates/envelope.html` in sepval-report's layout.

use sepval_report::html::{HtmlError, PageTemplate, render_page};
use serde::Serialize;

use crate::record::EnvelopeFile;

const ENVELOPE: PageTemplate = PageTemplate {
    name: "envelope.html",
    source: include_str!("../templates/envelope.html"),
};

#[derive(Serialize)]
struct Page {
    headline: String,
    lines: Vec<String>,
    figure: String,
    rows: Vec<RowView>,
    method: String,
    provenance: String,
}

#[derive(Serialize)]
struct RowView {
    condition: String,
    p5: String,
    p50: String,
    p95: String,
    below: String,
    fail: String,
    diverged: String,
    t: String,
    parts: String,
    verdict: &'static str,
}

fn mm(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.0}")
    } else {
        "-".into()
    }
}

fn pct(v: f64) -> String {
    if v.is_finite() {
        format!("{:.1} %", 100.0 * v)
    } else {
        "-".into()
    }
}

/// The page of `file`, its figure at `figure` (relative to the page).
pub fn render(file: &EnvelopeFile, figure: &str) -> Result<String, HtmlError> {
    let rows = file
        .rows
        .iter()
        .map(|r| {
            let c = &r.condition;
            RowView {
                condition: format!(
                    "Mach {:.3}, {:.0} m, alpha {:.1} deg, beta {:.1} deg, gamma {:.1} deg",
                    c.mach, c.altitude_m, c.alpha_deg, c.beta_deg, c.gamma_deg
                ),
                p5: mm(r.clearance_p5_mm),
                p50: mm(r.clearance_p50_mm),
                p95: mm(r.clearance_p95_mm),
                below: pct(r.p_below),
                fail: pct(r.p_fail),
                diverged: pct(r.diverged_share),
                t: if r.t_closest_s.is_finite() {
                    format!("{:.3}", r.t_closest_s)
                } else {
                    "-".into()
                },
                parts: if r.closest_store_part.is_empty() {
                    "-".into()
                } else {
                    format!("{} / {}", r.closest_store_part, r.closest_aircraft_part)
                },
                verdict: if r.cleared { "cleared" } else { "not cleared" },
            }
        })
        .collect();
    let page = Page {
        headline: file.headline.clone(),
        lines: file.summary.clone(),
        figure: figure.to_string(),
        rows,
        method: format!(
            "Every condition is a prediction of sepval predict with {} samples (seed {}): each \
             sample draws a model by its evidence and the factors from their covariance, is \
             simulated at the condition, and carries the model-form discrepancy calibrated on the \
             releases held out as a smooth error. The store's surface is placed along each \
             sample's trajectory and its smallest distance to the aircraft's surface taken once \
             the store has moved the ejector's stroke from carriage (docs/geometry.md). A \
             condition is cleared when at most {} of its samples come within {} mm of the \
             aircraft (MIL-STD-1289D) or diverge. The same samples serve every condition, so \
             the map changes where the physics does, not where the draws do.",
            file.provenance.samples,
            file.provenance.seed,
            pct(file.allowed_probability),
            file.criterion_mm
        ),
        provenance: format!(
            "From {}; aircraft {}; store {}. {} simulations in {:.1} s{}.",
            file.provenance.from,
            file.provenance.aircraft,
            file.provenance.store_shape,
            file.evaluations,
            file.wall_s,
            if file.resumed > 0 {
                format!(
                    " ({} conditions resumed from an interrupted sweep)",
                    file.resumed
                )
            } else {
                String::new()
            }
        ),
    };
    render_page(&ENVELOPE, &page)
}
