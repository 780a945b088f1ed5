//! DIR/plan.html: the plan as a page for people, the recommendation first (the condition and
//! why, in words), then the best conditions, the figures and how it was computed. The page is
//! the template `templates/plan.html` in sepval-report's layout (`sepval_report::html`); this
//! module turns a [`PlanFile`] into that template's context, every number written as the page
//! shows it.

use sepval_report::words::{condition, decimals};
use std::path::{Path, PathBuf};

use sepval_report::html::{HtmlError, PageTemplate, render_page};
use serde::Serialize;

use crate::ranking::Standing;
use crate::record::{ConditionRecord, PlanFile};

/// The page's template.
const PLAN: PageTemplate = PageTemplate {
    name: "plan.html",
    source: include_str!("../templates/plan.html"),
};

/// Rows of the table of best conditions.
const TOP_ROWS: usize = 10;

#[derive(Serialize)]
struct Page<'a> {
    headline: String,
    why: String,
    rivals: bool,
    top: Vec<Row>,
    conditions_note: String,
    figures: Vec<String>,
    method: String,
    models: Vec<ModelRow<'a>>,
    flown_pairs: Vec<PairRow>,
    reported: Vec<Row>,
    noise: String,
    evaluations: u64,
    wall_s: String,
    from: String,
}

#[derive(Serialize)]
struct Row {
    first: bool,
    rank: usize,
    mach: String,
    altitude_m: String,
    alpha_deg: String,
    beta_deg: String,
    gamma_deg: String,
    separation: String,
    separated: String,
    gain: String,
    note: String,
}

#[derive(Serialize)]
struct ModelRow<'a> {
    name: &'a str,
    role: &'static str,
    parameters: usize,
    delta_bic: String,
}

#[derive(Serialize)]
struct PairRow {
    pair: String,
    separation: String,
}

/// A number as the page shows it: at most three decimals ([`decimals`]).
pub(crate) fn number(v: f64) -> String {
    decimals(v, 3)
}

fn opt(v: Option<f64>) -> String {
    v.map_or("-".into(), number)
}

/// A condition in words ([`sepval_report::words::condition`]).
pub(crate) fn condition_words(c: &ConditionRecord) -> String {
    condition(c.mach, c.altitude_m, c.alpha_deg, c.beta_deg, c.gamma_deg)
}

fn row(c: &ConditionRecord, total_pairs: usize) -> Row {
    let note = match &c.standing {
        Standing::Ranked => String::new(),
        Standing::TablesLeft(n) => format!("leaves a table: {}", n.join("; ")),
        Standing::Diverged(n) => n.join("; "),
    };
    Row {
        first: c.rank == 1,
        rank: c.rank,
        mach: number(c.mach),
        altitude_m: number(c.altitude_m),
        alpha_deg: number(c.alpha_deg),
        beta_deg: number(c.beta_deg),
        gamma_deg: number(c.gamma_deg),
        separation: opt(c.separation),
        separated: format!("{} of {total_pairs}", c.separates.len()),
        gain: opt(c.information_gain),
        note,
    }
}

/// The recommendation and why, in words.
fn headline(file: &PlanFile) -> (String, String) {
    let (headline, why) = headline_alone(file);
    let held = file
        .conditions
        .first()
        .is_some_and(|c| c.pairs.iter().any(|p| p.locators_held));
    if held {
        let caution = " A model here has a located term (a step's or gust's time, a frequency, a decay length) whose locator the diagnosis refits but this plan holds at its value: its separations may be optimistic, and the diagnosis of the release decides.";
        (headline, format!("{why}{caution}"))
    } else {
        (headline, why)
    }
}

/// [`headline`] without the caution on held locators.
fn headline_alone(file: &PlanFile) -> (String, String) {
    let answer = &file.models[0].name;
    let best = file
        .conditions
        .first()
        .filter(|c| !matches!(c.standing, Standing::Diverged(_)));
    let Some(best) = best else {
        return (
            "No condition can be recommended: every model diverged or failed at every condition in the ranges.".into(),
            "Narrow the ranges to conditions the store flies (see the conditions reported below).".into(),
        );
    };
    let at = condition_words(best);
    let gain = opt(best.information_gain);
    let shrink = best.information_gain.map_or("-".into(), |g| {
        let f = (0.5 * g).exp();
        if f < 1e3 {
            number(f)
        } else {
            format!("{f:.1e}")
        }
    });
    let information = format!(
        "pooled with the releases flown, it would add {gain} to ln det of the information on the answer's {} parameters (their joint confidence region shrinks {shrink}-fold)",
        file.models[0].parameters
    );
    if file.ranked_by == "information" {
        return (
            format!("Fly the next release at {at}."),
            format!(
                "The diagnosis has no rivals (its answer, {answer}, is not in doubt), so the plan is for information alone: of the conditions in the ranges, this one would shrink the uncertainty of the fitted parameters most: {information}."
            ),
        );
    }
    let pairs = best.pairs.len();
    let separation = opt(best.separation);
    let threshold = number(file.threshold);
    if best.separates.len() == pairs {
        (
            format!("Fly the next release at {at}: it would tell the answer from its rivals."),
            format!(
                "The releases flown cannot tell the answer ({answer}) from {} rival(s). At this condition, whichever model is true, the other refitted to the new release together with the old ones would be left behind by a BIC margin of at least {separation} (above {threshold}: strong evidence), the largest in the ranges; {information}.",
                file.models.len() - 1
            ),
        )
    } else {
        (
            format!(
                "Fly the next release at {at}: the best in the ranges, but it separates only {} of {pairs} pair(s).",
                best.separates.len()
            ),
            format!(
                "The releases flown cannot tell the answer ({answer}) from its rivals, and no condition in the ranges separates every pair by more than {threshold} in BIC. This one separates the most pairs ({} of {pairs}; any of the models may be the true one, so every pair counts), and of those that separate as many its hardest pair is left the furthest apart, at {separation}. Widen the ranges, or plan again after this release; {information}.",
                best.separates.len()
            ),
        )
    }
}

/// The page of `file`, linking the `figures` (paths under `out`).
pub fn render(file: &PlanFile, figures: &[PathBuf], out: &Path) -> Result<String, HtmlError> {
    let pairs = file.flown_pairs.len();
    let (headline, why) = headline(file);
    let (ranked, reported): (Vec<&ConditionRecord>, Vec<&ConditionRecord>) = file
        .conditions
        .iter()
        .partition(|c| c.standing == Standing::Ranked);
    let page = Page {
        headline,
        why,
        rivals: file.ranked_by == "separation",
        top: ranked
            .iter()
            .take(TOP_ROWS)
            .map(|c| row(c, pairs))
            .collect(),
        conditions_note: format!(
            "{} conditions evaluated, {} shown; {} reported below (a model leaves a table or diverges there).",
            file.conditions.len(),
            ranked.len().min(TOP_ROWS),
            reported.len()
        ),
        figures: figures
            .iter()
            .map(|f| f.strip_prefix(out).unwrap_or(f).display().to_string())
            .collect(),
        method: method(file),
        models: file
            .models
            .iter()
            .map(|m| ModelRow {
                name: &m.name,
                role: if m.answer { "answer" } else { "rival" },
                parameters: m.parameters,
                delta_bic: number(m.delta_bic),
            })
            .collect(),
        flown_pairs: file
            .flown_pairs
            .iter()
            .map(|p| PairRow {
                pair: format!("{} / {}", p.models[0], p.models[1]),
                separation: number(p.separation),
            })
            .collect(),
        reported: reported.iter().map(|c| row(c, pairs)).collect(),
        noise: format!("{} m, {} deg", number(file.sigma_pos_m), file.sigma_att_deg),
        evaluations: file.evaluations,
        wall_s: number(file.wall_s),
        from: file.from.display().to_string(),
    };
    render_page(&PLAN, &page)
}

fn method(file: &PlanFile) -> String {
    format!(
        "Each model was simulated at every condition with every one of its free parameters stepped, \
         through the releases flown and a release at the condition sampled like the first one. \
         The separation of two models is the smaller of the two expected BIC margins left when one \
         is refitted (linearised, its parameters held to their ranges) to the other's noise-free \
         trajectories at the releases flown and the new one, in units of the noise; a pair is \
         separated above {}. The information gain is the growth of ln det of the answer's Fisher \
         information (parameters in units of their ranges, a unit prior on each). {} \
         See docs/planning.md.",
        number(file.threshold),
        if file.ranked_by == "separation" {
            "The conditions are ranked by the number of pairs they separate (any model may be \
             the true one, so every pair counts), then by their separation (the hardest pair's), \
             then by information gain."
        } else {
            "With no rivals, the conditions are ranked by information gain."
        }
    )
}
