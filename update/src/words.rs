//! The update in words: the answer first, what the data cannot tell apart, and notes.

use sepval_common::evaluation::Job;

use crate::record::{GoalsRecord, UpdateFile};
use crate::select::Selected;
use crate::uncertainty::Uncertainty;

/// `v` with at most `digits` significant figures, without a trailing exponent for ordinary
/// sizes.
pub fn number(v: f64, digits: usize) -> String {
    if !v.is_finite() {
        return "-".into();
    }
    if v == 0.0 {
        return "0".into();
    }
    let magnitude = v.abs().log10().floor() as i32;
    let decimals = (digits as i32 - 1 - magnitude).max(0) as usize;
    if !(-4..6).contains(&magnitude) {
        return format!("{v:.prec$e}", prec = digits.saturating_sub(1));
    }
    format!("{v:.decimals$}")
}

/// Goals as "4.1 mm / 0.12 deg".
pub fn goals_text(g: &GoalsRecord) -> String {
    match (g.j_pos_m, g.j_att_deg) {
        (Some(p), Some(a)) => format!("{} mm / {} deg", number(1000.0 * p, 3), number(a, 3)),
        _ => "did not simulate".into(),
    }
}

/// The mean of each goal over `goals` (those that simulated).
fn mean(goals: impl Iterator<Item = GoalsRecord>) -> GoalsRecord {
    let (mut p, mut a, mut n) = (0.0, 0.0, 0usize);
    let mut failed = false;
    for g in goals {
        match (g.j_pos_m, g.j_att_deg) {
            (Some(x), Some(y)) => {
                p += x;
                a += y;
                n += 1;
            }
            _ => failed = true,
        }
    }
    if n == 0 || failed {
        return GoalsRecord {
            j_pos_m: None,
            j_att_deg: None,
        };
    }
    GoalsRecord {
        j_pos_m: Some(p / n as f64),
        j_att_deg: Some(a / n as f64),
    }
}

/// The folds' mean predictions: (baseline, factors only, updated).
pub fn mean_predictions(file: &UpdateFile) -> (GoalsRecord, GoalsRecord, GoalsRecord) {
    let f = &file.cross_validation.folds;
    (
        mean(f.iter().map(|f| f.baseline)),
        mean(f.iter().map(|f| f.factors_only)),
        mean(f.iter().map(|f| f.updated)),
    )
}

/// What was predicted, in words.
fn held_out_words(file: &UpdateFile) -> String {
    if file.releases.len() > 1 {
        "releases it was not fitted to (each left out in turn)".into()
    } else {
        "the part of the release it was not fitted to".into()
    }
}

/// The answer in one sentence (or two).
pub fn verdict(file: &UpdateFile) -> String {
    let (base, factors, updated) = mean_predictions(file);
    let target = held_out_words(file);
    if !file.corrections.is_empty() {
        let names: Vec<String> = file
            .corrections
            .iter()
            .map(|c| {
                if c.field.starts_with("flowfield.") {
                    // The aircraft's field: one shape for every release, not a range.
                    return format!("{} (one for every release)", c.name);
                }
                format!(
                    "{} ({} to {})",
                    c.name,
                    number(c.explored.0, 3),
                    number(c.explored.1, 3)
                )
            })
            .collect();
        return format!(
            "Updated: {}. On {target}, the updated store predicts {} (factors alone: {}; the data as given: {}).",
            names.join(", "),
            goals_text(&updated),
            goals_text(&factors),
            goals_text(&base)
        );
    }
    if let Some(r) = file.rounds.iter().find(|r| r.correction.is_some()) {
        return format!(
            "No correction kept: the best the reconstruction proposed ({}) does not predict {target} enough better than the factors alone to be kept (cross-validated chi-square {} against {}; a correction must lower it by {}). The store's data stand; the factors are refitted, and predict {} (the data as given: {}).",
            r.correction.clone().unwrap_or_default(),
            number(r.cv_chi2_with.unwrap_or(f64::NAN), 5),
            number(r.cv_chi2_before, 5),
            number(crate::select::keep_needed(r.cv_chi2_before), 3),
            goals_text(&factors),
            goals_text(&base)
        );
    }
    format!(
        "No correction: what the fitted factors leave shows nothing a correction over distance, flow angles or Mach would predict. On {target} the factors alone predict {} (the data as given: {}).",
        goals_text(&factors),
        goals_text(&base)
    )
}

/// What the data cannot tell apart, in words.
pub fn cannot_tell(job: &Job, file: &UpdateFile) -> Vec<String> {
    let mut out: Vec<String> = file
        .rounds
        .iter()
        .filter(|r| r.kept)
        .flat_map(|r| {
            let taken = r.correction.clone().unwrap_or_default();
            r.cannot_tell.iter().map(move |other| {
                format!(
                    "the releases cannot tell a correction of {taken} from one of {other} (refitted, their cross-validated chi-squares are within 6)"
                )
            })
        })
        .collect();
    if job.events().len() == 1 {
        out.push(
            "one release goes along one path: its distance from the aircraft, its flow angles and time change together, so a correction over one of them may stand for one over another; releases at other conditions (another angle of attack, another Mach number) tell them apart"
                .into(),
        );
        out.push(
            "with one release nothing is known of how the data change with Mach: a correction holds at its flight condition only"
                .into(),
        );
    }
    out
}

/// Notes on the selection and the fit.
pub fn notes(selected: &Selected, uncertainty: &Uncertainty, file: &UpdateFile) -> Vec<String> {
    let mut out = Vec::new();
    let model = &selected.model;
    // The smoothness stage scales every lambda the screening chose by one multiplier: a best
    // at either end of those tried may lie beyond them.
    let tried = &selected.smoothness;
    let best = (0..tried.len()).min_by(|&a, &b| tried[a].1.total_cmp(&tried[b].1));
    if let Some(best) = best.filter(|&b| tried.len() > 1 && (b == 0 || b + 1 == tried.len())) {
        out.push(format!(
            "the corrections' smoothness is at the {} edge of the weights tried (lambda {} for the first that is smoothed): the cross-validation may prefer {} still",
            if best == 0 { "weak" } else { "strong" },
            number(tried[best].0, 2),
            if best == 0 { "less" } else { "more" },
        ));
    }
    let values = model.space.values(&model.fit.lm.x);
    for (k, c) in model.space.corrections().iter().enumerate() {
        let (lo, hi) = model.space.bounds(k);
        let near = |v: f64, b: f64| (v - b).abs() <= 5e-4 * (hi - lo);
        if values[k].iter().any(|&v| near(v, lo) || near(v, hi)) {
            out.push(format!(
                "{} reaches a bound of its values ({} to {}): the data want a larger change than the update allows",
                c.name(),
                number(lo, 3),
                number(hi, 3)
            ));
        }
    }
    for r in file.rounds.iter().filter(|r| !r.kept) {
        if let (Some(c), Some(with)) = (&r.correction, r.cv_chi2_with) {
            out.push(format!(
                "{c} was proposed in round {} but not kept: with it the cross-validated chi-square is {} (without it {})",
                r.round,
                number(with, 5),
                number(r.cv_chi2_before, 5)
            ));
        }
    }
    if uncertainty.residual_scale > 1.5 {
        out.push(format!(
            "the updated store leaves {} times the noise's variance in the residuals: the bands are widened by that, and something remains that no correction here describes",
            number(uncertainty.residual_scale, 3)
        ));
    }
    out
}
