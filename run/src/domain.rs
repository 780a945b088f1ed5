//! Where a fitted model may be flown (docs/model.md section 1, "The model's domain"), in one
//! place for `sepval predict`, `sepval plan` and `sepval envelope`:
//!
//! - **refused**: a condition outside the model's stated domain (Mach in (0, [`MAX_MACH`]],
//!   aircraft alpha and beta within +-[`MAX_ANGLE_DEG`] deg: the aerodynamics of section 3 are
//!   linear in the flow angles and carry no compressibility beyond what a Mach table gives) or
//!   outside the breakpoints of the scenario's aerodynamic tables in Mach, alpha or beta
//!   (beyond them a table is held at its edge, so the model would fly on made-up data);
//! - **said**: a condition within the domain but far from every release fitted ([`far`]):
//!   beyond the box of the releases' conditions by more than [`FAR_MACH`] in Mach,
//!   [`FAR_Q_FRACTION`] of the dynamic pressure, or [`FAR_ANGLE_DEG`] deg in alpha or beta;
//! - **measured**: how far a condition lies from the nearest release, in those same units
//!   ([`reach`]), and how far the held-out releases were predicted ([`covered_reach`]); the
//!   reach beyond what they cover widens a prediction's model-form band (docs/model.md section
//!   10a).

use sepval_common::atmosphere::isa_troposphere;
use sepval_common::scenario::{Flight, Scenario};
use sepval_common::table::{Coefficient, Variable};

/// The largest Mach number of the model's domain (one constant with the tables' Mach domain).
pub use sepval_core::limits::MAX_MACH;
/// The largest aircraft alpha and beta of the model's domain, either sign \[deg\].
pub const MAX_ANGLE_DEG: f64 = 30.0;
/// "Far" in Mach: beyond the releases' Mach span by more than this.
pub const FAR_MACH: f64 = 0.1;
/// "Far" in dynamic pressure: beyond the releases' span by more than this fraction of its
/// nearest end.
pub const FAR_Q_FRACTION: f64 = 0.25;
/// "Far" in aircraft alpha or beta: beyond the releases' span by more than this \[deg\].
pub const FAR_ANGLE_DEG: f64 = 5.0;

/// A quantity of the flight condition the domain bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bounded {
    /// Mach number.
    Mach,
    /// Aircraft angle of attack \[deg\].
    AlphaDeg,
    /// Aircraft sideslip \[deg\].
    BetaDeg,
}

impl Bounded {
    /// Every bounded quantity.
    pub const ALL: [Bounded; 3] = [Bounded::Mach, Bounded::AlphaDeg, Bounded::BetaDeg];

    /// Its name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Bounded::Mach => "Mach",
            Bounded::AlphaDeg => "alpha_deg",
            Bounded::BetaDeg => "beta_deg",
        }
    }

    /// Its value in a flight condition.
    pub fn get(self, f: &Flight) -> f64 {
        match self {
            Bounded::Mach => f.mach,
            Bounded::AlphaDeg => f.alpha_deg,
            Bounded::BetaDeg => f.beta_deg,
        }
    }

    fn variable(self) -> Variable {
        match self {
            Bounded::Mach => Variable::Mach,
            Bounded::AlphaDeg => Variable::Alpha,
            Bounded::BetaDeg => Variable::Beta,
        }
    }
}

/// A condition outside the domain.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{} = {value} is outside {why} ({lo} to {hi})", .quantity.name())]
pub struct DomainError {
    /// The quantity.
    pub quantity: Bounded,
    /// Its value.
    pub value: f64,
    /// The domain's low end.
    pub lo: f64,
    /// Its high end.
    pub hi: f64,
    /// Where the bound comes from, in words.
    pub why: &'static str,
}

const MODEL: &str = "the model's domain (docs/model.md section 1: Mach in (0, 3], aircraft alpha and beta within +-30 deg)";
const TABLES: &str = "the breakpoints of the scenario's aerodynamic tables (beyond them a table is held at its edge)";

/// The span of one quantity in which `scenario` may be flown, and where its tightest end
/// comes from.
pub fn span(scenario: &Scenario, q: Bounded) -> (f64, f64, &'static str, &'static str) {
    let (mut lo, mut hi) = match q {
        Bounded::Mach => (0.0, MAX_MACH),
        _ => (-MAX_ANGLE_DEG, MAX_ANGLE_DEG),
    };
    let (mut lo_why, mut hi_why) = (MODEL, MODEL);
    for (_, c) in scenario.aero.fields() {
        let Coefficient::Table(t) = c else { continue };
        for a in t.axes().iter().filter(|a| a.variable == q.variable()) {
            let (Some(&l), Some(&h)) = (a.breakpoints.first(), a.breakpoints.last()) else {
                continue;
            };
            if l > lo {
                (lo, lo_why) = (l, TABLES);
            }
            if h < hi {
                (hi, hi_why) = (h, TABLES);
            }
        }
    }
    (lo, hi, lo_why, hi_why)
}

/// Checks one value of `q` for `scenario`.
pub fn check_value(scenario: &Scenario, q: Bounded, value: f64) -> Result<(), DomainError> {
    let (lo, hi, lo_why, hi_why) = span(scenario, q);
    // Mach 0 itself is outside (the scenario needs Mach > 0); the angles' ends are inside.
    let below = if q == Bounded::Mach && lo_why == MODEL {
        value <= lo
    } else {
        value < lo
    };
    let why = if below {
        lo_why
    } else if value > hi {
        hi_why
    } else {
        return Ok(());
    };
    Err(DomainError {
        quantity: q,
        value,
        lo,
        hi,
        why,
    })
}

/// Checks the flight condition of `scenario` against its domain.
pub fn check(scenario: &Scenario) -> Result<(), DomainError> {
    for q in Bounded::ALL {
        check_value(scenario, q, q.get(&scenario.flight))?;
    }
    Ok(())
}

/// The distance of `condition` from the nearest release of `releases`, each quantity in its
/// "far" unit: sqrt((dM / [`FAR_MACH`])^2 + (ln(q / q_r) / ln(1 + [`FAR_Q_FRACTION`]))^2 +
/// (d alpha / [`FAR_ANGLE_DEG`])^2 + (d beta / [`FAR_ANGLE_DEG`])^2), minimised over the
/// releases r. 0 at a release; 1 is as far as 0.1 in Mach alone. The nearest release, not the
/// box or the hull of the releases: a condition between two releases is as far as half their
/// gap, because nothing was flown there (the conservative choice, docs/model.md).
/// `f64::INFINITY` when nothing was flown.
pub fn reach(releases: &[&Flight], condition: &Flight) -> f64 {
    let q = dynamic_pressure_pa(condition);
    releases
        .iter()
        .map(|r| {
            let dm = (condition.mach - r.mach) / FAR_MACH;
            let dq = (q / dynamic_pressure_pa(r)).ln() / (1.0 + FAR_Q_FRACTION).ln();
            let da = (condition.alpha_deg - r.alpha_deg) / FAR_ANGLE_DEG;
            let db = (condition.beta_deg - r.beta_deg) / FAR_ANGLE_DEG;
            (dm * dm + dq * dq + da * da + db * db).sqrt()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The reach the held-out evidence covers: the largest reach at which a release was predicted
/// without being fitted, each of `releases` from the others (left out in turn, when there are
/// at least two) and each of `validate` from all of `releases`; 0 when there is none. A
/// prediction's model-form band grows only with its reach beyond this (docs/model.md section
/// 10a): within it, the held-out releases measured how the model's form carries.
pub fn covered_reach(releases: &[&Flight], validate: &[&Flight]) -> f64 {
    let left_out = (0..releases.len())
        .filter(|_| releases.len() >= 2)
        .map(|j| {
            let others: Vec<&Flight> = (0..releases.len())
                .filter(|&i| i != j)
                .map(|i| releases[i])
                .collect();
            reach(&others, releases[j])
        });
    let validated = validate.iter().map(|v| reach(releases, v));
    left_out
        .chain(validated)
        .filter(|r| r.is_finite())
        .fold(0.0, f64::max)
}

/// Dynamic pressure of a flight condition \[Pa\].
fn dynamic_pressure_pa(f: &Flight) -> f64 {
    let air = isa_troposphere(f.altitude_m);
    let v = f.mach * air.speed_of_sound_m_s;
    0.5 * air.density_kg_m3 * v * v
}

/// When `condition` lies far from every release of `releases` (see the module documentation),
/// the sentence that says so, naming each quantity beyond its span; `None` when it is near.
pub fn far(releases: &[&Flight], condition: &Flight) -> Option<String> {
    if releases.is_empty() {
        return None;
    }
    let mut parts = Vec::new();
    let mach: Vec<f64> = releases.iter().map(|f| f.mach).collect();
    let (d, lo, hi) = beyond(condition.mach, &mach);
    if beyond_limit(d, FAR_MACH) {
        parts.push(format!(
            "Mach {} against {} (beyond by {d:.2}, more than {FAR_MACH})",
            condition.mach,
            span_words(lo, hi)
        ));
    }
    let q = dynamic_pressure_pa(condition);
    let qs: Vec<f64> = releases.iter().map(|f| dynamic_pressure_pa(f)).collect();
    let (d, lo, hi) = beyond(q, &qs);
    let edge = if q < lo { lo } else { hi };
    if beyond_limit(d, FAR_Q_FRACTION * edge) {
        parts.push(format!(
            "dynamic pressure {:.0} Pa against {} Pa (beyond by {:.0} %, more than {:.0} %)",
            q,
            span_words(lo.round(), hi.round()),
            100.0 * d / edge,
            100.0 * FAR_Q_FRACTION
        ));
    }
    let alpha: Vec<f64> = releases.iter().map(|f| f.alpha_deg).collect();
    let beta: Vec<f64> = releases.iter().map(|f| f.beta_deg).collect();
    for (name, value, values) in [
        ("alpha", condition.alpha_deg, alpha),
        ("beta", condition.beta_deg, beta),
    ] {
        let (d, lo, hi) = beyond(value, &values);
        if beyond_limit(d, FAR_ANGLE_DEG) {
            parts.push(format!(
                "{name} {value} deg against {} deg (beyond by {d:.1} deg, more than {FAR_ANGLE_DEG})",
                span_words(lo, hi)
            ));
        }
    }
    if parts.is_empty() {
        return None;
    }
    Some(format!(
        "Far from every release fitted, an extrapolation: {}.",
        parts.join("; ")
    ))
}

/// How far `value` lies beyond the span of `values` (0 inside), and the span.
fn beyond(value: f64, values: &[f64]) -> (f64, f64, f64) {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let d = if value < lo {
        lo - value
    } else if value > hi {
        value - hi
    } else {
        0.0
    };
    (d, lo, hi)
}

/// `d` beyond `limit` by more than rounding (0.8 - 0.7 is 0.10000000000000009: not beyond 0.1).
fn beyond_limit(d: f64, limit: f64) -> bool {
    d > limit * (1.0 + 1e-9)
}

fn span_words(lo: f64, hi: f64) -> String {
    if hi - lo <= 0.0 {
        format!("{lo} of the releases")
    } else {
        format!("{lo} to {hi} of the releases")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_domain_refuses_mach_5_and_alpha_89_and_names_itself() {
        let mut s = Scenario::embedded_default();
        assert!(check(&s).is_ok());
        s.flight.mach = 5.0;
        let e = check(&s).unwrap_err().to_string();
        assert!(
            e.starts_with("Mach = 5 is outside the model's domain"),
            "{e}"
        );
        s.flight.mach = 0.95;
        s.flight.alpha_deg = 89.0;
        let e = check(&s).unwrap_err().to_string();
        assert!(e.contains("alpha_deg = 89 is outside"), "{e}");
        assert!(e.contains("(-30 to 30)"), "{e}");
    }

    #[test]
    fn far_names_what_lies_beyond_the_releases() {
        let base = Scenario::embedded_default().flight;
        assert_eq!(far(&[&base], &base), None);
        let mut near = base.clone();
        near.mach -= 0.1;
        assert_eq!(far(&[&base], &near), None, "0.1 beyond is not far");
        let mut away = base.clone();
        away.mach = 2.5;
        let words = far(&[&base], &away).unwrap();
        assert!(
            words.starts_with("Far from every release fitted"),
            "{words}"
        );
        assert!(
            words.contains("Mach 2.5 against 0.95 of the releases"),
            "{words}"
        );
        assert!(words.contains("dynamic pressure"), "{words}");
    }

    #[test]
    fn reach_is_zero_at_a_release_one_a_far_unit_away_and_infinite_with_none() {
        let base = Scenario::embedded_default().flight;
        assert!(reach(&[&base], &base).abs() < 1e-12);
        assert!(reach(&[], &base).is_infinite());
        let mut a = base.clone();
        a.alpha_deg += 5.0;
        assert!((reach(&[&base], &a) - 1.0).abs() < 1e-12);
        let mut b = base.clone();
        b.alpha_deg += 10.0;
        // The nearest release decides: b is one unit from a, two from base.
        assert!((reach(&[&base, &a], &b) - 1.0).abs() < 1e-12);
        // Between two releases: half the gap, not zero.
        let mut mid = base.clone();
        mid.alpha_deg += 2.5;
        assert!((reach(&[&base, &a], &mid) - 0.5).abs() < 1e-12);
        // Two releases a unit apart, each predicted from the other, cover a unit of reach.
        assert!((covered_reach(&[&base, &a], &[]) - 1.0).abs() < 1e-12);
        assert!(covered_reach(&[&base], &[]).abs() < 1e-15);
        assert!((covered_reach(&[&base], &[&b]) - 2.0).abs() < 1e-12);
    }
}
