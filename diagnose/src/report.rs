//! The diagnosis in words: the verdict sentence, and DIR/report.html, a page for people beside
//! the figures it links to.

use std::collections::BTreeMap;
use std::path::Path;

use sepval_common::effects::CATALOGUE;

use super::reconstruct::Reconstruction;
use super::{
    Alternative, DiagnoseError, Diagnosis, DiscoveredTerm, ExtensionReport, ModelSummary,
    ParamValue,
};
use sepval_fit::space::Noise;
use sepval_report::figures::{
    IncrementPanel, IncrementSeries, increment_figure as draw_increments,
};

/// `s` escaped for HTML text and attribute values (`>` needs no escape in either, and
/// stays readable in the page's source: "0.004 m -> 0.003 m").
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('"', "&quot;")
}

/// The HTML report of `d`, its `figures` given relative to the report: the answer first (the
/// verdict, what was found with its uncertainty and gain, the figures), then the details.
pub(super) fn report_html(d: &Diagnosis, figures: &[String]) -> String {
    let mut h = String::new();
    h.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>sepval diagnosis</title>\n<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}table{border-collapse:collapse;font-size:90%;margin-bottom:1em}td,th{border:1px solid #ccc;padding:3px 6px;text-align:right}td:first-child,th:first-child{text-align:left}td.l{text-align:left}.yes{background:#e4f4e4}.verdict{font-size:120%;padding:1em;background:#f4f4f8;border-left:4px solid #446}.note{color:#555;font-size:90%}</style></head><body>\n");
    h.push_str("<h1>What the simulation still gets wrong</h1>\n");
    h.push_str(&format!("<p class=\"verdict\">{}</p>\n", esc(&d.verdict)));

    // What was found.
    h.push_str("<h2>What was found</h2>\n");
    if !d.discovered.is_empty() {
        h.push_str("<table><tr><th>axis</th><th>family</th><th>term</th><th>value ± standard error</th><th>chi2 drop</th><th>F</th><th>p</th><th>BIC change</th><th>reading</th></tr>\n");
        for t in &d.discovered {
            h.push_str(&format!(
                "<tr class=\"yes\"><td>{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{:.1}</td><td>{:.1}</td><td>{:.2e}</td><td>{:+.1}</td><td class=\"l\">{}</td></tr>\n",
                esc(&t.axis),
                esc(&t.family),
                esc(&t.term),
                esc(&fmt_discovered(t)),
                t.gain.chi2_drop,
                t.gain.f,
                t.gain.p_value,
                t.gain.delta_bic,
                esc(&t.reading)
            ));
            if !t.group.is_empty() {
                let g: Vec<String> = t
                    .group
                    .iter()
                    .map(|m| match m.correlation {
                        Some(rho) => format!(
                            "{} {} ({}, sensitivity correlation {rho:+.3})",
                            m.axis, m.term, m.family
                        ),
                        None => format!(
                            "{} {} ({}, refitted within 2 in chi2)",
                            m.axis, m.term, m.family
                        ),
                    })
                    .collect();
                h.push_str(&format!(
                    "<tr><td colspan=\"9\" class=\"l note\">The data cannot tell it from: {}</td></tr>\n",
                    esc(&g.join("; "))
                ));
            }
        }
        h.push_str("</table>\n");
    } else if !d.causes.is_empty() {
        h.push_str("<table><tr><th>cause</th><th>what it adds</th><th>values ± standard error</th><th>chi2 drop</th><th>BIC change</th></tr>\n");
        for id in &d.causes {
            let c = d.candidates.iter().rfind(|c| &c.id == id && c.significant);
            let values: Vec<String> = d
                .parameters
                .get(id)
                .map(|v| v.iter().map(fmt_value).collect())
                .unwrap_or_default();
            h.push_str(&format!(
                "<tr class=\"yes\"><td>{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td></tr>\n",
                esc(id),
                esc(c.map_or("", |c| c.adds.as_str())),
                esc(&values.join(", ")),
                c.map_or("-".into(), |c| format!("{:.1}", c.chi2_drop)),
                c.map_or("-".into(), |c| format!("{:+.1}", c.delta_bic)),
            ));
        }
        h.push_str("</table>\n");
    } else {
        h.push_str("<p>Nothing: neither an effect of the catalogue nor a term of the library is significant.</p>\n");
    }

    // The gain.
    h.push_str("<table><tr><th>model</th><th>parameters</th><th>chi2</th><th>J_pos [m]</th><th>J_att [deg]</th><th>white</th><th>at the noise floor</th></tr>\n");
    let row = |h: &mut String, name: &str, m: &ModelSummary, white: bool, floor: bool| {
        h.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td>{:.1}</td><td>{:.5}</td><td>{:.4}</td><td>{}</td><td>{}</td></tr>\n",
            esc(name),
            m.parameters,
            m.chi2,
            m.j_pos_m,
            m.j_att_deg,
            if white { "yes" } else { "no" },
            if floor { "yes" } else { "no" }
        ));
    };
    let (b, e) = (&d.residuals["baseline"], &d.residuals["extended"]);
    row(&mut h, "baseline", &d.baseline, b.white, b.at_noise_floor);
    row(&mut h, "answer", &d.extended, e.white, e.at_noise_floor);
    h.push_str("</table>\n");
    h.push_str(&format!(
        "<p>Noise: {:.4} m, {:.3} deg ({}). {} simulations in {:.1} s.</p>\n",
        d.sigma_pos_m,
        d.sigma_att_deg,
        esc(&d.sigma_source),
        d.evaluations,
        d.wall_s
    ));
    if let Some(x) = &d.extension {
        h.push_str(&format!(
            "<p>The discovered extension{}: chi2 drop {:.1} for {} parameter(s), F = {:.1}, p = {:.2e}, BIC change {:+.1}; explains the data to the noise: <b>{}</b>{}.</p>\n",
            if x.answer { "" } else { " (not the answer: see the alternatives)" },
            x.gain.chi2_drop,
            x.gain.parameters,
            x.gain.f,
            x.gain.p_value,
            x.gain.delta_bic,
            if x.explained { "yes" } else { "no" },
            x.file
                .as_ref()
                .map(|f| format!("; written to <code>{}</code> for <code>--extension</code>", esc(f)))
                .unwrap_or_default()
        ));
    }
    if !d.validation.is_empty() {
        let f = |v: Option<f64>, p: usize| {
            v.map_or("-".to_string(), |v| format!("{v:.prec$}", prec = p))
        };
        h.push_str("<h2>Prediction of events not fitted</h2>\n<table><tr><th>event</th><th>baseline J_pos [m]</th><th>answer J_pos [m]</th><th>baseline J_att [deg]</th><th>answer J_att [deg]</th><th>alternatives (J_pos [m], J_att [deg])</th><th>note</th></tr>\n");
        for v in &d.validation {
            h.push_str(&format!(
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td></tr>\n",
                esc(&v.event),
                f(v.baseline_j_pos_m, 5),
                f(v.extended_j_pos_m, 5),
                f(v.baseline_j_att_deg, 4),
                f(v.extended_j_att_deg, 4),
                esc(&v
                    .alternatives
                    .iter()
                    .map(|a| format!("{}: {:.5}, {:.4}", a.model, a.j_pos_m, a.j_att_deg))
                    .collect::<Vec<_>>()
                    .join("; ")),
                esc(&v.note)
            ));
        }
        h.push_str("</table>\n");
    }
    h.push_str("<h2>Figures</h2>\n");
    for f in figures {
        h.push_str(&format!(
            "<p><img src=\"{}\" style=\"max-width:100%\"></p>\n",
            esc(f)
        ));
    }

    // Details.
    h.push_str("<h2>Details</h2>\n");
    if !d.alternatives.is_empty() {
        h.push_str("<h3>Alternatives (explain part of the data, not as well)</h3>\n<table><tr><th>kind</th><th>model</th><th>chi2</th><th>J_pos [m]</th><th>J_att [deg]</th><th>BIC vs answer</th><th>note</th></tr>\n");
        for a in &d.alternatives {
            h.push_str(&format!(
                "<tr><td>{}</td><td class=\"l\">{}</td><td>{:.1}</td><td>{:.5}</td><td>{:.4}</td><td>{:+.1}</td><td class=\"l\">{}</td></tr>\n",
                esc(&a.kind),
                esc(&a.names.join(", ")),
                a.model.chi2,
                a.model.j_pos_m,
                a.model.j_att_deg,
                a.delta_bic_vs_answer,
                esc(&a.note)
            ));
        }
        h.push_str("</table>\n");
    }
    if !d.discovery_steps.is_empty() || !d.discovery_notes.is_empty() {
        h.push_str("<h3>Discovery, step by step</h3>\n<table><tr><th>step</th><th>chi2 before</th><th>best by F-to-enter (F)</th><th>refitted by output error (chi2)</th><th>entered</th></tr>\n");
        for st in &d.discovery_steps {
            let screened: Vec<String> = st
                .screened
                .iter()
                .take(5)
                .map(|x| format!("{} {} ({:.1})", x.axis, x.term, x.f))
                .collect();
            let verified: Vec<String> = st
                .verified
                .iter()
                .map(|x| format!("{} {} ({:.1})", x.axis, x.term, x.chi2))
                .collect();
            h.push_str(&format!(
                "<tr><td>{}</td><td>{:.1}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td></tr>\n",
                st.step,
                st.chi2,
                esc(&screened.join("; ")),
                esc(&verified.join("; ")),
                esc(st.accepted.as_deref().unwrap_or("nothing: the selection ends"))
            ));
        }
        h.push_str("</table>\n<ul>\n");
        for n in &d.discovery_notes {
            h.push_str(&format!("<li>{}</li>\n", esc(n)));
        }
        h.push_str("</ul>\n");
    }
    h.push_str("<h3>Residuals per channel</h3>\n<table><tr><th>channel</th><th>baseline RMS</th><th>answer RMS</th><th>sigma</th><th>baseline Ljung-Box p</th><th>answer Ljung-Box p</th><th>baseline RMS by segment</th></tr>\n");
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
    h.push_str("</table>\n<h3>Catalogue candidates</h3>\n<table><tr><th>effect</th><th>round</th><th>parameters</th><th>chi2 drop</th><th>F</th><th>p</th><th>threshold</th><th>BIC change</th><th>J_pos [m]</th><th>J_att [deg]</th><th>significant</th></tr>\n");
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
    h.push_str("</table>\n<p class=\"note\">A catalogue extension is significant when its F test passes at 1 % family-wise (Bonferroni over the candidates of its round) and it lowers the BIC, which charges its extra parameters; the lowest BIC among significant ones is chosen, then further effects are added while each addition stays significant. Discovered terms are selected by stepwise regression on the library of docs/model.md section 11 and kept only when the output-error refit of the factors and the terms together passes the same tests; they replace the catalogue's answer only when they beat it by more than 6 in BIC.</p>\n");
    if !d.reconstruction.is_empty() {
        h.push_str("<h3>Reconstruction</h3>\n<table><tr><th>event</th><th>regularisation (GCV)</th><th>effective parameters</th><th>normalised RMS after</th></tr>\n");
        for r in &d.reconstruction {
            h.push_str(&format!(
                "<tr><td>{}</td><td>{:.1e}</td><td>{:.1}</td><td>{:.3}</td></tr>\n",
                esc(&r.event),
                r.lambda,
                r.effective_parameters,
                r.rms_after
            ));
        }
        h.push_str("</table>\n");
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

/// What the verdict sentence is made of.
pub(super) struct VerdictInput<'a> {
    pub causes: &'a [String],
    pub explained: bool,
    pub parameters: &'a BTreeMap<String, Vec<ParamValue>>,
    pub discovered: &'a [DiscoveredTerm],
    /// The discovered extension, when it is the answer.
    pub extension: Option<&'a ExtensionReport>,
    pub alternatives: &'a [Alternative],
    pub base: &'a ModelSummary,
    pub ext: &'a ModelSummary,
    pub noise: Noise,
}

/// A discovered term's value: `coefficient ± se` and its locator.
pub fn fmt_discovered(d: &DiscoveredTerm) -> String {
    let value = match d.std_error {
        Some(se) => format!("{:.4} ± {:.2}", d.coefficient, se),
        None => format!("{:.4} (undetermined)", d.coefficient),
    };
    let locator = match (d.t_on_s, d.f_hz, d.lambda_m) {
        (Some(t), _, _) => format!(", t_on = {t:.3} s"),
        (_, Some(f), _) => format!(", f = {f:.2} Hz"),
        (_, _, Some(l)) => format!(", lambda = {l:.2} m"),
        _ => String::new(),
    };
    let locator = match (d.locator_std_error, locator.is_empty()) {
        (Some(se), false) => format!("{locator} ± {se:.2}"),
        _ => locator,
    };
    format!("{} {} = {value}{locator}", d.axis, d.term)
}

/// The verdict in one sentence.
pub(super) fn verdict(v: &VerdictInput) -> String {
    let (bp, ba) = (v.base.j_pos_m, v.base.j_att_deg);
    let (ep, ea) = (v.ext.j_pos_m, v.ext.j_att_deg);
    let gains =
        format!("position RMS {bp:.4} m -> {ep:.4} m, attitude RMS {ba:.3} deg -> {ea:.3} deg");
    if let (Some(e), Some(first)) = (v.extension, v.discovered.first()) {
        let mut reading = first.reading.clone();
        if let Some(c) = reading.get(0..1) {
            reading = c.to_lowercase() + &reading[1..];
        }
        let more = if v.discovered.len() > 1 {
            format!(" and {} more term(s)", v.discovered.len() - 1)
        } else {
            String::new()
        };
        let fit = if e.explained {
            "with it the model explains the data to the noise"
        } else {
            "with it the model still leaves structure beyond the noise"
        };
        let mimic = v
            .alternatives
            .iter()
            .find(|a| a.kind == "catalogue")
            .map(|a| {
                format!(
                    "; the catalogue's stand-in, {}, explains less (BIC {:+.1})",
                    a.names.join(" with "),
                    a.delta_bic_vs_answer
                )
            })
            .unwrap_or_default();
        return format!(
            "not explained by the catalogue: {reading} ({}){more}; {fit} ({gains}){mimic}",
            fmt_discovered(first)
        );
    }
    if v.causes.is_empty() {
        return if v.explained {
            format!(
                "the baseline model explains the data to the noise level (position RMS {bp:.4} m, sigma {:.4} m; attitude RMS {ba:.3} deg, sigma {:.3} deg)",
                v.noise.pos_m, v.noise.att_deg
            )
        } else {
            format!(
                "not explained: the residuals keep structure beyond the noise (position RMS {bp:.4} m, attitude RMS {ba:.3} deg) and neither an effect of the catalogue nor a term of the library accounts for it: the cause lies outside both"
            )
        };
    }
    let named: Vec<String> = v
        .causes
        .iter()
        .map(|id| {
            let adds = CATALOGUE
                .iter()
                .find(|e| e.id() == id)
                .map_or(id.as_str(), |e| e.adds());
            let values = v
                .parameters
                .get(id)
                .map(|v| v.iter().map(fmt_value).collect::<Vec<_>>().join(", "))
                .unwrap_or_default();
            format!(
                "missing {} ({id}), {values}",
                adds.split(':').next().unwrap_or(adds)
            )
        })
        .collect();
    if v.explained {
        format!("{}; {gains}", named.join("; and "))
    } else {
        format!(
            "not explained: the closest extension of the catalogue, {}, improves the fit ({gains}) but leaves structure beyond the noise: part of the cause lies outside the catalogue",
            named.join(" with ")
        )
    }
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
/// what the discovered terms give (`model[event][axis]`, axes in `Axis::ALL` order).
pub(super) fn increment_figure(
    path: &Path,
    reconstruction: &[Reconstruction],
    model: &super::discover::Curves,
) -> Result<(), DiagnoseError> {
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
