//! Releases through a gust, for the test binaries that diagnose one (included by `#[path]` in
//! `diagnose/tests/discovery` and `plan/tests/closing`, beside `simulate.rs` and
//! `generator.rs`): `sepval simulate --factors base.json --extension gust.toml --noise-seed S`
//! in process (a lateral 1-cosine gust of the extension's wind, on a base that is not the
//! default truth, with simulate's own seeded noise). A gust acts on every coefficient through
//! the flow angles, so no coefficient function of the tests' generator (`generator.rs`) can make one: these
//! releases come from the extension's wind, which `common/tests/model/wind.rs` checks against
//! the flow angles on its own.

use std::path::Path;

use serde_json::Value;

use crate::generator::BASE;
use crate::simulate::Simulate;

/// Another base (not the tests' default factors, nor the default truth).
pub const OTHER_BASE: &str = r#"{"fwdfac": 0.55, "aftfac": 0.6, "xinerfac": 1.02, "yinerfac": 0.97,
 "zinerfac": 1.01, "caoff": 0.01, "cyoff": -0.03, "czoff": 0.04, "cmoff": -0.05, "cnoff": 0.06,
 "cloff": 0.03, "caintfac": 0.9, "cyintfac": 1.2, "czintfac": 1.1, "cmintfac": 0.8,
 "cnintfac": 1.2, "clintfac": 0.7}"#;

/// The hidden gust: the air moves 3 m/s to starboard from t = 0.3 s over the default 0.1 s.
pub const GUST: &str = "format = \"sepval-extension/1\"\n\n[[term]]\naxis = \"wind_y\"\n\
                        family = \"wind\"\nregressor = \"step\"\nt_on_s = 0.3\ncoefficient = 3.0\n";

/// A short gust: the air moves 8 m/s to starboard and back between t = 0.3 s and 0.4 s.
pub const PULSE: &str = "format = \"sepval-extension/1\"\n\n[[term]]\naxis = \"wind_y\"\n\
                         family = \"wind\"\nregressor = \"pulse\"\nt_on_s = 0.3\n\
                         coefficient = 8.0\n";

/// Writes `dir/out`: a release through `gust` (an extension's text, written to
/// `dir/gust.toml`) on the base factors (written to `dir/base.json`), at the condition of
/// `scenario` (a file in `dir`; the embedded default when `None`), with simulate's noise of
/// `seed`.
pub fn gust_release(dir: &Path, gust: &str, scenario: Option<&str>, seed: u64, out: &str) {
    gust_release_on(dir, BASE, gust, scenario, seed, out);
}

/// [`gust_release`] on the factors `base` (a factors file's text).
pub fn gust_release_on(
    dir: &Path,
    base: &str,
    gust: &str,
    scenario: Option<&str>,
    seed: u64,
    out: &str,
) {
    let (factors, extension) = (dir.join("base.json"), dir.join("gust.toml"));
    std::fs::write(&factors, base).unwrap();
    std::fs::write(&extension, gust).unwrap();
    let scenario = scenario.map(|s| dir.join(s));
    Simulate {
        factors: factors.to_str().unwrap(),
        scenario: scenario.as_deref(),
        extension: Some(&extension),
        noise_seed: Some(seed),
        ..Simulate::default()
    }
    .run(&dir.join(out));
}

/// The (axis, family) of every term of a model record of diagnosis.json.
pub fn terms(model: &Value) -> Vec<(String, String)> {
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
