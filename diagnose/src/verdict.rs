//! The diagnosis in words: the verdict sentence, and how estimates read (a catalogue
//! parameter's value with its standard error, a discovered term's with its locator); the
//! terminal summary and the HTML page use the same wording.

use std::collections::BTreeMap;

use sepval_common::effects::CATALOGUE;
use sepval_fit::space::Noise;

use crate::{Alternative, DiscoveredTerm, ExtensionReport, Location, ModelSummary, ParamValue};

/// A catalogue parameter's value: `name = value ± se unit`.
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
    /// Why discovery beyond the catalogue could not run (the term budget full), if it could not.
    pub blocked: Option<&'a str>,
}

/// A discovered term's coefficient: `coefficient ± se`.
fn fmt_coefficient(d: &DiscoveredTerm) -> String {
    match d.std_error {
        Some(se) => format!("{:.4} ± {:.2}", d.coefficient, se),
        None => format!("{:.4} (undetermined)", d.coefficient),
    }
}

/// A discovered term in one short line (the terminal's summary): [`fmt_discovered`] with its
/// first location only (a gust's onset, a step's time, an oscillation's frequency).
pub fn fmt_discovered_brief(d: &DiscoveredTerm) -> String {
    match d.locations.first() {
        Some(l) => format!(
            "{} {} = {}, {}",
            d.axis,
            d.term,
            fmt_coefficient(d),
            fmt_location(l)
        ),
        None => fmt_discovered(d),
    }
}

/// A discovered term's value: `coefficient ± se` and its locator (its locations with their
/// intervals, when it has them).
pub fn fmt_discovered(d: &DiscoveredTerm) -> String {
    let value = fmt_coefficient(d);
    if !d.locations.is_empty() {
        let located: Vec<String> = d.locations.iter().map(fmt_location).collect();
        return format!("{} {} = {value}, {}", d.axis, d.term, located.join(", "));
    }
    let locator = match (d.t_on_s, d.f_hz, d.lambda_m) {
        (Some(t), _, _) if d.rise_s.is_some() && d.locator_std_error.is_some() => {
            let middle = t + d.rise_s.unwrap_or(0.0) / 2.0;
            format!(", t_on = {t:.3} s, middle {middle:.3} s")
        }
        (Some(t), _, _) => format!(", t_on = {t:.3} s"),
        (_, Some(f), _) => format!(", f = {f:.2} Hz"),
        (_, _, Some(l)) => format!(", lambda = {l:.2} m"),
        _ => String::new(),
    };
    let locator = match (d.locator_std_error, locator.is_empty()) {
        (Some(se), false) if d.t_on_s.is_some() => format!("{locator} ± {se:.3} s"),
        (Some(se), false) => format!("{locator} ± {se:.2}"),
        _ => locator,
    };
    let locator = match (d.rise_s, d.rise_std_error, d.locator_std_error) {
        (Some(t), Some(se), _) => format!("{locator}, length {t:.3} ± {se:.3} s"),
        (Some(t), None, Some(_)) => {
            format!("{locator}, length {t:.3} s (not determined by the data)")
        }
        (Some(t), None, None) => format!("{locator}, length {t:.3} s"),
        _ => locator,
    };
    format!("{} {} = {value}{locator}", d.axis, d.term)
}

/// A location with its standard error and 95 % interval: "t_on = 0.451 ± 0.004 s (95 %: 0.443
/// to 0.459 s)", or "t_on = 0.391 s (not determined by the data; 95 %: 0.221 to 0.463 s)".
pub fn fmt_location(l: &Location) -> String {
    let (label, unit, digits) = match l.quantity.as_str() {
        "t_on_s" => ("t_on =", "s", 3),
        "t_mid_s" => ("middle", "s", 3),
        "rise_s" => ("length", "s", 3),
        "f_hz" => ("f =", "Hz", 2),
        "phase_deg" => ("phase", "deg", 1),
        other => (other, "", 3),
    };
    let se = match l.std_error {
        Some(se) => format!(" ± {se:.digits$}"),
        None => String::new(),
    };
    let tag = if l.determined {
        ""
    } else {
        "not determined by the data; "
    };
    format!(
        "{label} {:.digits$}{se} {unit} ({tag}95 %: {:.digits$} to {:.digits$} {unit})",
        l.value, l.low, l.high
    )
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
        } else if let Some(why) = v.blocked {
            format!(
                "not explained: the residuals keep structure beyond the noise (position RMS {bp:.4} m, attitude RMS {ba:.3} deg) and no effect of the catalogue accounts for it; {why}, so terms beyond the catalogue were not looked for"
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
        let blocked = v
            .blocked
            .map(|why| format!("; {why}, so terms beyond the catalogue were not looked for"))
            .unwrap_or_default();
        format!(
            "not explained: the closest extension of the catalogue, {}, improves the fit ({gains}) but leaves structure beyond the noise: part of the cause lies outside the catalogue{blocked}",
            named.join(" with ")
        )
    }
}

/// Rival classes the verdict names one by one; the rest are counted (diagnosis.json lists
/// them all).
const CLASSES_NAMED: usize = 3;

/// The clause that names the rival classes left open beyond the answer's own single term:
/// "the first screening cannot tell the answer from any of 14 rolling-moment terms: roll rate,
/// sideslip, ... (the answer's class) or from ... (BIC +1.2), and 5 more classes of 40 terms
/// not told apart (rival_classes)"; none when every class is told apart.
pub(super) fn open_classes(classes: &[crate::RivalClass]) -> Option<String> {
    let open = classes
        .iter()
        .filter(|c| c.status != "told apart" && !(c.status == "answer" && c.members.len() == 1));
    let (mut refitted, unrefitted): (Vec<_>, Vec<_>) =
        open.partition(|c| c.status != "not refitted");
    refitted.sort_by_key(|c| c.status != "better");
    let named_count = refitted.len().min(CLASSES_NAMED);
    let named: Vec<String> = refitted[..named_count]
        .iter()
        .map(|c| match (c.status.as_str(), c.delta_bic) {
            ("answer", _) => format!("{} (the answer's class)", c.words),
            ("better", Some(d)) => format!("{} (BIC {d:+.1}: it fits better)", c.words),
            ("unsettled", Some(d)) => format!(
                "{} (the screening's best; its refit stopped at its iteration limit at BIC {d:+.1}: not settled)",
                c.words
            ),
            (_, Some(d)) => format!("{} (BIC {d:+.1})", c.words),
            _ => c.words.clone(),
        })
        .collect();
    let rest: Vec<&crate::RivalClass> = refitted[named_count..]
        .iter()
        .chain(&unrefitted)
        .copied()
        .collect();
    let rest_terms: usize = rest.iter().map(|c| c.members.len()).sum();
    let plural =
        |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
    let more = (!rest.is_empty()).then(|| {
        format!(
            "{} of {} not told apart (rival_classes)",
            plural(rest.len(), "more class", "more classes"),
            plural(rest_terms, "term", "terms")
        )
    });
    let text = match (named.is_empty(), more) {
        (false, Some(m)) => format!("{}, and {m}", named.join(" or from ")),
        (false, None) => named.join(" or from "),
        (true, Some(m)) => m,
        (true, None) => return None,
    };
    Some(format!(
        "the first screening cannot tell the answer from {text}"
    ))
}

/// The clause that says what the data cannot tell apart, when the answer has rivals: "this
/// release cannot tell it from A (BIC -1.2) or from B (BIC +3.4)".
pub(super) fn ambiguity(rivals: &[crate::RivalReport], events: usize) -> Option<String> {
    if rivals.is_empty() {
        return None;
    }
    let data = if events == 1 {
        "this release"
    } else {
        "these releases"
    };
    let named: Vec<String> = rivals
        .iter()
        .map(|r| {
            let better = if r.delta_bic <= -crate::RIVAL_MARGIN {
                ": it fits better, with no more terms"
            } else {
                ""
            };
            format!(
                "{} (BIC {:+.1}{better})",
                crate::rivals::rival_name(r),
                r.delta_bic
            )
        })
        .collect();
    Some(format!(
        "{data} cannot tell it from {}: a release that separates them settles it (`sepval plan`)",
        named.join(" or from ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn class(words: &str, status: &str, delta_bic: Option<f64>) -> crate::RivalClass {
        crate::RivalClass {
            words: words.into(),
            members: vec![words.into()],
            status: status.into(),
            delta_bic,
            member_terms: Vec::new(),
        }
    }

    #[test]
    fn an_unsettled_class_is_named_open_and_a_told_apart_one_is_not() {
        let classes = [
            class("Cm q d/2V", "unsettled", Some(3251.2)),
            class("Cm beta", "told apart", Some(40.0)),
        ];
        let text = open_classes(&classes).unwrap();
        assert!(text.contains("Cm q d/2V"), "{text}");
        assert!(text.contains("iteration limit"), "{text}");
        assert!(text.contains("+3251.2"), "{text}");
        assert!(!text.contains("Cm beta"), "{text}");
        assert_eq!(open_classes(&classes[1..]), None);
    }

    /// A location reads as its estimate, its standard error and its 95 % interval, or says it
    /// is not determined and gives no standard error.
    #[test]
    fn a_location_reads_with_its_interval_or_as_not_determined() {
        let mut l = Location {
            quantity: "t_on_s".into(),
            value: 0.4512,
            std_error: Some(0.0041),
            low: 0.4432,
            high: 0.4592,
            determined: true,
            basis: String::new(),
        };
        assert_eq!(
            fmt_location(&l),
            "t_on = 0.451 ± 0.004 s (95 %: 0.443 to 0.459 s)"
        );
        (l.std_error, l.determined, l.low) = (None, false, 0.2);
        assert_eq!(
            fmt_location(&l),
            "t_on = 0.451 s (not determined by the data; 95 %: 0.200 to 0.459 s)"
        );
    }
}
