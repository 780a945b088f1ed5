//! DIR/report.html, the diagnosis as a page for people beside the figures it links to: the
//! answer first (the verdict, what was found with its uncertainty and gain, the figures), then
//! the details. The page is the template `templates/report.html` in sepval-report's layout
//! (`sepval_report::html`); this module turns a [`Diagnosis`] into that template's context,
//! every number already written as the page shows it.

use sepval_report::html::{HtmlError, PageTemplate, render_page};
use serde::Serialize;

use crate::verdict::{fmt_discovered, fmt_value};
use crate::{BIC_MARGIN, Diagnosis, ModelSummary};

/// The page's template.
const REPORT: PageTemplate = PageTemplate {
    name: "report.html",
    source: include_str!("../templates/report.html"),
};

/// The page's context.
#[derive(Serialize)]
struct Page<'a> {
    verdict: &'a str,
    /// Why the answer is unreliable (the baseline fit failed), shown before everything else.
    unreliable: Option<&'a str>,
    /// Why the first baseline fit was replaced (a local optimum the catalogue showed).
    baseline_restart: Option<&'a str>,
    /// Refits that did not simulate, left out.
    skipped: Vec<String>,
    /// Tables the fitted runs left.
    tables_left: &'a [String],
    discovered: Vec<FoundRow>,
    causes: Vec<CauseRow<'a>>,
    models: Vec<ModelRow>,
    noise: NoiseLine<'a>,
    extension: Option<ExtensionLine<'a>>,
    validation: Vec<ValidationRow<'a>>,
    figures: &'a [String],
    alternatives: Vec<AlternativeRow<'a>>,
    rivals: Vec<RivalRow<'a>>,
    classes: Vec<ClassRow<'a>>,
    /// What the releases did to what an earlier diagnosis left open (`--after`).
    after: Option<crate::after::page::AfterSection<'a>>,
    discovery: Option<DiscoveryTable<'a>>,
    channels: Vec<ChannelRow>,
    candidates: Vec<CandidateRow<'a>>,
    bic_margin: String,
    reconstruction: Vec<ReconstructionRow<'a>>,
}

#[derive(Serialize)]
struct FoundRow {
    axis: String,
    family: String,
    term: String,
    value: String,
    chi2_drop: String,
    f: String,
    p: String,
    delta_bic: String,
    reading: String,
    /// The entries the data cannot tell from it; empty when none.
    group: String,
}

#[derive(Serialize)]
struct CauseRow<'a> {
    id: &'a str,
    adds: &'a str,
    values: String,
    chi2_drop: String,
    delta_bic: String,
}

#[derive(Serialize)]
struct ModelRow {
    name: &'static str,
    parameters: usize,
    chi2: String,
    j_pos_m: String,
    j_att_deg: String,
    white: &'static str,
    at_noise_floor: &'static str,
}

#[derive(Serialize)]
struct NoiseLine<'a> {
    pos_m: String,
    att_deg: String,
    source: &'a str,
    evaluations: u64,
    wall_s: String,
}

#[derive(Serialize)]
struct ExtensionLine<'a> {
    answer: bool,
    chi2_drop: String,
    parameters: usize,
    f: String,
    p: String,
    delta_bic: String,
    explained: &'static str,
    file: Option<&'a str>,
}

#[derive(Serialize)]
struct ValidationRow<'a> {
    event: &'a str,
    baseline_j_pos_m: String,
    answer_j_pos_m: String,
    baseline_j_att_deg: String,
    answer_j_att_deg: String,
    alternatives: String,
    note: &'a str,
}

#[derive(Serialize)]
struct AlternativeRow<'a> {
    kind: &'a str,
    names: String,
    chi2: String,
    j_pos_m: String,
    j_att_deg: String,
    delta_bic: String,
    note: &'a str,
}

#[derive(Serialize)]
struct DiscoveryTable<'a> {
    steps: Vec<StepRow<'a>>,
    notes: &'a [String],
}

#[derive(Serialize)]
struct StepRow<'a> {
    step: usize,
    chi2: String,
    screened: String,
    verified: String,
    entered: &'a str,
}

#[derive(Serialize)]
struct ChannelRow {
    channel: String,
    baseline_rms: String,
    answer_rms: String,
    sigma: String,
    baseline_p: String,
    answer_p: String,
    segments: String,
}

#[derive(Serialize)]
struct CandidateRow<'a> {
    /// `yes` or `no` (also the row's class).
    significant: &'static str,
    id: &'a str,
    round: usize,
    parameters: String,
    chi2_drop: String,
    f: String,
    p: String,
    threshold: String,
    delta_bic: String,
    j_pos_m: String,
    j_att_deg: String,
}

#[derive(Serialize)]
struct ReconstructionRow<'a> {
    event: &'a str,
    lambda: String,
    effective_parameters: String,
    rms_after: String,
}

fn yes_no(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

/// The HTML report of `d`, its `figures` given relative to the report.
pub(super) fn report_html(d: &Diagnosis, figures: &[String]) -> Result<String, HtmlError> {
    let (b, e) = (&d.residuals["baseline"], &d.residuals["extended"]);
    let model = |name, m: &ModelSummary, white, floor| ModelRow {
        name,
        parameters: m.parameters,
        chi2: format!("{:.1}", m.chi2),
        j_pos_m: format!("{:.5}", m.j_pos_m),
        j_att_deg: format!("{:.4}", m.j_att_deg),
        white: yes_no(white),
        at_noise_floor: yes_no(floor),
    };
    let page = Page {
        verdict: &d.verdict,
        unreliable: d.baseline_verdict.why(),
        baseline_restart: d.baseline_restart.as_deref(),
        skipped: d
            .skipped
            .iter()
            .map(|k| format!("{}: {}: {}", k.stage, k.model, k.reason))
            .collect(),
        tables_left: &d.tables_left,
        discovered: found_rows(d),
        causes: cause_rows(d),
        models: vec![
            model("baseline", &d.baseline, b.white, b.at_noise_floor),
            model("answer", &d.extended, e.white, e.at_noise_floor),
        ],
        noise: NoiseLine {
            pos_m: format!("{:.4}", d.sigma_pos_m),
            att_deg: format!("{:.3}", d.sigma_att_deg),
            source: &d.sigma_source,
            evaluations: d.evaluations,
            wall_s: format!("{:.1}", d.wall_s),
        },
        extension: d.extension.as_ref().map(|x| ExtensionLine {
            answer: x.answer,
            chi2_drop: format!("{:.1}", x.gain.chi2_drop),
            parameters: x.gain.parameters,
            f: format!("{:.1}", x.gain.f),
            p: format!("{:.2e}", x.gain.p_value),
            delta_bic: format!("{:+.1}", x.gain.delta_bic),
            explained: yes_no(x.explained),
            file: x.file.as_deref(),
        }),
        validation: validation_rows(d),
        figures,
        alternatives: alternative_rows(d),
        rivals: rival_rows(d),
        after: d.after.as_ref().map(crate::after::page::section),
        classes: d
            .rival_classes
            .iter()
            .map(|c| ClassRow {
                words: &c.words,
                members: c.members.join("; "),
                status: &c.status,
                delta_bic: c.delta_bic.map_or("-".into(), |v| format!("{v:+.1}")),
                open: c.status != "told apart",
            })
            .collect(),
        discovery: (!d.discovery_steps.is_empty() || !d.discovery_notes.is_empty()).then(|| {
            DiscoveryTable {
                steps: step_rows(d),
                notes: &d.discovery_notes,
            }
        }),
        channels: channel_rows(d),
        candidates: candidate_rows(d),
        bic_margin: format!("{BIC_MARGIN}"),
        reconstruction: d
            .reconstruction
            .iter()
            .map(|r| ReconstructionRow {
                event: &r.event,
                lambda: format!("{:.1e}", r.lambda),
                effective_parameters: format!("{:.1}", r.effective_parameters),
                rms_after: format!("{:.3}", r.rms_after),
            })
            .collect(),
    };
    render_page(&REPORT, &page)
}

fn found_rows(d: &Diagnosis) -> Vec<FoundRow> {
    d.discovered
        .iter()
        .map(|t| FoundRow {
            axis: t.axis.clone(),
            family: t.family.clone(),
            term: t.term.clone(),
            value: fmt_discovered(t),
            chi2_drop: format!("{:.1}", t.gain.chi2_drop),
            f: format!("{:.1}", t.gain.f),
            p: format!("{:.2e}", t.gain.p_value),
            delta_bic: format!("{:+.1}", t.gain.delta_bic),
            reading: t.reading.clone(),
            group: t
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
                .collect::<Vec<_>>()
                .join("; "),
        })
        .collect()
}

fn cause_rows(d: &Diagnosis) -> Vec<CauseRow<'_>> {
    d.causes
        .iter()
        .map(|id| {
            let c = d.candidates.iter().rfind(|c| &c.id == id && c.significant);
            let values: Vec<String> = d
                .parameters
                .get(id)
                .map(|v| v.iter().map(fmt_value).collect())
                .unwrap_or_default();
            CauseRow {
                id,
                adds: c.map_or("", |c| c.adds.as_str()),
                values: values.join(", "),
                chi2_drop: c.map_or("-".into(), |c| format!("{:.1}", c.chi2_drop)),
                delta_bic: c.map_or("-".into(), |c| format!("{:+.1}", c.delta_bic)),
            }
        })
        .collect()
}

fn validation_rows(d: &Diagnosis) -> Vec<ValidationRow<'_>> {
    let f =
        |v: Option<f64>, p: usize| v.map_or("-".to_string(), |v| format!("{v:.prec$}", prec = p));
    d.validation
        .iter()
        .map(|v| ValidationRow {
            event: &v.event,
            baseline_j_pos_m: f(v.baseline_j_pos_m, 5),
            answer_j_pos_m: f(v.extended_j_pos_m, 5),
            baseline_j_att_deg: f(v.baseline_j_att_deg, 4),
            answer_j_att_deg: f(v.extended_j_att_deg, 4),
            alternatives: v
                .alternatives
                .iter()
                .map(|a| format!("{}: {:.5}, {:.4}", a.model, a.j_pos_m, a.j_att_deg))
                .collect::<Vec<_>>()
                .join("; "),
            note: &v.note,
        })
        .collect()
}

/// A rival as the page lists it.
#[derive(Serialize)]
struct RivalRow<'a> {
    kind: &'a str,
    model: String,
    chi2: String,
    j_pos_m: String,
    j_att_deg: String,
    delta_bic: String,
    origin: &'a str,
}

/// A rival class (`docs/discovery.md` section 11.5, step 4b).
#[derive(Serialize)]
struct ClassRow<'a> {
    words: &'a str,
    members: String,
    status: &'a str,
    delta_bic: String,
    /// Not told apart by the data.
    open: bool,
}

fn rival_rows(d: &Diagnosis) -> Vec<RivalRow<'_>> {
    d.rivals
        .iter()
        .map(|r| RivalRow {
            kind: &r.kind,
            model: crate::rivals::rival_name(r),
            chi2: format!("{:.1}", r.chi2),
            j_pos_m: format!("{:.5}", r.j_pos_m),
            j_att_deg: format!("{:.4}", r.j_att_deg),
            delta_bic: format!("{:+.1}", r.delta_bic),
            origin: &r.origin,
        })
        .collect()
}

fn alternative_rows(d: &Diagnosis) -> Vec<AlternativeRow<'_>> {
    d.alternatives
        .iter()
        .map(|a| AlternativeRow {
            kind: &a.kind,
            names: a.names.join(", "),
            chi2: format!("{:.1}", a.model.chi2),
            j_pos_m: format!("{:.5}", a.model.j_pos_m),
            j_att_deg: format!("{:.4}", a.model.j_att_deg),
            delta_bic: format!("{:+.1}", a.delta_bic_vs_answer),
            note: &a.note,
        })
        .collect()
}

fn step_rows(d: &Diagnosis) -> Vec<StepRow<'_>> {
    d.discovery_steps
        .iter()
        .map(|st| StepRow {
            step: st.step,
            chi2: format!("{:.1}", st.chi2),
            screened: st
                .screened
                .iter()
                .take(5)
                .map(|x| format!("{} {} ({:.1})", x.axis, x.term, x.f))
                .collect::<Vec<_>>()
                .join("; "),
            verified: st
                .verified
                .iter()
                .map(|x| format!("{} {} ({:.1})", x.axis, x.term, x.chi2))
                .collect::<Vec<_>>()
                .join("; "),
            entered: st
                .accepted
                .as_deref()
                .unwrap_or("nothing: the selection ends"),
        })
        .collect()
}

fn channel_rows(d: &Diagnosis) -> Vec<ChannelRow> {
    let (b, e) = (&d.residuals["baseline"], &d.residuals["extended"]);
    b.channels
        .iter()
        .zip(&e.channels)
        .map(|(cb, ce)| ChannelRow {
            channel: format!("{} [{}]", cb.channel, cb.unit),
            baseline_rms: format!("{:.4}", cb.rms),
            answer_rms: format!("{:.4}", ce.rms),
            sigma: format!("{:.4}", cb.sigma),
            baseline_p: format!("{:.2e}", cb.ljung_box_p),
            answer_p: format!("{:.2e}", ce.ljung_box_p),
            segments: cb
                .segments
                .iter()
                .map(|s| format!("{} {:.3e}", s.name, s.rms))
                .collect::<Vec<_>>()
                .join("; "),
        })
        .collect()
}

fn candidate_rows(d: &Diagnosis) -> Vec<CandidateRow<'_>> {
    d.candidates
        .iter()
        .map(|c| CandidateRow {
            significant: yes_no(c.significant),
            id: &c.id,
            round: c.round,
            parameters: c
                .parameters
                .iter()
                .map(fmt_value)
                .collect::<Vec<_>>()
                .join(", "),
            chi2_drop: format!("{:.1}", c.chi2_drop),
            f: format!("{:.1}", c.f),
            p: format!("{:.2e}", c.p_value),
            threshold: format!("{:.1e}", c.p_threshold),
            delta_bic: format!("{:+.1}", c.delta_bic),
            j_pos_m: format!("{:.4}", c.goals[0]),
            j_att_deg: format!("{:.3}", c.goals[1]),
        })
        .collect()
}
