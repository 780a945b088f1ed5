//! The closed loop that keeps its word (issue 60, items 1 and 2): one release at the default
//! condition diagnosed; the plan made from it; the plan's top condition flown with the same
//! hidden cause; both releases diagnosed `--after` the first diagnosis with `--plan`. The
//! cases are the tests' own (`case`): a random base of factors (each factor in the middle 30 %
//! of its range) and random seeds for every case, drawn from a seed not used while the method
//! was built, and a hidden cause of five kinds: pitch damping and roll damping weaker than the
//! model's, a yaw moment growing with sideslip (`Cn beta`), a drag rise with Mach number (`CA
//! dm`) and nothing (null). Slow tier (`SEPVAL_SLOW_TESTS=1`): a case is two diagnoses and a
//! plan, one to three minutes on two cores.
//!
//! The slow tier runs the sweep's first two cases (pitch and roll damping): neither wrong and
//! one right at least (one miss allowed per ten cases begun: case 1 stays open);
//! `SEPVAL_SWEEPS=full` (`scripts/sweeps.sh`) all ten, 9 of them right.
//! `SEPVAL_AFTER_CASES=N` runs the first N cases of the sweep, and
//! `SEPVAL_AFTER_COMPARE=1` also diagnoses both releases without `--after` beside each, for the
//! wall times side by side (printed, never asserted: speed lives in measurements).

use std::path::Path;

use sepval_common::effects::MAX_EFFECT_PARAMS;
use sepval_common::model::{CoefficientFn, Coefficients, Flow};
use sepval_common::scenario::Scenario;
use sepval_common::telemetry::Trajectory;
use sepval_core::factors::{FACTOR_COUNT, Factors};
use sepval_plan::Quantity;
use sepval_tests::Gauss;
use serde_json::Value;

use crate::command::Diagnose;
use crate::generator::{Hidden, release_on, write};
use crate::releases::default_scenario;
use crate::{at_top, damped, grid, plan};

/// The hidden cause of a case.
#[derive(Debug, Clone, Copy)]
enum Cause {
    /// Pitch damping scaled by the factor.
    Pitch(f64),
    /// Roll damping scaled by the factor.
    Roll(f64),
    /// Cn += c beta.
    CnBeta(f64),
    /// CA += c (M - 0.85).
    Mach(f64),
    /// Nothing.
    Null,
}

impl Cause {
    /// The library term (`axis regressor`) that is the cause, `None` for the null.
    fn kind(self) -> Option<&'static str> {
        match self {
            Cause::Pitch(_) => Some("Cm q"),
            Cause::Roll(_) => Some("Cl p"),
            Cause::CnBeta(_) => Some("Cn beta"),
            Cause::Mach(_) => Some("CA dm"),
            Cause::Null => None,
        }
    }
}

/// Cn += p0 beta.
fn yaw_beta(p: &[f64; MAX_EFFECT_PARAMS], flow: &Flow, k: &mut Coefficients) {
    k.cn += p[0] * flow.beta_rad;
}

/// CA += p0 (M - 0.85) (CX = -CA).
fn drag_rise(p: &[f64; MAX_EFFECT_PARAMS], flow: &Flow, k: &mut Coefficients) {
    k.cx -= p[0] * (flow.mach - 0.85);
}

fn params(v: f64) -> [f64; MAX_EFFECT_PARAMS] {
    let mut p = [0.0; MAX_EFFECT_PARAMS];
    p[0] = v;
    p
}

/// One case: its cause, base and seeds.
struct Case {
    cause: Cause,
    base: Factors,
    seeds: [u64; 2],
}

impl Case {
    /// The truth (the scenario with the cause) and the hidden coefficient term, if any.
    fn truth(&self, model: &Scenario) -> (Scenario, Option<Hidden>) {
        match self.cause {
            Cause::Pitch(s) => (damped(model, s, |a| &mut a.cm_q_per_rad), None),
            Cause::Roll(s) => (damped(model, s, |a| &mut a.cl_p_per_rad), None),
            Cause::CnBeta(c) => (model.clone(), Some((yaw_beta as CoefficientFn, params(c)))),
            Cause::Mach(c) => (model.clone(), Some((drag_rise as CoefficientFn, params(c)))),
            Cause::Null => (model.clone(), None),
        }
    }
}

/// `count` cases, the five causes in turn, each on its own random base and seeds, drawn from
/// `seed` (cause sizes too: pitch damping 0.35 to 0.6 of the model's, roll damping 0.4 to 0.6,
/// Cn beta +0.12 to +0.2 per rad against the model's -0.3, a drag rise 0.4 to 0.8 per Mach).
fn cases(seed: u64, model: &Scenario, count: usize) -> Vec<Case> {
    let mut g = Gauss(seed);
    let mut out = Vec::new();
    for k in 0..count {
        let u = g.uniform();
        let cause = match k % 5 {
            0 => Cause::Pitch(0.35 + 0.25 * u),
            1 => Cause::Roll(0.4 + 0.2 * u),
            2 => Cause::CnBeta(0.12 + 0.08 * u),
            3 => Cause::Mach(0.4 + 0.4 * u),
            _ => Cause::Null,
        };
        let table = &model.factors.0;
        let mut f = [0.0; FACTOR_COUNT];
        for (v, s) in f.iter_mut().zip(table) {
            *v = s.min + (s.max - s.min) * (0.35 + 0.3 * g.uniform());
        }
        let seeds = [
            1000 + (g.uniform() * 1e6) as u64,
            2000 + (g.uniform() * 1e6) as u64,
        ];
        out.push(Case {
            cause,
            base: Factors(f),
            seeds,
        });
    }
    out
}

/// The kinds a model record of diagnosis.json names: its effects' ids and `axis regressor`.
fn kinds(m: &Value) -> Vec<String> {
    let mut out: Vec<String> = m["effects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["id"].as_str().unwrap().to_string())
        .collect();
    out.extend(m["terms"].as_array().unwrap().iter().map(|t| {
        format!(
            "{} {}",
            t["axis"].as_str().unwrap(),
            t["regressor"].as_str().unwrap()
        )
    }));
    out
}

/// Where the truth stands in a diagnosis: `right` (the answer names it, or names nothing for
/// the null), `open` (a rival or a member of a class not told apart names it; for the null,
/// the answer is ambiguous), `missed` (nothing named, the truth not open), `wrong` (a
/// confident wrong answer: another cause named, the truth not open).
fn standing(d: &Value, truth: Option<&str>) -> &'static str {
    let answer = kinds(&d["model"]);
    let Some(t) = truth else {
        return match (answer.is_empty(), d["ambiguous"].as_bool().unwrap()) {
            (true, _) => "right",
            (false, true) => "open",
            (false, false) => "wrong",
        };
    };
    if answer.iter().any(|k| k == t) {
        return "right";
    }
    let in_rival = d["rivals"]
        .as_array()
        .unwrap()
        .iter()
        .any(|r| kinds(&r["model"]).iter().any(|k| k == t));
    let in_class = d["rival_classes"].as_array().is_some_and(|cs| {
        cs.iter().any(|c| {
            c["status"] != "told apart"
                && c["member_terms"].as_array().is_some_and(|ms| {
                    ms.iter().any(|m| {
                        m.as_array().unwrap().iter().any(|t2| {
                            format!(
                                "{} {}",
                                t2["axis"].as_str().unwrap(),
                                t2["regressor"].as_str().unwrap()
                            ) == t
                        })
                    })
                })
        })
    });
    if in_rival || in_class {
        "open"
    } else if answer.is_empty() {
        "missed"
    } else {
        "wrong"
    }
}

/// The releases `releases` (the first `fit` fitted) diagnosed into `dir/out` with `scenario`,
/// `--after` and `--plan` as given.
fn diagnose_in(
    dir: &Path,
    releases: &[Trajectory],
    scenario: &Scenario,
    after: Option<&Path>,
    plan: Option<&Path>,
    out: &str,
) -> Value {
    let mut flags = Diagnose::of(Vec::new());
    for (flag, name) in write(dir, releases, releases.len(), Some(scenario)) {
        let path = dir.join(name);
        match flag {
            "--scenario" => flags.scenario = Some(path),
            _ => flags.data.push(path),
        }
    }
    flags.after = after.map(Path::to_path_buf);
    flags.plan = plan.map(Path::to_path_buf);
    flags.record(&dir.join(out))
}

/// One row of the sweep's table.
struct Row {
    line: String,
    first: &'static str,
    second: &'static str,
    fates_complete: bool,
}

/// One case run through the loop.
fn run_case(k: usize, case: &Case, compare: bool) -> Row {
    let model = default_scenario();
    let (truth, hidden) = case.truth(&model);
    let one = tempfile::tempdir().unwrap();
    let r1 = release_on(&truth, &case.base, hidden, case.seeds[0]);
    let first = diagnose_in(
        one.path(),
        std::slice::from_ref(&r1),
        &model,
        None,
        None,
        "diag",
    );
    let g = grid(
        &[
            (Quantity::Mach, 0.6, 1.1),
            (Quantity::AlphaDeg, -2.0, 4.0),
            (Quantity::BetaDeg, -4.0, 4.0),
        ],
        3,
    );
    let p = plan(one.path(), &g);
    let next = at_top(&truth, &p);
    let r2 = release_on(&next, &case.base, hidden, case.seeds[1]);
    let two = tempfile::tempdir().unwrap();
    let both = diagnose_in(
        two.path(),
        &[r1.clone(), r2.clone()],
        &model,
        Some(&one.path().join("diag")),
        Some(&one.path().join("plan")),
        "diag",
    );
    let plain = compare.then(|| {
        let three = tempfile::tempdir().unwrap();
        let d = diagnose_in(three.path(), &[r1, r2], &model, None, None, "diag");
        (
            d["wall_s"].as_f64().unwrap(),
            d["evaluations"].as_u64().unwrap(),
        )
    });
    let truth_kind = case.cause.kind();
    let fates = both["after"]["fates"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    let earlier_open = 1 + first["rivals"].as_array().unwrap().len();
    let fates_complete = kinds(&first["model"]).is_empty() || fates.len() >= earlier_open.min(16);
    let top = &p["conditions"][0];
    let row = Row {
        line: format!(
            "| {k} | {:?} | {} + class {} | M {} alpha {} beta {} alt {} | {} | {} -> {} | {} | wall {:.0} s, {} simulations{} |",
            case.cause,
            kinds(&first["model"]).join(" + "),
            first["rival_classes"]
                .as_array()
                .map(|cs| cs
                    .iter()
                    .filter(|c| c["status"] != "told apart")
                    .map(|c| c["words"].as_str().unwrap().to_string())
                    .collect::<Vec<_>>()
                    .join(" / "))
                .unwrap_or_default(),
            top["mach"],
            top["alpha_deg"],
            top["beta_deg"],
            top["altitude_m"],
            kinds(&both["model"]).join(" + "),
            standing(&first, truth_kind),
            standing(&both, truth_kind),
            fates
                .iter()
                .map(|f| f["words"].as_str().unwrap().to_string())
                .collect::<Vec<_>>()
                .join("; "),
            both["wall_s"].as_f64().unwrap(),
            both["evaluations"],
            plain.map_or(String::new(), |(w, e)| format!(
                " (without --after {w:.0} s, {e} simulations)"
            )),
        ),
        first: standing(&first, truth_kind),
        second: standing(&both, truth_kind),
        fates_complete,
    };
    eprintln!("{}", row.line);
    eprintln!("  both verdict: {}", both["verdict"]);
    if let Some(pc) = both["after"]["plan"].as_object() {
        eprintln!("  plan check: {}", Value::Object(pc.clone()));
    }
    row
}

/// How many of a sweep's `full` cases to run: `var`'s number when it is set, else
/// [`sepval_tests::sweep_cases`]'s (the tier's first `tier`, all with `SEPVAL_SWEEPS=full`).
fn cases_to_run(var: &str, full: usize, tier: usize) -> usize {
    std::env::var(var)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| sepval_tests::sweep_cases(full, tier))
}

/// The one case `var` names (numbered from 1, as the tables number them), when it is set.
fn case_alone(var: &str) -> Option<usize> {
    std::env::var(var).ok().and_then(|v| v.parse().ok())
}

/// The sweep: after the planned release at least 90 % right and none wrong; every earlier
/// explanation's fate in the report; the first release's confident wrong answers counted.
#[test]
fn the_loop_keeps_its_word_on_random_bases() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let count = cases_to_run("SEPVAL_AFTER_CASES", 10, 2);
    let compare = std::env::var("SEPVAL_AFTER_COMPARE").is_ok_and(|v| v == "1");
    // `SEPVAL_AFTER_CASE=K` runs case K alone (numbered from 1, as the table numbers them).
    let only = case_alone("SEPVAL_AFTER_CASE");
    let model = default_scenario();
    let all = cases(0x6060_2026_1206, &model, 10);
    let rows: Vec<Row> = all
        .iter()
        .take(count)
        .enumerate()
        .filter(|(k, _)| only.is_none_or(|o| o == k + 1))
        .map(|(k, c)| run_case(k + 1, c, compare))
        .collect();
    let table: Vec<&str> = rows.iter().map(|r| r.line.as_str()).collect();
    let table = table.join("\n");
    eprintln!("{table}");
    // One release never a confident wrong answer (issue 60): on this seed case 6 (pitch
    // damping 0.40 of the model's) was answered `pitch_stiffness_cubic` with the cause not open
    // until the rival classes were formed, and the rivals tested, at the level the catalogue's
    // answer met (2026-12-07; `one_release_is_never_a_confident_wrong_answer` holds it on
    // cases of its own).
    assert!(rows.iter().all(|r| r.first != "wrong"), "{table}");
    assert!(rows.iter().all(|r| r.second != "wrong"), "{table}");
    let right = rows.iter().filter(|r| r.second == "right").count();
    assert!(
        right >= sepval_tests::at_least(rows.len(), 9),
        "{right} of {} right\n{table}",
        rows.len()
    );
    assert!(rows.iter().all(|r| r.fates_complete), "{table}");
}

/// The issue's own failure: pitch damping 0.4 times the model's on the tests' base, one
/// release at the default condition, then the plan's condition of the issue (Mach 1.10,
/// 3 000 m, alpha -2 deg), both diagnosed after the first. The first answers `Cm q d/2V`; the
/// issue asks that the second refit it and prefer it, which the carried refit does not reach
/// (its best start ends far above the answer in BIC: docs/discovery.md 11.9, "Limit seen").
/// What is asserted is what holds: the earlier answer is carried and has its fate, and the
/// cause is never lost, the answer or open (a rival, or a class of this diagnosis not told
/// apart).
#[test]
fn weaker_pitch_damping_is_carried_and_stays_open_after_the_first_diagnosis() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let model = default_scenario();
    let truth = damped(&model, 0.4, |a| &mut a.cm_q_per_rad);
    let base = Factors::from_json_str(crate::generator::BASE, &model.factors).unwrap();
    let mut next = truth.clone();
    (
        next.flight.mach,
        next.flight.altitude_m,
        next.flight.alpha_deg,
    ) = (1.10, 3000.0, -2.0);
    let one = tempfile::tempdir().unwrap();
    let r1 = release_on(&truth, &base, None, 41);
    let first = diagnose_in(
        one.path(),
        std::slice::from_ref(&r1),
        &model,
        None,
        None,
        "diag",
    );
    let r2 = release_on(&next, &base, None, 43);
    let two = tempfile::tempdir().unwrap();
    let after = one.path().join("diag");
    let both = diagnose_in(two.path(), &[r1, r2], &model, Some(&after), None, "diag");
    eprintln!("first: {}", first["verdict"]);
    eprintln!("both: {}", both["verdict"]);
    let fates = both["after"]["fates"].as_array().unwrap();
    for f in fates {
        eprintln!("  {}", f["words"]);
    }
    assert!(
        kinds(&first["model"]).iter().any(|k| k == "Cm q"),
        "{}",
        first["verdict"]
    );
    assert!(
        fates
            .iter()
            .any(|f| f["name"] == "Cm q d/2V" && f["was"] == "the earlier answer"),
        "{}",
        both["after"]
    );
    assert_ne!(
        standing(&both, Some("Cm q")),
        "wrong",
        "{}",
        both["verdict"]
    );
    // The cause is never said to be told apart when its refit did not converge: it is the
    // answer, a rival, or not settled (its BIC only an upper bound).
    let cause = fates
        .iter()
        .find(|f| f["name"] == "Cm q d/2V" && f["was"] == "the earlier answer")
        .unwrap();
    assert!(
        cause["status"] != "told apart" || cause["cut_off"] == false,
        "{}",
        cause["words"]
    );
}

/// Plan and diagnosis agree (issue 60, item 2), on the roll-damping loop of
/// `weaker_roll_damping_is_named_after_the_planned_release` (the tests' base, other seeds):
/// every pair the plan said its top condition separates is recorded with the plan's predicted
/// separation and the diagnosis's after the release, each earlier rival has its fate, and the
/// disagreements are the pairs the diagnosis does not separate.
#[test]
fn the_plans_separations_are_set_against_the_diagnosis() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let model = default_scenario();
    let truth = damped(&model, 0.5, |a| &mut a.cl_p_per_rad);
    let base = Factors::from_json_str(crate::generator::BASE, &model.factors).unwrap();
    let one = tempfile::tempdir().unwrap();
    let r1 = release_on(&truth, &base, None, 31);
    let first = diagnose_in(
        one.path(),
        std::slice::from_ref(&r1),
        &model,
        None,
        None,
        "diag",
    );
    let g = grid(
        &[(Quantity::BetaDeg, -6.0, 6.0), (Quantity::Mach, 0.6, 0.95)],
        5,
    );
    let p = plan(one.path(), &g);
    let next = at_top(&truth, &p);
    let r2 = release_on(&next, &base, None, 33);
    let two = tempfile::tempdir().unwrap();
    let both = diagnose_in(
        two.path(),
        &[r1, r2],
        &model,
        Some(&one.path().join("diag")),
        Some(&one.path().join("plan")),
        "diag",
    );
    let check = &both["after"]["plan"];
    eprintln!("first: {}", first["verdict"]);
    eprintln!("plan top: {}", p["conditions"][0]["separates"]);
    eprintln!("check: {check}");
    eprintln!("both: {}", both["verdict"]);
    let said = p["conditions"][0]["separates"].as_array().unwrap().len();
    let pairs = check["pairs"].as_array().unwrap();
    assert_eq!(pairs.len(), said, "{check}");
    assert_eq!(check["rank"], 1, "{check}");
    for q in pairs {
        let after = q["after"].as_f64();
        let agree = q["agree"].as_bool();
        assert_eq!(agree, after.map(|a| a > 6.0), "{q}");
    }
    let disagreements = check["disagreements"].as_array().unwrap().len();
    let not_agreeing = pairs.iter().filter(|q| q["agree"] != true).count();
    assert_eq!(disagreements, not_agreeing, "{check}");
    let rivals = first["rivals"].as_array().unwrap().len();
    let fates = both["after"]["fates"].as_array().unwrap();
    assert!(fates.len() > rivals, "{}", both["after"]);
}

/// One release never a confident wrong answer (issue 60's done-when, the single diagnosis):
/// on cases of their own (seed 0x9E37_79B9_7F4A_7C15: not the sweep's, on which the fix was
/// made, nor a neighbour of it, since xorshift's first draws from seeds a bit apart nearly
/// agree; fifteen random bases and seeds, three of each cause: pitch damping, roll damping, `Cn
/// beta`, a drag rise with Mach number and the null), one release at the default condition
/// each, diagnosed alone. The truth must be the answer, or open (a rival, or a member of a
/// rival class not told apart; for the null, no answer or an ambiguous one), or missed (no
/// answer named): never another cause named with the truth not open. Each case's standing,
/// wall time and simulations are printed. The slow tier runs the first three (pitch damping,
/// roll damping and `Cn beta`: two of them were wrong before), `SEPVAL_SWEEPS=full`
/// (`scripts/sweeps.sh`) all fifteen, and `SEPVAL_FIRST_CASES=N` the first N. Before the
/// answer's level, the split of a class by axes and the exchanges (docs/discovery.md 11.5,
/// 4a and 4b), five of the fifteen were wrong (cases 2, 7 and 12, roll damping; 3, `Cn beta`;
/// 6, pitch damping; 2026-12-07).
#[test]
fn one_release_is_never_a_confident_wrong_answer() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let count = cases_to_run("SEPVAL_FIRST_CASES", 15, 3);
    // Measurements on other cases: `SEPVAL_FIRST_SEED=0x...` draws them from another seed and
    // `SEPVAL_FIRST_CASE=K` runs case K alone (numbered from 1, as the table numbers them).
    let seed = std::env::var("SEPVAL_FIRST_SEED").map_or(0x9E37_79B9_7F4A_7C15, |v| {
        u64::from_str_radix(v.trim_start_matches("0x").replace('_', "").as_str(), 16)
            .expect("SEPVAL_FIRST_SEED: a hexadecimal seed")
    });
    let only = case_alone("SEPVAL_FIRST_CASE");
    let model = default_scenario();
    let mut rows = Vec::new();
    for (k, case) in cases(seed, &model, 15)
        .iter()
        .take(count)
        .enumerate()
        .filter(|(k, _)| only.is_none_or(|o| o == k + 1))
    {
        let (truth, hidden) = case.truth(&model);
        let dir = tempfile::tempdir().unwrap();
        let r = release_on(&truth, &case.base, hidden, case.seeds[0]);
        let d = diagnose_in(dir.path(), &[r], &model, None, None, "diag");
        let s = standing(&d, case.cause.kind());
        let line = format!(
            "| {} | {:?} | {} | {s} | wall {:.1} s, {} simulations |",
            k + 1,
            case.cause,
            kinds(&d["model"]).join(" + "),
            d["wall_s"].as_f64().unwrap(),
            d["evaluations"],
        );
        eprintln!("{line}\n  verdict: {}", d["verdict"]);
        rows.push((s, line));
    }
    let table: Vec<&str> = rows.iter().map(|(_, l)| l.as_str()).collect();
    let table = table.join("\n");
    let count = |what: &str| rows.iter().filter(|(s, _)| *s == what).count();
    eprintln!(
        "{table}\nright {}, open {}, missed {}, wrong {} of {}",
        count("right"),
        count("open"),
        count("missed"),
        count("wrong"),
        rows.len()
    );
    assert_eq!(count("wrong"), 0, "{table}");
}
