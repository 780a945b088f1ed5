//! The store's estimate from its shape as a starting point (docs/aero.md, "The estimate as a
//! starting point"): `scenario --from-shape` writes a scenario whose `[aero]` is `sepval
//! aero`'s and the rest the base's, and refuses a bad shape leaving nothing; `campaign init
//! --prior-from-shape` over that scenario takes the estimate's uncertainty as the offsets'
//! spread, recorded, and refuses a bad shape or a factor given twice leaving nothing.

use std::path::Path;

use sepval_common::scenario::Scenario;
use sepval_tests::{ok, refused, sepval};
use serde_json::Value;

fn example_store() -> String {
    super::envelope::example("store.toml")
}

/// `scenario --from-shape` of the example store into `dir/name`; what it said on stderr.
fn from_shape(dir: &Path, name: &str) -> String {
    let store = example_store();
    let out = sepval(&["scenario", "--from-shape", &store, "--out", name], dir);
    ok(&out);
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn scenario_from_shape_is_the_estimates_aero_in_the_base() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let said = from_shape(dir, "est.toml");
    let est = Scenario::load(&dir.join("est.toml")).unwrap();
    let base = Scenario::embedded_default();
    // The [aero] is the one `sepval aero` writes on its default grids.
    let store = example_store();
    ok(&sepval(
        &["aero", "--store-shape", &store, "--out", "a"],
        dir,
    ));
    let aero_toml = std::fs::read_to_string(dir.join("a/aero.toml")).unwrap();
    let mut text = base.to_toml_string();
    let at = text.find("\n[aero]").unwrap() + 1;
    let end = at + 1 + text[at + 1..].find("\n[").unwrap() + 1;
    text.replace_range(at..end, &aero_toml);
    let via_aero = Scenario::from_toml_str(&text, "via aero").unwrap();
    assert_eq!(est.aero, via_aero.aero);
    assert!(
        est.aero
            .cm_alpha_per_rad
            .as_ref()
            .unwrap()
            .as_table()
            .is_some()
    );
    // The rest is the base's: the mass properties, the ejector, the interference, the flight.
    assert_eq!(est.store.mass_kg, base.store.mass_kg);
    assert_eq!(est.store.iyy_kg_m2, base.store.iyy_kg_m2);
    assert_eq!(est.ejector, base.ejector);
    assert_eq!(est.interference, base.interference);
    assert_eq!(est.flight, base.flight);
    // The factor table is the base's but for the static offsets, whose ranges reach three of
    // the estimate's sigmas (`sepval_aero::start::offset_ranges`): CA0's band at the default's
    // Mach 0.95 is wider than Anderson's caoff; none is narrowed.
    use sepval_core::factors::Factor;
    let offsets = [
        Factor::Caoff,
        Factor::Cyoff,
        Factor::Czoff,
        Factor::Cmoff,
        Factor::Cnoff,
    ];
    for f in Factor::ALL {
        let (e, b) = (est.factors.spec(f), base.factors.spec(f));
        if offsets.contains(&f) {
            assert!(
                e.min <= b.min && e.max >= b.max && e.step() <= b.step(),
                "{f:?}"
            );
        } else {
            assert_eq!(e, b, "{f:?}");
        }
    }
    assert!(
        est.factors.spec(Factor::Caoff).max > 0.3,
        "{:?}",
        est.factors
    );
    assert!(est.description.contains("caoff"), "{}", est.description);
    assert!(said.contains("factors: caoff range"), "{said}");
    assert!(!said.contains("factors: cloff"), "{said}");
    // It flies.
    ok(&sepval(
        &["simulate", "--scenario", "est.toml", "--out", "est.csv"],
        dir,
    ));
    // A given --scenario is the base.
    let mut heavy = base.clone();
    heavy.store.mass_kg = 1000.0;
    std::fs::write(dir.join("heavy.toml"), heavy.to_toml_string()).unwrap();
    ok(&sepval(
        &[
            "scenario",
            "--scenario",
            "heavy.toml",
            "--from-shape",
            &store,
            "--out",
            "heavy-est.toml",
        ],
        dir,
    ));
    let heavy = Scenario::load(&dir.join("heavy-est.toml")).unwrap();
    assert_eq!(heavy.store.mass_kg, 1000.0);
    assert_eq!(heavy.aero, est.aero);
}

#[test]
fn scenario_from_shape_refuses_bad_input_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let store = example_store();
    let text = std::fs::read_to_string(&store).unwrap();
    std::fs::write(
        dir.join("five.toml"),
        text.replace("count = 4", "count = 5"),
    )
    .unwrap();
    std::fs::write(
        dir.join("unknown.toml"),
        text.replace("[fins]", "[fins]\nsweep_deg = 3"),
    )
    .unwrap();
    std::fs::write(dir.join("shape.toml"), &text).unwrap();
    let cases: [(&[&str], &str); 5] = [
        (&["--from-shape", "five.toml"], "fins.count: 5 fins"),
        (&["--from-shape", "unknown.toml"], "sweep_deg"),
        (&["--from-shape", "missing.toml"], "missing.toml"),
        (
            &["--from-shape", "shape.toml", "--tables"],
            "cannot be used with",
        ),
        (
            &["--from-shape", "shape.toml", "--out", "shape.toml"],
            "shape.toml",
        ),
    ];
    for (args, says) in cases {
        let mut all = vec!["scenario"];
        all.extend_from_slice(args);
        if !args.contains(&"--out") {
            all.extend_from_slice(&["--out", "est.toml"]);
        }
        refused(&sepval(&all, dir), says);
        assert!(!dir.join("est.toml").exists(), "{args:?} left a file");
    }
    // The shape named as --out was not overwritten.
    assert_eq!(
        std::fs::read_to_string(dir.join("shape.toml")).unwrap(),
        text
    );
}

/// `campaign init` on a 3 x 3 grid (Mach 0.6 to 1.0, alpha -4 to 8 deg) with few samples.
fn init<'a>(aircraft: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "campaign",
        "init",
        "--aircraft",
        aircraft,
        "--mach",
        "0.6:1.0:3",
        "--alpha-deg",
        "-4:8:3",
        "--samples",
        "100",
        "--generations",
        "5",
        "--evaluator",
        "inproc",
        "--threads",
        "2",
        "--out",
        "c",
    ];
    args.extend(extra);
    args
}

#[test]
fn campaign_prior_from_shape_sets_the_offsets_spread_from_the_estimate() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    from_shape(dir, "est.toml");
    let aircraft = super::envelope::example("aircraft.toml");
    let store = example_store();
    let said = ok(&sepval(
        &init(
            &aircraft,
            &["--scenario", "est.toml", "--prior-from-shape", &store],
        ),
        dir,
    ));
    assert!(said.contains("czoff 0 sd"), "{said}");
    let camp: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("c/campaign.json")).unwrap())
            .unwrap();
    let prior = &camp["settings"]["prior"];
    let src = &prior["sources"][1];
    assert_eq!(src["kind"], "shape", "{src}");
    assert_eq!(src["points"], 27, "{src}");
    let mapped: Vec<&str> = src["mapped"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["factor"].as_str().unwrap())
        .collect();
    assert_eq!(mapped, ["caoff", "cyoff", "czoff", "cmoff", "cnoff"]);
    for f in mapped {
        let b = &prior["factors"][f];
        assert_eq!(b["mean"].as_f64().unwrap(), 0.0, "{f} {b}");
        let sd = b["sd"].as_f64().unwrap();
        assert!(sd > 0.0 && sd.is_finite(), "{f} {b}");
    }
    // The factors the estimate does not give keep the default.
    assert!((prior["factors"]["fwdfac"]["sd"].as_f64().unwrap() - 0.8 / 6.0).abs() < 1e-12);
    assert!((prior["factors"]["cloff"]["sd"].as_f64().unwrap() - 1.0 / 6.0).abs() < 1e-12);
}

#[test]
fn campaign_prior_from_shape_refuses_bad_input_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    from_shape(dir, "est.toml");
    let text = std::fs::read_to_string(example_store()).unwrap();
    std::fs::write(
        dir.join("five.toml"),
        text.replace("count = 4", "count = 5"),
    )
    .unwrap();
    std::fs::write(dir.join("shape.toml"), &text).unwrap();
    std::fs::write(
        dir.join("twice.json"),
        r#"{"format":"sepval-prior/1","factors":{"czoff":{"mean":0.0,"sd":0.05}}}"#,
    )
    .unwrap();
    let aircraft = super::envelope::example("aircraft.toml");
    let s = ["--scenario", "est.toml", "--prior-from-shape"];
    for (extra, says) in [
        (&["five.toml"][..], "--prior-from-shape five.toml"),
        (&["missing.toml"], "--prior-from-shape missing.toml"),
        (
            &["shape.toml", "--prior", "twice.json"],
            "sets czoff, which an earlier source",
        ),
    ] {
        let args = [&s[..], extra].concat();
        refused(&sepval(&init(&aircraft, &args), dir), says);
        assert!(!dir.join("c").exists(), "{extra:?}: c was written");
    }
}
