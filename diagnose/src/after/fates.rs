//! What the releases did to each explanation an earlier diagnosis left open: its fate, in the
//! record and in words ("Cm q d/2V: explains both releases to the noise, 1 term: the answer";
//! "Cm alpha + 3 terms: BIC +4289: told apart").

use crate::answer::{Answer, Setting};
use crate::contender::Contender;
use crate::rivals::same_model;
use crate::{Fitted, RIVAL_MARGIN, Result, RivalReport};

use super::{AfterReport, AfterState, CRITERION, Fate, significant, term_count};

/// The fates of `state`'s explanations against the final `answer` and `rivals`.
pub(crate) fn report(
    setting: &Setting,
    baseline: &Fitted,
    answer: &Answer,
    rivals: &[(Contender, RivalReport)],
    state: &AfterState,
) -> Result<AfterReport> {
    let job = &setting.job;
    let model = answer.model(baseline);
    let answer_bic = setting.bic(model);
    let releases = job.events().len();
    let pool = state.carried.len();
    // Under the criterion an answer that explains every release to the noise loses only to a
    // model that does so with as few terms: a cut-off refit with more terms cannot displace it.
    let settles_more_terms = crate::analysis::explains(setting, model)?;
    let answer_terms = term_count(model);
    let mut fates = Vec::new();
    let fate_of = |name: &str,
                   was: &str,
                   f: &Fitted,
                   start: Option<&str>,
                   cut_off: bool,
                   carried: bool|
     -> Result<Fate> {
        let delta_bic = setting.bic(f) - answer_bic;
        let explained = crate::analysis::explains(setting, f)?;
        let status = if same_model(f, model, job) {
            "answer"
        } else if rivals.iter().any(|(c, _)| same_model(&c.fitted, f, job)) {
            "rival"
        } else if cut_off && !(settles_more_terms && term_count(f) > answer_terms) {
            // Its refit stopped before it converged: its BIC is only an upper bound, so these
            // releases have not been shown to separate it (issue 60: the cause of the earlier
            // class, cut off here, would otherwise read as told apart).
            "not settled"
        } else if carried && !significant(setting, baseline, f, pool) {
            "not significant"
        } else {
            "told apart"
        };
        let terms = term_count(f);
        Ok(Fate {
            name: name.to_string(),
            was: was.to_string(),
            status: status.to_string(),
            terms,
            parameters: Some(f.space(job).len()),
            chi2: Some(f.lm.cost),
            delta_bic: Some(delta_bic),
            explained: Some(explained),
            start: start.map(str::to_string),
            cut_off,
            words: words(name, releases, explained, terms, delta_bic, status, cut_off),
        })
    };
    for (o, c) in state.opens.iter().zip(&state.carried) {
        match c {
            Some(c) => fates.push(fate_of(
                &o.name,
                &o.was,
                &c.fitted,
                Some(c.start),
                c.cut_off,
                true,
            )?),
            None => fates.push(Fate {
                name: o.name.clone(),
                was: o.was.clone(),
                status: "failed".into(),
                terms: o.carry.effects.len() + o.carry.entries.len(),
                parameters: None,
                chi2: None,
                delta_bic: None,
                explained: None,
                start: None,
                cut_off: false,
                words: format!("{}: no start of its refit simulated: not settled", o.name),
            }),
        }
    }
    if let Some((name, f)) = &state.displaced {
        let cut_off = f.lm.cut_off();
        fates.push(fate_of(
            name,
            "this diagnosis's own answer",
            f,
            None,
            cut_off,
            false,
        )?);
    }
    Ok(AfterReport {
        from: state.from.clone(),
        earlier_releases: state.earlier_releases,
        criterion: CRITERION.to_string(),
        fates,
        plan: None,
        notes: state.notes.clone(),
    })
}

/// A fate in words.
fn words(
    name: &str,
    releases: usize,
    explained: bool,
    terms: usize,
    delta_bic: f64,
    status: &str,
    cut_off: bool,
) -> String {
    let all = match releases {
        1 => "the release".to_string(),
        2 => "both releases".to_string(),
        n => format!("all {n} releases"),
    };
    let fit = if explained {
        format!("explains {all} to the noise")
    } else {
        format!("leaves structure beyond the noise in {all}")
    };
    let s = if terms == 1 { "" } else { "s" };
    let status = match status {
        "answer" => "the answer".to_string(),
        "rival" => format!(
            "still a rival (within {RIVAL_MARGIN} of the answer's BIC: these releases do not separate it)"
        ),
        "not significant" => "told apart (not significant against the baseline)".to_string(),
        "not settled" => {
            "not settled: these releases have not been shown to separate it".to_string()
        }
        other => other.to_string(),
    };
    let cut = if cut_off {
        " (its refit stopped at its iteration limit: its BIC is an upper bound)"
    } else {
        ""
    };
    if status == "the answer" {
        format!("{name}: {fit}, {terms} term{s}: {status}")
    } else {
        format!("{name}: {fit}, {terms} term{s}, BIC {delta_bic:+.1}{cut}: {status}")
    }
}

/// The verdict's sentence of `r`: the earlier answer's fate, how many earlier explanations stay
/// rivals, and the plan's disagreements; `None` when nothing was carried.
pub(crate) fn sentence(r: &AfterReport) -> Option<String> {
    if r.fates.is_empty() {
        return None;
    }
    let earlier = |f: &&Fate| f.was != "this diagnosis's own answer";
    let count = |s: &str| {
        r.fates
            .iter()
            .filter(earlier)
            .filter(|f| f.status == s)
            .count()
    };
    let mut out = format!(
        "of the {} explanations the earlier diagnosis left open, refitted on every release",
        r.fates
            .iter()
            .filter(|f| f.was != "this diagnosis's own answer")
            .count()
    );
    let answer = r.fates.iter().find(|f| f.status == "answer");
    match answer {
        Some(a) => out.push_str(&format!(", {} is the answer", a.name)),
        None => out.push_str(", none is the answer"),
    }
    out.push_str(&format!(
        ", {} still rival(s) and {} told apart",
        count("rival"),
        count("told apart") + count("not significant")
    ));
    let unsettled = count("not settled");
    if unsettled > 0 {
        out.push_str(&format!(
            "; {unsettled} not settled (a refit stopped before it converged: the answer is not shown to be better than {})",
            if unsettled == 1 { "it" } else { "them" }
        ));
    }
    if let Some(d) = r
        .fates
        .iter()
        .find(|f| f.was == "this diagnosis's own answer")
    {
        out.push_str(&format!(" (this release's own answer, {})", d.words));
    }
    if let Some(p) = &r.plan {
        if !p.disagreements.is_empty() {
            out.push_str(&format!(
                "; the plan and the diagnosis disagree on {} pair(s): {}",
                p.disagreements.len(),
                p.disagreements.join("; ")
            ));
        }
    }
    Some(out)
}
