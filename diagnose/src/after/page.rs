//! The report's section on what the releases did to what an earlier diagnosis left open
//! (`templates/report.html`), every number formatted here.

use serde::Serialize;

use super::AfterReport;

/// The section's context.
#[derive(Serialize)]
pub(crate) struct AfterSection<'a> {
    from: String,
    earlier_releases: usize,
    criterion: &'a str,
    fates: Vec<FateRow<'a>>,
    notes: &'a [String],
    plan: Option<PlanSection>,
}

#[derive(Serialize)]
struct FateRow<'a> {
    name: &'a str,
    was: &'a str,
    status: &'a str,
    terms: usize,
    delta_bic: String,
    explained: &'static str,
    start: &'a str,
    words: &'a str,
    class: &'static str,
}

#[derive(Serialize)]
struct PlanSection {
    plan: String,
    condition: String,
    pairs: Vec<PairRow>,
    disagreements: String,
}

#[derive(Serialize)]
struct PairRow {
    models: String,
    predicted: String,
    after: String,
    agree: &'static str,
    class: &'static str,
}

/// The section of `r`.
pub(crate) fn section(r: &AfterReport) -> AfterSection<'_> {
    let fates = r
        .fates
        .iter()
        .map(|f| FateRow {
            name: &f.name,
            was: &f.was,
            status: &f.status,
            terms: f.terms,
            delta_bic: f.delta_bic.map_or("-".into(), |v| format!("{v:+.1}")),
            explained: match f.explained {
                Some(true) => "yes",
                Some(false) => "no",
                None => "-",
            },
            start: f.start.as_deref().unwrap_or("-"),
            words: &f.words,
            class: match f.status.as_str() {
                "answer" => "yes",
                "rival" | "failed" | "not refitted" => "warn",
                _ => "",
            },
        })
        .collect();
    let plan = r.plan.as_ref().map(|p| PlanSection {
        plan: p.plan.display().to_string(),
        condition: match p.rank {
            Some(rank) => format!("{} (its rank {rank})", p.condition),
            None => p.condition.clone(),
        },
        pairs: p
            .pairs
            .iter()
            .map(|q| PairRow {
                models: format!("{} / {}", q.models[0], q.models[1]),
                predicted: format!("{:.1}", q.predicted),
                after: q.after.map_or("-".into(), |v| format!("{v:.1}")),
                agree: match q.agree {
                    Some(true) => "yes",
                    Some(false) => "no",
                    None => "-",
                },
                class: if q.agree == Some(true) { "" } else { "warn" },
            })
            .collect(),
        disagreements: p.disagreements.join("; "),
    });
    AfterSection {
        from: r.from.display().to_string(),
        earlier_releases: r.earlier_releases,
        criterion: &r.criterion,
        fates,
        notes: &r.notes,
        plan,
    }
}
