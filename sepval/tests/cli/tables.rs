//! Tabulated aerodynamics and interference (docs/model.md sections 1 and 3, "Tables"), end to
//! end: `scenario --tables` as a starting point, bad tables refused with file, line and column,
//! leaving a table reported or refused, and pooled fits of stores whose data only tables
//! describe (reduced searches: small fits, few generations).

use std::path::Path;

use sepval_common::scenario::Scenario;
use sepval_common::telemetry::Trajectory;
use sepval_tests::{Gauss, ok, refused, sepval};
use serde_json::Value;

#[test]
fn scenario_tables_writes_a_starting_point_that_simulates_as_the_default() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&sepval(&["scenario", "--tables", "--out", "mine"], d));
    for f in [
        "mine/scenario.toml",
        "mine/tables/aero_static.csv",
        "mine/tables/aero_damping.csv",
    ] {
        assert!(d.join(f).exists(), "{f}");
    }
    assert!(!d.join("mine/tables/interference.csv").exists());
    // Written again into the same directory: refused, nothing overwritten.
    refused(
        &sepval(&["scenario", "--tables", "--out", "mine"], d),
        "exists; choose a new directory (nothing was written)",
    );
    // Nor into an empty directory that exists: the tables appear only as a whole new one.
    std::fs::create_dir(d.join("empty")).unwrap();
    refused(
        &sepval(&["scenario", "--tables", "--out", "empty"], d),
        "exists; choose a new directory (nothing was written)",
    );
    assert_eq!(std::fs::read_dir(d.join("empty")).unwrap().count(), 0);
    ok(&sepval(
        &[
            "scenario",
            "--tables",
            "--interference-tables",
            "--out",
            "all",
        ],
        d,
    ));
    assert!(d.join("all/tables/interference.csv").exists());
    ok(&sepval(&["simulate", "--out", "constant.csv"], d));
    let b = Trajectory::read(&d.join("constant.csv")).unwrap();
    // Simulated from another directory: the CSV files are found relative to the scenario. The
    // aerodynamics as tables reproduce the default to rounding; the sampled interference to its
    // interpolation error.
    for (name, pos_m, att_deg) in [("mine", 1e-9, 1e-9), ("all", 1e-4, 1e-2)] {
        let scenario = format!("{name}/scenario.toml");
        let out = format!("{name}.csv");
        ok(&sepval(
            &[
                "simulate",
                "--scenario",
                &scenario,
                "--strict-tables",
                "--out",
                &out,
            ],
            d,
        ));
        let a = Trajectory::read(&d.join(&out)).unwrap();
        for k in 0..a.len() {
            for j in 0..3 {
                assert!((a.pos_m[k][j] - b.pos_m[k][j]).abs() <= pos_m, "{name}");
                assert!(
                    (a.att_deg[k][j] - b.att_deg[k][j]).abs() <= att_deg,
                    "{name}"
                );
            }
        }
    }
}

#[test]
fn the_example_store_simulates_inside_its_tables() {
    let dir = tempfile::tempdir().unwrap();
    let example =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/tabulated-store/scenario.toml");
    let example = example.to_str().unwrap();
    ok(&sepval(
        &[
            "simulate",
            "--scenario",
            example,
            "--strict-tables",
            "--out",
            "store.csv",
        ],
        dir.path(),
    ));
    assert_eq!(
        Trajectory::read(&dir.path().join("store.csv"))
            .unwrap()
            .len(),
        201
    );
}

/// A directory holding the default scenario with `cz` as the table file `cz.csv` (`csv`).
fn with_cz_table(dir: &Path, csv: &str) {
    let text = sepval_common::scenario::DEFAULT_SCENARIO_TOML.replace(
        "cz_alpha_per_rad = -6.0",
        "cz = { csv = \"tables/cz.csv\" }",
    );
    std::fs::create_dir_all(dir.join("tables")).unwrap();
    std::fs::write(dir.join("s.toml"), text).unwrap();
    std::fs::write(dir.join("tables/cz.csv"), csv).unwrap();
}

#[test]
fn bad_tables_are_refused_with_file_line_and_column_and_nothing_is_written() {
    let cases = [
        (
            "mach [-],alpha [deg],cz [-]\n0.5,0,0\n0.5,5,-0.5\n0.5,4,-1\n",
            "tables/cz.csv: line 4, column 2 (`alpha [deg]`): breakpoints are not strictly increasing: 4 after 5",
        ),
        (
            "alpha [deg],cz [-]\n-10,1\n10,nan\n",
            "tables/cz.csv: line 3, column 2 (`cz [-]`): expected a finite number, found `nan`",
        ),
        (
            "alpha [deg],cz [-]\n-10,1\n10,-inf\n",
            "tables/cz.csv: line 3, column 2 (`cz [-]`): expected a finite number, found `-inf`",
        ),
        (
            "alpha [deg],cz [-]\n-10,1\n10\n",
            "tables/cz.csv: line 3: expected 2 fields as in the header, found 1",
        ),
        (
            "alpha,cz [-]\n-10,1\n10,-1\n",
            "tables/cz.csv: line 1, column 1: `alpha` has no unit: write it as `alpha [deg]`",
        ),
        (
            "alpha [grad],cz [-]\n-10,1\n10,-1\n",
            "tables/cz.csv: line 1, column 1: unknown unit in `alpha [grad]`: expected `alpha [deg]` or `alpha [rad]`",
        ),
        (
            "distance [m],cz [-]\n0,1\n10,-1\n",
            "tables/cz.csv: line 1, column 1: `distance [m]`: a static coefficient may be tabulated over mach, alpha, beta only, not over distance",
        ),
    ];
    for (csv, expected) in cases {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        with_cz_table(d, csv);
        let out = sepval(&["simulate", "--scenario", "s.toml", "--out", "o.csv"], d);
        refused(&out, expected);
        refused(&out, "scenario s.toml: `aero.cz`: ");
        assert!(!d.join("o.csv").exists());
        let out = sepval(
            &["scenario", "--scenario", "s.toml", "--tables", "--out", "t"],
            d,
        );
        refused(&out, expected);
        assert!(!d.join("t").exists());
    }
    // A table file that does not exist.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    with_cz_table(d, "alpha [deg],cz [-]\n-10,1\n10,-1\n");
    std::fs::remove_file(d.join("tables/cz.csv")).unwrap();
    let out = sepval(&["simulate", "--scenario", "s.toml", "--out", "o.csv"], d);
    refused(&out, "`aero.cz`: ");
    refused(&out, "tables/cz.csv: cannot read table: No such file");
    assert!(!d.join("o.csv").exists());
    // A derivative tabulated over alpha (the wrong dimension), inline: line and column of TOML.
    let text = sepval_common::scenario::DEFAULT_SCENARIO_TOML.replace(
        "cm_q_per_rad = -80.0",
        "cm_q_per_rad = { alpha_deg = [-10.0, 10.0], values = [-80.0, -70.0] }",
    );
    std::fs::write(d.join("s.toml"), text).unwrap();
    let out = sepval(&["simulate", "--scenario", "s.toml", "--out", "o.csv"], d);
    refused(&out, "line 34, column 16");
    refused(
        &out,
        "is a table over alpha: a derivative may be tabulated over mach only",
    );
    assert!(!d.join("o.csv").exists());
}

#[test]
fn leaving_a_table_is_reported_or_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // CZ over alpha within +-1 deg only: the store's alpha leaves it.
    with_cz_table(
        d,
        "alpha [deg],cz [-]\n-1,0.10471975511965977\n1,-0.10471975511965977\n",
    );
    let out = sepval(&["simulate", "--scenario", "s.toml", "--out", "o.csv"], d);
    ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("warning: left table `aero.cz` in ")
            && stderr.contains("alpha_deg by up to "),
        "{stderr}"
    );
    std::fs::remove_file(d.join("o.csv")).unwrap();
    let out = sepval(
        &[
            "simulate",
            "--scenario",
            "s.toml",
            "--strict-tables",
            "--out",
            "o.csv",
        ],
        d,
    );
    refused(&out, "--strict-tables: the run left table `aero.cz` in ");
    refused(&out, "(nothing written)");
    assert!(!d.join("o.csv").exists());
}

// ---------------------------------------------------------------------------------------------
// Pooled fits.

/// The truth factors of these fits (not the default truth).
const TRUTH: &str = r#"{"fwdfac": 0.45, "aftfac": 0.65, "xinerfac": 0.98, "yinerfac": 1.03,
 "zinerfac": 0.97, "caoff": -0.02, "cyoff": 0.04, "czoff": -0.06, "cmoff": 0.1, "cnoff": -0.08,
 "cloff": -0.05, "caintfac": 1.1, "cyintfac": 1.4, "czintfac": 0.9, "cmintfac": 1.3,
 "cnintfac": 0.8, "clintfac": 1.6}"#;

/// One release of `scenario` at Mach `mach` and aircraft alpha `alpha_deg` (written as the
/// data's metadata), truth factors, 0.6 s at 100 Hz, with 0.003 m and 0.1 deg of noise.
fn release(scenario: &Scenario, mach: f64, alpha_deg: f64, seed: u64) -> Trajectory {
    let mut s = scenario.clone();
    s.flight.mach = mach;
    s.flight.alpha_deg = alpha_deg;
    let sim = sepval_common::simulation::Simulator::new(&s);
    let factors = sepval_core::factors::Factors::from_json_str(TRUTH, &s.factors).unwrap();
    let times: Vec<f64> = (0..=60).map(|k| k as f64 / 100.0).collect();
    let clean = sim
        .simulate(&factors, &sepval_common::effects::EffectSet::NONE, &times)
        .unwrap();
    let mut g = Gauss(0x9E37_79B9_7F4A_7C15 ^ seed.wrapping_mul(0x2545_F491_4F6C_DD1D));
    let mut t = Trajectory {
        pos_m: clean
            .pos_m
            .iter()
            .map(|p| p.map(|v| v + 0.003 * g.normal()))
            .collect(),
        att_deg: clean
            .att_deg
            .iter()
            .map(|a| a.map(|v| v + 0.1 * g.normal()))
            .collect(),
        times_s: times,
        ..Trajectory::default()
    };
    t.push_metadata("mach", &mach.to_string());
    t.push_metadata("alpha_deg", &alpha_deg.to_string());
    t
}

/// A pooled ga+lm fit of `releases` with `scenario` (sigmas given: the true noise), its best
/// goals and the whole result.
fn pooled_fit(dir: &Path, scenario: &Scenario, releases: &[Trajectory], out: &str) -> Value {
    std::fs::write(dir.join(format!("{out}.toml")), scenario.to_toml_string()).unwrap();
    let scenario_file = format!("{out}.toml");
    let mut args: Vec<String> = vec!["fit".into(), "--scenario".into(), scenario_file];
    for (k, r) in releases.iter().enumerate() {
        let name = format!("release{}.csv", k + 1);
        if !dir.join(&name).exists() {
            r.write(&dir.join(&name)).unwrap();
        }
        args.extend(["--data".into(), name]);
    }
    for a in [
        "--method",
        "ga+lm",
        "--generations",
        "12",
        "--population",
        "40",
        "--sigma-pos-m",
        "0.003",
        "--sigma-att-deg",
        "0.1",
        "--truth-factors",
        "truth.json",
        "--evaluator",
        "inproc",
        "--threads",
        "2",
        "--no-figures",
        "--out",
        out,
    ] {
        args.push(a.into());
    }
    std::fs::write(dir.join("truth.json"), TRUTH).unwrap();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&sepval(&args, dir));
    serde_json::from_str(&std::fs::read_to_string(dir.join(out).join("result.json")).unwrap())
        .unwrap()
}

fn best_goals(r: &Value) -> (f64, f64) {
    let b = &r["methods"]["ga+lm"]["best"];
    (
        b["j_pos_m"].as_f64().unwrap(),
        b["j_att_deg"].as_f64().unwrap(),
    )
}

/// A scenario from the default with `edits` (from, to) applied to its text.
fn store(edits: &[(&str, &str)]) -> Scenario {
    let mut text = sepval_common::scenario::DEFAULT_SCENARIO_TOML.to_string();
    for (from, to) in edits {
        assert!(text.contains(from), "{from}");
        text = text.replace(from, to);
    }
    Scenario::from_toml_str(&text, "synthetic store").unwrap()
}

#[test]
fn a_store_whose_drag_and_pitch_stiffness_change_with_mach_needs_its_tables() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // A synthetic store (not the Eglin data): drag rising through transonic, pitch stiffness
    // from unstable to stable, released at Mach 0.7 and 1.1.
    let tables = store(&[
        (
            "ca0 = 1.10",
            "ca0 = { mach = [0.6, 0.9, 1.2], values = [0.6, 1.0, 1.6] }",
        ),
        (
            "cm_alpha_per_rad = 0.30",
            "cm_alpha_per_rad = { mach = [0.6, 0.9, 1.2], values = [0.6, 0.2, -1.2] }",
        ),
    ]);
    let releases = [release(&tables, 0.7, 0.0, 1), release(&tables, 1.1, 0.0, 2)];
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let with = pooled_fit(d, &tables, &releases, "tables");
    let (jp, ja) = best_goals(&with);
    assert!(
        jp <= 1.1 * 0.003 && ja <= 1.1 * 0.1,
        "with tables: {jp} m, {ja} deg"
    );
    assert!(
        with["events"]
            .as_array()
            .unwrap()
            .iter()
            .all(|e| e.get("tables_left").is_none()),
        "{}",
        with["events"]
    );
    // The same store as constants (its values at Mach 0.9): no factor set explains both.
    let constant = store(&[
        ("ca0 = 1.10", "ca0 = 1.0"),
        ("cm_alpha_per_rad = 0.30", "cm_alpha_per_rad = 0.2"),
    ]);
    let without = pooled_fit(d, &constant, &releases, "constants");
    let (jp_c, ja_c) = best_goals(&without);
    assert!(
        jp_c > 2.0 * 0.003 || ja_c > 2.0 * 0.1,
        "with constants: {jp_c} m, {ja_c} deg"
    );
}

#[test]
fn an_interference_field_no_exponential_has_is_recovered_by_a_pooled_fit() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // Pitching moment increment changing sign below the carriage and a normal-force bump,
    // over distance and local alpha; two releases at different aircraft alpha.
    let field = store(&[
        (
            "dcz0 = -0.60",
            "dcz0 = { distance_m = [0.0, 0.4, 1.0, 2.0, 30.0], values = [-0.2, -1.0, -0.4, 0.0, 0.0] }",
        ),
        (
            "dcm0 = -1.50",
            "dcm0 = { distance_m = [0.0, 0.3, 0.8, 1.5, 30.0], alpha_deg = [-20.0, 20.0], values = [[-1.0, -1.4], [0.8, 1.2], [1.2, 0.6], [0.0, 0.0], [0.0, 0.0]] }",
        ),
    ]);
    let releases = [
        release(&field, 0.95, -2.0, 3),
        release(&field, 0.95, 3.0, 4),
    ];
    let dir = tempfile::tempdir().unwrap();
    let r = pooled_fit(dir.path(), &field, &releases, "field");
    let (jp, ja) = best_goals(&r);
    assert!(jp <= 1.1 * 0.003 && ja <= 1.1 * 0.1, "{jp} m, {ja} deg");
    // The multipliers of the tabulated increments are recovered within three standard errors.
    let truth = &r["truth"];
    let mut checked = 0;
    for p in r["identifiability"]["parameters"].as_array().unwrap() {
        let name = p["name"].as_str().unwrap();
        if ["czintfac", "cmintfac"].contains(&name) && p["identifiable"].as_bool().unwrap() {
            let z = (p["value"].as_f64().unwrap() - truth[name].as_f64().unwrap())
                / p["std_error"].as_f64().unwrap();
            assert!(z.abs() <= 3.0, "{name}: {z} standard errors from the truth");
            checked += 1;
        }
    }
    assert!(checked >= 1, "{}", r["identifiability"]["parameters"]);
    // The contract's exponential decay cannot take this shape: its best fit stays off the floor.
    let exponential = store(&[]);
    let e = pooled_fit(dir.path(), &exponential, &releases, "exponential");
    let (jp_e, ja_e) = best_goals(&e);
    assert!(
        jp_e > 2.0 * 0.003 || ja_e > 2.0 * 0.1,
        "exponential: {jp_e} m, {ja_e} deg"
    );
}
