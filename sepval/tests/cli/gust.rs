//! A gust in the data (issue 22, item 2): a release made with `sepval simulate --extension`
//! (a lateral 1-cosine gust, on a base that is not the default truth, with simulate's own seeded
//! noise) is diagnosed, and the diagnosis names the air's motion, a `wind` term on `wind_y`, at
//! the gust's time, rather than a coefficient that mimics it; where one release cannot tell the
//! gust from a step of a coefficient, the step is its rival (issue 22, item 1).
//!
//! A gust acts on every coefficient through the flow angles, so no coefficient function of
//! `discover`'s generator can make one: these releases come from the extension's wind, which
//! `common/tests/model/wind.rs` checks against the flow angles on its own.

use std::path::Path;

use sepval_tests::{REDUCED_BUDGET, ok, sepval};
use serde_json::Value;

/// Factors of the base model (not the default truth).
const BASE: &str = r#"{"fwdfac": 0.45, "aftfac": 0.65, "xinerfac": 0.98, "yinerfac": 1.03,
 "zinerfac": 0.97, "caoff": -0.02, "cyoff": 0.04, "czoff": -0.06, "cmoff": 0.1, "cnoff": -0.08,
 "cloff": -0.05, "caintfac": 1.1, "cyintfac": 1.4, "czintfac": 0.9, "cmintfac": 1.3,
 "cnintfac": 0.8, "clintfac": 1.6}"#;

/// Another base (not the tests' default factors, nor the default truth).
const OTHER_BASE: &str = r#"{"fwdfac": 0.55, "aftfac": 0.6, "xinerfac": 1.02, "yinerfac": 0.97,
 "zinerfac": 1.01, "caoff": 0.01, "cyoff": -0.03, "czoff": 0.04, "cmoff": -0.05, "cnoff": 0.06,
 "cloff": 0.03, "caintfac": 0.9, "cyintfac": 1.2, "czintfac": 1.1, "cmintfac": 0.8,
 "cnintfac": 1.2, "clintfac": 0.7}"#;

/// The hidden gust: the air moves 3 m/s to starboard from t = 0.3 s over the default 0.1 s.
const GUST: &str = "format = \"sepval-extension/1\"\n\n[[term]]\naxis = \"wind_y\"\n\
                    family = \"wind\"\nregressor = \"step\"\nt_on_s = 0.3\ncoefficient = 3.0\n";
const T_ON_S: f64 = 0.3;

/// A short gust: the air moves 8 m/s to starboard and back between t = 0.3 s and 0.4 s.
pub(crate) const PULSE: &str = "format = \"sepval-extension/1\"\n\n[[term]]\naxis = \"wind_y\"\n\
                                family = \"wind\"\nregressor = \"pulse\"\nt_on_s = 0.3\n\
                                coefficient = 8.0\n";

/// Writes `DIR/OUT`: a release through `gust` (an extension's text) on the base factors, at
/// the condition of `scenario` (a file in `dir`; the embedded default when `None`), with
/// simulate's noise of `seed`.
pub(crate) fn gust_release(dir: &Path, gust: &str, scenario: Option<&str>, seed: u64, out: &str) {
    gust_release_on(dir, BASE, gust, scenario, seed, out);
}

/// [`gust_release`] on the factors `base` (a factors file's text).
fn gust_release_on(
    dir: &Path,
    base: &str,
    gust: &str,
    scenario: Option<&str>,
    seed: u64,
    out: &str,
) {
    std::fs::write(dir.join("base.json"), base).unwrap();
    std::fs::write(dir.join("gust.toml"), gust).unwrap();
    let seed = seed.to_string();
    let mut args = vec![
        "simulate",
        "--factors",
        "base.json",
        "--extension",
        "gust.toml",
    ];
    if let Some(s) = scenario {
        args.extend(["--scenario", s]);
    }
    args.extend(["--noise-seed", &seed, "--out", out]);
    ok(&sepval(&args, dir));
}

/// `sepval diagnose --data ... --out OUT` in `dir` with the CLI tests' reduced budget, in
/// process; returns diagnosis.json.
pub(crate) fn diagnose(dir: &Path, data: &[&str], out: &str) -> Value {
    let mut args = vec!["diagnose"];
    for d in data {
        args.extend(["--data", d]);
    }
    args.extend(REDUCED_BUDGET);
    args.extend(["--out", out]);
    ok(&sepval(&args, dir));
    serde_json::from_slice(&std::fs::read(dir.join(out).join("diagnosis.json")).unwrap()).unwrap()
}

/// The (axis, family) of every term of a model record of diagnosis.json.
pub(crate) fn terms(model: &Value) -> Vec<(String, String)> {
    model["terms"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| {
            (
                t["axis"].as_str().unwrap().to_string(),
                t["family"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

#[test]
fn a_short_gust_and_a_side_force_step_are_rivals_on_one_release() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // An 8 m/s gust lasting 0.1 s: on one release a step of the side force fits about as well.
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    gust_release(dir, PULSE, None, 7, "gust.csv");
    let d = diagnose(dir, &["gust.csv"], "diag");
    let wind = ("wind_y".to_string(), "wind".to_string());
    assert_eq!(terms(&d["model"]), [wind], "{}", d["verdict"]);
    assert_eq!(d["ambiguous"], true, "{}", d["verdict"]);
    let rivals = d["rivals"].as_array().unwrap();
    let step = rivals
        .iter()
        .find(|r| terms(&r["model"]).iter().any(|(_, f)| f == "step"))
        .unwrap_or_else(|| panic!("no coefficient step among the rivals: {}", d["verdict"]));
    assert!(step["delta_bic"].as_f64().unwrap().abs() < 6.0, "{step}");
    let verdict = d["verdict"].as_str().unwrap();
    assert!(verdict.contains("cannot tell it from"), "{verdict}");
}

/// A short gust (issue 36, item 3): the air moves 10 m/s to starboard from t = 0.45 s over
/// 20 ms, a fifth of the library's shortest, on another base and seed. Its middle is placed
/// within 25 ms, with a standard error that covers the truth (measured: 0.441 ± 0.012 s for
/// the truth's 0.46 s; the issue asked for 10 ms, finer than this release's own standard
/// error); its length is either determined (the truth within three standard errors) or said
/// not to be (measured: estimating it lowers the chi-square by 0.6, so it is held).
#[test]
fn a_short_gust_is_placed_by_its_middle_and_its_length_is_honest() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let short = GUST
        .replace("t_on_s = 0.3", "t_on_s = 0.45\nrise_s = 0.02")
        .replace("coefficient = 3.0", "coefficient = 10.0");
    gust_release_on(dir, OTHER_BASE, &short, None, 11, "gust.csv");
    let d = diagnose(dir, &["gust.csv"], "diag");
    let first = &d["discovered"][0];
    assert_eq!(first["axis"], "wind_y", "{}", d["verdict"]);
    let (t_on, rise_s) = (
        first["t_on_s"].as_f64().unwrap(),
        first["rise_s"].as_f64().unwrap(),
    );
    let middle = t_on + rise_s / 2.0;
    let se = first["locator_std_error"].as_f64().unwrap();
    assert!((middle - 0.46).abs() < 0.025, "middle {middle} s: {first}");
    assert!(
        (middle - 0.46).abs() < 3.0 * se,
        "middle {middle} ± {se} s: {first}"
    );
    let verdict = d["verdict"].as_str().unwrap();
    match first["rise_std_error"].as_f64() {
        Some(se) => assert!(
            (rise_s - 0.02).abs() < 3.0 * se,
            "length {rise_s} ± {se}: {first}"
        ),
        None => assert!(verdict.contains("not determined by the data"), "{verdict}"),
    }
}

#[test]
fn a_lateral_gust_is_discovered_as_wind_at_its_time() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    std::fs::write(dir.join("base.json"), BASE).unwrap();
    std::fs::write(dir.join("gust.toml"), GUST).unwrap();
    ok(&sepval(
        &[
            "simulate",
            "--factors",
            "base.json",
            "--extension",
            "gust.toml",
            "--noise-seed",
            "7",
            "--out",
            "gust.csv",
        ],
        dir,
    ));
    // The file says what made it: the extension and its terms.
    let csv = std::fs::read_to_string(dir.join("gust.csv")).unwrap();
    assert!(
        csv.contains("# extension = gust.toml")
            && csv.contains("# extension_terms = wind_y onset(t - 0.3 s; 0.1 s) = 3"),
        "{}",
        &csv[..600]
    );
    let head = ["diagnose", "--data", "gust.csv"];
    let out = sepval(
        &[&head[..], &REDUCED_BUDGET, &["--out", "diag"]].concat(),
        dir,
    );
    ok(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.lines().all(|l| l.chars().count() <= 160), "{stdout}");
    let d: Value =
        serde_json::from_slice(&std::fs::read(dir.join("diag/diagnosis.json")).unwrap()).unwrap();
    let first = &d["discovered"][0];
    assert_eq!(
        (first["axis"].as_str(), first["family"].as_str()),
        (Some("wind_y"), Some("wind")),
        "{}\n{}",
        d["verdict"],
        serde_json::to_string_pretty(&d["discovered"]).unwrap()
    );
    // The refit estimates the gust's middle, with its standard error (issue 36, item 3): the
    // truth's within 25 ms and within three standard errors.
    let (t_on, rise_s) = (
        first["t_on_s"].as_f64().unwrap(),
        first["rise_s"].as_f64().unwrap(),
    );
    let (middle, truth) = (t_on + rise_s / 2.0, T_ON_S + 0.05);
    let se = first["locator_std_error"].as_f64().unwrap();
    assert!((middle - truth).abs() < 0.025, "middle {middle} s: {first}");
    assert!(
        (middle - truth).abs() < 3.0 * se,
        "middle {middle} ± {se} s: {first}"
    );
    let w = first["coefficient"].as_f64().unwrap();
    assert!((1.5..4.5).contains(&w), "{w} m/s");
    assert!(rise_s > 0.0, "{first}");
    let reading = first["reading"].as_str().unwrap();
    assert!(reading.starts_with("A lateral gust of"), "{reading}");
    // The extension written reads back and simulates, with its gust's two locators.
    let ext = std::fs::read_to_string(dir.join("diag/extension.toml")).unwrap();
    assert!(
        ext.contains("family = \"wind\"") && ext.contains("rise_s = "),
        "{ext}"
    );
    ok(&sepval(
        &[
            "simulate",
            "--factors",
            "diag/factors.json",
            "--extension",
            "diag/extension.toml",
            "--out",
            "ext.csv",
        ],
        dir,
    ));
}

#[test]
fn a_baseline_in_a_local_optimum_is_restarted_and_names_no_effect() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // The short gust on two releases, the second at 1 000 m where the dynamic pressure is 3.4
    // times the first's: the baseline's refinement stops in a local optimum of the factors (12
    // sigma in position), from which each catalogue refit escapes with its effect near neutral.
    // The restart (docs/discovery.md section 11.5, step 2a) refits the baseline from the catalogue's factors
    // and the catalogue from it: no effect is then named for the factors' escape.
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let mut low = sepval_common::scenario::Scenario::embedded_default();
    low.flight.altitude_m = 1000.0;
    std::fs::write(dir.join("low.toml"), low.to_toml_string()).unwrap();
    gust_release(dir, PULSE, None, 7, "gust.csv");
    gust_release(dir, PULSE, Some("low.toml"), 8, "low.csv");
    let d = diagnose(dir, &["gust.csv", "low.csv"], "diag");
    let restart = d["baseline_restart"].as_str().unwrap_or_else(|| {
        panic!("no restart: {}", d["verdict"]);
    });
    assert!(restart.contains("local optimum"), "{restart}");
    assert!(
        d["causes"].as_array().unwrap().is_empty(),
        "{}",
        d["verdict"]
    );
    // Where the restarted baseline stops depends on the factors' landscape, which has more
    // than one optimum here: before arithmetic version 3 (stroke ends located to the last bit)
    // it stopped within 2 sigma and nothing was named; since, it stops at 7.8 sigma (a plain
    // 60-generation `ga+lm` fit reaches 2.3 sigma) and discovery names the gust itself, 8.5 +-
    // 0.5 m/s from 0.301 s (truth: 8 m/s from 0.3 s). Either is right: nothing named, or the
    // hidden gust, never a catalogue effect for the factors' escape.
    if let Some(first) = d["discovered"].as_array().and_then(|a| a.first()) {
        assert_eq!(
            (first["axis"].as_str(), first["family"].as_str()),
            (Some("wind_y"), Some("wind")),
            "{}",
            d["verdict"]
        );
        let middle = first["t_on_s"].as_f64().unwrap() + first["rise_s"].as_f64().unwrap() / 2.0;
        assert!((middle - 0.35).abs() < 0.025, "{first}");
    }
    let html = std::fs::read_to_string(dir.join("diag/report.html")).unwrap();
    assert!(html.contains("local optimum"));
}
