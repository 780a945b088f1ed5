//! The diagnosis in words: the verdict sentence, and DIR/report.html, a page for people beside
//! the figures it links to.

use std::collections::BTreeMap;

use sepval_common::effects::CATALOGUE;

use super::{Diagnosis, ModelSummary, ParamValue};
use crate::refine::Noise;

/// `s` escaped for HTML text.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The HTML report of `d`, its `figures` given relative to the report.
pub(super) fn report_html(d: &Diagnosis, figures: &[String]) -> String {
    let mut h = String::new();
    h.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>sepval diagnosis</title>\n<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}table{border-collapse:collapse;font-size:90%}td,th{border:1px solid #ccc;padding:3px 6px;text-align:right}td:first-child,th:first-child{text-align:left}.yes{background:#e4f4e4}.verdict{font-size:120%;padding:1em;background:#f4f4f8;border-left:4px solid #446}</style></head><body>\n");
    h.push_str("<h1>What the simulation still gets wrong</h1>\n");
    h.push_str(&format!("<p class=\"verdict\">{}</p>\n", esc(&d.verdict)));
    h.push_str(&format!(
        "<p>Causes: <b>{}</b>. Explained to the noise: <b>{}</b>. Noise: {:.4} m, {:.3} deg ({}). {} simulations in {:.1} s.</p>\n",
        if d.causes.is_empty() { "none".to_string() } else { esc(&d.causes.join(", ")) },
        if d.explained { "yes" } else { "no" },
        d.sigma_pos_m,
        d.sigma_att_deg,
        esc(&d.sigma_source),
        d.evaluations,
        d.wall_s
    ));
    h.push_str("<h2>Residuals per channel</h2>\n<table><tr><th>channel</th><th>baseline RMS</th><th>extended RMS</th><th>sigma</th><th>baseline Ljung-Box p</th><th>extended Ljung-Box p</th><th>baseline RMS by segment</th></tr>\n");
    let (b, e) = (&d.residuals["baseline"], &d.residuals["extended"]);
    for (cb, ce) in b.channels.iter().zip(&e.channels) {
        let segs: Vec<String> = cb
            .segments
            .iter()
            .map(|s| format!("{} {:.3e}", esc(&s.name), s.rms))
            .collect();
        h.push_str(&format!(
            "<tr><td>{} [{}]</td><td>{:.4}</td><td>{:.4}</td><td>{:.4}</td><td>{:.2e}</td><td>{:.2e}</td><td>{}</td></tr>\n",
            cb.channel, cb.unit, cb.rms, ce.rms, cb.sigma, cb.ljung_box_p, ce.ljung_box_p, segs.join("; ")
        ));
    }
    h.push_str("</table>\n<h2>Candidate extensions</h2>\n<table><tr><th>effect</th><th>round</th><th>parameters</th><th>chi2 drop</th><th>F</th><th>p</th><th>threshold</th><th>BIC change</th><th>J_pos [m]</th><th>J_att [deg]</th><th>significant</th></tr>\n");
    for c in &d.candidates {
        let params: Vec<String> = c.parameters.iter().map(fmt_value).collect();
        h.push_str(&format!(
            "<tr class=\"{}\"><td>{}</td><td>{}</td><td>{}</td><td>{:.1}</td><td>{:.1}</td><td>{:.2e}</td><td>{:.1e}</td><td>{:+.1}</td><td>{:.4}</td><td>{:.3}</td><td>{}</td></tr>\n",
            if c.significant { "yes" } else { "no" },
            esc(&c.id),
            c.round,
            esc(&params.join(", ")),
            c.chi2_drop,
            c.f,
            c.p_value,
            c.p_threshold,
            c.delta_bic,
            c.goals[0],
            c.goals[1],
            if c.significant { "yes" } else { "no" }
        ));
    }
    h.push_str("</table>\n<p>An extension is significant when its F test passes at 1 % family-wise (Bonferroni over the candidates of its round) and it lowers the BIC, which charges its extra parameters; the lowest BIC among significant ones is chosen, then further effects are added while each addition stays significant.</p>\n");
    h.push_str("<h2>Residuals before and after</h2>\n");
    for f in figures {
        h.push_str(&format!(
            "<p><img src=\"{}\" style=\"max-width:100%\"></p>\n",
            esc(f)
        ));
    }
    h.push_str("</body></html>\n");
    h
}

pub(super) fn fmt_value(v: &ParamValue) -> String {
    match v.std_error {
        Some(se) => format!(
            "{} = {:.4} ± {:.2} {}",
            v.name,
            v.value,
            se,
            per_unit(&v.unit)
        ),
        None => format!(
            "{} = {:.4} {} (undetermined)",
            v.name,
            v.value,
            per_unit(&v.unit)
        ),
    }
}

fn per_unit(unit: &str) -> String {
    match unit.strip_prefix("1/") {
        Some(u) => format!("per {u}"),
        None => unit.to_string(),
    }
}

pub(super) fn verdict(
    causes: &[String],
    explained: bool,
    parameters: &BTreeMap<String, Vec<ParamValue>>,
    base: &ModelSummary,
    ext: &ModelSummary,
    noise: Noise,
) -> String {
    let rms = |s: &ModelSummary| (s.j_pos_m, s.j_att_deg);
    let (bp, ba) = rms(base);
    let (ep, ea) = rms(ext);
    if causes.is_empty() {
        return if explained {
            format!(
                "the baseline model explains the data to the noise level (position RMS {bp:.4} m, sigma {:.4} m; attitude RMS {ba:.3} deg, sigma {:.3} deg)",
                noise.pos_m, noise.att_deg
            )
        } else {
            format!(
                "not explained: the residuals keep structure beyond the noise (position RMS {bp:.4} m, attitude RMS {ba:.3} deg) and no effect of the catalogue accounts for it: the cause lies outside the catalogue"
            )
        };
    }
    let named: Vec<String> = causes
        .iter()
        .map(|id| {
            let adds = CATALOGUE
                .iter()
                .find(|e| e.id() == id)
                .map_or(id.as_str(), |e| e.adds());
            let values = parameters
                .get(id)
                .map(|v| v.iter().map(fmt_value).collect::<Vec<_>>().join(", "))
                .unwrap_or_default();
            format!(
                "missing {} ({id}), {values}",
                adds.split(':').next().unwrap_or(adds)
            )
        })
        .collect();
    let gains =
        format!("position RMS {bp:.4} m -> {ep:.4} m, attitude RMS {ba:.3} deg -> {ea:.3} deg");
    if explained {
        format!("{}; {gains}", named.join("; and "))
    } else {
        format!(
            "not explained: the closest extension of the catalogue, {}, improves the fit ({gains}) but leaves structure beyond the noise: part of the cause lies outside the catalogue",
            named.join(" with ")
        )
    }
}
