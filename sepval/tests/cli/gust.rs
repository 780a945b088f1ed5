//! Discovery end to end through the binary (issue 22, item 2): a release made by `sepval
//! simulate --extension` (a lateral 1-cosine gust, on a base that is not the default truth,
//! with simulate's own seeded noise) and the file saying what made it; `sepval diagnose` of it
//! naming the air's motion, a `wind` term on `wind_y`, at the gust's time, in a summary of at
//! most 12 lines of at most 160 characters, with its page and figures; the extension it writes
//! read back by `sepval simulate`. Slow tier. The other gusts, the rivals and every discovery
//! family are tested in process (`diagnose/tests/discovery`), the closed loops in
//! `plan/tests/closing`.

use sepval_tests::{REDUCED_BUDGET, ok, sepval};
use serde_json::Value;

/// Factors of the base model (not the default truth).
const BASE: &str = r#"{"fwdfac": 0.45, "aftfac": 0.65, "xinerfac": 0.98, "yinerfac": 1.03,
 "zinerfac": 0.97, "caoff": -0.02, "cyoff": 0.04, "czoff": -0.06, "cmoff": 0.1, "cnoff": -0.08,
 "cloff": -0.05, "caintfac": 1.1, "cyintfac": 1.4, "czintfac": 0.9, "cmintfac": 1.3,
 "cnintfac": 0.8, "clintfac": 1.6}"#;

/// The hidden gust: the air moves 3 m/s to starboard from t = 0.3 s over the default 0.1 s.
const GUST: &str = "format = \"sepval-extension/1\"\n\n[[term]]\naxis = \"wind_y\"\n\
                    family = \"wind\"\nregressor = \"step\"\nt_on_s = 0.3\ncoefficient = 3.0\n";
/// When [`GUST`] begins.
const T_ON_S: f64 = 0.3;

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
    // The summary is a few short lines; the page says the verdict; the increments are drawn.
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.lines().count() <= 12, "{stdout}");
    assert!(stdout.lines().all(|l| l.chars().count() <= 160), "{stdout}");
    let d: Value =
        serde_json::from_slice(&std::fs::read(dir.join("diag/diagnosis.json")).unwrap()).unwrap();
    let html = std::fs::read_to_string(dir.join("diag/report.html")).unwrap();
    assert!(html.contains(d["verdict"].as_str().unwrap().split(',').next().unwrap()));
    assert!(dir.join("diag/figures/increments.png").exists());
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
