//! A short gust's onset estimated, not matched (issue 60, item 3; `docs/discovery.md` section
//! 11.5, step 13): the air moves 10 m/s to starboard from t = 0.45 s over 20 ms (the case of
//! `gust.rs`'s short gust), on ten seeds of simulate's noise, each on its own random base of
//! factors (seeds 101 to 110, none used to tune). The onset's reported 95 % interval holds the
//! truth on at least 9 of them, and so does the middle's; each estimate lies in its own
//! interval, and an onset reported as not determined carries no standard error and the verdict
//! says so. How often the onset lands within 10 ms of the truth is printed, not asserted: one
//! release at this noise does not determine a short gust's length, hence not its onset
//! (`docs/discovery.md` section 11.5, step 13, the measurement). Slow tier: the first three
//! seeds, 2 of 3 (one miss allowed per ten begun; about 40 s a diagnosis on a loaded two-core
//! machine); all ten with `SEPVAL_SWEEPS=full` (`scripts/sweeps.sh`), 9 of 10.

use sepval_core::factors::{Factor, FactorTable};
use sepval_tests::Gauss;
use serde_json::Value;

use crate::command::diagnosis_of as diagnose;
use crate::gusts::{GUST, OTHER_BASE, gust_release_on};

/// The hidden gust's onset and middle \[s\].
const ONSET_S: f64 = 0.45;
const MIDDLE_S: f64 = 0.46;

/// A base of factors drawn about `OTHER_BASE` for `seed`: each factor moved by a normal draw of
/// 5 % of its range, held within the middle 80 % of its range.
fn random_base(seed: u64) -> String {
    let other: Value = serde_json::from_str(OTHER_BASE).unwrap();
    let table = FactorTable::default();
    let mut g = Gauss(0x5DEE_CE66_D1CE_4E5B ^ seed.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let fields: Vec<String> = Factor::NAMES
        .iter()
        .zip(&table.0)
        .map(|(name, spec)| {
            let range = spec.max - spec.min;
            let v = other[*name].as_f64().unwrap() + 0.05 * range * g.normal();
            let v = v.clamp(spec.min + 0.1 * range, spec.max - 0.1 * range);
            format!("\"{name}\": {v}")
        })
        .collect();
    format!("{{{}}}", fields.join(", "))
}

/// The location `quantity` of the first discovered term.
fn location<'a>(d: &'a Value, quantity: &str) -> &'a Value {
    d["discovered"][0]["locations"]
        .as_array()
        .and_then(|ls| ls.iter().find(|l| l["quantity"] == quantity))
        .unwrap_or_else(|| panic!("no {quantity}: {}", d["verdict"]))
}

fn covers(l: &Value, truth: f64) -> bool {
    l["low"].as_f64().unwrap() <= truth && truth <= l["high"].as_f64().unwrap()
}

#[test]
fn a_short_gusts_onset_interval_holds_the_truth_on_nine_of_ten_seeds() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let short = GUST
        .replace("t_on_s = 0.3", "t_on_s = 0.45\nrise_s = 0.02")
        .replace("coefficient = 3.0", "coefficient = 10.0");
    let seeds = sepval_tests::sweep_cases(10, 3) as u64;
    let (mut onset_covered, mut middle_covered, mut within_10_ms) = (0, 0, 0);
    eprintln!(
        "seed | onset: estimate, SE, 95 % interval, covered | middle: estimate ± SE, covered"
    );
    for seed in 101..101 + seeds {
        let dir = tempfile::tempdir().unwrap();
        let dir = dir.path();
        gust_release_on(dir, &random_base(seed), &short, None, seed, "gust.csv");
        let d = diagnose(dir, &["gust.csv"], "diag");
        assert_eq!(d["discovered"][0]["axis"], "wind_y", "{}", d["verdict"]);
        let (onset, middle) = (location(&d, "t_on_s"), location(&d, "t_mid_s"));
        let (o, m) = (covers(onset, ONSET_S), covers(middle, MIDDLE_S));
        onset_covered += usize::from(o);
        middle_covered += usize::from(m);
        eprintln!(
            "{seed} | {:.4}, {}, [{:.4}, {:.4}], {o} (determined: {}) | {:.4} ± {}, {m}; {:.1} s",
            onset["value"].as_f64().unwrap(),
            onset["std_error"],
            onset["low"].as_f64().unwrap(),
            onset["high"].as_f64().unwrap(),
            onset["determined"],
            middle["value"].as_f64().unwrap(),
            middle["std_error"],
            d["wall_s"].as_f64().unwrap_or(f64::NAN),
        );
        let verdict = d["verdict"].as_str().unwrap();
        let value = onset["value"].as_f64().unwrap();
        within_10_ms += usize::from((value - ONSET_S).abs() <= 0.010);
        assert!(
            covers(onset, value),
            "the estimate outside its interval: {onset}"
        );
        if onset["determined"] == false {
            assert!(onset["std_error"].is_null(), "{onset}");
            assert!(verdict.contains("not determined by the data"), "{verdict}");
        }
    }
    eprintln!(
        "onset within 10 ms of the truth on {within_10_ms} of {seeds} (not asserted: one release does not determine it)"
    );
    let least = sepval_tests::at_least(seeds as usize, 9);
    assert!(
        onset_covered >= least,
        "the onset's interval held the truth on {onset_covered} of {seeds}"
    );
    assert!(
        middle_covered >= least,
        "the middle's interval held the truth on {middle_covered} of {seeds}"
    );
}
