//! The loop closed (issue 22, item 4), in process: a hidden cause on one release that a mimic
//! fits as well, diagnosed; a plan of where to fly next; the "flight" made at the plan's top
//! condition with the same hidden cause; both releases diagnosed together. The true cause must
//! be named and the mimic dropped. Slow tier (`SEPVAL_SLOW_TESTS=1`): each loop is two
//! diagnoses and a plan, 15 to 45 s alone on two cores.
//!
//! Each diagnosis is the one `sepval diagnose ... --generations 20 --evaluator inproc --threads
//! 2` makes (`diagnose/tests/support/command.rs`: the command's own options), and each plan the
//! one `sepval plan --from diag --out plan ... --evaluator inproc --threads 2` makes of it (the
//! library calls of `sepval/src/command/plan.rs`: `read_diagnosis`, `prepare`, `plan`,
//! `plan_file`, `write_outputs`), so both are the commands' to the last bit. The data come
//! from the tests' own generator (`diagnose/tests/support/generator.rs`: the scenario's own
//! aerodynamics or initial state changed, on a base that is not the default truth, with the
//! generator's own noise), never from the catalogue's or the extension's code; a gust, which no
//! coefficient function can make, comes from simulate's library calls through an extension's
//! wind (`diagnose/tests/support/gusts.rs`). No two loops diagnose the same releases, so no
//! diagnosis is shared between them. Moved from `sepval/tests/cli/closing.rs`, each assertion
//! kept; the binary's own test of `plan` (`sepval/tests/cli/plan.rs`) runs the command end to
//! end (a plan made here and one made by the binary from the same diagnosis were the same
//! plan.json but for its wall time and `from`, 2026-11-28).

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use sepval_common::evaluation::InProcess;
use sepval_common::scenario::{Aero, Scenario};
use sepval_common::table::DerivativeCoefficient;
use sepval_plan::{Quantity, Range, plan_file, prepare, read_diagnosis, write_outputs};
use sepval_run::inputs;
use sepval_solve::run::NoProgress;
use serde_json::Value;

#[path = "../../../diagnose/tests/support/command.rs"]
mod command;
#[path = "../../../diagnose/tests/support/generator.rs"]
mod generator;
// Shared with `diagnose/tests/discovery`, which makes every gust of it; a loop makes one.
#[allow(dead_code)]
#[path = "../../../diagnose/tests/support/gusts.rs"]
mod gusts;
#[path = "../../../diagnose/tests/support/releases.rs"]
mod releases;
#[path = "../../../diagnose/tests/support/simulate.rs"]
mod simulate;

mod after;

use command::diagnosis_of;
use gusts::{PULSE, gust_release, terms};
use releases::{default_scenario, diagnose, release};

/// `model` with the damping derivative `pick` chooses scaled by `scale` (the hidden cause).
fn damped(
    model: &Scenario,
    scale: f64,
    pick: fn(&mut Aero) -> &mut DerivativeCoefficient,
) -> Scenario {
    let mut truth = model.clone();
    let d = pick(&mut truth.aero);
    *d = DerivativeCoefficient::constant(scale * d.as_constant().unwrap());
    truth
}

/// The three runs of a closed loop.
struct Loop {
    /// The diagnosis of the first release.
    first: Value,
    /// The plan made from it.
    plan: Value,
    /// The diagnosis of both releases.
    both: Value,
}

/// `truth`'s flight condition set to the top condition of `plan`.
fn at_top(truth: &Scenario, plan: &Value) -> Scenario {
    let top = &plan["conditions"][0];
    let mut next = truth.clone();
    let f = &mut next.flight;
    f.mach = top["mach"].as_f64().unwrap();
    f.altitude_m = top["altitude_m"].as_f64().unwrap();
    f.alpha_deg = top["alpha_deg"].as_f64().unwrap();
    f.beta_deg = top["beta_deg"].as_f64().unwrap();
    f.gamma_deg = top["gamma_deg"].as_f64().unwrap();
    next
}

/// Diagnoses one release of `truth` (modelled by `model`), plans over `grid` from it, flies
/// `truth` at the plan's top condition and diagnoses the two releases together.
fn close_loop(model: &Scenario, truth: &Scenario, seeds: [u64; 2], grid: Grid) -> Loop {
    let one = tempfile::tempdir().unwrap();
    let first = diagnose(
        one.path(),
        &[release(truth, None, seeds[0])],
        1,
        Some(model),
    );
    let plan = plan(one.path(), &grid);
    let next = at_top(truth, &plan);
    let two = tempfile::tempdir().unwrap();
    let releases = [
        release(truth, None, seeds[0]),
        release(&next, None, seeds[1]),
    ];
    let both = diagnose(two.path(), &releases, 2, Some(model));
    eprintln!(
        "wall_s: first diagnosis {}, plan {}, both {}",
        first["wall_s"], plan["wall_s"], both["wall_s"]
    );
    Loop { first, plan, both }
}

/// The grid of a plan: `--mach LO:HI` and the like, and `--points N`.
struct Grid {
    /// The ranges given, in the order of `[flight]` (as `sepval plan` gathers its flags).
    ranges: Vec<Range>,
    /// Points per axis.
    points: usize,
}

/// The grid over `ranges` (each quantity with its low and high ends), `points` per axis.
fn grid(ranges: &[(Quantity, f64, f64)], points: usize) -> Grid {
    let mut ranges: Vec<Range> = ranges
        .iter()
        .map(|&(quantity, lo, hi)| Range { quantity, lo, hi })
        .collect();
    ranges.sort_by_key(|r| Quantity::ALL.iter().position(|q| *q == r.quantity));
    Grid { ranges, points }
}

/// `sepval plan --from diag --out plan RANGES --evaluator inproc --threads 2` in `dir`, in
/// process (the command's library calls, in its order); returns plan.json.
fn plan(dir: &Path, grid: &Grid) -> Value {
    let (from, out) = (dir.join("diag"), dir.join("plan"));
    let diagnosis = read_diagnosis(&from).unwrap();
    // The releases the diagnosis was made from, read as its record names them.
    let r = &diagnosis.inputs;
    let (scenario, extension) = (r.scenario.as_deref(), r.extension.as_deref());
    let mut tell = |said: String| eprintln!("{said}");
    let (flown, _) = inputs::job(&r.data, scenario, extension, r.outliers, &mut tell).unwrap();
    let prepared = prepare(diagnosis, &flown, &grid.ranges, grid.points).unwrap();
    let start = Instant::now();
    let mut evaluator = InProcess::new(Arc::new(prepared.job.clone()), 2);
    let found = sepval_plan::plan(&prepared, &mut evaluator, &mut NoProgress).unwrap();
    drop(evaluator);
    let file = plan_file(&prepared, &found, &from, start.elapsed().as_secs_f64());
    write_outputs(&prepared, &found, &file, &out).unwrap();
    serde_json::from_slice(&std::fs::read(out.join("plan.json")).unwrap()).unwrap()
}

/// Every explanation a diagnosis leaves open, in words: the answer first, then each rival
/// (`effect + axis regressor`).
fn open(d: &Value) -> Vec<String> {
    let words = |m: &Value| {
        let mut parts: Vec<String> = m["effects"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e["id"].as_str().unwrap().to_string())
            .collect();
        parts.extend(m["terms"].as_array().unwrap().iter().map(|t| {
            format!(
                "{} {}",
                t["axis"].as_str().unwrap(),
                t["regressor"].as_str().unwrap()
            )
        }));
        parts.join(" + ")
    };
    let mut out = vec![words(&d["model"])];
    out.extend(
        d["rivals"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| words(&r["model"])),
    );
    out
}

/// A diagnosis in a few lines, for a failing assertion.
fn shown(d: &Value) -> String {
    format!(
        "verdict: {}\nopen: {:?}\nrivals' delta BIC: {:?}\ndiscovered: {}",
        d["verdict"],
        open(d),
        d["rivals"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r["delta_bic"].clone())
            .collect::<Vec<_>>(),
        d["discovered"]
    )
}

/// Whether the top condition of `plan` separates the models named `a` and `b`.
fn separates(plan: &Value, a: &str, b: &str) -> bool {
    plan["conditions"][0]["separates"]
        .as_array()
        .unwrap()
        .iter()
        .any(|p| (p[0] == a && p[1] == b) || (p[0] == b && p[1] == a))
}

#[test]
fn weaker_roll_damping_is_named_after_the_planned_release() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // Roll damping half the model's: on one release the catalogue's roll_due_to_sideslip fits
    // as well as the true cause (a Cl change with p d/2V), and so do other Cl terms.
    let model = default_scenario();
    let truth = damped(&model, 0.5, |a| &mut a.cl_p_per_rad);
    let l = close_loop(
        &model,
        &truth,
        [31, 33],
        grid(
            &[(Quantity::BetaDeg, -6.0, 6.0), (Quantity::Mach, 0.6, 0.95)],
            5,
        ),
    );
    let first = open(&l.first);
    assert!(first.contains(&"Cl p".to_string()), "{}", shown(&l.first));
    assert!(
        first.contains(&"roll_due_to_sideslip".to_string()),
        "{}",
        shown(&l.first)
    );
    assert!(
        separates(&l.plan, "roll_due_to_sideslip", "Cl: p d/2V"),
        "{}",
        l.plan["conditions"][0]
    );
    // Both releases: the cause is named, as a discovered Cl rate term in p, and the mimic is
    // neither the answer nor a rival.
    let both = open(&l.both);
    assert_eq!(both[0], "Cl p", "{}", shown(&l.both));
    let named = &l.both["discovered"][0];
    assert_eq!(
        (&named["axis"], &named["family"]),
        (&Value::from("Cl"), &Value::from("rate")),
        "{}",
        shown(&l.both)
    );
    assert!(
        !both.iter().any(|m| m.contains("roll_due_to_sideslip")),
        "{}",
        shown(&l.both)
    );
}

/// Pitch damping changed (issue 36, item 2: on releases of an independent simulator, one
/// release at Mach 0.95 and the planned one gave a `Cm` flow-angle term with no rivals where the
/// cause was `Cm q d/2V`). Here from the tests' own generator, pitch damping at 0.4 of the model's,
/// on seeds other than the other loops': after the plan's top condition is flown, the cause is
/// the answer or among the rivals, never missing from what the two releases leave open.
#[test]
fn weaker_pitch_damping_is_named_or_open_after_the_planned_release() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let model = default_scenario();
    let truth = damped(&model, 0.4, |a| &mut a.cm_q_per_rad);
    let l = close_loop(
        &model,
        &truth,
        [41, 43],
        grid(
            &[(Quantity::Mach, 0.6, 1.1), (Quantity::AlphaDeg, -2.0, 4.0)],
            4,
        ),
    );
    eprintln!("first: {}", shown(&l.first));
    eprintln!("plan top: {}", l.plan["conditions"][0]);
    eprintln!("both: {}", shown(&l.both));
    let both = open(&l.both);
    assert!(both.iter().any(|m| m == "Cm q"), "{}", shown(&l.both));
}

/// Issue 36, item 2, at the issue's own second condition: pitch damping 0.4 times the model's,
/// one release at the default condition and one at Mach 1.10, 3 000 m, alpha -2 deg, diagnosed
/// together. The rate term's refit from the baseline's factors stops at its iteration limit far
/// from the truth's optimum (docs/discovery.md 11.5, step 4b, "Why unsettled"), and a Mach term
/// with more terms wins: the cause must stay open (the answer, a rival, or a class not told
/// apart), never told apart on a refit that was cut off.
#[test]
fn weaker_pitch_damping_stays_open_at_the_issues_second_condition() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let model = default_scenario();
    let truth = damped(&model, 0.4, |a| &mut a.cm_q_per_rad);
    let mut next = truth.clone();
    (
        next.flight.mach,
        next.flight.altitude_m,
        next.flight.alpha_deg,
    ) = (1.10, 3000.0, -2.0);
    let dir = tempfile::tempdir().unwrap();
    let releases = [release(&truth, None, 41), release(&next, None, 43)];
    let both = diagnose(dir.path(), &releases, 2, Some(&model));
    let classes = both["rival_classes"].as_array().unwrap();
    let open_class = classes.iter().find(|c| {
        c["status"] != "told apart"
            && c["members"]
                .as_array()
                .unwrap()
                .iter()
                .any(|m| m == "Cm q d/2V")
    });
    assert!(
        open(&both).iter().any(|m| m == "Cm q") || open_class.is_some(),
        "{}\nclasses: {classes:?}",
        shown(&both)
    );
    // The verdict names it: by its label, or by the words of the open class that holds it
    // (since the classes' candidates include the entries that screen as a catalogue answer
    // does, `Cm (M - 1.025)` joins its class, which is then the answer's: "any of 2
    // pitching-moment terms: pitch rate, Mach (the answer's class)"; 2026-12-07).
    let verdict = both["verdict"].as_str().unwrap();
    assert!(
        verdict.contains("Cm q d/2V")
            || open_class.is_some_and(|c| verdict.contains(c["words"].as_str().unwrap())),
        "{verdict}\nclasses: {classes:?}"
    );
}

#[test]
fn rates_at_release_are_named_after_the_planned_release() {
    // 128 s beside another test (2026-11-26): the slow tier's longest closed loop.
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // The store leaves with pitch and yaw rates the model does not have: on one release the
    // catalogue's release_rates is the answer and a discovered term a rival.
    let model = default_scenario();
    let mut truth = model.clone();
    truth.initial.rates_deg_s = [0.0, 8.0, -6.0];
    let l = close_loop(
        &model,
        &truth,
        [32, 34],
        grid(
            &[(Quantity::BetaDeg, -6.0, 6.0), (Quantity::Mach, 0.6, 0.95)],
            5,
        ),
    );
    assert_eq!(open(&l.first)[0], "release_rates", "{}", shown(&l.first));
    let mimic = &l.first["rivals"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["kind"] == "discovered")
        .unwrap_or_else(|| panic!("no term rivals: {}", shown(&l.first)));
    let top = &l.plan["conditions"][0];
    assert!(!top["separates"].as_array().unwrap().is_empty(), "{top}");
    // Both releases: release_rates is named and no term is left as a rival.
    assert_eq!(open(&l.both), ["release_rates"], "{}", shown(&l.both));
    assert!(
        l.both["discovered"].as_array().unwrap().is_empty(),
        "{} (the mimic was {mimic})",
        shown(&l.both)
    );
}

#[test]
fn a_gust_is_named_and_its_coefficient_mimics_dropped_after_the_planned_release() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // A short lateral gust: on one release coefficient terms (a side-force step among them) fit
    // about as well. The same gust on a release at the plan's top condition settles it.
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    gust_release(dir, PULSE, None, 7, "gust.csv");
    let first = diagnosis_of(dir, &["gust.csv"], "diag");
    let wind = vec![("wind_y".to_string(), "wind".to_string())];
    assert_eq!(terms(&first["model"]), wind, "{}", shown(&first));
    let coefficient_rival = |d: &Value| {
        d["rivals"].as_array().unwrap().iter().any(|r| {
            terms(&r["model"])
                .iter()
                .any(|(axis, _)| !axis.starts_with("wind"))
        })
    };
    assert!(coefficient_rival(&first), "{}", shown(&first));
    let plan = plan(
        dir,
        &grid(
            &[(Quantity::Mach, 0.6, 0.95), (Quantity::BetaDeg, -6.0, 6.0)],
            5,
        ),
    );
    assert!(
        !plan["conditions"][0]["separates"]
            .as_array()
            .unwrap()
            .is_empty(),
        "{}",
        plan["conditions"][0]
    );
    let next = at_top(&default_scenario(), &plan);
    std::fs::write(dir.join("next.toml"), next.to_toml_string()).unwrap();
    gust_release(dir, PULSE, Some("next.toml"), 8, "next.csv");
    let both = diagnosis_of(dir, &["gust.csv", "next.csv"], "both");
    eprintln!(
        "wall_s: first diagnosis {}, plan {}, both {}",
        first["wall_s"], plan["wall_s"], both["wall_s"]
    );
    // Both releases: the gust is named, at its time, and no coefficient is left as a rival.
    assert_eq!(terms(&both["model"]), wind, "{}", shown(&both));
    let t_on = both["discovered"][0]["t_on_s"].as_f64().unwrap();
    assert!((t_on - 0.3).abs() < 0.025, "t_on {t_on} s");
    assert!(!coefficient_rival(&both), "{}", shown(&both));
}
