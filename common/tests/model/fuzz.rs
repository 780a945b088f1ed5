//! Property-based hardening of the model library's readers of outside input: telemetry CSV
//! ([`Trajectory::parse`], and [`Trajectory::read`] on files of arbitrary bytes, invalid UTF-8
//! included), scenario TOML ([`Scenario::from_toml_str`]), factors JSON
//! ([`Factors::from_json_str`]), effect specs of the command line ([`EffectSet::push_spec`])
//! and model-extension TOML ([`parse_extension`], `docs/discovery.md`).
//!
//! Each is fed arbitrary text and structured mutations of a valid input (the embedded default
//! flight test, the embedded default scenario, the truth factors): bytes flipped, inserted and
//! deleted, the format's own syntax inserted, lines duplicated, deleted and swapped, the text cut,
//! numbers replaced by huge, non-finite, negative or malformed ones (`sepval_tests::fuzz`), and
//! nesting thousands of levels deep. Every call must return, `Ok` or an error with a message,
//! without a panic, within [`MAX_CALL`](sepval_tests::fuzz::MAX_CALL), and without any single
//! allocation beyond a small multiple of its input's size (this test binary counts allocations:
//! [`CountingAllocator`]). What is read must hold what the reader promises (times strictly
//! increasing and within the plausible bounds, a valid scenario, factors within their bounds,
//! terms that can be run), and must read back the same after being written. An extension file
//! that is refused names the line at fault (the field's own line when one field is wrong).
//!
//! The cases are bounded (about a second in all) and drawn from a fixed seed; run more, or
//! others, with `PROPTEST_CASES=20000 PROPTEST_RNG_SEED=7 cargo test --release -p sepval-common
//! --test model fuzz`.

use proptest::prelude::*;
use proptest::sample::select;
use proptest::test_runner::TestCaseError;
use sepval_common::effects::{CATALOGUE, EffectSet};
use sepval_common::extension::locator::{F_HZ, LAMBDA_M, LocatorDomain, MACH0, RISE_S, T_ON_S};
use sepval_common::extension::{
    Axis, EXTENSION_FORMAT, ExtensionError, Family, MAX_TERMS, Regressor, Term, TermRecord,
    extension_toml, parse_extension,
};
use sepval_common::scenario::{DEFAULT_SCENARIO_TOML, Scenario};
use sepval_common::synthetic::default_flight_test;
use sepval_common::telemetry::{TelemetryError, Trajectory};
use sepval_core::factors::{FactorTable, Factors};
use sepval_core::limits::{
    MAX_ANGLE_DEG, MAX_EXTENSION_BYTES, MAX_POSITION_M, MAX_SCENARIO_BYTES, MAX_SPAN_S,
    MAX_TABLE_CSV_BYTES, MAX_TELEMETRY_BYTES,
};
use std::path::PathBuf;

use sepval_tests::fuzz::{
    CountingAllocator, Edit, PathKind, apply, check_cost, check_typed, config, edits, measure,
    number_edits, number_text, path_kind, text_edit, within_deadline,
};

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

/// Largest single allocation a reader may make for `len` bytes of input: `per_byte` times
/// them (vectors grow by doubling) and a little more.
fn max_allocation(len: usize, per_byte: usize) -> usize {
    per_byte * len + (64 << 10)
}

/// Bytes a telemetry or JSON reader may allocate at once per byte of input.
const PER_BYTE: usize = 16;

/// Bytes the TOML parser may allocate at once per byte of input: it lists the input's tokens
/// (events of about 30 bytes each) before building the tables, and a token can be one byte.
const PER_BYTE_TOML: usize = 64;

/// The syntax of a telemetry file, where its reader decides.
const TELEMETRY_TOKENS: &[&str] = &[
    ",",
    ",,,,,,,",
    "\"",
    "\"\"",
    ",\"0\"",
    "#",
    "# event = x",
    "# : v",
    "\n",
    "\r\n",
    "\r",
    "\u{feff}",
    " ",
    "\t",
    "t_s",
    "x_m",
    "x_ft",
    "z_ft",
    "x_km",
    "roll_rad",
    "yaw_deg",
    "mach",
    "_",
    "NaN",
    "inf",
    "1e308",
    "é",
    "\u{0}",
    "\u{2028}",
];

/// The syntax of TOML, where its parser decides, and nesting far beyond any scenario's.
const TOML_TOKENS: &[&str] = &[
    "[",
    "]",
    "[[",
    "]]",
    "{",
    "}",
    "=",
    ",",
    "\"",
    "'",
    "'''",
    "\"\"\"",
    ".",
    "#",
    "\n",
    "\r\n",
    "\\",
    "\\u0000",
    "\\uD800",
    "\\U0010FFFF",
    "é",
    "\u{feff}",
    "a.b.c = 1\n",
    "\n[store]\n",
    "\n[factors]\n",
    "\n[initial]\nvelocity_m_s = [1, 2, 3]\n",
    "\n[[ejector.curve]]\n",
    "curve = []\n",
    "curve = [[0.0, 1.0]]\n",
    "curve = [[0.0, 1.0, 2.0], [1, 2]]\n",
    "fwdfac = { min = 0.2, max = 1.0, bits = 64 }\n",
    "fwdfac = { min = 0.2, max = 0.2, bits = 5 }\n",
    "bits = 4294967296\n",
    "bits = -1\n",
    "unknown = 1\n",
    "mass_kg = 1\n",
    "inf",
    "nan",
    "-inf",
    "true",
    "1979-05-27T07:32:00Z",
    "0x7FFFFFFFFFFFFFFF",
    "1_000",
    "x = [[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[\n",
    "x = {a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a={a=\n",
    "a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a = 1\n",
    "[a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a]\n",
];

/// The syntax of JSON, where its parser decides.
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
    "\"fwdfac\": 0.5,",
    "\"clintfac\": 1,",
    "\"unknown\": 1,",
    "\"fwdfac\": [0.5],",
    "\"fwdfac\": {\"a\": 1},",
    "1e999",
    "-0",
    " ",
    "\n",
    "é",
    "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[",
    "{\"a\":{\"a\":{\"a\":{\"a\":{\"a\":{\"a\":{\"a\":{\"a\":{\"a\":{\"a\":{\"a\":{\"a\":{\"a\":{\"a\":{\"a\":",
];

/// Arbitrary text: any characters, or mostly the characters of a format (`alphabet`, a regex
/// class) so that the parser gets past its first check.
fn arbitrary_text(alphabet: &'static str) -> BoxedStrategy<String> {
    prop_oneof![
        any::<String>(),
        proptest::string::string_regex(&format!("{alphabet}{{0,1500}}")).expect("a valid regex"),
    ]
    .boxed()
}

/// The embedded default flight test as its file, its comments and first 40 samples: a few
/// kilobytes.
fn telemetry_base() -> String {
    let text = default_flight_test().to_csv_string();
    let header = text.find("t_s,").expect("a header");
    let mut end = header;
    for _ in 0..41 {
        end += text[end..].find('\n').expect("samples") + 1;
    }
    text[..end].to_string()
}

/// What a trajectory read from a file promises.
fn check_trajectory(t: &Trajectory, name: &str) -> Result<(), TestCaseError> {
    prop_assert!(!t.is_empty());
    prop_assert_eq!(t.pos_m.len(), t.len());
    prop_assert_eq!(t.att_deg.len(), t.len());
    prop_assert!(t.metadata.len() <= t.comments.len());
    for k in 0..t.len() {
        let within = |v: f64, bound: f64| v.is_finite() && v.abs() <= bound;
        prop_assert!(within(t.times_s[k], MAX_SPAN_S), "time {}", t.times_s[k]);
        prop_assert!(t.pos_m[k].iter().all(|&v| within(v, MAX_POSITION_M)));
        prop_assert!(t.att_deg[k].iter().all(|&v| within(v, MAX_ANGLE_DEG)));
        prop_assert!(k == 0 || t.times_s[k] > t.times_s[k - 1]);
    }
    // Written and read again: the same trajectory, to the bit.
    let again = Trajectory::parse(&t.to_csv_string(), name);
    prop_assert_eq!(again.as_ref(), Ok(t));
    Ok(())
}

/// Parses telemetry text and checks every property.
fn telemetry_text(text: &str) -> Result<(), TestCaseError> {
    let (result, cost) = measure(|| Trajectory::parse(text, "fuzz.csv"));
    check_cost(
        "Trajectory::parse",
        cost,
        max_allocation(text.len(), PER_BYTE),
    )?;
    check_typed("Trajectory::parse", &result)?;
    if let Ok(t) = &result {
        check_trajectory(t, "fuzz.csv")?;
    }
    Ok(())
}

/// Reads telemetry bytes from a file and checks every property: as the text parses when they
/// are UTF-8, refused naming a line that is not otherwise.
fn telemetry_file(bytes: &[u8]) -> Result<(), TestCaseError> {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = dir.path().join("fuzz.csv");
    std::fs::write(&path, bytes).expect("write the file");
    let (result, cost) = measure(|| Trajectory::read(&path));
    check_cost(
        "Trajectory::read",
        cost,
        max_allocation(bytes.len(), PER_BYTE),
    )?;
    check_typed("Trajectory::read", &result)?;
    let name = path.display().to_string();
    match std::str::from_utf8(bytes) {
        Ok(text) => prop_assert_eq!(&result, &Trajectory::parse(text, &name)),
        Err(_) => {
            if let Err(TelemetryError::NotText { line, .. }) = &result {
                let raw = bytes.split(|&b| b == b'\n').nth(line - 1);
                prop_assert!(raw.is_some_and(|l| std::str::from_utf8(l).is_err()));
            }
        }
    }
    if let Ok(t) = &result {
        check_trajectory(t, &name)?;
    }
    Ok(())
}

/// Parses scenario TOML and checks every property: a scenario read is valid and reads back the
/// same after being written.
fn scenario_text(text: &str) -> Result<(), TestCaseError> {
    let (result, cost) = measure(|| Scenario::from_toml_str(text, "fuzz.toml"));
    check_cost(
        "Scenario::from_toml_str",
        cost,
        max_allocation(text.len(), PER_BYTE_TOML),
    )?;
    check_typed("Scenario::from_toml_str", &result)?;
    if let Ok(s) = &result {
        prop_assert!(s.validate("fuzz.toml").is_ok());
        let again = Scenario::from_toml_str(&s.to_toml_string(), "again.toml");
        prop_assert!(again.as_ref().is_ok_and(|a| a == s), "{again:?}");
    }
    Ok(())
}

/// Parses factors JSON and checks every property: the factors read are within the table's
/// bounds and read back the same after being written.
fn factors_text(text: &str) -> Result<(), TestCaseError> {
    let table = FactorTable::default();
    let (result, cost) = measure(|| Factors::from_json_str(text, &table));
    check_cost(
        "Factors::from_json_str",
        cost,
        max_allocation(text.len(), PER_BYTE),
    )?;
    check_typed("Factors::from_json_str", &result)?;
    if let Ok(f) = &result {
        prop_assert!(table.check(f).is_ok());
        let json = serde_json::to_string(f).expect("factors serialise");
        prop_assert_eq!(Factors::from_json_str(&json, &table).ok(), Some(*f));
    }
    Ok(())
}

/// Adds effect specs to an empty set (as `--effect` flags do) and checks every property: the
/// set holds what was added, and its text form reads back the same.
fn effect_specs(specs: &[String]) -> Result<(), TestCaseError> {
    let mut set = EffectSet::NONE;
    for spec in specs {
        let before = set.len();
        let (result, cost) = measure(|| set.push_spec(spec));
        check_cost(
            "EffectSet::push_spec",
            cost,
            max_allocation(spec.len(), PER_BYTE),
        )?;
        check_typed("EffectSet::push_spec", &result)?;
        prop_assert_eq!(set.len(), before + usize::from(result.is_ok()));
    }
    prop_assert!(set.iter().all(|a| a.values().iter().all(|v| v.is_finite())));
    if !set.is_empty() {
        let mut again = EffectSet::NONE;
        for spec in set.to_string().split(' ') {
            again.push_spec(spec).expect("a set's text reads back");
        }
        prop_assert_eq!(again, set);
    }
    Ok(())
}

/// An effect spec: a catalogue id (or another name) and a list of numbers (mostly as many as
/// the effect takes), then perhaps edited.
fn effect_spec() -> BoxedStrategy<String> {
    let id_and_count = prop_oneof![
        4 => (0..CATALOGUE.len()).prop_map(|k| (CATALOGUE[k].id(), CATALOGUE[k].params().len())),
        1 => select(&["", " ", "x", "release_rates ", "=", "release_rates=1"][..]).prop_map(|id| (id, 1)),
    ];
    let value = || prop_oneof![3 => (-2.0..2.0f64).prop_map(|v| v.to_string()), 1 => number_text()];
    (id_and_count, any::<bool>())
        .prop_flat_map(move |((id, n), exact)| {
            let count = if exact { n..n + 1 } else { 0..6 };
            (Just(id), prop::collection::vec(value(), count))
        })
        .prop_map(|(id, values)| format!("{id}={}", values.join(",")))
        .prop_flat_map(|spec| {
            prop_oneof![
                2 => Just(spec.clone()),
                1 => edits(text_edit(EFFECT_TOKENS), 2).prop_map(move |e| mutated(&spec, &e)),
            ]
        })
        .boxed()
}

/// The syntax of an effect spec.
const EFFECT_TOKENS: &[&str] = &["=", ",", ",,", " ", "-", "e", ".", "NaN", "inf", "é"];

/// Mutated text as a string (edits may cut characters: lossy, as a file would be read by a
/// caller that decodes it first).
fn mutated(base: &str, e: &[Edit]) -> String {
    String::from_utf8_lossy(&apply(base.as_bytes(), e, &[])).into_owned()
}

proptest! {
    #![proptest_config(config(512))]

    #[test]
    fn telemetry_arbitrary_text(text in arbitrary_text("[-0-9a-z_,.\"#=: \\r\\n]")) {
        telemetry_text(&text)?;
    }

    #[test]
    fn scenario_arbitrary_text(text in arbitrary_text("[-0-9a-z_.=\\[\\]{},\"' #\\n]")) {
        scenario_text(&text)?;
    }

    #[test]
    fn factors_arbitrary_text(text in arbitrary_text("[-0-9a-z.:{},\\[\\]\" \\n]")) {
        factors_text(&text)?;
    }

    #[test]
    fn effect_specs_of_the_command_line(specs in prop::collection::vec(effect_spec(), 1..6)) {
        effect_specs(&specs)?;
    }

    #[test]
    fn telemetry_files_of_arbitrary_bytes(bytes in prop::collection::vec(any::<u8>(), 0..2000)) {
        telemetry_file(&bytes)?;
    }
}

proptest! {
    #![proptest_config(config(2048))]

    #[test]
    fn telemetry_mutations(e in edits(text_edit(TELEMETRY_TOKENS), 8)) {
        telemetry_text(&mutated(&telemetry_base(), &e))?;
    }

    #[test]
    fn scenario_mutations(written in any::<bool>(), e in edits(text_edit(TOML_TOKENS), 8)) {
        // The file as a user has it (comments, layout) or as sepval writes it.
        let base = if written {
            Scenario::embedded_default().to_toml_string()
        } else {
            DEFAULT_SCENARIO_TOML.to_string()
        };
        scenario_text(&mutated(&base, &e))?;
    }

    #[test]
    fn factors_mutations(pretty in any::<bool>(), e in edits(text_edit(JSON_TOKENS), 8)) {
        let base = if pretty {
            serde_json::to_string_pretty(&Factors::TRUTH)
        } else {
            serde_json::to_string(&Factors::TRUTH)
        }
        .expect("factors serialise");
        factors_text(&mutated(&base, &e))?;
    }
}

proptest! {
    #![proptest_config(config(1024))]

    /// Numbers replaced by huge, non-finite, negative or malformed ones: the checks of values.
    #[test]
    fn telemetry_numbers(e in number_edits(3)) {
        telemetry_text(&mutated(&telemetry_base(), &e))?;
    }

    #[test]
    fn scenario_numbers(written in any::<bool>(), e in number_edits(3)) {
        let base = if written {
            Scenario::embedded_default().to_toml_string()
        } else {
            DEFAULT_SCENARIO_TOML.to_string()
        };
        scenario_text(&mutated(&base, &e))?;
    }

    #[test]
    fn factors_numbers(e in number_edits(3)) {
        let base = serde_json::to_string_pretty(&Factors::TRUTH).expect("factors serialise");
        factors_text(&mutated(&base, &e))?;
    }
}

proptest! {
    #![proptest_config(config(64))]

    /// Files of mutated bytes, invalid UTF-8 included (edits here keep every byte they make).
    #[test]
    fn telemetry_file_mutations(e in edits(text_edit(TELEMETRY_TOKENS), 8)) {
        telemetry_file(&apply(telemetry_base().as_bytes(), &e, &[]))?;
    }

    /// A line of thousands of columns, as header or as row.
    #[test]
    fn telemetry_with_many_columns(extra in 0..20_000usize, row_extra in 0..20_000usize, quoted in any::<bool>()) {
        let q = |s: &str| if quoted { format!("\"{s}\"") } else { s.to_string() };
        let mut header = ["t_s", "x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"]
            .map(q)
            .join(",");
        header.push_str(&",other_v".repeat(extra));
        let mut row = "0,0,0,0,0,0,0".to_string();
        row.push_str(&",1".repeat(row_extra));
        telemetry_text(&format!("{header}\n{row}\n"))?;
    }

    /// Nesting thousands of levels deep: arrays, inline tables, dotted keys, table headers.
    #[test]
    fn scenario_deeply_nested(kind in 0..5usize, depth in 1..20_000usize) {
        let text = match kind {
            0 => format!("x = {}{}", "[".repeat(depth), "]".repeat(depth)),
            1 => format!("x = {}1{}", "{a=".repeat(depth), "}".repeat(depth)),
            2 => format!("{} = 1", vec!["a"; depth].join(".")),
            3 => format!("[{}]\nb = 1", vec!["a"; depth].join(".")),
            _ => format!("{DEFAULT_SCENARIO_TOML}\n[initial]\nvelocity_m_s = {}", "[".repeat(depth)),
        };
        scenario_text(&text)?;
    }

    /// Nesting thousands of levels deep.
    #[test]
    fn factors_deeply_nested(array in any::<bool>(), depth in 1..20_000usize) {
        let text = if array {
            format!("{}{}", "[".repeat(depth), "]".repeat(depth))
        } else {
            format!("{}1{}", "{\"fwdfac\":".repeat(depth), "}".repeat(depth))
        };
        factors_text(&text)?;
    }
}

/// The syntax of an extension file, where its reader decides: TOML's own, and the fields,
/// names and values of terms.
const EXTENSION_TOKENS: &[&str] = &[
    "[",
    "]",
    "[[",
    "]]",
    "{",
    "}",
    "=",
    ",",
    "\"",
    "'",
    "\"\"\"",
    ".",
    "#",
    "\n",
    "\r\n",
    "\\",
    "é",
    "\u{feff}",
    "\n[[term]]\n",
    "\n[term]\n",
    "term = []\n",
    "term = [{ axis = \"Cn\", family = \"rate\", regressor = \"r\", coefficient = 1 }]\n",
    "format = \"sepval-extension/2\"\n",
    "axis = \"ejector\"\n",
    "axis = \"CZ\"\n",
    "family = \"step\"\n",
    "family = \"window\"\n",
    "regressor = \"sin\"\n",
    "regressor = \"stroke\"\n",
    "lambda_m = 0\n",
    "mach0 = -1\n",
    "t_on_s = nan\n",
    "f_hz = -1\n",
    "coefficient = inf\n",
    "coefficient = \"1\"\n",
    "std_error = -1\n",
    "reading = \"\"\"\naxis = 1\n\"\"\"\n",
    "colour = 1\n",
    "nan",
    "inf",
    "-0",
    "1e309",
];

/// A value of a locator's domain: ordinary, or at its edges (the smallest positive doubles
/// for an open lower bound).
fn in_domain(d: LocatorDomain) -> BoxedStrategy<f64> {
    // The neighbours by their bits (f64::next_up and next_down need Rust 1.86): max is
    // positive, min negative or zero.
    let toward_zero = |x: f64| f64::from_bits(x.to_bits() - 1);
    let mut edges = vec![d.max, toward_zero(d.max)];
    if d.min_open {
        edges.extend([f64::MIN_POSITIVE, 5e-324, 1e-300]);
    } else {
        edges.push(d.min);
        if d.min < 0.0 {
            edges.push(toward_zero(d.min));
        }
    }
    prop_oneof![
        4 => 0.01..10.0f64,
        1 => select(edges),
    ]
    .boxed()
}

/// The domain of the locator named `name`.
fn domain_of(name: &str) -> LocatorDomain {
    [LAMBDA_M, MACH0, T_ON_S, F_HZ]
        .into_iter()
        .find(|d| d.name == name)
        .expect("a locator of the library")
}

/// Any finite number, the extremes included.
fn finite() -> BoxedStrategy<f64> {
    use prop::num::f64::{NEGATIVE, NORMAL, POSITIVE, SUBNORMAL, ZERO};
    prop_oneof![
        2 => -10.0..10.0f64,
        1 => POSITIVE | NEGATIVE | NORMAL | SUBNORMAL | ZERO,
    ]
    .boxed()
}

/// A term an extension file can hold: a regressor of the library on an axis it may act on, a
/// locator in its family's domain, any finite coefficient.
fn valid_term() -> BoxedStrategy<Term> {
    let library: Vec<Regressor> = Regressor::ALL
        .iter()
        .filter(|(_, f, _)| *f != Family::Window)
        .map(|(r, _, _)| *r)
        .collect();
    select(library)
        .prop_flat_map(|regressor| {
            let axes: Vec<Axis> = Axis::ALL
                .into_iter()
                .filter(|a| regressor.fits(*a))
                .collect();
            let locator = match regressor.family().locator() {
                Some("t_on_s") => prop_oneof![
                    2 => in_domain(T_ON_S),
                    1 => -10.0..10.0f64,
                    1 => Just(-0.0),
                ]
                .boxed(),
                Some("f_hz") => prop_oneof![
                    3 => 0.0..60.0f64,
                    1 => in_domain(F_HZ),
                    1 => Just(-0.0),
                ]
                .boxed(),
                Some(name) => in_domain(domain_of(name)),
                None => Just(0.0).boxed(),
            };
            (Just(regressor), select(axes), locator, finite())
        })
        .prop_flat_map(|(regressor, axis, locator, coefficient)| {
            // A wind's second locator, its onset or pulse length.
            let rise_s = if regressor.family() == Family::Wind {
                prop_oneof![2 => 0.01..1.0f64, 1 => in_domain(RISE_S)].boxed()
            } else {
                Just(0.0).boxed()
            };
            (Just((regressor, axis, locator, coefficient)), rise_s)
        })
        .prop_map(|((regressor, axis, locator, coefficient), rise_s)| Term {
            axis,
            regressor,
            locator: [locator, rise_s],
            coefficient,
        })
        .boxed()
}

/// A valid extension's terms, with (or without) the informational fields a diagnosis writes:
/// a standard error and a reading of any text.
fn valid_extension() -> BoxedStrategy<(Vec<Term>, Vec<TermRecord>)> {
    prop::collection::vec(
        (
            valid_term(),
            prop::option::of(finite()),
            prop::option::of(any::<String>()),
        ),
        0..=MAX_TERMS,
    )
    .prop_map(|items| {
        let terms = items.iter().map(|(t, _, _)| *t).collect();
        let records = items
            .into_iter()
            .map(|(t, std_error, reading)| TermRecord {
                std_error,
                reading,
                ..TermRecord::of(&t)
            })
            .collect();
        (terms, records)
    })
    .boxed()
}

/// The same terms to the bit (`==` would let -0 pass for 0).
fn same_terms(a: &[Term], b: &[Term]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            x.axis == y.axis
                && x.regressor == y.regressor
                && x.coefficient.to_bits() == y.coefficient.to_bits()
                && x.locator.map(f64::to_bits) == y.locator.map(f64::to_bits)
        })
}

/// What an extension error promises: it names a line of the text (the parser's `line N`, or
/// the term's own line), except the two refusals of the whole file (its format tag, its number
/// of terms), which name what they refuse.
fn check_extension_error(e: &ExtensionError, text: &str) -> Result<(), TestCaseError> {
    let lines = text.split('\n').count();
    match e {
        ExtensionError::Term {
            path,
            line,
            index,
            field,
            ..
        } => {
            prop_assert_eq!(path, "fuzz.toml");
            prop_assert!((1..=lines).contains(line), "line {line} of {lines}: {e}");
            prop_assert!((1..=MAX_TERMS).contains(index), "{e}");
            // The field's own line, or (a field not written) the line where its term opens.
            let named = text
                .split('\n')
                .nth(line - 1)
                .unwrap_or_default()
                .trim_start();
            let own = named
                .strip_prefix(*field)
                .is_some_and(|rest| rest.trim_start().starts_with('='));
            prop_assert!(
                own || named.starts_with('[') || named.contains('{'),
                "{e}: line {line} is `{named}`"
            );
        }
        ExtensionError::Parse { path, message } => {
            prop_assert_eq!(path, "fuzz.toml");
            let whole_file = (message.starts_with("format `")
                && message.ends_with(&format!("this sepval reads `{EXTENSION_FORMAT}`")))
                || message.ends_with(&format!(" terms, at most {MAX_TERMS}"));
            prop_assert!(
                whole_file || message.contains("line "),
                "an error that names no line: {e}"
            );
        }
        other => prop_assert!(false, "reading text gave {other}"),
    }
    Ok(())
}

/// Reads extension TOML and checks every property: the terms read can be run, are at most
/// [`MAX_TERMS`], and read back the same after being written; an error names its line.
fn extension_text(text: &str) -> Result<(), TestCaseError> {
    let (result, cost) = measure(|| parse_extension(text, "fuzz.toml"));
    check_cost(
        "parse_extension",
        cost,
        max_allocation(text.len(), PER_BYTE_TOML),
    )?;
    check_typed("parse_extension", &result)?;
    match &result {
        Ok(terms) => {
            prop_assert!(terms.len() <= MAX_TERMS);
            for t in terms {
                prop_assert!(t.check().is_ok(), "{t:?}: {:?}", t.check());
            }
            let records: Vec<TermRecord> = terms.iter().map(TermRecord::of).collect();
            let again = parse_extension(&extension_toml(&records), "again.toml");
            prop_assert!(
                again.as_ref().is_ok_and(|a| same_terms(a, terms)),
                "{again:?} against {terms:?}"
            );
        }
        Err(e) => check_extension_error(e, text)?,
    }
    Ok(())
}

/// An example extension of several terms, as a diagnosis writes it.
fn extension_base() -> String {
    let term = |axis, regressor, locator, coefficient| Term {
        axis,
        regressor,
        locator: [locator, 0.0],
        coefficient,
    };
    let terms = [
        term(Axis::Cn, Regressor::FBeta, 0.5, -2.0),
        term(Axis::CY, Regressor::Step, 0.43, 0.2),
        term(Axis::Cl, Regressor::Sin, 6.25, 0.015),
        term(Axis::Cl, Regressor::Cos, 6.25, 0.012),
        term(Axis::CA, Regressor::Dm, 0.9, 0.5),
        term(Axis::Ejector, Regressor::Stroke, 0.0, -0.6),
    ];
    let records: Vec<TermRecord> = terms
        .iter()
        .map(|t| TermRecord {
            std_error: Some(0.01),
            reading: Some("a reading".into()),
            ..TermRecord::of(t)
        })
        .collect();
    extension_toml(&records)
}

/// One field of a valid file made invalid: what is written there instead, and whether the
/// refusal is the parser's (a value of the wrong type, an unknown key) or the term check's.
#[derive(Debug, Clone)]
enum Spoil {
    /// A name that is no axis.
    AxisName,
    /// An axis the term's regressor cannot act on.
    AxisUnfit,
    /// A name that is no family of the library.
    FamilyName,
    /// A name that is no regressor of the term's family.
    RegressorName,
    /// A coefficient that is not finite.
    CoefficientNotFinite(&'static str),
    /// A coefficient that is not a number.
    CoefficientType,
    /// A locator outside its domain.
    LocatorDomain(&'static str),
    /// A locator of another family added.
    LocatorExtra,
    /// A key no term has.
    UnknownKey,
}

fn spoil() -> BoxedStrategy<Spoil> {
    prop_oneof![
        Just(Spoil::AxisName),
        Just(Spoil::AxisUnfit),
        Just(Spoil::FamilyName),
        Just(Spoil::RegressorName),
        select(&["nan", "inf", "-inf", "+nan"][..]).prop_map(Spoil::CoefficientNotFinite),
        Just(Spoil::CoefficientType),
        select(
            &[
                "0",
                "-0.0",
                "-1",
                "nan",
                "inf",
                "-inf",
                "1e300",
                "-1e300",
                "1.7976931348623157e308",
                "1000.0000000000001",
                "7200.000000000001",
                "1000000.0000000001"
            ][..]
        )
        .prop_map(Spoil::LocatorDomain),
        Just(Spoil::LocatorExtra),
        Just(Spoil::UnknownKey),
    ]
    .boxed()
}

/// The line (1-based) of `field` in the `k`-th `[[term]]` table of `text` as
/// [`extension_toml`] lays it out.
fn field_line_of(text: &str, k: usize, field: &str) -> Option<usize> {
    let mut table = None;
    for (n, line) in text.lines().enumerate() {
        if line == "[[term]]" {
            table = Some(table.map_or(0, |t| t + 1));
        } else if table == Some(k) && line.starts_with(&format!("{field} = ")) {
            return Some(n + 1);
        }
    }
    None
}

/// `text` with line `line` (1-based) replaced by `with`.
fn replace_line(text: &str, line: usize, with: &str) -> String {
    text.split('\n')
        .enumerate()
        .map(|(n, l)| if n + 1 == line { with } else { l })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Spoils one field of term `k` of a valid extension and checks that the refusal names that
/// field and its line.
fn spoiled_field(terms: &[Term], k: usize, how: &Spoil) -> Result<(), TestCaseError> {
    let records: Vec<TermRecord> = terms.iter().map(TermRecord::of).collect();
    let text = extension_toml(&records);
    let term = terms[k];
    let locator = term.regressor.family().locator();
    let line = |field: &str| field_line_of(&text, k, field).expect("the field is written");
    // A field's line rewritten: (its line, the new text).
    let rewrite = |field: &str, value: String| (line(field), format!("{field} = {value}"));
    // A line added after the regressor's: (the regressor's line, it and the new one).
    let added = |extra: String| {
        let at = line("regressor");
        let own = text.split('\n').nth(at - 1).unwrap_or_default();
        (at, format!("{own}\n{extra}"))
    };
    // (the field named, the line rewritten and its new text, the line named, whether the
    // parser refuses it rather than the term check).
    let (field, (at, with), parser) = match how {
        Spoil::AxisName => ("axis", rewrite("axis", "\"Cz\"".into()), false),
        Spoil::AxisUnfit => {
            // The ejector for an aerodynamic regressor, an aerodynamic axis for a stroke
            // shape; a step fits every axis, so it gets a name that is no axis.
            let axis = match term.regressor.family() {
                Family::Step => "ejector axis",
                Family::EjectorStroke => "Cm",
                _ => "ejector",
            };
            ("axis", rewrite("axis", format!("\"{axis}\"")), false)
        }
        Spoil::FamilyName => ("family", rewrite("family", "\"window\"".into()), false),
        Spoil::RegressorName => (
            "regressor",
            rewrite("regressor", "\"window\"".into()),
            false,
        ),
        Spoil::CoefficientNotFinite(v) => {
            ("coefficient", rewrite("coefficient", v.to_string()), false)
        }
        Spoil::CoefficientType => (
            "coefficient",
            rewrite("coefficient", "\"0.5\"".into()),
            true,
        ),
        Spoil::LocatorDomain(v) => match locator {
            // A value of the domain (a step time of 0, a frequency of 0) spoils nothing.
            Some(name) if v.parse().is_ok_and(|x| domain_of(name).contains(x)) => return Ok(()),
            Some(name) => (name, rewrite(name, v.to_string()), false),
            None => return Ok(()),
        },
        Spoil::LocatorExtra => {
            let extra = ["lambda_m", "mach0", "t_on_s", "f_hz"]
                .into_iter()
                .find(|n| Some(*n) != locator)
                .expect("four locators");
            (extra, added(format!("{extra} = 0.5")), false)
        }
        Spoil::UnknownKey => ("colour", added("colour = 1".into()), true),
    };
    let named_line = if with.contains('\n') { at + 1 } else { at };
    let spoilt = replace_line(&text, at, &with);
    let result = parse_extension(&spoilt, "fuzz.toml");
    prop_assert!(result.is_err(), "{how:?} accepted:\n{spoilt}");
    let e = result.unwrap_err();
    check_extension_error(&e, &spoilt)?;
    if parser {
        let ExtensionError::Parse { message, .. } = &e else {
            return Err(TestCaseError::fail(format!(
                "{how:?}: not the parser's: {e}"
            )));
        };
        prop_assert!(
            message.contains(&format!("line {named_line}")),
            "{how:?} on line {named_line}: {e}\n{spoilt}"
        );
    } else {
        let ExtensionError::Term {
            line,
            index,
            field: named,
            ..
        } = &e
        else {
            return Err(TestCaseError::fail(format!(
                "{how:?}: not a term error: {e}"
            )));
        };
        prop_assert_eq!(
            (*line, *index, *named),
            (named_line, k + 1, field),
            "{}\n{}",
            e,
            spoilt
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(512))]

    #[test]
    fn extension_arbitrary_text(text in arbitrary_text("[-0-9a-zA-Z_.=\\[\\]{},\"' #\\n]")) {
        extension_text(&text)?;
    }

    /// A valid extension written by `extension_toml` reads back as the same terms, to the bit.
    #[test]
    fn extension_round_trip((terms, records) in valid_extension()) {
        let text = extension_toml(&records);
        let read = parse_extension(&text, "fuzz.toml");
        prop_assert!(
            read.as_ref().is_ok_and(|r| same_terms(r, &terms)),
            "{read:?} against {terms:?}\n{text}"
        );
        extension_text(&text)?;
    }

    /// One field of one term made invalid: the refusal names that field and its line.
    #[test]
    fn extension_spoiled_field(
        (terms, k) in prop::collection::vec(valid_term(), 1..=MAX_TERMS)
            .prop_flat_map(|t| { let n = t.len(); (Just(t), 0..n) }),
        how in spoil(),
    ) {
        spoiled_field(&terms, k, &how)?;
    }
}

proptest! {
    #![proptest_config(config(2048))]

    #[test]
    fn extension_mutations(e in edits(text_edit(EXTENSION_TOKENS), 8)) {
        extension_text(&mutated(&extension_base(), &e))?;
    }

    #[test]
    fn extension_numbers(e in number_edits(3)) {
        extension_text(&mutated(&extension_base(), &e))?;
    }
}

/// The bases are valid, so that the mutations start from what the readers accept.
#[test]
fn the_bases_read() {
    let t = Trajectory::parse(&telemetry_base(), "base.csv").unwrap();
    assert_eq!(t.len(), 40);
    check_trajectory(&t, "base.csv").unwrap();
    scenario_text(DEFAULT_SCENARIO_TOML).unwrap();
    Scenario::from_toml_str(DEFAULT_SCENARIO_TOML, "base").unwrap();
    let json = serde_json::to_string(&Factors::TRUTH).unwrap();
    assert_eq!(
        Factors::from_json_str(&json, &FactorTable::default()).unwrap(),
        Factors::TRUTH
    );
    telemetry_file(telemetry_base().as_bytes()).unwrap();
    assert_eq!(parse_extension(&extension_base(), "base").unwrap().len(), 6);
    extension_text(&extension_base()).unwrap();
}

/// Reads `path` with reader `reader` (0 telemetry, 1 a table through a scenario, 2 a scenario,
/// 3 an extension): `Ok` or the error's chain.
fn read_as(reader: usize, path: PathBuf, dir: PathBuf) -> Result<(), String> {
    use crate::input_files::chain;
    match reader {
        0 => Trajectory::read(&path).map(drop).map_err(|e| chain(&e)),
        1 => {
            let text = DEFAULT_SCENARIO_TOML.replace(
                "cl_p_per_rad = -40.0",
                &format!(
                    "cl_p_per_rad = {{ csv = {:?} }}",
                    path.display().to_string()
                ),
            );
            let s = dir.join("with-table.toml");
            std::fs::write(&s, text).map_err(|e| e.to_string())?;
            Scenario::load(&s).map(drop).map_err(|e| chain(&e))
        }
        2 => Scenario::load(&path).map(drop).map_err(|e| chain(&e)),
        _ => sepval_common::extension::load_extension(&path)
            .map(drop)
            .map_err(|e| chain(&e)),
    }
}

proptest! {
    #![proptest_config(config(48))]

    /// Every reader given every kind of path answers at once: what is not a regular file, or
    /// is over the reader's limit, is refused naming the path and why; a regular file within
    /// it is read or refused for its content.
    #[test]
    fn readers_refuse_what_is_not_a_regular_file_within_its_limit(
        reader in 0..4usize,
        kind in path_kind(),
        bytes in prop::collection::vec(any::<u8>(), 0..200),
    ) {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let limit = [MAX_TELEMETRY_BYTES, MAX_TABLE_CSV_BYTES, MAX_SCENARIO_BYTES, MAX_EXTENSION_BYTES][reader];
        let path = kind.make(dir.path(), "input", &bytes, limit);
        let shown = path.display().to_string();
        let d = dir.path().to_path_buf();
        let result = within_deadline(&format!("reader {reader} on {kind:?}"), move || read_as(reader, path, d))?;
        match (kind.refusal(), result) {
            (Some(why), Err(e)) => prop_assert!(e.contains(&format!("{shown}: ")) && e.contains(why), "{kind:?}: {e}"),
            (Some(_), Ok(())) => prop_assert!(false, "{kind:?} read by reader {reader}"),
            (None, Err(e)) => prop_assert!(!e.is_empty()),
            (None, Ok(())) => prop_assert!(kind == PathKind::Regular),
        }
    }
}
