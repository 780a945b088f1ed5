//! Edited checkpoints against `sepval fit --resume` and `sepval rerun`: an edit by hand is
//! refused by the digest, naming the part edited; an edit sealed again with a matching digest
//! (who knows the rule can write one) meets the consistency checks, the re-evaluation of the
//! population and archive and the replay of the generation. An unedited checkpoint is used
//! whatever its layout.

use std::path::{Path, PathBuf};

use sepval_fit::checkpoint::Checkpoint;
use sepval_tests::{deterministic_part, ok, sepval};
use serde_json::Value;

/// `fit --method ga --generations G --population 10` in `dir/out`, in-process.
fn small_fit(dir: &Path, generations: &str, out: &str) {
    ok(&sepval(
        &[
            "fit",
            "--method",
            "ga",
            "--generations",
            generations,
            "--population",
            "10",
            "--evaluator",
            "inproc",
            "--no-figures",
            "--out",
            out,
        ],
        dir,
    ));
}

/// The run's generation-3 checkpoint, relative to `dir`.
const GEN3: &str = "r/generations/gen-0003.json";

/// `GEN3` edited as JSON text, written beside it as `NAME.json` (so that generation 2's
/// checkpoint is its previous one); its path relative to `dir`.
fn edit_by_hand(dir: &Path, name: &str, edit: impl FnOnce(&mut Value)) -> String {
    let mut v: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join(GEN3)).unwrap()).unwrap();
    edit(&mut v);
    let path = format!("r/generations/{name}.json");
    std::fs::write(dir.join(&path), serde_json::to_string(&v).unwrap()).unwrap();
    path
}

/// `GEN3` edited as a checkpoint and sealed again (saved with the digest of the edited content),
/// written beside it as `NAME.json`; its path relative to `dir`.
fn edit_and_seal(dir: &Path, name: &str, edit: impl FnOnce(&mut Checkpoint)) -> String {
    let mut c: Checkpoint =
        serde_json::from_str(&std::fs::read_to_string(dir.join(GEN3)).unwrap()).unwrap();
    edit(&mut c);
    let path = format!("r/generations/{name}.json");
    c.save(&dir.join(&path)).unwrap();
    path
}

/// An edit of a checkpoint's JSON.
type JsonEdit = Box<dyn FnOnce(&mut Value)>;

/// The next f64 up.
fn up(x: f64) -> f64 {
    f64::from_bits(x.to_bits() + 1)
}

/// `rerun CKPT` and `fit --resume CKPT` both exit with status 2 and print every `expected`
/// (stdout and stderr together); returns what each printed.
fn both_refuse(dir: &Path, ckpt: &str, expected: &[&str]) -> [String; 2] {
    let out = format!("resumed-{}", ckpt.replace('/', "-"));
    let runs = [
        vec!["rerun", ckpt, "--evaluator", "inproc"],
        vec![
            "fit",
            "--resume",
            ckpt,
            "--generations",
            "4",
            "--evaluator",
            "inproc",
            "--no-figures",
            "--out",
            &out,
        ],
    ];
    runs.map(|args| {
        let o = sepval(&args, dir);
        let all = format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        assert_eq!(o.status.code(), Some(2), "{args:?}: {all}");
        for e in expected {
            assert!(all.contains(e), "{args:?}: expected {e:?} in\n{all}");
        }
        assert!(!dir.join(&out).join("result.json").exists(), "{args:?}");
        all
    })
}

#[test]
fn a_checkpoint_edited_by_hand_is_refused_naming_what_was_edited() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    small_fit(dir, "3", "r");
    let cases: Vec<(&str, &str, JsonEdit)> = vec![
        (
            "goal",
            "changed: state.population[4]",
            Box::new(|v| {
                let g = &mut v["state"]["population"][4]["outcome"]["j_pos_m"];
                *g = Value::from(up(g.as_f64().unwrap()));
            }),
        ),
        (
            "bit",
            "changed: state.population[4]",
            Box::new(|v| {
                let c = &mut v["state"]["population"][4]["chromosome"];
                let mut bits = c.as_str().unwrap().as_bytes().to_vec();
                bits[7] ^= b'0' ^ b'1';
                *c = Value::from(String::from_utf8(bits).unwrap());
            }),
        ),
        (
            "word-pos",
            "changed: state.rng",
            Box::new(|v| {
                let p = &mut v["state"]["rng"]["word_pos"];
                let n: u128 = p.as_str().unwrap().parse().unwrap();
                *p = Value::from((n + 1).to_string());
            }),
        ),
        (
            "archive-goal",
            "changed: state.archive[2]",
            Box::new(|v| {
                let g = &mut v["state"]["archive"][2]["outcome"]["j_att_deg"];
                *g = Value::from(up(g.as_f64().unwrap()));
            }),
        ),
        (
            "infinite-stat",
            "changed: state.history",
            Box::new(|v| v["state"]["history"][0]["best_j_att_deg"] = Value::from("inf")),
        ),
    ];
    for (name, what, edit) in cases {
        let ckpt = edit_by_hand(dir, name, edit);
        let message = format!(
            "checkpoint {ckpt}: its content does not match its digest: edited by hand? ({what})"
        );
        both_refuse(dir, &ckpt, &[&message]);
    }
}

#[test]
fn an_edit_sealed_again_is_caught_by_the_checks_the_reevaluation_or_the_replay() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    small_fit(dir, "3", "r");
    let gen3: Checkpoint =
        serde_json::from_str(&std::fs::read_to_string(dir.join(GEN3)).unwrap()).unwrap();
    let (population, archive) = (&gen3.state.population, &gen3.state.archive);
    let in_archive =
        |m: &sepval_solve::ga::Member| archive.iter().any(|a| a.chromosome == m.chromosome);
    let previous = "the previous generation's checkpoint r/generations/gen-0002.json";

    // A population goal one ulp worse: still dominated, so consistent; the re-evaluation and
    // the replay see it.
    // (Nor the population's best in either goal or weighted, which the history records.)
    let min = |k: usize| {
        population
            .iter()
            .map(|m| m.objectives()[k])
            .fold(f64::INFINITY, f64::min)
    };
    let best = gen3
        .state
        .best(gen3.sigma.weights())
        .unwrap()
        .chromosome
        .clone();
    let i = population
        .iter()
        .position(|m| {
            let o = m.objectives();
            m.outcome.goals().is_some()
                && !in_archive(m)
                && o[0] > min(0)
                && o[1] > min(1)
                && m.chromosome != best
        })
        .expect("a finished member outside the archive");
    let ckpt = edit_and_seal(dir, "sealed-goal", |c| {
        if let sepval_common::evaluation::Outcome::Goals { j_pos_m, .. } =
            &mut c.state.population[i].outcome
        {
            *j_pos_m = up(*j_pos_m);
        }
    });
    let n = archive.len();
    let failures = format!(
        "generation 3: 1 of 10 population members and 0 of {n} archive members do not \
         reproduce their goals bit for bit (population member {i})"
    );
    let [rerun, fit] = both_refuse(
        dir,
        &ckpt,
        &[
            &failures,
            &format!("replayed from {previous}, its state differs in state.population[{i}]"),
        ],
    );
    assert!(
        rerun.contains(&format!("population member {i}: saved Goals")),
        "{rerun}"
    );
    assert!(
        fit.contains(&format!("checkpoint {ckpt} does not reproduce: {failures}")),
        "{fit}"
    );

    // A flipped chromosome bit: the chromosome no longer decodes to the recorded values (or
    // the member is no longer in the archive nor dominated by it).
    let ckpt = edit_and_seal(dir, "sealed-bit", |c| {
        let bits = c.state.population[i].chromosome.bits_mut();
        bits[0] = !bits[0];
    });
    both_refuse(
        dir,
        &ckpt,
        &[&format!("checkpoint {ckpt}: population member {i}")],
    );

    // The generator one word on: only the replay from generation 2 sees it.
    let ckpt = edit_and_seal(dir, "sealed-word-pos", |c| {
        let n: u128 = c.state.rng.word_pos.parse().unwrap();
        c.state.rng.word_pos = (n + 1).to_string();
    });
    both_refuse(
        dir,
        &ckpt,
        &[&format!(
            "generation 3: replayed from {previous}, its state differs in state.rng"
        )],
    );

    // An archive goal one ulp better: the re-evaluation of the archive sees it (or the
    // population member with its chromosome does).
    let j = archive.len() - 1;
    let ckpt = edit_and_seal(dir, "sealed-archive-goal", |c| {
        if let sepval_common::evaluation::Outcome::Goals { j_att_deg, .. } =
            &mut c.state.archive[j].outcome
        {
            *j_att_deg = f64::from_bits(j_att_deg.to_bits() - 1);
        }
    });
    both_refuse(dir, &ckpt, &[&format!("archive member {j}")]);

    // An infinite statistic reads back (it is not "not a sepval checkpoint"); the replay finds
    // that generation 1 had finished members.
    let ckpt = edit_and_seal(dir, "sealed-infinite-stat", |c| {
        c.state.history[0].best_j_pos_m = f64::INFINITY;
    });
    assert!(
        std::fs::read_to_string(dir.join(&ckpt))
            .unwrap()
            .contains(r#""best_j_pos_m":"inf""#)
    );
    let [rerun, _] = both_refuse(
        dir,
        &ckpt,
        &[&format!(
            "generation 3: replayed from {previous}, its state differs in state.history"
        )],
    );
    assert!(!rerun.contains("not a sepval checkpoint"), "{rerun}");
}

#[test]
fn checkpoints_of_the_earlier_format_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    small_fit(dir, "3", "r");
    let ckpt = edit_by_hand(dir, "format-1", |v| {
        v["format"] = Value::from("sepval-ga-checkpoint/1");
        v.as_object_mut().unwrap().remove("digest");
    });
    both_refuse(
        dir,
        &ckpt,
        &[&format!(
            "checkpoint {ckpt}: format `sepval-ga-checkpoint/1` was written by an earlier \
             sepval, without a digest of its content, so an edit to it cannot be detected"
        )],
    );
}

#[test]
fn an_unedited_checkpoint_is_used_whatever_its_layout() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    small_fit(dir, "3", "r");
    small_fit(dir, "4", "uninterrupted");
    // Pretty-printed with its keys in alphabetical order (serde_json's map): a hand edit that
    // changes no value.
    let v: Value = serde_json::from_str(&std::fs::read_to_string(dir.join(GEN3)).unwrap()).unwrap();
    let ckpt: PathBuf = dir.join("r/generations/reformatted.json");
    std::fs::write(&ckpt, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let ckpt = ckpt.strip_prefix(dir).unwrap().to_str().unwrap();
    let out = ok(&sepval(&["rerun", ckpt, "--evaluator", "inproc"], dir));
    assert!(
        out.contains("generation 3: all 10 population and")
            && out.contains("archive members reproduce their goals bit for bit")
            && out.contains(
                "replaying it from the previous generation's checkpoint \
                 r/generations/gen-0002.json gives the same state"
            ),
        "{out}"
    );
    ok(&sepval(
        &[
            "fit",
            "--resume",
            ckpt,
            "--generations",
            "4",
            "--evaluator",
            "inproc",
            "--no-figures",
            "--out",
            "resumed",
        ],
        dir,
    ));
    assert_eq!(
        deterministic_part(&dir.join("uninterrupted/result.json")),
        deterministic_part(&dir.join("resumed/result.json"))
    );
    // Alone, it is re-evaluated but not replayed, and says so.
    std::fs::create_dir(dir.join("alone")).unwrap();
    std::fs::copy(dir.join(GEN3), dir.join("alone/gen-0003.json")).unwrap();
    let out = ok(&sepval(
        &["rerun", "alone/gen-0003.json", "--evaluator", "inproc"],
        dir,
    ));
    assert!(
        out.contains(
            "not replayed: the previous generation's checkpoint alone/gen-0002.json is not there"
        ),
        "{out}"
    );
    // Generation 1 is replayed from the seed.
    let out = ok(&sepval(
        &[
            "rerun",
            "r/generations/gen-0001.json",
            "--evaluator",
            "inproc",
        ],
        dir,
    ));
    assert!(
        out.contains("replaying it from the settings' seed gives the same state"),
        "{out}"
    );
}
