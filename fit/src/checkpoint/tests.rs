//! Checkpoints written and read back: the digest, non-finite statistics, earlier formats and
//! the consistency checks.

#![allow(clippy::float_cmp)] // exact values on purpose

use std::sync::Arc;

use sepval_common::evaluation::{Candidate, Evaluator, InProcess, Job, Outcome};
use sepval_common::scenario::Scenario;
use sepval_common::synthetic::default_flight_test;
use serde_json::Value;

use super::*;
use crate::problem::factors_of;
use sepval_solve::ga::GaSearch;
use sepval_solve::rng::{RngState, seeded};
use sepval_solve::run::Solver;

/// An edit of a checkpoint's JSON.
type JsonEdit = Box<dyn Fn(&mut Value)>;

/// An edit of a checkpoint.
type Edit = Box<dyn Fn(&mut Checkpoint)>;

fn job() -> Arc<Job> {
    Arc::new(Job::single(
        "default",
        &Scenario::embedded_default(),
        default_flight_test(),
    ))
}

/// The checkpoint after `generations` of a small GA on `job`; with `finish` false no member
/// finishes (every outcome a failure), so the statistics are infinite.
fn checkpoint(job: &Arc<Job>, generations: usize, finish: bool) -> Checkpoint {
    let settings = GaSettings {
        population: 6,
        generations,
        seed: 5,
        ..GaSettings::default()
    };
    let sigma = Sigma {
        pos_m: 0.01,
        att_deg: 0.1,
        source: "given".into(),
    };
    let genes = job.factor_table().0.to_vec();
    let mut ga = GaSearch::new(settings.clone(), sigma.weights(), genes).unwrap();
    let mut evaluator = InProcess::new(Arc::clone(job), 1);
    while let Some(ask) = ga.ask().unwrap() {
        let told: Vec<Outcome> = if finish {
            let batch: Vec<Candidate> = ask
                .points
                .iter()
                .map(|v| Candidate::baseline(factors_of(v)))
                .collect();
            let evaluations = evaluator.evaluate(&batch, false).unwrap();
            evaluations.into_iter().map(|e| e.outcome).collect()
        } else {
            ask.points
                .iter()
                .map(|_| Outcome::failed("no member finishes"))
                .collect()
        };
        ga.tell(told).unwrap();
    }
    Checkpoint {
        format: CHECKPOINT_FORMAT.into(),
        digest: None,
        arithmetic: Some(sepval_common::ARITHMETIC_VERSION),
        method: "ga".into(),
        settings,
        hill: HillSettings::default(),
        sigma,
        data_sha256: job.data_sha256().into(),
        scenario_sha256: job.scenario_sha256().into(),
        inputs: InputsRecord {
            data: Vec::new(),
            scenario: None,
            extension: None,
            outliers: Default::default(),
        },
        state: ga.state().unwrap().clone(),
        probes: Vec::new(),
    }
}

/// Loads `path` and checks it against `job`: the error's message, if any.
fn refusal(path: &Path, job: &Job) -> Option<String> {
    match Checkpoint::load(path).and_then(|c| c.check_job(job, path)) {
        Ok(()) => None,
        Err(e) => Some(e.to_string()),
    }
}

fn edit_json(path: &Path, to: &Path, edit: impl FnOnce(&mut Value)) {
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    edit(&mut v);
    std::fs::write(to, serde_json::to_string(&v).unwrap()).unwrap();
}

fn next_up(v: &Value) -> Value {
    let x = v.as_f64().unwrap();
    Value::from(f64::from_bits(x.to_bits() + 1))
}

#[test]
fn a_saved_checkpoint_loads_back_identical_with_its_digest() {
    let (job, dir) = (job(), tempfile::tempdir().unwrap());
    let c = checkpoint(&job, 3, true);
    let path = dir.path().join("gen-0003.json");
    c.save(&path).unwrap();
    let back = Checkpoint::load(&path).unwrap();
    back.check_job(&job, &path).unwrap();
    assert_eq!(back.digest, Some(c.compute_digest()));
    assert_eq!(
        Checkpoint {
            digest: None,
            ..back.clone()
        },
        c
    );
    // What save writes is the digest and the canonical form, nothing else.
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.starts_with(r#"{"format":"sepval-ga-checkpoint/2","digest":{"sha256":""#));
    assert_eq!(
        back.digest.unwrap().sha256,
        sepval_common::scenario::hex_sha256(&c.canonical_form())
    );
}

#[test]
fn infinite_statistics_are_written_as_text_and_read_back_exactly() {
    let (job, dir) = (job(), tempfile::tempdir().unwrap());
    let c = checkpoint(&job, 2, false);
    assert!(c.state.archive.is_empty());
    for h in &c.state.history {
        assert_eq!(h.best_j_pos_m, f64::INFINITY);
        assert_eq!(h.best_j_att_deg, f64::INFINITY);
        assert_eq!(h.best_weighted, f64::INFINITY);
    }
    let path = dir.path().join("gen-0002.json");
    c.save(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains(r#""best_j_pos_m":"inf","best_j_att_deg":"inf","best_weighted":"inf""#),
        "{text}"
    );
    assert!(!text.contains(r#""best_weighted":null"#), "{text}");
    let back = Checkpoint::load(&path).unwrap();
    back.check_job(&job, &path).unwrap();
    assert_eq!(back.state.history, c.state.history);
}

#[test]
fn whitespace_key_order_and_number_spelling_do_not_matter() {
    let (job, dir) = (job(), tempfile::tempdir().unwrap());
    let path = dir.path().join("gen-0002.json");
    checkpoint(&job, 2, true).save(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    // Pretty-printed, keys in alphabetical order (serde_json's map), a number spelt otherwise.
    let v: Value = serde_json::from_str(&text).unwrap();
    let pretty = serde_json::to_string_pretty(&v)
        .unwrap()
        .replace(r#""pos_m": 0.01"#, r#""pos_m": 1.0e-2"#);
    assert!(pretty.contains("1.0e-2"));
    let other = dir.path().join("reformatted.json");
    std::fs::write(&other, pretty).unwrap();
    assert_eq!(refusal(&other, &job), None);
    assert_eq!(
        Checkpoint::load(&other).unwrap(),
        Checkpoint::load(&path).unwrap()
    );
}

#[test]
fn every_edited_value_is_refused_naming_its_part() {
    let (job, dir) = (job(), tempfile::tempdir().unwrap());
    let path = dir.path().join("gen-0003.json");
    checkpoint(&job, 3, true).save(&path).unwrap();
    let cases: Vec<(&str, JsonEdit)> = vec![
        (
            "changed: state.population[4]",
            Box::new(|v| {
                let g = &mut v["state"]["population"][4]["outcome"]["j_pos_m"];
                *g = next_up(g);
            }),
        ),
        (
            "changed: state.population[2]",
            Box::new(|v| {
                let c = &mut v["state"]["population"][2]["chromosome"];
                let mut bits = c.as_str().unwrap().to_string().into_bytes();
                bits[10] = if bits[10] == b'0' { b'1' } else { b'0' };
                *c = Value::from(String::from_utf8(bits).unwrap());
            }),
        ),
        (
            "changed: state.rng",
            Box::new(|v| {
                let p = &mut v["state"]["rng"]["word_pos"];
                let n: u128 = p.as_str().unwrap().parse().unwrap();
                *p = Value::from((n + 1).to_string());
            }),
        ),
        (
            "changed: state.archive[0]",
            Box::new(|v| {
                let g = &mut v["state"]["archive"][0]["outcome"]["j_att_deg"];
                *g = next_up(g);
            }),
        ),
        (
            "changed: state.history",
            Box::new(|v| v["state"]["history"][0]["best_j_pos_m"] = Value::from("inf")),
        ),
        (
            "changed: settings",
            Box::new(|v| v["settings"]["seed"] = Value::from(6)),
        ),
        (
            "changed: state.population[5]",
            Box::new(|v| v["state"]["population"][5]["values"][0] = Value::from(0.5)),
        ),
        (
            "gone: state.population[5]",
            Box::new(|v| {
                v["state"]["population"].as_array_mut().unwrap().pop();
            }),
        ),
        (
            "changed: digest.sha256",
            Box::new(|v| v["digest"]["sha256"] = Value::from("0".repeat(64))),
        ),
        (
            "changed: digest.parts",
            Box::new(|v| v["digest"]["parts"]["state.rng"] = Value::from("0".repeat(16))),
        ),
    ];
    for (expected, edit) in cases {
        let edited = dir.path().join("edited.json");
        edit_json(&path, &edited, edit);
        let err = refusal(&edited, &job).unwrap_or_else(|| panic!("{expected}: accepted"));
        assert!(
            err.contains(&format!(
                "checkpoint {}: its content does not match its digest: edited by hand? ({expected}",
                edited.display()
            )),
            "{expected}: {err}"
        );
    }
}

#[test]
fn earlier_formats_unread_keys_and_a_missing_digest_are_refused() {
    let (job, dir) = (job(), tempfile::tempdir().unwrap());
    let path = dir.path().join("gen-0002.json");
    checkpoint(&job, 2, true).save(&path).unwrap();
    let edited = dir.path().join("edited.json");
    let cases: Vec<(&str, JsonEdit)> = vec![
        (
            "format `sepval-ga-checkpoint/1` was written by an earlier sepval, without a digest",
            // As the earlier sepval wrote it: no digest, an infinite statistic as null.
            Box::new(|v| {
                v["format"] = Value::from(CHECKPOINT_FORMAT_1);
                v.as_object_mut().unwrap().remove("digest");
                v["state"]["history"][0]["best_weighted"] = Value::Null;
            }),
        ),
        (
            "format `sepval-ga-checkpoint/3`, this sepval reads `sepval-ga-checkpoint/2`",
            Box::new(|v| v["format"] = Value::from("sepval-ga-checkpoint/3")),
        ),
        (
            "no digest of its content (`digest`)",
            Box::new(|v| {
                v.as_object_mut().unwrap().remove("digest");
            }),
        ),
        (
            "`state.archive[1].note` is not part of a sepval checkpoint",
            Box::new(|v| v["state"]["archive"][1]["note"] = Value::from("better")),
        ),
        (
            "`comment` is not part of a sepval checkpoint",
            Box::new(|v| v["comment"] = Value::from("mine")),
        ),
    ];
    for (expected, edit) in cases {
        edit_json(&path, &edited, edit);
        let err = refusal(&edited, &job).unwrap_or_else(|| panic!("{expected}: accepted"));
        assert!(
            err.starts_with(&format!("checkpoint {}: ", edited.display()))
                && err.contains(expected),
            "{expected}: {err}"
        );
    }
}

#[test]
fn content_sealed_again_after_an_edit_meets_the_consistency_checks() {
    let (job, dir) = (job(), tempfile::tempdir().unwrap());
    let good = checkpoint(&job, 3, true);
    let path = dir.path().join("gen-0003.json");
    let last = good.state.archive.len() - 1;
    // A member of the population that is not in the archive (dominated by it).
    let free = good
        .state
        .population
        .iter()
        .position(|m| {
            !good
                .state
                .archive
                .iter()
                .any(|a| a.chromosome == m.chromosome)
        })
        .expect("a dominated member");
    let shortened = format!(
        "population member {free}: chromosome of 92 bits, the factor table's genes make 93"
    );
    let cases: Vec<(&str, Edit)> = vec![
        (
            "population member 1: its chromosome decodes to factor",
            Box::new(|c| {
                let v = &mut c.state.population[1].values[3];
                *v = f64::from_bits(v.to_bits() + 1);
            }),
        ),
        (
            "population member 2",
            Box::new(|c| {
                let bits = c.state.population[2].chromosome.bits_mut();
                bits[0] = !bits[0];
            }),
        ),
        (
            &shortened,
            Box::new(move |c| {
                let mut bits = c.state.population[free].chromosome.bits().to_vec();
                bits.pop();
                c.state.population[free].chromosome =
                    sepval_core::encoding::Chromosome::from_bits(bits);
            }),
        ),
        (
            "population member 3: goals J_pos -1 m",
            Box::new(|c| {
                c.state.population[3].outcome = Outcome::Goals {
                    j_pos_m: -1.0,
                    j_att_deg: 1.0,
                }
            }),
        ),
        (
            "population member 3: diverged in event 4, the job has 1",
            Box::new(|c| {
                c.state.population[3].outcome = Outcome::Diverged { t_s: 0.1, event: 4 };
            }),
        ),
        (
            "19 simulations recorded, but 3 generations of 6 make 18",
            Box::new(|c| c.state.evaluations += 1),
        ),
        (
            "generation 4: expected 1 to the settings' 3 generations",
            Box::new(|c| c.state.generation = 4),
        ),
        (
            "generator state (state.rng): generator seed",
            Box::new(|c| c.state.rng.seed_hex = format!("0é{}", "0".repeat(61))),
        ),
        (
            "generator state (state.rng) is not written as sepval writes it",
            Box::new(|c| c.state.rng.word_pos = format!("0{}", c.state.rng.word_pos)),
        ),
        (
            "generator state (state.rng): its key and stream are not those of the settings' seed 5",
            Box::new(|c| {
                c.state.rng = RngState {
                    word_pos: c.state.rng.word_pos.clone(),
                    ..RngState::of(&seeded(6))
                }
            }),
        ),
        (
            "archive member",
            Box::new(move |c| {
                let a = &mut c.state.archive[last];
                a.outcome = Outcome::Goals {
                    j_pos_m: 1e9,
                    j_att_deg: 1e9,
                };
            }),
        ),
        (
            "history of generation 3 (state.history): best_j_pos_m",
            Box::new(|c| c.state.history[2].best_j_pos_m *= 0.5),
        ),
        (
            "history entry 1 (state.history): generation 2 after 13 simulations",
            Box::new(|c| c.state.history[1].evaluations += 1),
        ),
        (
            "1 refinement attempt(s) (probes), but method `ga` makes none",
            Box::new(|c| {
                c.probes.push(crate::results::Probe {
                    generation: 2,
                    evaluations_before: 12,
                    evaluations: 30,
                    goals: [0.1, 0.2],
                    reached_floor: false,
                })
            }),
        ),
        (
            "method `hill`: a checkpoint is written by ga, both or ga+lm",
            Box::new(|c| c.method = "hill".into()),
        ),
        (
            "noise levels sigma_pos -0.01 m",
            Box::new(|c| c.sigma.pos_m = -0.01),
        ),
        (
            "data_sha256 `abc` is not a SHA-256",
            Box::new(|c| c.data_sha256 = "abc".into()),
        ),
    ];
    for (expected, edit) in cases {
        let mut c = good.clone();
        edit(&mut c);
        c.save(&path).unwrap();
        let err = refusal(&path, &job).unwrap_or_else(|| panic!("{expected}: accepted"));
        assert!(
            err.starts_with(&format!("checkpoint {}: ", path.display())) && err.contains(expected),
            "{expected}: {err}"
        );
    }
    good.save(&path).unwrap();
    assert_eq!(refusal(&path, &job), None);
}

#[test]
fn probes_of_ga_lm_must_count_their_simulations() {
    let (job, dir) = (job(), tempfile::tempdir().unwrap());
    let mut c = checkpoint(&job, 3, true);
    c.method = "ga+lm".into();
    let probe = |generation, evaluations_before| crate::results::Probe {
        generation,
        evaluations_before,
        evaluations: 30,
        goals: [0.1, 0.2],
        reached_floor: false,
    };
    let path = dir.path().join("gen-0003.json");
    c.probes = vec![probe(1, 6), probe(3, 48)];
    c.save(&path).unwrap();
    assert_eq!(refusal(&path, &job), None);
    c.probes = vec![probe(1, 6), probe(3, 18)];
    c.save(&path).unwrap();
    let err = refusal(&path, &job).unwrap();
    assert!(
        err.contains(
            "probe 1: 18 simulations before it recorded, the generations and earlier probes make 48"
        ),
        "{err}"
    );
}

/// Counts are compared exactly, never after wrapping (found by the property
/// `checkpoint_probes_sealed` of the cli tests: an attempt of 2^64 - 2 simulations made the next
/// one's count wrap to 2, and the checkpoint was accepted; in a debug build it panicked).
#[test]
fn counts_that_overflow_are_refused_not_wrapped() {
    let (job, dir) = (job(), tempfile::tempdir().unwrap());
    let path = dir.path().join("gen-0003.json");
    let mut c = checkpoint(&job, 3, true);
    c.method = "ga+lm".into();
    let probe = |generation, evaluations_before, evaluations| crate::results::Probe {
        generation,
        evaluations_before,
        evaluations,
        goals: [0.1, 0.2],
        reached_floor: false,
    };
    c.probes = vec![probe(0, 0, u64::MAX - 1), probe(1, 4, 0)];
    c.save(&path).unwrap();
    let err = refusal(&path, &job).unwrap();
    assert!(
        err.contains(
            "probe 1: 4 simulations before it recorded, the generations and earlier probes make \
             18446744073709551620"
        ),
        "{err}"
    );
    // Generations beyond the search's limit (sepval_solve::ga::MAX_GENERATIONS) are refused
    // as a setting, before any count is made of them.
    let mut c = checkpoint(&job, 3, true);
    c.settings.generations = usize::MAX;
    c.save(&path).unwrap();
    let err = refusal(&path, &job).unwrap();
    assert!(
        err.contains("expected at most 100000 (MAX_GENERATIONS)"),
        "{err}"
    );
    // A generation whose count of simulations would wrap is past the settings' generations,
    // which the limit above keeps at most 100 000: refused as such.
    let mut c = checkpoint(&job, 3, true);
    c.state.generation = 1 << 63;
    c.state.evaluations = 0;
    c.save(&path).unwrap();
    let err = refusal(&path, &job).unwrap();
    assert!(
        err.contains("generation 9223372036854775808: expected 1 to the settings' 3 generations"),
        "{err}"
    );
}

#[test]
fn previous_path_is_the_generation_before_in_the_same_directory() {
    let c = checkpoint(&job(), 2, false);
    assert_eq!(
        c.previous_path(Path::new("run/generations/edited.json")),
        Some(PathBuf::from("run/generations/gen-0001.json"))
    );
    let mut first = c.clone();
    first.state.generation = 1;
    assert_eq!(first.previous_path(Path::new("gen-0001.json")), None);
}
