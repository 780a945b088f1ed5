//! The diagnosis finds effects hidden in flight data, in process: every catalogue effect at a
//! clearly visible magnitude on a base that is not the default truth, two effects together,
//! data of the baseline model (no cause), and a cause outside the catalogue. Slow tier
//! (`SEPVAL_SLOW_TESTS=1`); one diagnosis of about 10 s each.
//!
//! Each case is the diagnosis that `sepval diagnose --data d.csv --generations 20 --evaluator
//! inproc --threads 2` makes of what `sepval simulate --factors base.json --noise-seed S
//! --effect ...` writes: the data are simulated, written and read back by the same library
//! functions the commands call (`support/simulate.rs`), and diagnosed with the command's own
//! options (`DiagnoseOptions::new`, `support/command.rs`), so the diagnosis is the command's to
//! the last bit. The binary's own test of the command (`sepval/tests/cli/diagnose.rs`) keeps
//! one such case end to end.

use std::path::Path;

use sepval_common::scenario::Scenario;
use sepval_diagnose::Diagnosis;

// Shared with the other test binaries that diagnose; this one diagnoses without a
// `--validate`, a `--scenario` or an `--extension`, so it reads no diagnosis.json back.
#[allow(dead_code)]
#[path = "../support/command.rs"]
mod command;
#[path = "../support/simulate.rs"]
mod simulate;

use command::Diagnose;
use simulate::Simulate;

/// Factors of the base model of these tests (not the default truth).
const BASE: &str = r#"{"fwdfac": 0.45, "aftfac": 0.65, "xinerfac": 0.98, "yinerfac": 1.03,
 "zinerfac": 0.97, "caoff": -0.02, "cyoff": 0.04, "czoff": -0.06, "cmoff": 0.1, "cnoff": -0.08,
 "cloff": -0.05, "caintfac": 1.1, "cyintfac": 1.4, "czintfac": 0.9, "cmintfac": 1.3,
 "cnintfac": 0.8, "clintfac": 1.6}"#;

/// `sepval diagnose --data d.csv --generations 20 --evaluator inproc --threads 2` of what
/// `sepval simulate --factors base.json --noise-seed seed [--scenario truth] --effect ...`
/// writes (the embedded default scenario fitted).
fn hidden(effects: &[&str], seed: u64, truth: Option<&Path>) -> Diagnosis {
    let dir = tempfile::tempdir().unwrap();
    let (base, data) = (dir.path().join("base.json"), dir.path().join("d.csv"));
    std::fs::write(&base, BASE).unwrap();
    Simulate {
        factors: base.to_str().unwrap(),
        scenario: truth,
        effects,
        noise_seed: Some(seed),
        ..Simulate::default()
    }
    .run(&data);
    let out = dir.path().join("diag");
    let d = Diagnose::of(vec![data]).run(&out);
    // The files a diagnosis writes: the page says the verdict, the residuals are drawn.
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains(d.verdict.split(',').next().unwrap()));
    assert!(out.join("figures/residuals_event1.png").is_file());
    assert!(out.join("diagnosis.json").is_file());
    d
}

/// The effect of `effect` (`id=values`) is the first cause named, explained to the noise,
/// its parameters estimated, and every catalogue effect tried in the first round.
fn named_first(effect: &str) {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let id = effect.split('=').next().unwrap();
    let d = hidden(&[effect], 5, None);
    assert_eq!(
        d.causes.first().map(String::as_str),
        Some(id),
        "{effect}: {}",
        d.verdict
    );
    assert!(d.explained, "{effect}: {}", d.verdict);
    assert!(d.parameters.contains_key(id));
    assert_eq!(d.candidates.iter().filter(|c| c.round == 1).count(), 11);
}

#[test]
fn roll_due_to_sideslip_is_found() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let d = hidden(&["roll_due_to_sideslip=-0.3"], 5, None);
    assert_eq!(d.causes, ["roll_due_to_sideslip"]);
    let p = &d.parameters["roll_due_to_sideslip"][0];
    let se = p.std_error.unwrap();
    assert!(
        (p.value + 0.3).abs() < 3.0 * se + 0.01,
        "{} +- {se}",
        p.value
    );
    assert!(
        d.verdict
            .starts_with("missing rolling moment due to sideslip")
    );
    assert!(d.extended.j_att_deg < 0.2 * d.baseline.j_att_deg);
}

#[test]
fn pitch_stiffness_cubic_is_found() {
    named_first("pitch_stiffness_cubic=30");
}

#[test]
fn cg_offset_is_found() {
    named_first("cg_offset=0.05");
}

#[test]
fn inertia_product_xz_is_found() {
    named_first("inertia_product_xz=30");
}

#[test]
fn ejector_delay_is_found() {
    named_first("ejector_delay=0.01");
}

#[test]
fn ejector_cant_is_found() {
    named_first("ejector_cant=0.1");
}

#[test]
fn interference_decay_is_found() {
    named_first("interference_decay=1.5");
}

#[test]
fn release_rates_are_found() {
    named_first("release_rates=0.2,-0.1,0.1");
}

#[test]
fn telemetry_time_offset_is_found() {
    named_first("telemetry_time_offset=0.01");
}

#[test]
fn tracked_point_offset_is_found() {
    named_first("tracked_point_offset=0.5");
}

#[test]
fn two_effects_hidden_together_are_both_named() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let d = hidden(&["roll_due_to_sideslip=-0.3", "ejector_cant=0.1"], 8, None);
    let mut c = d.causes.clone();
    c.sort();
    assert_eq!(c, ["ejector_cant", "roll_due_to_sideslip"], "{}", d.verdict);
    assert!(d.explained);
}

#[test]
fn data_from_the_baseline_model_name_no_cause() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    for seed in [1, 2, 3] {
        let d = hidden(&[], seed, None);
        assert!(d.causes.is_empty(), "seed {seed}: {}", d.verdict);
        assert!(d.explained);
        // Every candidate is reported, none significant, each with its bound.
        for c in &d.candidates {
            assert!(!c.significant);
            assert!(c.note.contains("not significant"));
        }
    }
}

#[test]
fn an_effect_outside_the_catalogue_is_not_explained() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // Pitch damping five times the scenario's: no catalogue effect is that. The scenario as
    // `sepval scenario` writes it, edited, and given as `--scenario` to simulate.
    let dir = tempfile::tempdir().unwrap();
    let text = Scenario::embedded_default().to_toml_string();
    assert!(text.contains("cm_q_per_rad = -80.0"), "{text}");
    let path = dir.path().join("s.toml");
    std::fs::write(
        &path,
        text.replace("cm_q_per_rad = -80.0", "cm_q_per_rad = -400.0"),
    )
    .unwrap();
    let d = hidden(&[], 3, Some(&path));
    assert!(!d.explained, "{}", d.verdict);
    assert!(d.verdict.starts_with("not explained"));
}
