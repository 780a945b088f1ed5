//! Issue 58's yardstick in the test tiers: `sepval campaign rehearse` beside a wall
//! (examples/campaign-wall/README.md: the example aircraft with a wall 0.3 m beside the store,
//! a 5 x 5 grid of Mach 0.6-0.95 and altitude 1-9 km whose boundary runs diagonally through
//! the middle, a prior of known accuracy that each truth is a draw from, `--fly-risk 0.05`),
//! against the three truths of `scripts/campaign-rehearsals.sh`: a null, a cause in the
//! catalogue and a cause outside it. Every rehearsal must clear nothing the truth fails in any
//! round, fly only truly safe releases, clear at least 95 % of the truly safe conditions and
//! decide at least 90 % of all right at the end. Over the three, at most 4 releases on average and the forecasts calibrated
//! (conditions settled / `expected_settled` within 0.7-1.3). The fast tier flies the null at
//! fewer samples; the slow tier the catalogue's cause (the same targets over it alone), and
//! `SEPVAL_SWEEPS=full` (`scripts/sweeps.sh`) all three. ("Settled" checked by flying each safe candidate
//! in turn is tested on a 3 x 3 grid, in campaign.rs: here it is a dozen `add`s a rehearsal,
//! about 12 min on this machine; scripts/campaign-rehearsals.sh --check-settled runs it.)

use std::path::{Path, PathBuf};

use sepval_tests::{ok, sepval};
use serde_json::Value;

/// A file of examples/campaign-wall.
fn wall(name: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/campaign-wall")
        .join(name);
    p.canonicalize().unwrap().display().to_string()
}

/// The truth flags of rehearsal `name`, as scripts/campaign-rehearsals.sh has them.
fn truth(name: &str) -> Vec<String> {
    let mut flags = vec![
        "--truth-factors".to_string(),
        wall(&format!("truth-factors-{name}.json")),
    ];
    match name {
        "null" => {}
        "catalogue" => flags.extend(["--truth-effect".into(), "ejector_cant=-0.03".into()]),
        "extension" => {
            flags.extend(["--truth-extension".into(), wall("extension-cn-mach.toml")]);
        }
        _ => panic!("no rehearsal {name}"),
    }
    flags
}

/// Rehearsal `name` beside the wall in `dir`/`name` with `samples` a condition; its
/// rehearsal.json.
fn rehearse(dir: &Path, name: &str, samples: &str) -> Value {
    let (aircraft, prior) = (wall("aircraft.toml"), wall("prior.json"));
    let mut args: Vec<String> = [
        "campaign",
        "rehearse",
        "--out",
        name,
        "--aircraft",
        &aircraft,
        "--mach",
        "0.6:0.95:5",
        "--altitude-m",
        "1000:9000:5",
        "--prior",
        &prior,
        "--fly-risk",
        "0.05",
        "--samples",
        samples,
        "--generations",
        "20",
        "--seed",
        "1",
        "--releases",
        "6",
        "--evaluator",
        "inproc",
        "--threads",
        "2",
    ]
    .map(String::from)
    .to_vec();
    args.extend(truth(name));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&sepval(&args, dir));
    let path = dir.join(name).join("rehearsal.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// What one rehearsal did, against the targets.
struct Held {
    releases: usize,
    expected: f64,
    settled: u64,
}

/// Checks one rehearsal against the targets every rehearsal must meet (module docs).
fn holds(name: &str, r: &Value) -> Held {
    let truth = r["truth"].as_array().unwrap();
    let n = truth.len();
    let failing = truth.iter().filter(|t| t["fails"] == true).count();
    assert!(
        (0.4..=0.6).contains(&(failing as f64 / n as f64)),
        "{name}: the boundary must run through the middle: {failing} of {n} fail"
    );
    for round in r["rounds"].as_array().unwrap() {
        assert_eq!(round["false_clears"], 0, "{name}: a false clear: {round}");
    }
    let flown = r["flown"].as_array().unwrap();
    for f in flown {
        assert_eq!(f["truly_safe"], true, "{name}: an unsafe release: {f}");
    }
    let last = r["rounds"].as_array().unwrap().last().unwrap();
    let count = |k: &str| last["counts"][k].as_u64().unwrap() as usize;
    let safe_cleared = count("cleared") - last["false_clears"].as_u64().unwrap() as usize;
    let fails_right = count("fails") - last["false_fails"].as_u64().unwrap() as usize;
    let safe = n - failing;
    assert!(
        safe_cleared as f64 >= 0.95 * safe as f64,
        "{name}: {safe_cleared} of the {safe} truly safe conditions cleared: {}",
        r["words"]
    );
    assert!(
        (safe_cleared + fails_right) as f64 >= 0.9 * n as f64,
        "{name}: {} of {n} decided right: {}",
        safe_cleared + fails_right,
        r["words"]
    );
    assert_eq!(r["settled"], true, "{name}: {}", r["words"]);
    let expected: f64 = flown
        .iter()
        .map(|f| f["expected_settled"].as_f64().unwrap())
        .sum();
    let settled: u64 = flown.iter().map(|f| f["settled"].as_u64().unwrap()).sum();
    // Never 0 expected where a release settles several.
    for f in flown {
        if f["settled"].as_u64().unwrap() >= 2 {
            assert!(
                f["expected_settled"].as_f64().unwrap() >= 0.5,
                "{name}: {f}"
            );
        }
    }
    Held {
        releases: flown.len(),
        expected,
        settled,
    }
}

#[test]
fn a_wall_rehearsal_of_a_null_truth_settles_the_envelope_in_few_releases() {
    let tmp = tempfile::tempdir().unwrap();
    let r = rehearse(tmp.path(), "null", "100");
    let held = holds("null", &r);
    assert!(held.releases <= 4, "{}", r["words"]);
    let ratio = held.settled as f64 / held.expected;
    assert!((0.7..=1.3).contains(&ratio), "{ratio}: {}", r["words"]);
}

#[test]
fn wall_rehearsals_of_three_truths_settle_with_calibrated_forecasts() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    // The null is last: the fast tier flies it (at 100 samples) above.
    let truths = sepval_tests::sweep_cases(3, 1);
    let held: Vec<Held> = ["catalogue", "extension", "null"]
        .iter()
        .take(truths)
        .map(|name| holds(name, &rehearse(tmp.path(), name, "200")))
        .collect();
    let releases = held.iter().map(|h| h.releases).sum::<usize>() as f64 / held.len() as f64;
    assert!(releases <= 4.0, "{releases} releases on average");
    let expected: f64 = held.iter().map(|h| h.expected).sum();
    let settled: u64 = held.iter().map(|h| h.settled).sum();
    let ratio = settled as f64 / expected;
    assert!(
        (0.7..=1.3).contains(&ratio),
        "settled {settled} / expected {expected:.1} = {ratio:.2}"
    );
}
