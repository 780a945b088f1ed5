//! When one release cannot tell causes apart, the diagnosis says so: its `rivals` list every
//! explanation within the BIC margin of the answer, from the catalogue and from the library,
//! so that a mimic comes with the cause it mimics. The data come from the tests' own generator
//! (`support/generator.rs`: a changed scenario, never the catalogue's or the extension's code, on
//! a base that is not the default truth, with the generator's own noise). Moved from
//! `sepval/tests/cli/rivals.rs`, each assertion kept.

use serde_json::Value;

use crate::releases::{default_scenario, diagnose, release};

/// Every explanation the diagnosis leaves open: the answer's and each rival's
/// (effects, `axis regressor` of each term).
fn open_explanations(d: &Value) -> Vec<(Vec<String>, Vec<String>)> {
    let model = |m: &Value| {
        let effects = m["effects"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e["id"].as_str().unwrap().to_string())
            .collect();
        let terms = m["terms"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| {
                format!(
                    "{} {}",
                    t["axis"].as_str().unwrap(),
                    t["regressor"].as_str().unwrap()
                )
            })
            .collect();
        (effects, terms)
    };
    let mut out = vec![model(&d["model"])];
    for r in d["rivals"].as_array().unwrap() {
        out.push(model(&r["model"]));
    }
    out
}

/// The summary of a diagnosis for a failing assertion.
fn shown(d: &Value) -> String {
    format!(
        "verdict: {}\nrivals: {}\nalternatives: {}",
        d["verdict"],
        serde_json::to_string_pretty(
            &d["rivals"]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| (r["origin"].clone(), r["delta_bic"].clone()))
                .collect::<Vec<_>>()
        )
        .unwrap(),
        d["alternatives"]
    )
}

#[test]
fn weaker_roll_damping_and_its_catalogue_mimic_are_rivals() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // The data's roll damping is half the model's; the store rolls from interference alone. On
    // one release the catalogue's rolling moment due to sideslip fits as well: the diagnosis
    // must name the true cause (a Cl change with p d/2V) beside whichever it answers.
    let dir = tempfile::tempdir().unwrap();
    let model = default_scenario();
    let mut truth = model.clone();
    truth.aero.cl_p_per_rad = sepval_common::table::DerivativeCoefficient::constant(
        0.5 * model.aero.cl_p_per_rad.as_constant().unwrap(),
    );
    let r = release(&truth, None, 31);
    let d = diagnose(dir.path(), &[r], 1, Some(&model));
    let open = open_explanations(&d);
    assert_eq!(d["ambiguous"], true, "{}", shown(&d));
    assert!(
        open.iter()
            .any(|(e, t)| e.is_empty() && t == &["Cl p".to_string()]),
        "{}",
        shown(&d)
    );
    assert!(
        open.iter().any(|(e, t)| !e.is_empty() && t.is_empty()),
        "{}",
        shown(&d)
    );
    assert_rivals_well_formed(&d);
}

#[test]
fn a_term_mimics_rates_at_release() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // The store leaves with pitch and yaw rates the model does not have (the catalogue's
    // release_rates): on one release a discovered term explains it within the margin too.
    let dir = tempfile::tempdir().unwrap();
    let model = default_scenario();
    let mut truth = model.clone();
    truth.initial.rates_deg_s = [0.0, 8.0, -6.0];
    let r = release(&truth, None, 32);
    let d = diagnose(dir.path(), &[r], 1, Some(&model));
    assert_eq!(d["causes"][0], "release_rates", "{}", shown(&d));
    let rivals = d["rivals"].as_array().unwrap();
    assert!(
        rivals.iter().any(|r| r["kind"] == "discovered"),
        "{}",
        shown(&d)
    );
    assert_rivals_well_formed(&d);
}

/// Each rival within the margin, best first, with its model and numbers; the verdict says the
/// data cannot tell them apart; no rival is also an alternative.
fn assert_rivals_well_formed(d: &Value) {
    let rivals = d["rivals"].as_array().unwrap();
    let mut last = f64::NEG_INFINITY;
    for r in rivals {
        let db = r["delta_bic"].as_f64().unwrap();
        assert!(db.abs() < 6.0 && db >= last, "{}", shown(d));
        last = db;
        for k in ["chi2", "j_pos_m", "j_att_deg"] {
            assert!(r[k].as_f64().unwrap() > 0.0, "{k}: {r}");
        }
        assert!(["catalogue", "discovered"].contains(&r["kind"].as_str().unwrap()));
        assert_eq!(r["model"]["factors"].as_object().unwrap().len(), 17, "{r}");
    }
    let verdict = d["verdict"].as_str().unwrap();
    assert!(verdict.contains("cannot tell it from"), "{verdict}");
    for a in d["alternatives"].as_array().unwrap() {
        assert!(
            a["delta_bic_vs_answer"].as_f64().unwrap().abs() >= 6.0,
            "{a}"
        );
    }
}

/// Whether `member` (`axis formula`) is open in `d`: a term of the answer or of a rival, or a
/// member of a rival class of the answer or of a rival.
fn open_member(d: &Value, member: &str) -> bool {
    let (axis, regressor) = member.split_once(' ').unwrap();
    let as_term = |m: &Value| {
        m["terms"]
            .as_array()
            .unwrap()
            .iter()
            .any(|t| t["axis"] == axis && t["regressor"] == regressor)
    };
    as_term(&d["model"])
        || d["rivals"]
            .as_array()
            .unwrap()
            .iter()
            .any(|r| as_term(&r["model"]))
}

/// Whether the formula `member` (`axis formula`) is in a class of the answer, of a rival or
/// of a better fit than the answer.
fn in_open_class(d: &Value, member: &str) -> bool {
    d["rival_classes"].as_array().is_some_and(|classes| {
        classes.iter().any(|c| {
            ["answer", "rival", "better"].contains(&c["status"].as_str().unwrap())
                && c["members"].as_array().unwrap().iter().any(|m| m == member)
        })
    })
}

#[test]
fn a_damping_change_on_one_release_leaves_the_rate_term_open() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // Issue 36, item 1: stronger roll damping (1.6 and 2 times the model's) on one release,
    // seeds other than the tests' defaults. Before the rival classes, 1.6 was answered as
    // sideslip and 2 as a pitch-rate interference term, the roll-rate term (third and ninth
    // by F-to-enter) never refitted, so never a rival. Now the rate term is in the answer's
    // class or in a rival's (measured 2026-11-27: a class of 23 rolling-moment terms with BIC
    // -6.6 for 1.6; the answer's class of 31 for 2).
    // Pitch damping the same way (0.2 and 2.5 times the model's: at 0.4 the baseline explains
    // seed 57 to the noise).
    use sepval_common::table::DerivativeCoefficient;
    let model = default_scenario();
    let roll = |k: f64| {
        let mut truth = model.clone();
        let c = model.aero.cl_p_per_rad.as_constant().unwrap();
        truth.aero.cl_p_per_rad = DerivativeCoefficient::constant(k * c);
        truth
    };
    let pitch = |k: f64| {
        let mut truth = model.clone();
        let c = model.aero.cm_q_per_rad.as_constant().unwrap();
        truth.aero.cm_q_per_rad = DerivativeCoefficient::constant(k * c);
        truth
    };
    let cases = [
        ("roll damping x1.6", roll(1.6), 53, "Cl"),
        ("roll damping x2", roll(2.0), 54, "Cl"),
        ("pitch damping x0.2", pitch(0.2), 57, "Cm"),
        ("pitch damping x2.5", pitch(2.5), 58, "Cm"),
    ];
    for (what, truth, seed, axis) in cases {
        let dir = tempfile::tempdir().unwrap();
        let r = release(&truth, None, seed);
        let d = diagnose(dir.path(), &[r], 1, Some(&model));
        let rate = if axis == "Cl" { "p" } else { "q" };
        assert!(
            open_member(&d, &format!("{axis} {rate}"))
                || in_open_class(&d, &format!("{axis} {rate} d/2V")),
            "{what}: {}\nclasses: {}",
            shown(&d),
            d["rival_classes"]
        );
        assert!(
            d["verdict"]
                .as_str()
                .unwrap()
                .contains("the first screening cannot tell the answer from"),
            "{}",
            d["verdict"]
        );
        for c in d["rival_classes"].as_array().unwrap() {
            let members = c["members"].as_array().unwrap().len();
            assert!(members >= 1, "{c}");
            let words = c["words"].as_str().unwrap();
            assert!(
                members == 1 || words.starts_with(&format!("any of {members} ")),
                "{c}"
            );
            assert_eq!(
                c["delta_bic"].is_null(),
                c["status"] == "not refitted",
                "{c}"
            );
        }
    }
}
