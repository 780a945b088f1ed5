//! Property-based hardening of the checkpoint reader, [`Checkpoint::load`] (and of
//! [`Checkpoint::check_job`] on what it reads), on files of arbitrary bytes and on structured
//! mutations of a real checkpoint: the generation-2 checkpoint of a small fit
//! (`sepval fit --method ga --generations 2 --population 4 --evaluator inproc`, run once).
//!
//! Three kinds of mutations, from the surface inwards: the file's text edited as bytes (bytes,
//! lines, JSON syntax, numbers replaced by huge, non-finite, negative or malformed ones), which
//! the digest refuses; its JSON edited node by node (values replaced, keys removed or added,
//! array elements repeated, dropped or swapped), sealed again with a matching digest whenever it
//! still reads as a checkpoint; and the checkpoint value edited field by field (counts,
//! generator state, outcomes, chromosomes, archive, history, refinement attempts set to hostile
//! values) and saved, so sealed. The sealed ones reach the consistency checks. Every load must
//! return, `Ok` or an error with a message, without a panic, within
//! [`MAX_CALL`](sepval_tests::fuzz::MAX_CALL), and without any single allocation beyond a small
//! multiple of the file's size (this test binary counts allocations). A checkpoint loaded must
//! be consistent in exact arithmetic (counts of generations, simulations and refinement
//! attempts), load again the same after being saved, and check against the job without a panic.
//!
//! The cases are bounded (a few seconds in all) and drawn from a fixed seed; run more, or
//! others, with `PROPTEST_CASES=5000 PROPTEST_RNG_SEED=7 cargo test --release -p
//! sepval --test cli fuzz`.

use std::sync::LazyLock;

use proptest::prelude::*;
use proptest::sample::select;
use proptest::test_runner::TestCaseError;
use sepval_common::evaluation::{Job, Outcome};
use sepval_common::scenario::Scenario;
use sepval_common::synthetic::default_flight_test;
use sepval_core::encoding::Chromosome;
use sepval_fit::checkpoint::{CHECKPOINT_FORMAT, CHECKPOINT_FORMAT_1, Checkpoint};
use sepval_fit::results::Probe;
use sepval_solve::ga::{GaState, GenerationStats, Member};
use sepval_tests::fuzz::{
    At, CountingAllocator, Edit, apply, at, check_cost, check_typed, config, edits, length_value,
    measure, number_text, text_edit,
};
use sepval_tests::{ok, sepval};
use serde_json::Value;

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

/// Largest single allocation loading `len` bytes may make: the text, its canonical form and
/// what it holds, a few times over, and a little more.
fn max_allocation(len: usize) -> usize {
    16 * len + (64 << 10)
}

/// The generation-2 checkpoint of a small fit, as its file holds it.
static BASE: LazyLock<String> = LazyLock::new(|| {
    let dir = tempfile::tempdir().expect("a temporary directory");
    ok(&sepval(
        &[
            "fit",
            "--method",
            "ga",
            "--generations",
            "2",
            "--population",
            "4",
            "--evaluator",
            "inproc",
            "--no-figures",
            "--out",
            "r",
        ],
        dir.path(),
    ));
    std::fs::read_to_string(Checkpoint::path(&dir.path().join("r"), 2)).expect("a checkpoint")
});

/// The base checkpoint, read.
static CHECKPOINT: LazyLock<Checkpoint> =
    LazyLock::new(|| serde_json::from_str(&BASE).expect("the base reads"));

/// The job the base was made with (the embedded default flight test).
static JOB: LazyLock<Job> = LazyLock::new(|| {
    Job::single(
        "embedded default synthetic flight test",
        &Scenario::embedded_default(),
        default_flight_test(),
    )
});

/// What a loaded checkpoint promises, in exact arithmetic.
fn check_consistent(c: &Checkpoint) -> Result<(), TestCaseError> {
    let (s, st) = (&c.settings, &c.state);
    let pop = s.population as u128;
    prop_assert!(c.digest.is_some());
    prop_assert!(st.generation >= 1 && st.generation <= s.generations);
    prop_assert_eq!(st.population.len(), s.population);
    prop_assert_eq!(u128::from(st.evaluations), st.generation as u128 * pop);
    prop_assert_eq!(st.history.len(), st.generation);
    let mut probed = 0u128;
    for p in &c.probes {
        prop_assert!(p.generation <= st.generation);
        prop_assert_eq!(
            u128::from(p.evaluations_before),
            p.generation as u128 * pop + probed
        );
        probed += u128::from(p.evaluations);
    }
    Ok(())
}

/// Writes `bytes` as a checkpoint file, loads it and checks every property.
fn load(bytes: &[u8]) -> Result<(), TestCaseError> {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = dir.path().join("gen-0002.json");
    std::fs::write(&path, bytes).expect("write the checkpoint");
    let (result, cost) = measure(|| Checkpoint::load(&path));
    check_cost("Checkpoint::load", cost, max_allocation(bytes.len()))?;
    check_typed("Checkpoint::load", &result)?;
    if let Ok(c) = &result {
        check_consistent(c)?;
        let again = dir.path().join("again.json");
        c.save(&again).expect("save");
        let back = Checkpoint::load(&again).ok();
        prop_assert_eq!(back.as_ref(), Some(c));
        let (checked, cost) = measure(|| c.check_job(&JOB, &path));
        check_cost("Checkpoint::check_job", cost, max_allocation(bytes.len()))?;
        check_typed("Checkpoint::check_job", &checked)?;
    }
    Ok(())
}

/// The JSON syntax, where the parser and the checkpoint's readers decide.
const JSON_TOKENS: &[&str] = &[
    "{",
    "}",
    "[",
    "]",
    ",",
    ":",
    "\"",
    "\\",
    "\\u0000",
    "\\ud800",
    "null",
    "true",
    "\"inf\"",
    "\"nan\"",
    "\"note\": 1,",
    "\"digest\": null,",
    " ",
    "\n",
    "é",
    "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[",
];

/// A JSON value that a checkpoint's field may be replaced by.
fn hostile_json() -> BoxedStrategy<Value> {
    const TEXTS: &[&str] = &[
        "",
        "inf",
        "-inf",
        "nan",
        "ga",
        "ga+lm",
        "both",
        "hill",
        CHECKPOINT_FORMAT_1,
        CHECKPOINT_FORMAT,
        "goals",
        "diverged",
        "failed",
        "0101",
        "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef",
        "0123456789ABCDEF0123456789ABCDEF0123456789ABCDEF0123456789ABCDEF",
        "+123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef",
        "0é23456789abcdef0123456789abcdef0123456789abcdef0123456789abcde",
        "-1",
        "+7",
        "٣",
        "340282366920938463463374607431768211455",
        "340282366920938463463374607431768211456",
    ];
    prop_oneof![
        Just(Value::Null),
        any::<bool>().prop_map(Value::from),
        length_value().prop_map(Value::from),
        any::<i64>().prop_map(Value::from),
        any::<f64>().prop_map(Value::from),
        select(TEXTS).prop_map(Value::from),
        (select(TEXTS), 1..300usize).prop_map(|(t, n)| Value::from(t.repeat(n))),
        Just(Value::Array(Vec::new())),
        Just(Value::Object(serde_json::Map::new())),
        (1..200usize)
            .prop_map(|depth| { (0..depth).fold(Value::from(1), |v, _| Value::Array(vec![v])) }),
    ]
    .boxed()
}

/// An edit of the checkpoint's JSON, node by node.
#[derive(Debug, Clone)]
enum JsonEdit {
    /// Replaces a node.
    Replace(At, Value),
    /// Removes a node from its object or array.
    Remove(At),
    /// Adds a key to an object.
    AddKey(At, String, Value),
    /// Repeats an array element.
    Repeat(At),
    /// Swaps two elements of an array.
    Swap(At, At),
}

fn json_edit() -> BoxedStrategy<JsonEdit> {
    let key = prop_oneof![
        Just("note".to_string()),
        Just("digest".to_string()),
        select(&["generation", "evaluations", "probes", "status", "reason"][..])
            .prop_map(String::from),
    ];
    prop_oneof![
        4 => (at(), hostile_json()).prop_map(|(i, v)| JsonEdit::Replace(i, v)),
        1 => at().prop_map(JsonEdit::Remove),
        1 => (at(), key, hostile_json()).prop_map(|(i, k, v)| JsonEdit::AddKey(i, k, v)),
        1 => at().prop_map(JsonEdit::Repeat),
        1 => (at(), at()).prop_map(|(a, b)| JsonEdit::Swap(a, b)),
    ]
    .boxed()
}

/// The JSON pointers of every node of `v` but the root, depth first.
fn pointers(v: &Value, here: &str, out: &mut Vec<String>) {
    let children: Vec<(String, &Value)> = match v {
        Value::Object(m) => m
            .iter()
            .map(|(k, c)| {
                (
                    format!("{here}/{}", k.replace('~', "~0").replace('/', "~1")),
                    c,
                )
            })
            .collect(),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .map(|(i, c)| (format!("{here}/{i}"), c))
            .collect(),
        _ => Vec::new(),
    };
    for (p, c) in children {
        out.push(p.clone());
        pointers(c, &p, out);
    }
}

/// The pointer of a node's parent and the node's key in it.
fn split(pointer: &str) -> (&str, &str) {
    pointer.rsplit_once('/').expect("not the root")
}

/// `v` after `edit`.
fn edit_json(v: &mut Value, edit: &JsonEdit) {
    let mut all = Vec::new();
    pointers(v, "", &mut all);
    if all.is_empty() {
        return;
    }
    let pick = |i: &At| all[i.of(all.len())].clone();
    match edit {
        JsonEdit::Replace(i, new) => {
            if let Some(node) = v.pointer_mut(&pick(i)) {
                *node = new.clone();
            }
        }
        JsonEdit::Remove(i) => {
            let p = pick(i);
            let (parent, key) = split(&p);
            match v.pointer_mut(parent) {
                Some(Value::Object(m)) => {
                    m.remove(&key.replace("~1", "/").replace("~0", "~"));
                }
                Some(Value::Array(a)) => {
                    if let Ok(k) = key.parse::<usize>() {
                        a.remove(k);
                    }
                }
                _ => {}
            }
        }
        JsonEdit::AddKey(i, key, new) => {
            let p = pick(i);
            let (parent, _) = split(&p);
            if let Some(Value::Object(m)) = v.pointer_mut(parent) {
                m.insert(key.clone(), new.clone());
            }
        }
        JsonEdit::Repeat(i) | JsonEdit::Swap(i, _) => {
            let p = pick(i);
            let (parent, key) = split(&p);
            if let (Some(Value::Array(a)), Ok(k)) = (v.pointer_mut(parent), key.parse::<usize>()) {
                match edit {
                    JsonEdit::Swap(_, j) => {
                        let j = j.of(a.len());
                        a.swap(k, j);
                    }
                    _ => {
                        let e = a[k].clone();
                        a.insert(k, e);
                    }
                }
            }
        }
    }
}

/// The file of `v`, sealed with the digest of what it reads as, when it reads as a checkpoint.
fn sealed_json(mut v: Value) -> Vec<u8> {
    if let Ok(c) = serde_json::from_value::<Checkpoint>(v.clone()) {
        if let Value::Object(m) = &mut v {
            m.insert(
                "digest".into(),
                serde_json::to_value(c.compute_digest()).expect("a digest serialises"),
            );
        }
    }
    serde_json::to_vec_pretty(&v).expect("JSON serialises")
}

/// A double that a checkpoint's field may be set to.
fn hostile_f64() -> BoxedStrategy<f64> {
    const EDGES: &[f64] = &[
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::MAX,
        f64::MIN_POSITIVE,
        -0.0,
        0.0,
        -1.0,
        0.5,
        1.0,
        1e308,
    ];
    prop_oneof![2 => select(EDGES), 1 => any::<f64>()].boxed()
}

/// An outcome that a member may be given.
fn hostile_outcome() -> BoxedStrategy<Outcome> {
    prop_oneof![
        (hostile_f64(), hostile_f64())
            .prop_map(|(j_pos_m, j_att_deg)| Outcome::Goals { j_pos_m, j_att_deg }),
        (hostile_f64(), prop_oneof![0..3usize, any::<usize>()])
            .prop_map(|(t_s, event)| Outcome::Diverged { t_s, event }),
        (".{0,300}").prop_map(|reason| Outcome::Failed { reason }),
    ]
    .boxed()
}

/// An edit of the checkpoint value, field by field.
#[derive(Debug, Clone)]
enum Field {
    Generation(u64),
    Generations(u64),
    Population(u64),
    Evaluations(u64),
    Seed(u64),
    Probability(usize, f64),
    Sigma(f64, f64),
    Hill(usize, f64),
    Method(&'static str),
    SeedHex(String),
    Stream(u64),
    WordPos(String),
    Outcome(bool, At, Outcome),
    FlipBit(bool, At, At),
    Chromosome(bool, At, Vec<bool>),
    Value(bool, At, f64),
    DropValue(bool, At),
    RepeatMember(bool, At),
    RemoveMember(bool, At),
    SwapMembers(bool, At, At),
    ToArchive(At),
    History(At, usize, f64, u64),
    RepeatHistory(At),
    RemoveHistory(At),
    /// Refinement attempts (method ga+lm), consistent up to `evaluations` of each.
    Probes(Vec<(At, u64, [f64; 2])>),
    /// One refinement attempt of any counts.
    Probe(u64, u64, u64),
}

fn field() -> BoxedStrategy<Field> {
    const METHODS: &[&str] = &["ga", "ga+lm", "both", "hill", "hill+lm", "", "GA"];
    let count = || prop_oneof![3 => 0..8u64, 1 => length_value()];
    let member = || (any::<bool>(), at());
    prop_oneof![
        count().prop_map(Field::Generation),
        count().prop_map(Field::Generations),
        count().prop_map(Field::Population),
        count().prop_map(Field::Evaluations),
        any::<u64>().prop_map(Field::Seed),
        (0..3usize, hostile_f64()).prop_map(|(k, v)| Field::Probability(k, v)),
        (hostile_f64(), hostile_f64()).prop_map(|(p, a)| Field::Sigma(p, a)),
        (0..3usize, hostile_f64()).prop_map(|(k, v)| Field::Hill(k, v)),
        select(METHODS).prop_map(Field::Method),
        prop_oneof!["[0-9a-fA-F+é-]{60,66}", ".{0,70}"].prop_map(Field::SeedHex),
        any::<u64>().prop_map(Field::Stream),
        prop_oneof![
            "[0-9+ -]{0,45}",
            ".{0,10}",
            any::<u128>().prop_map(|v| v.to_string())
        ]
        .prop_map(Field::WordPos),
        (member(), hostile_outcome()).prop_map(|((a, i), o)| Field::Outcome(a, i, o)),
        (member(), at()).prop_map(|((a, i), b)| Field::FlipBit(a, i, b)),
        (member(), prop::collection::vec(any::<bool>(), 0..200))
            .prop_map(|((a, i), bits)| Field::Chromosome(a, i, bits)),
        (member(), hostile_f64()).prop_map(|((a, i), v)| Field::Value(a, i, v)),
        member().prop_map(|(a, i)| Field::DropValue(a, i)),
        member().prop_map(|(a, i)| Field::RepeatMember(a, i)),
        member().prop_map(|(a, i)| Field::RemoveMember(a, i)),
        (member(), at()).prop_map(|((a, i), j)| Field::SwapMembers(a, i, j)),
        at().prop_map(Field::ToArchive),
        (at(), 0..5usize, hostile_f64(), count())
            .prop_map(|(i, k, v, n)| Field::History(i, k, v, n)),
        at().prop_map(Field::RepeatHistory),
        at().prop_map(Field::RemoveHistory),
        prop::collection::vec(
            (
                at(),
                prop_oneof![0..50u64, length_value()],
                prop::array::uniform2(hostile_f64())
            ),
            1..4
        )
        .prop_map(Field::Probes),
        (count(), count(), count()).prop_map(|(g, b, e)| Field::Probe(g, b, e)),
    ]
    .boxed()
}

/// The archive's members, or the population's.
fn members(st: &mut GaState, archive: bool) -> &mut Vec<Member> {
    if archive {
        &mut st.archive
    } else {
        &mut st.population
    }
}

/// `c` after `edit`.
fn edit_checkpoint(c: &mut Checkpoint, edit: &Field) {
    let st = &mut c.state;
    match edit.clone() {
        Field::Generation(g) => st.generation = g as usize,
        Field::Generations(g) => c.settings.generations = g as usize,
        Field::Population(p) => c.settings.population = p as usize,
        Field::Evaluations(e) => st.evaluations = e,
        Field::Seed(s) => c.settings.seed = s,
        Field::Probability(k, v) => {
            *[
                &mut c.settings.p_crossover,
                &mut c.settings.p_jump,
                &mut c.settings.p_creep,
            ][k] = v;
        }
        Field::Sigma(p, a) => {
            c.sigma.pos_m = p;
            c.sigma.att_deg = a;
        }
        Field::Hill(k, v) => {
            *[
                &mut c.hill.fd_step,
                &mut c.hill.initial_step,
                &mut c.hill.min_step,
            ][k] = v;
        }
        Field::Method(m) => c.method = m.to_string(),
        Field::SeedHex(s) => st.rng.seed_hex = s,
        Field::Stream(s) => st.rng.stream = s,
        Field::WordPos(p) => st.rng.word_pos = p,
        Field::Outcome(a, i, o) => {
            let ms = members(st, a);
            if !ms.is_empty() {
                let k = i.of(ms.len());
                ms[k].outcome = o;
            }
        }
        Field::FlipBit(a, i, b) => {
            let ms = members(st, a);
            if !ms.is_empty() {
                let k = i.of(ms.len());
                let mut bits = ms[k].chromosome.bits().to_vec();
                if !bits.is_empty() {
                    let j = b.of(bits.len());
                    bits[j] = !bits[j];
                }
                ms[k].chromosome = Chromosome::from_bits(bits);
            }
        }
        Field::Chromosome(a, i, bits) => {
            let ms = members(st, a);
            if !ms.is_empty() {
                let k = i.of(ms.len());
                ms[k].chromosome = Chromosome::from_bits(bits);
            }
        }
        Field::Value(a, i, v) => {
            let ms = members(st, a);
            if !ms.is_empty() {
                let k = i.of(ms.len());
                let values = &mut ms[k].values;
                let j = i.of(values.len());
                match values.get_mut(j) {
                    Some(x) => *x = v,
                    None => values.push(v),
                }
            }
        }
        Field::DropValue(a, i) => {
            let ms = members(st, a);
            if !ms.is_empty() {
                let k = i.of(ms.len());
                ms[k].values.pop();
            }
        }
        Field::RepeatMember(a, i) => {
            let ms = members(st, a);
            if !ms.is_empty() {
                let k = i.of(ms.len());
                ms.insert(k, ms[k].clone());
            }
        }
        Field::RemoveMember(a, i) => {
            let ms = members(st, a);
            if !ms.is_empty() {
                let k = i.of(ms.len());
                ms.remove(k);
            }
        }
        Field::SwapMembers(a, i, j) => {
            let ms = members(st, a);
            if !ms.is_empty() {
                let (x, y) = (i.of(ms.len()), j.of(ms.len()));
                ms.swap(x, y);
            }
        }
        Field::ToArchive(i) => {
            if !st.population.is_empty() {
                let k = i.of(st.population.len());
                st.archive.push(st.population[k].clone());
            }
        }
        Field::History(i, k, v, n) => {
            if !st.history.is_empty() {
                let j = i.of(st.history.len());
                let h: &mut GenerationStats = &mut st.history[j];
                match k {
                    0 => h.best_j_pos_m = v,
                    1 => h.best_j_att_deg = v,
                    2 => h.best_weighted = v,
                    3 => h.generation = n as usize,
                    _ => h.evaluations = n,
                }
            }
        }
        Field::RepeatHistory(i) => {
            if !st.history.is_empty() {
                let j = i.of(st.history.len());
                st.history.insert(j, st.history[j].clone());
            }
        }
        Field::RemoveHistory(i) => {
            if !st.history.is_empty() {
                let j = i.of(st.history.len());
                st.history.remove(j);
            }
        }
        Field::Probes(probes) => {
            c.method = "ga+lm".into();
            let pop = c.settings.population as u64;
            let (mut probed, mut generation) = (0u64, 0usize);
            for (g, evaluations, goals) in probes {
                generation = generation.max(g.of(st.generation + 1));
                c.probes.push(Probe {
                    generation,
                    // What a sepval that wraps its sums computes.
                    evaluations_before: (generation as u64).wrapping_mul(pop).wrapping_add(probed),
                    evaluations,
                    goals,
                    reached_floor: false,
                });
                probed = probed.wrapping_add(evaluations);
            }
        }
        Field::Probe(generation, evaluations_before, evaluations) => c.probes.push(Probe {
            generation: generation as usize,
            evaluations_before,
            evaluations,
            goals: [0.1, 0.2],
            reached_floor: false,
        }),
    }
}

/// Loads `c` saved (so sealed with its digest) and checks every property.
fn load_sealed(c: &Checkpoint) -> Result<(), TestCaseError> {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = dir.path().join("sealed.json");
    c.save(&path).expect("save");
    load(&std::fs::read(&path).expect("read back"))
}

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn checkpoint_arbitrary_bytes(bytes in prop_oneof![
        prop::collection::vec(any::<u8>(), 0..2000),
        "[{}\\[\\]\":, 0-9a-z.]{0,2000}".prop_map(String::into_bytes),
    ]) {
        load(&bytes)?;
    }

    #[test]
    fn checkpoint_text_mutations(e in edits(text_edit(JSON_TOKENS), 6)) {
        load(&apply(BASE.as_bytes(), &e, &[]))?;
    }

}

proptest! {
    #![proptest_config(config(512))]

    #[test]
    fn checkpoint_json_mutations_sealed(e in prop::collection::vec(json_edit(), 1..4)) {
        let mut v: Value = serde_json::from_str(&BASE).expect("the base is JSON");
        for edit in &e {
            edit_json(&mut v, edit);
        }
        load(&sealed_json(v))?;
    }

    #[test]
    fn checkpoint_numbers_sealed(e in prop::collection::vec((at(), number_text()), 1..3)) {
        // Numbers of the text replaced, then the file sealed again if it still reads.
        let edits: Vec<Edit> = e.into_iter().map(|(i, t)| Edit::ReplaceNumber(i, t)).collect();
        let text = apply(BASE.as_bytes(), &edits, &[]);
        match serde_json::from_slice::<Value>(&text) {
            Ok(v) => load(&sealed_json(v))?,
            Err(_) => load(&text)?,
        }
    }

    /// Refinement attempts (method ga+lm) whose counts add up, or would in wrapping
    /// arithmetic, with other edits.
    #[test]
    fn checkpoint_probes_sealed(
        probes in prop::collection::vec(
            (
                at(),
                prop_oneof![0..50u64, length_value()],
                prop::array::uniform2(prop_oneof![3 => 0.0..10.0f64, 1 => hostile_f64()]),
            ),
            1..4,
        ),
        e in prop::collection::vec(field(), 0..2),
    ) {
        let mut c = CHECKPOINT.clone();
        edit_checkpoint(&mut c, &Field::Probes(probes));
        for edit in &e {
            edit_checkpoint(&mut c, edit);
        }
        load_sealed(&c)?;
    }

    #[test]
    fn checkpoint_fields_sealed(e in prop::collection::vec(field(), 1..4)) {
        let mut c = CHECKPOINT.clone();
        for edit in &e {
            edit_checkpoint(&mut c, edit);
        }
        load_sealed(&c)?;
    }
}

/// The base is a valid checkpoint of the default job, so that the mutations start from what
/// the reader accepts and reach the checks against the job.
#[test]
fn the_base_loads_and_fits_the_job() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gen-0002.json");
    std::fs::write(&path, BASE.as_bytes()).unwrap();
    let c = Checkpoint::load(&path).unwrap();
    c.check_job(&JOB, &path).unwrap();
    assert_eq!(c.state.generation, 2);
    load(BASE.as_bytes()).unwrap();
    load_sealed(&CHECKPOINT).unwrap();
    load(&sealed_json(serde_json::from_str(&BASE).unwrap())).unwrap();
}
