//! Rival classes: every library entry the screening cannot tell from the best, grouped by what
//! it changes in the residuals (issue 36, item 1; `docs/discovery.md` section 11.5,
//! step 4b).
//!
//! Verification refits only the few best entries by F-to-enter, so on one release the true
//! cause can be missing from the rivals while a dozen terms explain the misfit about equally
//! (a weaker roll damping answered as sideslip, the rate term never refitted). The rival set
//! is instead the whole class the data cannot tell apart:
//!
//! 1. **Candidates.** An entry's screening statistic X = dof F (its chi-square drop over the
//!    residual variance) is, for large residual degrees of freedom, a noncentral chi-square of
//!    `dof` degrees of freedom and noncentrality lambda (N. L. Johnson, S. Kotz and N.
//!    Balakrishnan, "Continuous Univariate Distributions", vol. 2, 2nd ed., 1995, chapter 29:
//!    mean dof + lambda, variance 2 (dof + 2 lambda)). From the best entry's X the one-sided
//!    95 % lower confidence bound of its noncentrality, lambda_lo, solves
//!    `dof + lambda + z sqrt(2 (dof + 2 lambda)) = X` (normal approximation, z = 1.645). An
//!    entry is a candidate when it passes the step's Bonferroni threshold (with a catalogue
//!    answer, the larger of it and the level that answer met, `crate::catalogue_level`) and its
//!    own X is at least `dof + lambda_lo`, what an entry of that noncentrality shows on average:
//!    another noise realisation could have ranked it first.
//! 2. **Classes.** Each candidate's signature is what it would change in the residuals: the
//!    projection of the residuals (beyond the model's own sensitivities) on its directions.
//!    Candidates are taken best first; each joins the first class whose lead's signature has a
//!    cosine of at least [`CLASS_COS`] with its own, or leads a new class.
//! 3. The caller refits one representative (the lead) per class, within a budget, and the
//!    rival rule decides each class by its representative.

use nalgebra::{DMatrix, DVector};
use sepval_common::extension::{Axis, Family, Regressor};

use crate::library::Entry;
use crate::stepwise::{Score, column_basis, new_directions, project_out};

/// The one-sided 95 % normal quantile of the candidates' rule.
pub const CLASS_Z: f64 = 1.645;
/// Cosine between two signatures above which they are one class.
pub const CLASS_COS: f64 = 0.95;
/// Kinds of member a class's words name at most.
const KINDS_NAMED: usize = 6;
/// Class representatives refitted at most, beyond the classes a refit already represents.
pub const CLASS_REFITS: usize = 6;

/// Entries the screening cannot tell apart, best first.
#[derive(Debug, Clone, PartialEq)]
pub struct Class {
    /// Entry indices, the lead (largest statistic) first.
    pub members: Vec<usize>,
}

/// A class as the diagnosis carries it from discovery's first step to the rival search.
#[derive(Debug, Clone)]
pub(crate) struct ClassInfo {
    /// Its lead's index among the first step's screened entries.
    pub lead: usize,
    /// Its members, the lead first.
    pub members: Vec<Entry>,
    /// In words.
    pub words: String,
}

impl ClassInfo {
    /// The class of `class` over `entries`.
    pub fn new(class: &Class, entries: &[Entry]) -> ClassInfo {
        ClassInfo {
            lead: class.members[0],
            members: class.members.iter().map(|&e| entries[e].clone()).collect(),
            words: words(class, entries),
        }
    }

    /// Whether `axis` and `regressor` are those of one of its members.
    pub fn holds(&self, axis: Axis, regressor: Regressor) -> bool {
        self.members
            .iter()
            .any(|m| m.axis() == axis && m.terms[0].regressor == regressor)
    }
}

/// The class of `classes` that holds `entry`'s kind (its lead's class first).
pub(crate) fn class_of(classes: &[ClassInfo], entry: &Entry) -> Option<usize> {
    classes
        .iter()
        .position(|c| c.holds(entry.axis(), entry.terms[0].regressor))
}

/// The one-sided lower confidence bound of the noncentrality of a chi-square statistic `x` of
/// `dof` degrees of freedom at normal quantile `z` (0 when `x` is within the central spread).
pub fn lower_noncentrality(x: f64, dof: f64, z: f64) -> f64 {
    // With u = sqrt(2 (dof + 2 lambda)): u^2 / 4 + z u + dof / 2 - x = 0.
    let disc = z * z + x - dof / 2.0;
    if disc.is_nan() || disc <= 0.0 {
        return 0.0;
    }
    let u = 2.0 * (disc.sqrt() - z);
    if u <= 0.0 {
        return 0.0;
    }
    ((u * u / 2.0 - dof) / 2.0).max(0.0)
}

/// The entries (indices into `entries`) that the screening cannot tell from the best: passing
/// `threshold` (the step's Bonferroni level) with a statistic at least the best's lower bound;
/// and, with a catalogue answer whose signature screens at `answer` (its statistic X on one
/// degree of freedom), those the screening cannot tell from the answer: a statistic at least
/// the answer's lower bound, whatever their p (the answer met its level by its refit, not by
/// the screening, and an entry that screens as it does could have met it too). Best first.
/// `scores` are sorted best first, as `stepwise::screen` returns them.
pub fn candidates(
    scores: &[Score],
    entry_cols: &[Vec<usize>],
    threshold: f64,
    answer: Option<f64>,
) -> Vec<usize> {
    let stat = |s: &Score| entry_cols[s.entry].len() as f64 * s.f;
    let dof = |s: &Score| entry_cols[s.entry].len() as f64;
    let best_lo = scores
        .iter()
        .find(|s| s.p < threshold)
        .map(|best| lower_noncentrality(stat(best), dof(best), CLASS_Z));
    let answer_lo = answer.map(|x| lower_noncentrality(x, 1.0, CLASS_Z));
    let mut out: Vec<&Score> = scores
        .iter()
        .filter(|s| {
            let like_best = best_lo.is_some_and(|l| s.p < threshold && stat(s) >= dof(s) + l);
            let like_answer = answer_lo.is_some_and(|l| stat(s) >= dof(s) + l);
            like_best || like_answer
        })
        .collect();
    out.sort_by(|a, b| stat(b).total_cmp(&stat(a)));
    out.into_iter().map(|s| s.entry).collect()
}

/// The classes of `candidates` (best first): residuals `r0`, the model's own sensitivities
/// `fixed`, the entries' columns `cols` (`entry_cols[k]`: entry k's).
pub fn classes(
    r0: &DVector<f64>,
    fixed: &DMatrix<f64>,
    cols: &DMatrix<f64>,
    entry_cols: &[Vec<usize>],
    candidates: &[usize],
) -> Vec<Class> {
    let basis = column_basis(fixed);
    let mut r = r0.clone();
    project_out(&mut r, &basis);
    let signature = |e: usize| {
        let q = new_directions(cols, &entry_cols[e], &basis);
        let mut v = DVector::zeros(r.len());
        for b in &q {
            v.axpy(b.dot(&r), b, 1.0);
        }
        let n = v.norm();
        (n > 0.0).then(|| v / n)
    };
    let mut leads: Vec<DVector<f64>> = Vec::new();
    let mut out: Vec<Class> = Vec::new();
    for &e in candidates {
        let Some(v) = signature(e) else { continue };
        match leads.iter().position(|l| l.dot(&v) >= CLASS_COS) {
            Some(k) => out[k].members.push(e),
            None => {
                leads.push(v);
                out.push(Class { members: vec![e] });
            }
        }
    }
    out
}

/// A class in words: "any of 14 rolling-moment terms: roll rate, sideslip, Mach, a step near
/// 0.6 s, ..." (each kind once, in the members' order).
pub fn words(class: &Class, entries: &[Entry]) -> String {
    let members: Vec<&Entry> = class.members.iter().map(|&e| &entries[e]).collect();
    words_of(&members)
}

/// Members of a class in words, as [`words`] puts them.
pub(crate) fn words_of(members: &[&Entry]) -> String {
    if let [one] = members {
        return one.label();
    }
    let mut kinds: Vec<String> = Vec::new();
    for e in members {
        let w = kind_words(e);
        if !kinds.contains(&w) {
            kinds.push(w);
        }
    }
    let axis = members[0].axis();
    let what = if members.iter().all(|e| e.axis() == axis) {
        axis_words(axis)
    } else {
        "terms on several axes"
    };
    let shown = kinds.len().min(KINDS_NAMED);
    let etc = if kinds.len() > shown { ", ..." } else { "" };
    format!(
        "any of {} {what}: {}{etc}",
        members.len(),
        kinds[..shown].join(", ")
    )
}

/// What the terms of an axis are, in words.
fn axis_words(axis: Axis) -> &'static str {
    match axis {
        Axis::CA => "axial-force terms",
        Axis::CY => "side-force terms",
        Axis::CZ => "normal-force terms",
        Axis::Cl => "rolling-moment terms",
        Axis::Cm => "pitching-moment terms",
        Axis::Cn => "yawing-moment terms",
        Axis::Ejector => "ejector terms",
        Axis::WindY | Axis::WindZ => "gusts",
    }
}

/// What an entry depends on, in words.
fn kind_words(e: &Entry) -> String {
    let t = &e.terms[0];
    let near = |what: &str| {
        format!(
            "{what} near {} s",
            crate::readings::fmt_num((t.locator[0] * 20.0).round() / 20.0)
        )
    };
    match (e.family(), t.regressor) {
        (Family::Rate, Regressor::P) => "roll rate".into(),
        (Family::Rate, Regressor::Q) => "pitch rate".into(),
        (Family::Rate, _) => "yaw rate".into(),
        (Family::FlowAngle, Regressor::Alpha | Regressor::Alpha2 | Regressor::Alpha3) => {
            "angle of attack".into()
        }
        (Family::FlowAngle, Regressor::Beta | Regressor::Beta2 | Regressor::Beta3) => {
            "sideslip".into()
        }
        (Family::FlowAngle, _) => "alpha times beta".into(),
        (Family::Interference, _) => "distance from the aircraft".into(),
        (Family::InterferenceFlowAngle, _) => "flow angle or rate near the aircraft".into(),
        (Family::Mach, _) => "Mach".into(),
        (Family::Step, _) => near("a step"),
        (Family::Oscillation, _) => format!(
            "an oscillation at {} Hz",
            crate::readings::fmt_num(t.locator[0])
        ),
        (Family::EjectorStroke, _) => "the ejector's stroke".into(),
        (Family::Wind, _) => near("a gust"),
        (Family::Window, _) => "a time window".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lower_bound_is_below_the_statistic_and_zero_in_the_central_spread() {
        // X = 32 on one degree of freedom: lambda_lo about 17.6 (mean 18.6 of an entry with it).
        let l = lower_noncentrality(32.0, 1.0, CLASS_Z);
        assert!((17.0..18.5).contains(&l), "{l}");
        // It solves the equation it stands for.
        let lhs = 1.0 + l + CLASS_Z * (2.0 * (1.0 + 2.0 * l)).sqrt();
        assert!((lhs - 32.0).abs() < 1e-9, "{lhs}");
        assert!(lower_noncentrality(2.0, 1.0, CLASS_Z) < 1e-12);
        assert!(lower_noncentrality(f64::NAN, 1.0, CLASS_Z) < 1e-12);
        // Large statistics: the bound is within a few standard deviations.
        let l = lower_noncentrality(1000.0, 1.0, CLASS_Z);
        assert!((880.0..920.0).contains(&l), "{l}");
    }

    #[test]
    fn near_equal_explanations_are_candidates_and_collinear_ones_one_class() {
        let m = 400;
        let t: Vec<f64> = (0..m).map(|i| i as f64 / m as f64).collect();
        let fixed = DMatrix::from_fn(m, 1, |_, _| 1.0);
        // Columns: a signal, a near copy, an unrelated shape that explains it about as well
        // (a smaller share of a larger column), and a weak one.
        let s = |x: f64| (x * 6.0).sin();
        let cols = DMatrix::from_fn(m, 4, |i, j| match j {
            0 => s(t[i]),
            1 => s(t[i]) + 0.02 * (t[i] * 40.0).cos(),
            2 => s(t[i]) + 0.25 * (t[i] * 13.0).cos(),
            _ => (t[i] * 29.0).cos(),
        });
        let entry_cols = vec![vec![0], vec![1], vec![2], vec![3]];
        let r0 = DVector::from_fn(m, |i, _| 0.3 * s(t[i]) + 0.01 * ((i * 7919) % 13) as f64);
        let scores = crate::stepwise::screen(&r0, &fixed, &cols, &entry_cols);
        let c = candidates(&scores, &entry_cols, 0.01, None);
        assert!(c.contains(&0) && c.contains(&1), "{c:?} {scores:?}");
        assert!(!c.contains(&3), "{c:?}");
        let k = classes(&r0, &fixed, &cols, &entry_cols, &c);
        let with = |e: usize| k.iter().position(|cl| cl.members.contains(&e));
        assert_eq!(with(0), with(1), "{k:?}");
        assert_eq!(k.iter().map(|cl| cl.members.len()).sum::<usize>(), c.len());
    }

    #[test]
    fn entries_that_screen_as_the_catalogues_answer_does_are_candidates_whatever_their_p() {
        let score = |entry: usize, f: f64, p: f64| Score {
            entry,
            f,
            p,
            drop: f,
            pse_falls: true,
        };
        // The best entry far past the threshold; one just outside it (the roll-damping case of
        // seed 0x6060_2026_1207: X 10.6, p 1.1e-3, against 9.1e-4); one in the noise.
        let scores = [
            score(0, 40.0, 1e-9),
            score(1, 10.6, 1.1e-3),
            score(2, 1.5, 0.22),
        ];
        let cols = vec![vec![0], vec![1], vec![2]];
        let level = 0.01 / 11.0;
        assert_eq!(candidates(&scores, &cols, level, None), vec![0]);
        // The answer's signature screens at X 17.6: lower bound 7.4, so X >= 8.4 qualifies.
        assert_eq!(candidates(&scores, &cols, level, Some(17.6)), vec![0, 1]);
        // An answer screening far above: only the best's own band.
        assert_eq!(candidates(&scores, &cols, level, Some(60.0)), vec![0]);
        // With nothing passing the threshold, the answer's band alone makes the candidates.
        let weak = [score(1, 10.6, 1.1e-3), score(2, 1.5, 0.22)];
        assert_eq!(candidates(&weak, &cols, level, None), Vec::<usize>::new());
        assert_eq!(candidates(&weak, &cols, level, Some(17.6)), vec![1]);
    }
}
