//! Refinement to the noise floor, identifiability, pooled events and resolution advice, end
//! to end on noisy synthetic data (reduced genetic searches).

use std::path::Path;

use sepval_tests::{ok, sepval};
use serde_json::Value;

fn result(dir: &Path, run: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join(run).join("result.json")).unwrap())
        .unwrap()
}

fn fit(dir: &Path, out: &str, extra: &[&str]) -> Value {
    let mut args = vec![
        "fit",
        "--method",
        "ga+lm",
        "--generations",
        "30",
        "--evaluator",
        "inproc",
        "--no-figures",
        "--out",
        out,
    ];
    args.extend_from_slice(extra);
    ok(&sepval(&args, dir));
    result(dir, out)
}

fn std_error(r: &Value, name: &str) -> f64 {
    r["identifiability"]["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == name)
        .unwrap()["std_error"]
        .as_f64()
        .unwrap()
}

#[test]
fn ga_lm_reaches_the_noise_floor_and_recovers_every_identifiable_factor() {
    let dir = tempfile::tempdir().unwrap();
    // Noise is known here: give it, so the floor is the true one (0.003 m, 0.1 deg).
    let r = fit(
        dir.path(),
        "run",
        &[
            "--seed",
            "4",
            "--sigma-pos-m",
            "0.003",
            "--sigma-att-deg",
            "0.1",
        ],
    );
    let m = &r["methods"]["ga+lm"];
    let (jp, ja) = (
        m["best"]["j_pos_m"].as_f64().unwrap(),
        m["best"]["j_att_deg"].as_f64().unwrap(),
    );
    assert!(jp <= 1.1 * 0.003 && ja <= 1.1 * 0.1, "{jp} {ja}");
    let to_floor = m["evaluations_to_floor"]
        .as_u64()
        .expect("reached the floor");
    assert!(to_floor <= m["best"]["evaluations"].as_u64().unwrap());
    let truth = &r["truth"];
    let id = &r["identifiability"];
    for p in id["parameters"].as_array().unwrap() {
        if p["identifiable"].as_bool().unwrap() {
            let name = p["name"].as_str().unwrap();
            let z = (p["value"].as_f64().unwrap() - truth[name].as_f64().unwrap())
                / p["std_error"].as_f64().unwrap();
            assert!(z.abs() <= 3.0, "{name}: {z} standard errors from the truth");
        }
    }
    // The roll inertia factor and the roll moment offset compensate each other.
    let pairs = id["compensating"].as_array().unwrap();
    assert!(
        pairs.iter().any(|c| {
            let (a, b) = (c["a"].as_str().unwrap(), c["b"].as_str().unwrap());
            (a, b) == ("xinerfac", "cloff") || (a, b) == ("cloff", "xinerfac")
        }),
        "{pairs:?}"
    );
    // Refined values stay within the factor bounds.
    for (name, v) in m["best"]["factors"].as_object().unwrap() {
        let v = v.as_f64().unwrap();
        assert!(v.is_finite(), "{name}");
    }
    let res = r["resolution"].as_array().unwrap();
    assert_eq!(res.len(), 17);
    let cloff = res.iter().find(|x| x["factor"] == "cloff").unwrap();
    assert_eq!(
        cloff["coarse"], true,
        "one cloff grid step moves roll by degrees"
    );
}

#[test]
fn refined_factors_respect_the_bounds_of_the_scenario() {
    let dir = tempfile::tempdir().unwrap();
    // Narrow xinerfac's range so that its truth (1.04) lies outside: the refinement must stop
    // at the bound rather than leave the box.
    ok(&sepval(&["scenario", "--out", "s.toml"], dir.path()));
    let text = std::fs::read_to_string(dir.path().join("s.toml")).unwrap();
    let text = text.replace(
        "[factors.xinerfac]\nmin = 0.9\nmax = 1.1\nbits = 4",
        "[factors.xinerfac]\nmin = 0.9\nmax = 0.95\nbits = 4",
    );
    assert!(
        text.contains("max = 0.95"),
        "scenario layout changed: {text}"
    );
    std::fs::write(dir.path().join("s.toml"), text).unwrap();
    ok(&sepval(
        &["simulate", "--noise-seed", "3", "--out", "d.csv"],
        dir.path(),
    ));
    let r = fit(
        dir.path(),
        "b",
        &["--scenario", "s.toml", "--data", "d.csv"],
    );
    let x = r["methods"]["ga+lm"]["best"]["factors"]["xinerfac"]
        .as_f64()
        .unwrap();
    assert!((0.9..=0.95).contains(&x), "{x}");
}

#[test]
fn pooling_two_events_narrows_the_compensating_pair() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(&["scenario", "--out", "base.toml"], dir.path()));
    let base = std::fs::read_to_string(dir.path().join("base.toml")).unwrap();
    let other = base
        .replace("mach = 0.95", "mach = 0.8")
        .replace("alpha_deg = 0.0", "alpha_deg = 3.0");
    assert_ne!(base, other);
    std::fs::write(dir.path().join("m08.toml"), other).unwrap();
    ok(&sepval(
        &["simulate", "--noise-seed", "11", "--out", "e1.csv"],
        dir.path(),
    ));
    ok(&sepval(
        &[
            "simulate",
            "--scenario",
            "m08.toml",
            "--noise-seed",
            "12",
            "--out",
            "e2.csv",
        ],
        dir.path(),
    ));
    let sigma = ["--sigma-pos-m", "0.003", "--sigma-att-deg", "0.1"];
    let mut a1 = vec!["--data", "e1.csv"];
    a1.extend(sigma);
    let mut pooled = vec!["--data", "e1.csv", "--data", "e2.csv"];
    pooled.extend(sigma);
    let single = fit(dir.path(), "one", &a1);
    let both = fit(dir.path(), "two", &pooled);
    assert_eq!(both["events"].as_array().unwrap().len(), 2);
    for name in ["xinerfac", "cloff"] {
        let (s1, s2) = (std_error(&single, name), std_error(&both, name));
        assert!(s2 < 0.5 * s1, "{name}: pooled {s2} vs single {s1}");
    }
    let m = &both["methods"]["ga+lm"]["best"];
    assert!(m["j_pos_m"].as_f64().unwrap() <= 1.1 * 0.003);
}

#[test]
fn a_bad_flight_condition_in_metadata_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(&["simulate", "--out", "d.csv"], dir.path()));
    let text = std::fs::read_to_string(dir.path().join("d.csv")).unwrap();
    std::fs::write(
        dir.path().join("bad.csv"),
        text.replace("# mach = 0.95", "# mach = fast"),
    )
    .unwrap();
    let out = sepval(
        &["fit", "--data", "bad.csv", "--out", "x", "--no-figures"],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("metadata `# mach = fast` is not a number")
    );
}

#[test]
fn ga_lm_resumes_to_the_same_result() {
    let dir = tempfile::tempdir().unwrap();
    let args = |out: &'static str| {
        vec![
            "fit",
            "--method",
            "ga+lm",
            "--generations",
            "12",
            "--population",
            "20",
            "--evaluator",
            "inproc",
            "--no-figures",
            "--out",
            out,
        ]
    };
    ok(&sepval(&args("full"), dir.path()));
    ok(&sepval(
        &[
            "fit",
            "--resume",
            "full/generations/gen-0005.json",
            "--evaluator",
            "inproc",
            "--no-figures",
            "--out",
            "resumed",
        ],
        dir.path(),
    ));
    let strip = |mut v: Value| {
        v.as_object_mut().unwrap().remove("run");
        // The digest seals the record's timings too.
        v.as_object_mut().unwrap().remove("digest");
        for m in v["methods"].as_object_mut().unwrap().values_mut() {
            m["best"].as_object_mut().unwrap().remove("wall_s");
        }
        v
    };
    assert_eq!(
        strip(result(dir.path(), "full")),
        strip(result(dir.path(), "resumed"))
    );
}
