//! A gust in the data (issue 22, item 2): a release made with `sepval simulate --extension`
//! (a lateral 1-cosine gust, on a base that is not the default truth, with simulate's own seeded
//! noise) is diagnosed, and the diagnosis names the air's motion, a `wind` term on `wind_y`, at
//! the gust's time, rather than a coefficient that mimics it.

use sepval_tests::{ok, sepval};
use serde_json::Value;

/// Factors of the base model (not the default truth).
const BASE: &str = r#"{"fwdfac": 0.45, "aftfac": 0.65, "xinerfac": 0.98, "yinerfac": 1.03,
 "zinerfac": 0.97, "caoff": -0.02, "cyoff": 0.04, "czoff": -0.06, "cmoff": 0.1, "cnoff": -0.08,
 "cloff": -0.05, "caintfac": 1.1, "cyintfac": 1.4, "czintfac": 0.9, "cmintfac": 1.3,
 "cnintfac": 0.8, "clintfac": 1.6}"#;

/// The hidden gust: the air moves 3 m/s to starboard from t = 0.3 s over the default 0.1 s.
const GUST: &str = "format = \"sepval-extension/1\"\n\n[[term]]\naxis = \"wind_y\"\n\
                    family = \"wind\"\nregressor = \"step\"\nt_on_s = 0.3\ncoefficient = 3.0\n";
const T_ON_S: f64 = 0.3;

#[test]
fn a_lateral_gust_is_discovered_as_wind_at_its_time() {
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
    let out = sepval(
        &[
            "diagnose",
            "--data",
            "gust.csv",
            "--generations",
            "20",
            "--evaluator",
            "inproc",
            "--threads",
            "2",
            "--out",
            "diag",
        ],
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
    let t_on = first["t_on_s"].as_f64().unwrap();
    assert!((t_on - T_ON_S).abs() < 0.025, "t_on {t_on} s");
    let w = first["coefficient"].as_f64().unwrap();
    assert!((1.5..4.5).contains(&w), "{w} m/s");
    assert!(first["rise_s"].as_f64().unwrap() > 0.0, "{first}");
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
