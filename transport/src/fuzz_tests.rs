//! Property-based hardening of every decoder of what another process sends: frames
//! ([`Frame::decode`]), frames read from a byte stream ([`crate::uds`]'s reader), job setups
//! ([`decode_setup`]), requests ([`WireRequest::candidate`]), responses
//! ([`WireResponse::outcome`]) and answers ([`Answer::evaluations`]).
//!
//! Each is fed arbitrary bytes or field values and structured mutations of valid messages (a
//! frame of every kind; the setup of a small job): bytes flipped, inserted, deleted, the message
//! cut, length fields and aligned words set to huge counts (2^60, `u64::MAX`, counts whose
//! product with an item size overflows: `sepval_tests::fuzz`), and for setups the scenario text,
//! names, sample values and counts edited before the bytes are sealed again with a matching
//! header (so that decoding itself is exercised, not only the hash check). Every call must
//! return, `Ok` or an error with a message, without a panic, within
//! [`MAX_CALL`](sepval_tests::fuzz::MAX_CALL), and without any single allocation beyond a small
//! multiple of the bytes present (four times them; 64 for setups, whose scenarios go through
//! the TOML parser; this test binary counts allocations: a count must be checked against the
//! bytes before anything is allocated for it). What is decoded must encode back to
//! the very bytes (frames), or hold what a job promises (setups).
//!
//! The cases are bounded (a few seconds in all) and drawn from a fixed seed; run more, or
//! others, with `PROPTEST_CASES=20000 PROPTEST_RNG_SEED=7 cargo test --release -p
//! sepval-transport --lib fuzz`.

use std::sync::LazyLock;

use proptest::prelude::*;
use proptest::sample::select;
use proptest::test_runner::TestCaseError;
use sepval_common::correction::MAX_CORRECTION_VALUES;
use sepval_common::effects::{CATALOGUE, EffectSet, MAX_ACTIVE_EFFECTS, MAX_EFFECT_PARAMS};
use sepval_common::evaluation::{Candidate, Event, Job, Outcome};
use sepval_common::extension::{Axis, MAX_TERMS, Regressor, Term, TermSet};
use sepval_common::scenario::Scenario;
use sepval_common::synthetic::default_flight_test;
use sepval_core::factors::{FACTOR_COUNT, Factors};
use sepval_core::limits::{MAX_ANGLE_DEG, MAX_POSITION_M, MAX_SPAN_S};
use sepval_tests::fuzz::{
    At, CountingAllocator, Edit, apply, at, binary_edit, check_cost, check_typed, config, edits,
    length_value, measure, number_edits, text_edit,
};

use crate::codec::Frame;
use crate::setup::{catalogue_bytes, decode_setup, encode_setup, sha256};
use crate::wire::{
    Answer, Chunk, ChunkHeader, MAGIC, PROTOCOL_VERSION, REASON_CAPACITY, SetupHeader,
    WireObservation, WireRequest, WireResponse, WireTerm, serve_locally,
};

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

/// Largest single allocation a decoder may make for `len` bytes present: what they hold,
/// decoded (items are no larger in memory than on the wire), twice over, and a little more.
fn max_allocation(len: usize) -> usize {
    4 * len + (64 << 10)
}

/// Largest single allocation decoding a setup of `len` bytes may make: its scenarios are TOML,
/// whose parser lists a ~30-byte event per token before building the tables, and a token can
/// be one byte (the bound of `common/tests/model/fuzz.rs`).
fn max_setup_allocation(len: usize) -> usize {
    64 * len + (64 << 10)
}

/// A job of one event, the embedded default flight test's first 20 samples: its setup is a
/// few kilobytes.
static JOB: LazyLock<Job> = LazyLock::new(|| {
    let mut data = default_flight_test();
    data.times_s.truncate(20);
    data.pos_m.truncate(20);
    data.att_deg.truncate(20);
    Job::single("fuzz.csv", &Scenario::embedded_default(), data)
});

/// A valid frame of every kind.
static FRAMES: LazyLock<Vec<Frame>> = LazyLock::new(|| {
    let mut effects = EffectSet::NONE;
    effects.push_spec("release_rates=0.1,0.2,0.3").unwrap();
    let batch = [
        Candidate {
            factors: Factors::TRUTH,
            effects,
            terms: TermSet::of(&[Term {
                axis: Axis::Cn,
                regressor: Regressor::FBeta,
                locator: [0.6, 0.0],
                coefficient: -0.8,
            }])
            .unwrap(),
            corrections: sepval_common::correction::CorrectionValues::NONE,
        },
        Candidate::baseline(Factors([9.0; FACTOR_COUNT])),
    ];
    let chunk = Chunk::new(4, &[0, 1], &batch, true);
    let mut answer = serve_locally(&JOB, &chunk);
    answer.responses.push(WireResponse::new(
        2,
        &Outcome::Diverged { t_s: 0.5, event: 0 },
    ));
    let (header, bytes) = encode_setup(&JOB);
    vec![
        Frame::Setup {
            run_id: "run-a".into(),
            header,
            bytes: bytes[..64].to_vec(),
        },
        Frame::Ready {
            pid: 7,
            credits: 2,
            setup_sha256: [5; 32],
            host: "host".into(),
        },
        Frame::Chunk(chunk),
        Frame::Answer(answer),
        Frame::Quit("done".into()),
        Frame::Dropped("late".into()),
    ]
});

/// The lengths a frame's encoding carries (of its text, bytes and items).
fn lengths_of(frame: &Frame) -> Vec<u64> {
    let n = |k: usize| k as u64;
    match frame {
        Frame::Setup { run_id, bytes, .. } => vec![n(run_id.len()), n(bytes.len())],
        Frame::Ready { host, .. } => vec![n(host.len())],
        Frame::Chunk(c) => vec![n(c.requests.len())],
        Frame::Answer(a) => vec![n(a.responses.len()), n(a.samples.len())],
        Frame::Quit(t) | Frame::Dropped(t) => vec![n(t.len())],
    }
}

/// Offsets of `bytes` holding one of `lengths` as a little-endian u64: the length fields (and
/// perhaps a field that happens to hold the same value, one more mutation).
fn offsets_of(bytes: &[u8], lengths: &[u64]) -> Vec<usize> {
    (0..bytes.len().saturating_sub(7))
        .filter(|&o| lengths.iter().any(|l| bytes[o..o + 8] == l.to_le_bytes()))
        .collect()
}

/// Decodes a frame and checks every property: a decoded frame encodes to the very bytes.
fn frame_bytes(bytes: &[u8]) -> Result<(), TestCaseError> {
    let (result, cost) = measure(|| Frame::decode(bytes));
    check_cost("Frame::decode", cost, max_allocation(bytes.len()))?;
    check_typed("Frame::decode", &result)?;
    if let Ok(frame) = &result {
        prop_assert_eq!(frame.encode(), bytes, "{:?}", frame);
    }
    Ok(())
}

/// Arbitrary bytes, or arbitrary bytes after a valid start (magic, protocol, a kind) so that
/// the body is read.
fn frame_like() -> BoxedStrategy<Vec<u8>> {
    let start = prop_oneof![
        Just(Vec::new()),
        Just(MAGIC.to_le_bytes().to_vec()),
        (0..8u32).prop_map(|kind| {
            let mut b = MAGIC.to_le_bytes().to_vec();
            b.extend_from_slice(&PROTOCOL_VERSION.to_le_bytes());
            b.extend_from_slice(&kind.to_le_bytes());
            b
        }),
    ];
    (start, prop::collection::vec(any::<u8>(), 0..600))
        .prop_map(|(mut s, tail)| {
            s.extend(tail);
            s
        })
        .boxed()
}

/// Reads a frame as a byte stream carries it (a u32 length, then the frame) and checks every
/// property: a frame of the length announced is read, and nothing is allocated for bytes that
/// are not there.
fn stream_bytes(stream: &[u8]) -> Result<(), TestCaseError> {
    let (result, cost) = measure(|| crate::uds::read_frame(&mut std::io::Cursor::new(stream)));
    check_cost("uds::read_frame", cost, max_allocation(stream.len()))?;
    check_typed("uds::read_frame", &result)?;
    match &result {
        Ok(Some(frame)) => {
            // The frame is the bytes announced (what follows belongs to the next one).
            let len = u32::from_le_bytes(stream[..4].try_into().expect("4 bytes")) as usize;
            prop_assert_eq!(&frame.encode()[..], &stream[4..4 + len]);
        }
        Ok(None) => prop_assert!(stream.len() < 4),
        Err(_) => {}
    }
    Ok(())
}

/// A double as another process may send it: any bits, or a value at the edge of a check.
fn hostile_f64() -> BoxedStrategy<f64> {
    const EDGES: &[f64] = &[
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::MAX,
        f64::MIN,
        f64::MIN_POSITIVE,
        4e-324,
        -0.0,
        0.0,
        1.0,
        -1.0,
        1e308,
        MAX_SPAN_S,
        MAX_SPAN_S * (1.0 + f64::EPSILON),
        MAX_POSITION_M * (1.0 + f64::EPSILON),
        MAX_ANGLE_DEG * (1.0 + f64::EPSILON),
    ];
    prop_oneof![2 => select(EDGES), 1 => any::<f64>(), 1 => -10.0..10.0f64].boxed()
}

/// An edit of a job setup's content, made before the bytes are sealed again.
#[derive(Debug, Clone)]
enum SetupEdit {
    /// Edits an event's scenario text.
    Scenario(At, Vec<Edit>),
    /// Replaces an event's name.
    Name(At, Vec<u8>),
    /// Sets one value of one sample.
    Sample(At, At, usize, f64),
    /// Announces another count of samples than the event holds.
    SampleCount(At, u64),
    /// Drops samples from the end of an event (all of them, perhaps).
    DropSamples(At, usize),
    /// Repeats an event.
    DuplicateEvent(At),
    /// Removes an event.
    RemoveEvent(At),
    /// Announces another count of events than the setup holds.
    EventCount(u64),
}

/// The TOML syntax that matters to a scenario inside a setup.
const TOML_TOKENS: &[&str] = &[
    "[",
    "]",
    "{",
    "}",
    "=",
    ",",
    "\"",
    ".",
    "#",
    "\n",
    "\\",
    "é",
    "inf",
    "nan",
    "[factors]\n",
];

fn setup_edit() -> BoxedStrategy<SetupEdit> {
    prop_oneof![
        3 => (at(), prop_oneof![edits(text_edit(TOML_TOKENS), 4), number_edits(2)])
            .prop_map(|(i, e)| SetupEdit::Scenario(i, e)),
        1 => (at(), prop::collection::vec(any::<u8>(), 0..40)).prop_map(|(i, n)| SetupEdit::Name(i, n)),
        3 => (at(), at(), 0..7usize, hostile_f64()).prop_map(|(e, s, f, v)| SetupEdit::Sample(e, s, f, v)),
        1 => (at(), length_value()).prop_map(|(e, n)| SetupEdit::SampleCount(e, n)),
        1 => (at(), 1..25usize).prop_map(|(e, n)| SetupEdit::DropSamples(e, n)),
        1 => at().prop_map(SetupEdit::DuplicateEvent),
        1 => at().prop_map(SetupEdit::RemoveEvent),
        1 => length_value().prop_map(SetupEdit::EventCount),
    ]
    .boxed()
}

/// One event of a setup, as its bytes lay it out.
#[derive(Debug, Clone)]
struct SetupEvent {
    name: Vec<u8>,
    scenario: Vec<u8>,
    samples: Vec<[f64; 7]>,
    /// The count of samples announced, when not `samples.len()`.
    count: Option<u64>,
}

/// The events of `job`, as its setup lays them out.
fn setup_events(job: &Job) -> Vec<SetupEvent> {
    job.events()
        .iter()
        .map(|e| SetupEvent {
            name: e.name.as_bytes().to_vec(),
            scenario: e.simulator.scenario().to_toml_string().into_bytes(),
            samples: (0..e.data.len())
                .map(|k| {
                    let (p, a) = (e.data.pos_m[k], e.data.att_deg[k]);
                    [e.data.times_s[k], p[0], p[1], p[2], a[0], a[1], a[2]]
                })
                .collect(),
            count: None,
        })
        .collect()
}

/// The setup bytes of `events` (the layout of [`encode_setup`]), announcing `count` events
/// when given; and the offsets of its length fields.
fn setup_bytes(events: &[SetupEvent], count: Option<u64>) -> (Vec<u8>, Vec<usize>) {
    let mut b = Vec::new();
    let mut lengths = vec![0];
    let u64 = |b: &mut Vec<u8>, v: u64| b.extend_from_slice(&v.to_le_bytes());
    u64(&mut b, count.unwrap_or(events.len() as u64));
    for e in events {
        lengths.push(b.len());
        u64(&mut b, e.name.len() as u64);
        b.extend_from_slice(&e.name);
        lengths.push(b.len());
        u64(&mut b, e.scenario.len() as u64);
        b.extend_from_slice(&e.scenario);
        lengths.push(b.len());
        u64(&mut b, e.count.unwrap_or(e.samples.len() as u64));
        for s in &e.samples {
            s.iter()
                .for_each(|v| b.extend_from_slice(&v.to_bits().to_le_bytes()));
        }
    }
    (b, lengths)
}

/// `events` after `edits`, with the count of events announced.
fn edit_setup(mut events: Vec<SetupEvent>, edits: &[SetupEdit]) -> (Vec<SetupEvent>, Option<u64>) {
    let mut count = None;
    for e in edits {
        let n = events.len();
        match e {
            SetupEdit::Scenario(i, text) if n > 0 => {
                let s = &mut events[i.of(n)].scenario;
                *s = apply(s, text, &[]);
            }
            SetupEdit::Name(i, name) if n > 0 => events[i.of(n)].name = name.clone(),
            SetupEdit::Sample(i, k, field, v) if n > 0 => {
                let samples = &mut events[i.of(n)].samples;
                if !samples.is_empty() {
                    let k = k.of(samples.len());
                    samples[k][*field] = *v;
                }
            }
            SetupEdit::SampleCount(i, c) if n > 0 => events[i.of(n)].count = Some(*c),
            SetupEdit::DropSamples(i, k) if n > 0 => {
                let samples = &mut events[i.of(n)].samples;
                samples.truncate(samples.len().saturating_sub(*k));
            }
            SetupEdit::DuplicateEvent(i) if n > 0 => events.push(events[i.of(n)].clone()),
            SetupEdit::RemoveEvent(i) if n > 0 => {
                events.remove(i.of(n));
            }
            SetupEdit::EventCount(c) => count = Some(*c),
            _ => {}
        }
    }
    (events, count)
}

/// The header that matches `bytes` (as a coordinator seals them).
fn sealed(bytes: &[u8]) -> SetupHeader {
    SetupHeader {
        magic: MAGIC,
        protocol: PROTOCOL_VERSION,
        reserved: 0,
        len: bytes.len() as u64,
        sha256: sha256(bytes),
        catalogue: catalogue_bytes(),
    }
}

/// Decodes a setup and checks every property: a job decoded holds samples a telemetry file
/// could, and encodes to a setup that decodes to the same job.
fn setup(header: &SetupHeader, bytes: &[u8]) -> Result<(), TestCaseError> {
    let (result, cost) = measure(|| decode_setup(header, bytes));
    check_cost("decode_setup", cost, max_setup_allocation(bytes.len()))?;
    check_typed("decode_setup", &result)?;
    if let Ok(job) = &result {
        prop_assert!(!job.events().is_empty());
        for Event { data, .. } in job.events() {
            prop_assert!(!data.is_empty());
            for k in 0..data.len() {
                let within = |v: f64, bound: f64| v.is_finite() && v.abs() <= bound;
                prop_assert!(within(data.times_s[k], MAX_SPAN_S));
                prop_assert!(data.pos_m[k].iter().all(|&v| within(v, MAX_POSITION_M)));
                prop_assert!(data.att_deg[k].iter().all(|&v| within(v, MAX_ANGLE_DEG)));
                prop_assert!(k == 0 || data.times_s[k] > data.times_s[k - 1]);
            }
        }
        let (h, b) = encode_setup(job);
        let again = decode_setup(&h, &b).expect("an encoded job decodes");
        prop_assert_eq!(again.data_sha256(), job.data_sha256());
        prop_assert_eq!(again.scenario_sha256(), job.scenario_sha256());
    }
    Ok(())
}

/// A request as another process may send it: any values, mostly near the valid ones.
fn wire_request() -> BoxedStrategy<WireRequest> {
    let count = prop_oneof![3 => 0..=(MAX_ACTIVE_EFFECTS as u32 + 1), 1 => any::<u32>()];
    let index = prop_oneof![3 => 0..(CATALOGUE.len() as u32 + 2), 1 => any::<u32>()];
    let param = prop_oneof![3 => -1.0..1.0f64, 1 => hostile_f64()];
    let term_count = prop_oneof![3 => 0..=(MAX_TERMS as u32 + 1), 1 => any::<u32>()];
    let small = prop_oneof![3 => 0..30u32, 1 => any::<u32>()];
    let term = (
        small.clone(),
        small,
        prop::array::uniform2(prop_oneof![3 => -1.0..2.0f64, 1 => hostile_f64()]),
        prop_oneof![3 => -1.0..1.0f64, 1 => hostile_f64()],
    )
        .prop_map(|(axis, regressor, locator, coefficient)| WireTerm {
            axis,
            regressor,
            locator,
            coefficient,
        });
    (
        (
            any::<u64>(),
            prop::array::uniform17(prop_oneof![3 => 0.0..2.0f64, 1 => hostile_f64()]),
            count,
            prop::array::uniform4(index),
            any::<u32>(),
            prop::array::uniform4(prop::array::uniform3(param)),
        ),
        (term_count, any::<u32>(), prop::array::uniform8(term)),
        (
            prop_oneof![3 => 0..=(MAX_CORRECTION_VALUES as u32 + 1), 1 => any::<u32>()],
            any::<u32>(),
            prop::collection::vec(
                prop_oneof![3 => -1.0..1.0f64, 1 => hostile_f64()],
                MAX_CORRECTION_VALUES,
            ),
        ),
    )
        .prop_map(
            |(
                (index, factors, effect_count, effect_index, reserved, params),
                (term_count, reserved_terms, terms),
                (correction_count, reserved_corrections, values),
            )| {
                let mut effect_params = [[0.0; MAX_EFFECT_PARAMS]; MAX_ACTIVE_EFFECTS];
                for (row, p) in effect_params.iter_mut().zip(params) {
                    row[..3].copy_from_slice(&p);
                }
                let mut corrections = [0.0; MAX_CORRECTION_VALUES];
                corrections.copy_from_slice(&values);
                WireRequest {
                    index,
                    factors,
                    effect_count,
                    effect_index,
                    reserved,
                    effect_params,
                    term_count,
                    reserved_terms,
                    terms,
                    correction_count,
                    reserved_corrections,
                    corrections,
                }
            },
        )
        .boxed()
}

/// A response as another process may send it: any values, mostly near the valid ones, its
/// reason text or any bytes.
fn wire_response() -> BoxedStrategy<WireResponse> {
    let status = prop_oneof![3 => 0..4u32, 1 => any::<u32>()];
    let reason_len = prop_oneof![3 => 0..=(REASON_CAPACITY as u32 + 2), 1 => any::<u32>()];
    let reason = prop_oneof![
        any::<String>().prop_map(|s| s.into_bytes()),
        prop::collection::vec(any::<u8>(), 0..=REASON_CAPACITY),
    ]
    .prop_map(|bytes| {
        let mut r = [0u8; REASON_CAPACITY];
        let n = bytes.len().min(REASON_CAPACITY);
        r[..n].copy_from_slice(&bytes[..n]);
        r
    });
    (
        (any::<u64>(), status, prop_oneof![0..3u32, any::<u32>()]),
        (hostile_f64(), hostile_f64(), hostile_f64()),
        (reason_len, any::<u32>(), reason),
    )
        .prop_map(
            |(
                (index, status, event),
                (j_pos_m, j_att_deg, t_s),
                (reason_len, reserved, reason),
            )| {
                WireResponse {
                    index,
                    status,
                    event,
                    j_pos_m,
                    j_att_deg,
                    t_s,
                    reason_len,
                    reserved,
                    reason,
                }
            },
        )
        .boxed()
}

/// Two outcomes are the same to the bit (NaN goals included).
fn same(a: &Outcome, b: &Outcome) -> bool {
    format!("{a:?}") == format!("{b:?}")
        && match (a, b) {
            (
                Outcome::Goals { j_pos_m, j_att_deg },
                Outcome::Goals {
                    j_pos_m: p,
                    j_att_deg: q,
                },
            ) => j_pos_m.to_bits() == p.to_bits() && j_att_deg.to_bits() == q.to_bits(),
            (Outcome::Diverged { t_s, .. }, Outcome::Diverged { t_s: t, .. }) => {
                t_s.to_bits() == t.to_bits()
            }
            _ => true,
        }
}

proptest! {
    #![proptest_config(config(1024))]

    #[test]
    fn frame_decode_arbitrary_bytes(bytes in frame_like()) {
        frame_bytes(&bytes)?;
    }

    #[test]
    fn frame_decode_mutations(kind in 0..6usize, e in edits(binary_edit(), 6)) {
        let frame = &FRAMES[kind];
        let bytes = frame.encode();
        let offsets = offsets_of(&bytes, &lengths_of(frame));
        frame_bytes(&apply(&bytes, &e, &offsets))?;
    }

    #[test]
    fn stream_frames(kind in 0..6usize, len in length_value(), e in edits(binary_edit(), 3), edit in any::<bool>()) {
        let frame = &FRAMES[kind];
        let bytes = frame.encode();
        let body = if edit {
            apply(&bytes, &e, &offsets_of(&bytes, &lengths_of(frame)))
        } else {
            bytes
        };
        // The length announced: the body's, or any.
        let announced = if edit { len as u32 } else { body.len() as u32 };
        let mut stream = announced.to_le_bytes().to_vec();
        stream.extend_from_slice(&body);
        stream_bytes(&stream)?;
    }

    #[test]
    fn request_candidate(r in wire_request()) {
        let (result, cost) = measure(|| r.candidate());
        check_cost("WireRequest::candidate", cost, 64 << 10)?;
        check_typed("WireRequest::candidate", &result)?;
        if let Ok(c) = &result {
            prop_assert_eq!(c.effects.len(), r.effect_count as usize);
            for (k, a) in c.effects.iter().enumerate() {
                prop_assert_eq!(a.index, r.effect_index[k] as usize);
                prop_assert!(a.values().iter().all(|v| v.is_finite()));
            }
            prop_assert!(c.factors.0.iter().zip(&r.factors).all(|(a, b)| a.to_bits() == b.to_bits()));
            prop_assert_eq!(c.terms.len(), r.term_count as usize);
            prop_assert!(c.terms.iter().all(|t| t.check().is_ok()));
            let again = WireRequest::new(r.index, c).candidate().expect("a candidate's request");
            prop_assert_eq!(again.effects, c.effects);
            prop_assert_eq!(again.terms, c.terms);
        }
    }

    #[test]
    fn response_outcome(r in wire_response()) {
        let (result, cost) = measure(|| r.outcome());
        check_cost("WireResponse::outcome", cost, 64 << 10)?;
        check_typed("WireResponse::outcome", &result)?;
        if let Ok(o) = &result {
            if let Outcome::Failed { reason } = o {
                prop_assert!(reason.len() <= REASON_CAPACITY);
            }
            let again = WireResponse::new(r.index, o).outcome().expect("an outcome's response");
            prop_assert!(same(&again, o), "{:?} became {:?}", o, again);
        }
    }

    #[test]
    fn answer_evaluations(
        indices in prop::collection::vec(prop_oneof![3 => 0..4usize, 1 => any::<usize>()], 0..4),
        responses in prop::collection::vec(wire_response(), 0..5),
        answered in prop_oneof![3 => Just(None), 1 => (0..5usize).prop_map(Some)],
        with_samples in any::<bool>(),
        samples in prop_oneof![3 => Just(None), 1 => (0..100usize).prop_map(Some)],
        same_indices in any::<bool>(),
    ) {
        // As many responses as candidates (mostly), answering them in order (mostly).
        let mut responses = responses;
        let goals = Outcome::Goals { j_pos_m: 0.1, j_att_deg: 0.2 };
        responses.resize(answered.unwrap_or(indices.len()), WireResponse::new(0, &goals));
        if same_indices {
            for (r, &i) in responses.iter_mut().zip(&indices) {
                r.index = i as u64;
            }
        }
        let per = JOB.sample_count();
        let n = samples.unwrap_or(per * indices.len());
        let answer = Answer {
            header: ChunkHeader { chunk_id: 1, count: responses.len() as u32, with_samples: u32::from(with_samples) },
            responses,
            samples: vec![WireObservation::MISSING; n],
        };
        let (result, cost) = measure(|| answer.evaluations(&indices, &JOB));
        check_cost("Answer::evaluations", cost, max_allocation(n * 48 + 1024))?;
        check_typed("Answer::evaluations", &result)?;
        if let Ok(evaluations) = &result {
            prop_assert_eq!(evaluations.len(), indices.len());
            for (k, (index, e)) in evaluations.iter().enumerate() {
                prop_assert_eq!(*index, indices[k]);
                if let Some(events) = &e.samples {
                    prop_assert!(with_samples && e.outcome.goals().is_some());
                    prop_assert_eq!(events.iter().map(Vec::len).sum::<usize>(), per);
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn setup_arbitrary_bytes(
        bytes in prop::collection::vec(any::<u8>(), 0..600),
        start in prop::collection::vec(prop_oneof![3 => 0..4u64, 1 => length_value()], 0..3),
    ) {
        // Arbitrary bytes, perhaps after counts (of events, of a name's bytes, ...).
        let mut b: Vec<u8> = start.iter().flat_map(|v| v.to_le_bytes()).collect();
        b.extend(bytes);
        setup(&sealed(&b), &b)?;
    }

    #[test]
    fn setup_mutations(e in prop::collection::vec(setup_edit(), 1..4), bytes in edits(binary_edit(), 3), edit_bytes in any::<bool>()) {
        let (events, count) = edit_setup(setup_events(&JOB), &e);
        let (mut b, lengths) = setup_bytes(&events, count);
        if edit_bytes {
            b = apply(&b, &bytes, &lengths);
        }
        setup(&sealed(&b), &b)?;
    }

    #[test]
    fn setup_headers(field in 0..6usize, value in length_value(), bit in 0..256usize) {
        let (header, bytes) = encode_setup(&JOB);
        let mut h = header;
        match field {
            0 => h.magic = value,
            1 => h.protocol = value as u32,
            2 => h.reserved = value as u32,
            3 => h.len = value,
            4 => h.sha256[bit / 8] ^= 1 << (bit % 8),
            _ => h.catalogue[bit / 8] ^= 1 << (bit % 8),
        }
        setup(&h, &bytes)?;
    }
}

/// The bases are valid, so that the mutations start from what the decoders accept.
#[test]
fn the_bases_decode() {
    for f in FRAMES.iter() {
        frame_bytes(&f.encode()).unwrap();
        let mut stream = (f.encode().len() as u32).to_le_bytes().to_vec();
        stream.extend(f.encode());
        stream_bytes(&stream).unwrap();
    }
    let (b, _) = setup_bytes(&setup_events(&JOB), None);
    assert_eq!(b, encode_setup(&JOB).1);
    decode_setup(&sealed(&b), &b).unwrap();
    setup(&sealed(&b), &b).unwrap();
}
