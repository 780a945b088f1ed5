//! A diagnosis that knows what was open (`--after DIR`, issue 60, item 1), in the fast tier: an
//! earlier diagnosis of the first release whose record leaves the true cause open (a member
//! of a rival class), then both releases diagnosed after it. The cause carried forward must be
//! refitted on both releases and be the answer, with its fate in the record and on the page;
//! a record edited after its seal is refused. The diagnoses run on a reduced budget (the
//! baseline's genetic search over 3 generations) so that the test stays in the fast tier; the
//! sweep of closed loops is in `plan/tests/closing/after.rs` (slow tier).

use std::path::Path;

use sepval_common::extension::{Axis, Regressor, Term, TermRecord};
use sepval_common::table::DerivativeCoefficient;
use sepval_diagnose::after::Earlier;
use sepval_diagnose::{Diagnosis, RivalClass};
use serde_json::Value;

use crate::command::Diagnose;
use crate::generator::{default_scenario, release, write};

/// The releases written into `dir`, diagnosed into `dir/out` with the reduced budget, after
/// `after` when given.
fn diagnosed(
    dir: &Path,
    releases: &[sepval_common::telemetry::Trajectory],
    after: Option<&Path>,
    out: &str,
) -> Value {
    let model = default_scenario();
    let mut flags = Diagnose::of(Vec::new());
    flags.generations = 3;
    for (flag, name) in write(dir, releases, releases.len(), Some(&model)) {
        let path = dir.join(name);
        match flag {
            "--scenario" => flags.scenario = Some(path),
            _ => flags.data.push(path),
        }
    }
    flags.after = after.map(Path::to_path_buf);
    flags.record(&dir.join(out))
}

/// Pitch damping half the model's: the first release's record is made to leave `Cm q d/2V`
/// open (a member of a rival class, with the earlier answer's factors as its only fit), and
/// the diagnosis of both releases after it must refit it and answer with it.
#[test]
fn an_open_cause_carried_forward_is_refitted_and_answers() {
    let model = default_scenario();
    let mut truth = model.clone();
    truth.aero.cm_q_per_rad =
        DerivativeCoefficient::constant(0.5 * model.aero.cm_q_per_rad.as_constant().unwrap());
    let mut next = truth.clone();
    (next.flight.mach, next.flight.alpha_deg) = (0.8, 3.0);
    let r1 = release(&truth, None, 601);
    let r2 = release(&next, None, 602);
    let dir = tempfile::tempdir().unwrap();
    let one = dir.path().join("one");
    std::fs::create_dir_all(&one).unwrap();
    diagnosed(&one, std::slice::from_ref(&r1), None, "diag");
    // The earlier record, with the cause as the member of an open class (the record resealed,
    // as the diagnosis seals it).
    let path = one.join("diag/diagnosis.json");
    let mut d: Diagnosis = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let cm_q = Term {
        axis: Axis::Cm,
        regressor: Regressor::Q,
        locator: [0.0, 0.0],
        coefficient: 0.1,
    };
    d.rival_classes.insert(
        0,
        RivalClass {
            words: "Cm q d/2V".into(),
            members: vec!["Cm q d/2V".into()],
            status: "rival".into(),
            delta_bic: Some(1.0),
            member_terms: vec![vec![TermRecord::of(&cm_q)]],
        },
    );
    std::fs::write(&path, sepval_run::sealed::sealed(&d)).unwrap();
    let two = dir.path().join("two");
    std::fs::create_dir_all(&two).unwrap();
    let both = diagnosed(
        &two,
        &[r1.clone(), r2.clone()],
        Some(&one.join("diag")),
        "diag",
    );
    let after = &both["after"];
    eprintln!("{}", both["verdict"]);
    let fates = after["fates"].as_array().unwrap();
    let words: Vec<&str> = fates.iter().map(|f| f["words"].as_str().unwrap()).collect();
    let cause = fates
        .iter()
        .find(|f| f["name"] == "Cm q d/2V")
        .unwrap_or_else(|| panic!("no fate for the cause: {words:?}"));
    assert_eq!(cause["status"], "answer", "{words:?}\n{}", both["verdict"]);
    let answer_terms: Vec<String> = both["model"]["terms"]
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
    assert!(
        answer_terms.contains(&"Cm q".to_string()),
        "{answer_terms:?}"
    );
    assert_eq!(after["earlier_releases"], 1);
    let html = std::fs::read_to_string(two.join("diag/report.html")).unwrap();
    assert!(html.contains("What these releases did to what the earlier diagnosis left open"));
    assert!(html.contains("Cm q d/2V"));

    // A record edited after its seal is refused, naming the directory.
    assert!(Earlier::read(&one.join("diag")).is_ok());
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replacen("\"rival\"", "\"told apart\"", 1)).unwrap();
    let e = Earlier::read(&one.join("diag"))
        .err()
        .expect("an edited record was read");
    assert!(e.to_string().starts_with("--after "), "{e}");
}
