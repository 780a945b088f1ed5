//! `sepval plan` end to end on diagnoses of synthetic data on a base that is not the default
//! truth (a hidden roll_due_to_sideslip, which has no rivals; roll damping half the model's,
//! which has several): plan.json's fields and ranking with and without rivals,
//! the refusals of bad inputs with nothing written, and the same plan, bit for bit, over
//! iceoryx2 workers as in process. Reduced budgets; release build.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use sepval_common::scenario::Scenario;
use sepval_common::telemetry::Trajectory;
use sepval_tests::{REDUCED_BUDGET, ok, refused, sepval};
use serde_json::{Value, json};

use super::generator::{default_scenario, release, write};

/// Factors of the base model of these tests (not the default truth).
const BASE: &str = r#"{"fwdfac": 0.45, "aftfac": 0.65, "xinerfac": 0.98, "yinerfac": 1.03,
 "zinerfac": 0.97, "caoff": -0.02, "cyoff": 0.04, "czoff": -0.06, "cmoff": 0.1, "cnoff": -0.08,
 "cloff": -0.05, "caintfac": 1.1, "cyintfac": 1.4, "czintfac": 0.9, "cmintfac": 1.3,
 "cnintfac": 0.8, "clintfac": 1.6}"#;

/// A directory holding `diag/` (a diagnosis with no rivals), made once for every test here;
/// [`with_rivals`] adds `damping/diag/` (a diagnosis with real rivals) for the slow tier.
pub(crate) fn fixture() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        // Under target/ (CARGO_TARGET_TMPDIR), not /tmp: a static is never dropped, so the
        // fixture's directory is never removed.
        let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
        let p = dir.path();
        std::fs::write(p.join("base.json"), BASE).unwrap();
        ok(&sepval(
            &[
                "simulate",
                "--factors",
                "base.json",
                "--noise-seed",
                "5",
                "--effect",
                "roll_due_to_sideslip=-0.3",
                "--out",
                "d.csv",
            ],
            p,
        ));
        let head = ["diagnose", "--data", "d.csv"];
        ok(&sepval(
            &[&head[..], &REDUCED_BUDGET, &["--out", "diag"]].concat(),
            p,
        ));
        let d: Value =
            serde_json::from_str(&std::fs::read_to_string(p.join("diag/diagnosis.json")).unwrap())
                .unwrap();
        assert_eq!(d["rivals"], json!([]), "{}", d["verdict"]);
        dir
    })
    .path()
}

/// The fixture with `damping/diag/` too: a diagnosis with real rivals, made once.
pub(crate) fn with_rivals() -> &'static Path {
    static DAMPING: OnceLock<()> = OnceLock::new();
    let p = fixture();
    DAMPING.get_or_init(|| {
        // Real rivals: roll damping half the model's, on one release (the first case of
        // `diagnose/tests/discovery/rivals.rs`, by the tests' own generator): the catalogue's
        // roll_due_to_sideslip and the library's Cl terms, the true `Cl p` among them, cannot
        // be told apart.
        let model = default_scenario();
        let mut truth = model.clone();
        truth.aero.cl_p_per_rad = sepval_common::table::DerivativeCoefficient::constant(
            0.5 * model.aero.cl_p_per_rad.as_constant().unwrap(),
        );
        std::fs::create_dir(p.join("damping")).unwrap();
        let d = diagnose(
            &p.join("damping"),
            &[release(&truth, None, 31)],
            1,
            Some(&model),
        );
        assert_eq!(d["ambiguous"], true, "{}", d["verdict"]);
    });
    p
}

/// Writes the releases of the tests' generator into `dir` and diagnoses them through the
/// binary, `sepval diagnose` with the reduced budget (the first `fit` of them fitted, the rest
/// validated), with `scenario` (the embedded default when `None`); returns the diagnosis,
/// having checked its page, its figures and its summary: at most 12 lines, none over 160
/// characters (the rivals' line among them).
fn diagnose(dir: &Path, releases: &[Trajectory], fit: usize, scenario: Option<&Scenario>) -> Value {
    let mut args: Vec<String> = vec!["diagnose".into()];
    for (flag, name) in write(dir, releases, fit, scenario) {
        args.extend([flag.to_string(), name]);
    }
    for a in REDUCED_BUDGET.into_iter().chain(["--out", "diag"]) {
        args.push(a.into());
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = sepval(&args, dir);
    ok(&out);
    let d: Value =
        serde_json::from_slice(&std::fs::read(dir.join("diag/diagnosis.json")).unwrap()).unwrap();
    let html = std::fs::read_to_string(dir.join("diag/report.html")).unwrap();
    assert!(html.contains(d["verdict"].as_str().unwrap().split(',').next().unwrap()));
    assert!(dir.join("diag/figures/increments.png").exists());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.lines().count() <= 12, "{stdout}");
    assert!(stdout.lines().all(|l| l.chars().count() <= 160), "{stdout}");
    d
}

/// Runs `sepval plan --from FROM --out OUT` with `extra` flags in the fixture, in process;
/// returns plan.json.
fn plan(from: &str, out: &str, extra: &[&str]) -> Value {
    let mut args = vec!["plan", "--from", from, "--out", out];
    args.extend(extra);
    if !extra.contains(&"--evaluator") {
        args.extend(["--evaluator", "inproc", "--threads", "2"]);
    }
    let stdout = ok(&sepval(&args, fixture()));
    assert!(stdout.contains("recommend:"), "{stdout}");
    let dir = fixture().join(out);
    for f in ["plan.html", "figures/separation.png", "figures/rivals.png"] {
        assert!(dir.join(f).is_file(), "{f}");
    }
    serde_json::from_str(&std::fs::read_to_string(dir.join("plan.json")).unwrap()).unwrap()
}

fn numbers(conditions: &Value, field: &str) -> Vec<f64> {
    conditions
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c[field].as_f64().unwrap())
        .collect()
}

#[test]
fn without_rivals_the_plan_ranks_by_information() {
    let p = plan("diag", "info", &["--mach", "0.6:0.95", "--points", "4"]);
    assert_eq!(p["format"], "sepval-plan/1");
    assert_eq!(p["ranked_by"], "information");
    let c = &p["conditions"];
    assert_eq!(c.as_array().unwrap().len(), 4);
    let gains = numbers(c, "information_gain");
    assert!(gains.iter().all(|g| *g > 0.0), "{gains:?}");
    assert!(gains.windows(2).all(|w| w[0] >= w[1]), "{gains:?}");
    for (k, c) in c.as_array().unwrap().iter().enumerate() {
        assert_eq!(c["rank"], k + 1);
        assert_eq!(c["separation"], Value::Null);
        assert_eq!(c["separates"], json!([]));
        assert_eq!(c["status"], "ranked");
        // Axes not given stay at the first release's condition (the default scenario's).
        assert_eq!(c["beta_deg"], 0.0);
        for f in ["mach", "altitude_m", "alpha_deg", "gamma_deg"] {
            assert!(c[f].is_f64(), "{f}");
        }
    }
    let html = std::fs::read_to_string(fixture().join("info/plan.html")).unwrap();
    assert!(html.contains("Fly the next release at Mach"), "{html}");
    // A second plan into the same directory is refused, and nothing of the first is touched;
    // with --overwrite it replaces the first.
    let again = [
        "plan", "--from", "diag", "--out", "info", "--mach", "0.6:0.95",
    ];
    let before = std::fs::read(fixture().join("info/plan.json")).unwrap();
    let refused = sepval(
        &[&again[..], &["--points", "3", "--evaluator", "inproc"]].concat(),
        fixture(),
    );
    assert_eq!(refused.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(stderr.contains("--overwrite"), "{stderr}");
    assert_eq!(
        std::fs::read(fixture().join("info/plan.json")).unwrap(),
        before
    );
    let p = plan(
        "diag",
        "info",
        &["--mach", "0.6:0.95", "--points", "3", "--overwrite"],
    );
    assert_eq!(p["conditions"].as_array().unwrap().len(), 3);
}

#[test]
fn with_rivals_the_plan_ranks_by_pairs_separated_and_ipc_gives_the_same_bits() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    with_rivals();
    let flags = ["--mach", "0.7:0.95", "--beta-deg", "-6:6", "--points", "3"];
    let p = plan("damping/diag", "sep", &flags);
    assert_eq!(p["ranked_by"], "separation");
    let names: Vec<&str> = p["models"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    // The answer, the true cause and at least one more rival: pairs of rivals, neither of them
    // the answer, are compared too.
    assert!(names.len() >= 3, "{names:?}");
    assert!(names.contains(&"Cl: p d/2V"), "{names:?}");
    let all_pairs = names.len() * (names.len() - 1) / 2;
    let c = p["conditions"].as_array().unwrap();
    assert_eq!(c.len(), 9);
    let key = |c: &Value| {
        (
            c["separates"].as_array().unwrap().len(),
            c["separation"].as_f64().unwrap(),
            c["information_gain"].as_f64().unwrap(),
        )
    };
    for c in c {
        assert_eq!(c["status"], "ranked", "{c}");
        let pairs = c["pairs"].as_array().unwrap();
        assert_eq!(pairs.len(), all_pairs);
        // `separation` is the hardest pair's; `separates` lists the pairs above the threshold.
        let hardest = pairs
            .iter()
            .map(|q| q["separation"].as_f64().unwrap())
            .fold(f64::INFINITY, f64::min);
        assert_eq!(
            c["separation"].as_f64().unwrap().to_bits(),
            hardest.to_bits()
        );
        let separated: Vec<Value> = pairs
            .iter()
            .filter(|q| q["separation"].as_f64().unwrap() > 6.0)
            .map(|q| q["models"].clone())
            .collect();
        assert_eq!(c["separates"], json!(separated), "{c}");
    }
    // Ranked by the pairs separated, then the hardest pair's separation, then information.
    for w in c.windows(2) {
        let (a, b) = (key(&w[0]), key(&w[1]));
        let order =
            a.0.cmp(&b.0)
                .then(a.1.total_cmp(&b.1))
                .then(a.2.total_cmp(&b.2));
        assert_ne!(order, std::cmp::Ordering::Less, "{a:?} before {b:?}");
    }
    // The counts differ across the grid, so the rule is exercised, not only the separation.
    assert!(
        key(&c[0]).0 > key(&c[8]).0,
        "{:?} {:?}",
        key(&c[0]),
        key(&c[8])
    );
    let mut flags_ipc = flags.to_vec();
    flags_ipc.extend(["--evaluator", "ipc", "--workers", "2"]);
    let q = plan("damping/diag", "sep-ipc", &flags_ipc);
    // Same conditions, scores and pairs to the last bit (JSON numbers round-trip exactly).
    assert_eq!(p["conditions"], q["conditions"]);
    assert_eq!(p["evaluations"], q["evaluations"]);
}

/// Fails unless `sepval plan` with `args` is refused with `expected` and writes nothing.
fn refused_plan(args: &[&str], expected: &str) {
    let out: PathBuf = fixture().join("refused");
    let mut all = vec!["plan", "--out", "refused", "--evaluator", "inproc"];
    all.extend(args);
    refused(&sepval(&all, fixture()), expected);
    assert!(!out.exists(), "{args:?} wrote {}", out.display());
}

#[test]
fn bad_inputs_are_refused_naming_the_flag_and_nothing_is_written() {
    refused_plan(
        &["--from", "diag", "--mach", "0.9:0.6"],
        "--mach 0.9:0.6: LO is above HI",
    );
    refused_plan(&["--from", "diag", "--mach", "-0.5:0.9"], "--mach -0.5:0.9");
    refused_plan(
        &["--from", "diag", "--altitude-m", "0:nan"],
        "--altitude-m 0:NaN: expected finite numbers",
    );
    refused_plan(
        &["--from", "diag", "--beta-deg", "-95:0"],
        "--beta-deg -95:0",
    );
    refused_plan(
        &["--from", "diag", "--gamma-deg", "3"],
        "--gamma-deg 3: expected LO:HI",
    );
    refused_plan(
        &["--from", "diag", "--points", "0", "--mach", "0.6:0.9"],
        "--points 0",
    );
    refused_plan(
        &["--from", "."],
        "holds no diagnosis.json: not the output of `sepval diagnose`",
    );
    refused_plan(&["--from", "d.csv"], "not a directory");
}
