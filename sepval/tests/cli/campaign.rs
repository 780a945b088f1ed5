//! `sepval campaign` end to end: init under the prior, next (never an unsafe condition, a
//! batch of distinct conditions, none safe said with the least risky), add (a release checked,
//! fitted, round 1), the refusals (a release twice, a broken file, another store's) with
//! nothing changed, the same bits on threads and on iceoryx2 workers (the prior's envelope and
//! an added round), no false clear in any round of a rehearsal, and an interrupted add undone.
//! Reduced samples; release build.

use std::path::Path;

use super::hardening_on_disk::snapshot;

use sepval_tests::{ok, refused, sepval};
use serde_json::Value;

fn aircraft() -> String {
    super::envelope::example("aircraft.toml")
}

/// `campaign init` of a 5 x 5 grid in `dir`/`out` with `criterion` mm on `threads` threads.
fn init(dir: &Path, out: &str, criterion: &str, threads: &str) {
    let evaluator = ["--evaluator", "inproc", "--threads", threads];
    init_on(dir, out, GRID_5X5, criterion, "100", &evaluator);
}

/// The 5 x 5 grid of most tests: Mach 0.6 to 1.0, alpha -4 to 8 deg.
const GRID_5X5: [&str; 2] = ["0.6:1.0:5", "-4:8:5"];

/// `campaign init` of the grid `[mach, alpha_deg]` (each `FROM:TO:N`) in `dir`/`out`.
fn init_on(
    dir: &Path,
    out: &str,
    [mach, alpha_deg]: [&str; 2],
    criterion: &str,
    samples: &str,
    evaluator: &[&str],
) {
    let a = aircraft();
    let mut args = vec![
        "campaign",
        "init",
        "--aircraft",
        &a,
        "--mach",
        mach,
        "--alpha-deg",
        alpha_deg,
        "--samples",
        samples,
        "--clearance-mm",
        criterion,
        "--generations",
        "5",
        "--out",
        out,
    ];
    args.extend(evaluator);
    ok(&sepval(&args, dir));
}

/// The campaign's derived files agree with its records: report.html says status.json's counts
/// and names every release flown, and every round has its map.
fn pages_agree(camp: &Path) {
    let file = json(&camp.join("campaign.json"));
    let status = json(&camp.join("status.json"));
    let html = std::fs::read_to_string(camp.join("report.html")).unwrap();
    let counts = format!(
        "cleared {} of {} conditions, {} fail, {} undecided",
        status["cleared"], status["conditions"], status["fails"], status["undecided"]
    );
    assert!(html.contains(&counts), "{counts} not in {html}");
    let releases = file["releases"].as_array().unwrap();
    assert_eq!(status["releases_flown"], releases.len());
    for r in releases {
        assert!(html.contains(r["file"].as_str().unwrap()), "{r}");
    }
    if releases.is_empty() {
        assert!(html.contains("No release has checked the model yet"));
    }
    for r in file["rounds"].as_array().unwrap() {
        let map = format!("figures/state-{:02}.png", r["round"].as_u64().unwrap());
        assert!(camp.join(&map).is_file(), "{map}");
    }
    assert!(camp.join("figures/counts.png").is_file());
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn next_plans_only_safe_distinct_conditions_and_says_when_none_is_safe() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    init(dir, "c", "108", "2");
    let env = std::fs::read_to_string(dir.join("c/envelope.csv")).unwrap();
    assert!(env.lines().next().unwrap().ends_with(",state"), "{env}");
    pages_agree(&dir.join("c"));
    ok(&sepval(&["campaign", "next", "c", "--count", "3"], dir));
    let next = json(&dir.join("c/next.json"));
    assert_eq!(next["format"], "sepval-campaign-next/1");
    let releases = next["releases"].as_array().unwrap();
    assert!(!releases.is_empty(), "{next}");
    let mut seen = Vec::new();
    for r in releases {
        assert!(r["p_fail"].as_f64().unwrap() <= 0.01, "unsafe planned: {r}");
        let at = (r["mach"].to_string(), r["alpha_deg"].to_string());
        assert!(!seen.contains(&at), "the same condition twice: {next}");
        seen.push(at);
        let why = r["why"].as_str().unwrap();
        assert!(
            why.contains("expected to settle") || why.contains("farthest from every release"),
            "{why}"
        );
    }
    // A criterion that nothing meets with the fly risk: nothing planned, the least risky named.
    init(dir, "d", "125", "2");
    let out = sepval(&["campaign", "next", "d"], dir);
    ok(&out);
    let next = json(&dir.join("d/next.json"));
    assert_eq!(next["releases"].as_array().unwrap().len(), 0, "{next}");
    assert!(
        next["least_risky"]["p_fail"].as_f64().unwrap() > 0.01,
        "{next}"
    );
}

#[test]
fn the_envelope_is_the_same_bits_on_one_thread_two_and_two_iceoryx2_workers() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // A 3 x 3 grid: the same bits is a property of each condition, and 9 conditions cost a
    // third of 25 (before 2026-12-02 the 5 x 5 grid, 19 s of the fast tier).
    let on = |out: &str, evaluator: &[&str]| init_on(dir, out, GRID_3X3, "25.4", "100", evaluator);
    on("one", &["--evaluator", "inproc", "--threads", "1"]);
    on("two", &["--evaluator", "inproc", "--threads", "2"]);
    on("ipc", &["--evaluator", "ipc", "--workers", "2"]);
    let read = |d: &str| std::fs::read(dir.join(d).join("envelope.csv")).unwrap();
    assert_eq!(read("one"), read("two"));
    assert_eq!(read("one"), read("ipc"));
    let status = json(&dir.join("one/status.json"));
    assert_eq!(status["conditions"], 9);
    assert_eq!(status["releases_flown"], 0);
}

/// A release flown at Mach 0.8, alpha 2 deg with the truth factors and noise, in `dir`.
fn release(dir: &Path, name: &str, noise_seed: &str) -> String {
    release_of(dir, name, noise_seed, &[])
}

/// [`release`] with each `(key, line)` of `more`: the first line of the default scenario that
/// starts with `key = ` becomes `line`.
fn release_of(dir: &Path, name: &str, noise_seed: &str, more: &[(&str, &str)]) -> String {
    ok(&sepval(&["scenario", "--out", "base.toml"], dir));
    let text = std::fs::read_to_string(dir.join("base.toml")).unwrap();
    let mut edits: Vec<(&str, &str, bool)> =
        [("mach", "mach = 0.8"), ("alpha_deg", "alpha_deg = 2.0")]
            .iter()
            .chain(more)
            .map(|(k, l)| (*k, *l, false))
            .collect();
    let text: String = text
        .lines()
        .map(|l| {
            for (key, line, done) in edits.iter_mut() {
                if !*done && l.starts_with(&format!("{key} = ")) {
                    *done = true;
                    return line.to_string();
                }
            }
            l.to_string()
        })
        .collect::<Vec<_>>()
        .join("\n");
    assert!(
        edits.iter().all(|e| e.2),
        "a key not in the scenario: {edits:?}"
    );
    let scenario = format!("{name}.toml");
    std::fs::write(dir.join(&scenario), text).unwrap();
    ok(&sepval(
        &[
            "simulate",
            "--scenario",
            &scenario,
            "--factors",
            "truth",
            "--noise-seed",
            noise_seed,
            "--out",
            name,
        ],
        dir,
    ));
    name.to_string()
}

#[test]
fn add_records_a_round_the_same_on_threads_and_workers_and_refuses_a_copy_a_broken_file_and_another_store()
 {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // A 3 x 3 grid holding the release's condition (Mach 0.8, alpha 2 deg): the refusals do
    // not depend on the grid's size, nor the same bits on threads and workers (before
    // 2026-12-02 the 5 x 5 grid, 35 s of the fast tier).
    let threads = ["--evaluator", "inproc", "--threads", "2"];
    init_on(dir, "c", GRID_3X3, "25.4", "100", &threads);
    let r = release(dir, "r1.csv", "5");
    let add_to = |camp: &str, file: &str, evaluator: &[&str]| {
        let args = [&["campaign", "add", camp, "--data", file][..], evaluator].concat();
        sepval(&args, dir)
    };
    let add = |file: &str| add_to("c", file, &["--evaluator", "inproc", "--threads", "2"]);
    ok(&add(&r));
    let camp = json(&dir.join("c/campaign.json"));
    assert_eq!(camp["format"], "sepval-campaign/1");
    assert_eq!(camp["releases"].as_array().unwrap().len(), 1);
    assert_eq!(camp["rounds"].as_array().unwrap().len(), 2);
    assert!(dir.join("c/rounds/01/diagnosis/diagnosis.json").is_file());
    assert!(
        dir.join("c/rounds/01/diagnosis/baseline/result.json")
            .is_file()
    );
    assert!(dir.join("c/figures/state-01.png").is_file());
    let status = sepval(&["campaign", "status", "c"], dir);
    ok(&status);
    assert!(String::from_utf8_lossy(&status.stdout).contains("after 1 release"));
    let before = snapshot(&dir.join("c"));
    // The same release under another name.
    std::fs::copy(dir.join(&r), dir.join("copy.csv")).unwrap();
    refused(&add("copy.csv"), "already in the campaign");
    // A file that does not read.
    std::fs::write(dir.join("broken.csv"), "t_s,x_m\n0,1,2,3\n").unwrap();
    refused(&add("broken.csv"), "broken.csv");
    // A release of another store: a heavier one, its mass in its metadata as telemetry
    // records it (`sepval simulate` names the scenario, not the store's fields).
    let heavy = release_of(dir, "heavy.csv", "6", &[("mass_kg", "mass_kg = 1000.0")]);
    let text = std::fs::read_to_string(dir.join(&heavy)).unwrap();
    std::fs::write(dir.join(&heavy), format!("# store.mass_kg = 1000\n{text}")).unwrap();
    refused(&add(&heavy), "another store");
    assert_eq!(
        snapshot(&dir.join("c")),
        before,
        "a refusal changed the campaign"
    );
    // What the user puts in the campaign directory is never the campaign's: `status` leaves
    // it, and an add whose copy would go where a file is refuses, the file kept (before
    // 2026-11-29 both removed it, the release given from there included).
    std::fs::write(dir.join("c/releases/notes.txt"), "mine").unwrap();
    std::fs::create_dir_all(dir.join("c/rounds/05")).unwrap();
    std::fs::write(dir.join("c/rounds/05/notes.txt"), "mine").unwrap();
    let r2 = release(dir, "r2.csv", "7");
    std::fs::copy(dir.join(&r2), dir.join("c/releases/02.csv")).unwrap();
    ok(&sepval(&["campaign", "status", "c"], dir));
    refused(
        &add("c/releases/02.csv"),
        "c/releases/02.csv is there already, and the campaign's record (campaign.json) does not name it",
    );
    for f in [
        "releases/notes.txt",
        "rounds/05/notes.txt",
        "releases/02.csv",
    ] {
        assert!(dir.join("c").join(f).is_file(), "{f} was removed");
    }
    // The same release added over two iceoryx2 workers: the same round, bit for bit.
    let workers = ["--evaluator", "ipc", "--workers", "2"];
    init_on(dir, "w", GRID_3X3, "25.4", "100", &workers);
    ok(&add_to("w", &r, &workers));
    for file in ["envelope.csv", "rounds/01/assessment.json"] {
        let read = |c: &str| std::fs::read(dir.join(c).join(file)).unwrap();
        assert!(
            read("c") == read("w"),
            "{file} differs between 2 threads and 2 workers"
        );
    }
}

#[test]
fn init_refuses_a_directory_that_is_not_empty_and_bad_probabilities() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::create_dir(dir.join("c")).unwrap();
    std::fs::write(dir.join("c/thesis.tex"), "mine").unwrap();
    let a = aircraft();
    let init = |extra: &[&str], out: &str| {
        let mut args = vec!["campaign", "init", "--aircraft", &a, "--mach", "0.6:1.0:2"];
        args.extend(extra);
        args.extend(["--out", out]);
        sepval(&args, dir)
    };
    refused(&init(&[], "c"), "not empty");
    assert_eq!(
        std::fs::read_to_string(dir.join("c/thesis.tex")).unwrap(),
        "mine"
    );
    refused(&init(&["--allowed", "0.7"], "d"), "--allowed 0.7");
    assert!(!dir.join("d").exists());
}

/// `campaign rehearse` over a 3 x 3 grid with `extra` truth flags; returns rehearsal.json.
fn rehearse(dir: &Path, out: &str, criterion: &str, extra: &[&str]) -> Value {
    let a = aircraft();
    let mut args = vec![
        "campaign",
        "rehearse",
        "--aircraft",
        &a,
        "--mach",
        "0.6:1.2:3",
        "--alpha-deg",
        "-6:10:3",
        "--samples",
        "100",
        "--clearance-mm",
        criterion,
        "--evaluator",
        "inproc",
        "--threads",
        "2",
        "--generations",
        "5",
        "--releases",
        "4",
        "--truth-factors",
        "nominal",
        "--out",
        out,
    ];
    args.extend(extra);
    ok(&sepval(&args, dir));
    json(&dir.join(out).join("rehearsal.json"))
}

#[test]
fn a_rehearsal_of_a_null_truth_settles_with_no_false_clear_or_fail() {
    let tmp = tempfile::tempdir().unwrap();
    let r = rehearse(tmp.path(), "null", "25.4", &[]);
    pages_agree(&tmp.path().join("null"));
    // The page shows the comparison with the truth first, round by round, as rehearsal.json
    // records it.
    let html = std::fs::read_to_string(tmp.path().join("null/report.html")).unwrap();
    let section = html
        .find("Against the truth (a rehearsal)")
        .expect("the rehearsal's section");
    assert!(section < html.find("figures/state-").unwrap(), "first");
    assert!(html.contains(r["words"].as_str().unwrap()), "{html}");
    let rounds = r["rounds"].as_array().unwrap().len();
    let flown = r["flown"].as_array().unwrap().len();
    let told = html.matches("<td>safe</td>").count() + html.matches("<td>UNSAFE</td>").count();
    assert_eq!(told, flown, "{html}");
    assert!(rounds >= 2, "{r}");
    assert_eq!(r["format"], "sepval-campaign-rehearsal/1");
    assert_eq!(r["settled"], true, "{r}");
    for round in r["rounds"].as_array().unwrap() {
        assert_eq!(round["false_clears"], 0, "{round}");
        assert_eq!(round["false_fails"], 0, "{round}");
    }
    forecasts_account_for_the_rounds(&r, &html);
}

/// Each release flown carries the plan's forecast and what it settled, and these account for
/// the rounds: the conditions settled less those unsettled, release by release, are the
/// undecided conditions the round before less those after.
fn forecasts_account_for_the_rounds(r: &Value, html: &str) {
    let rounds = r["rounds"].as_array().unwrap();
    let undecided = |k: usize| rounds[k]["counts"]["undecided"].as_i64().unwrap();
    for (k, f) in r["flown"].as_array().unwrap().iter().enumerate() {
        let expected = f["expected_settled"].as_f64().unwrap();
        assert!(expected >= 0.0, "{f}");
        let net = f["settled"].as_i64().unwrap() - f["unsettled"].as_i64().unwrap();
        assert_eq!(
            net,
            undecided(k) - undecided(k + 1),
            "release {}: {r}",
            k + 1
        );
        let row = format!(
            "<td>{:.1}</td><td>{}</td></tr>",
            expected,
            f["settled"].as_i64().unwrap()
        );
        assert!(html.contains(&row), "{row} not in the page");
    }
    assert!(
        r["words"]
            .as_str()
            .unwrap()
            .contains("the plan expected them to settle"),
        "{r}"
    );
}

#[test]
fn a_rehearsal_with_a_hidden_cause_flies_only_truly_safe_releases_and_stays_conservative() {
    // A diagnosis per round with discovery at work: 122 s of the fast tier's 167 (2026-11-27).
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let r = rehearse(
        tmp.path(),
        "hidden",
        "100",
        &[
            "--truth-effect",
            "pitch_stiffness_cubic=-1000",
            "--check-settled",
        ],
    );
    let truth_fails = r["truth"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|t| t["fails"] == true)
        .count();
    assert!(
        truth_fails > 0,
        "the truth must fail somewhere in the grid: {r}"
    );
    assert!(!r["flown"].as_array().unwrap().is_empty(), "{r}");
    for f in r["flown"].as_array().unwrap() {
        assert_eq!(f["truly_safe"], true, "an unsafe release was flown: {f}");
    }
    // Nothing the truth fails is cleared in any round: not by the prior (which clears
    // nothing before a release checks it: a hidden cubic pitch stiffness brings the store back
    // to the pylon at alpha 10 deg where no sample of the prior goes), not once the cause is
    // diagnosed.
    for round in r["rounds"].as_array().unwrap() {
        assert_eq!(round["false_clears"], 0, "{round}");
    }
    // Settled within the issue's 4 releases (measured 2026-11-27: after 2, 6 cleared, 1 fails,
    // 2 undecided that no safe release is expected to settle).
    assert_eq!(r["settled"], true, "{r}");
    settled_holds(&r);
}

/// A rehearsal that settled with conditions undecided had the claim checked
/// (`--check-settled`): every condition then safe to fly was flown in turn, and none settled
/// a condition.
fn settled_holds(r: &Value) {
    let last = r["rounds"].as_array().unwrap().last().unwrap();
    if last["counts"]["undecided"] == 0 {
        return;
    }
    let check = r["settled_check"].as_array().expect("the settled check");
    assert!(!check.is_empty(), "{r}");
    for c in check {
        assert_eq!(c["settled"], 0, "\"settled\" was wrong: {c}");
    }
    let words = r["words"].as_str().unwrap();
    assert!(words.contains(&format!("\"settled\" checked by flying each of the {} condition(s) then safe to fly in turn: none settles", check.len())), "{words}");
}

#[test]
fn a_rehearsal_with_a_hidden_cause_outside_the_catalogue_settles_conservatively_and_names_it() {
    // A diagnosis with discovery per round: 25 s on 2 threads (2026-11-27).
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // A pitch moment in the square of the angle of attack: no effect of the catalogue has it,
    // and it makes the store tumble (diverge, a failure) at alpha 10 deg from Mach 0.9 up.
    std::fs::write(
        dir.join("hidden.toml"),
        "format = \"sepval-extension/1\"\n\n[[term]]\naxis = \"Cm\"\nfamily = \"flow_angle\"\nregressor = \"alpha2\"\ncoefficient = 20.0\n",
    )
    .unwrap();
    let r = rehearse(dir, "outside", "100", &["--truth-extension", "hidden.toml"]);
    let truth = r["truth"].as_array().unwrap();
    let fails: Vec<&Value> = truth.iter().filter(|t| t["fails"] == true).collect();
    assert!(
        !fails.is_empty() && fails.len() < truth.len(),
        "the truth's boundary must lie inside the grid: {r}"
    );
    // Where the truth tumbles (diverges) the condition fails; it is not a refusal.
    let tumbles = truth
        .iter()
        .filter(|t| t["min_clearance_mm"] == "nan")
        .count();
    assert!(tumbles > 0, "{r}");
    assert!(
        r["words"].as_str().unwrap().contains(&format!(
            "the truth tumbles (its simulation diverges) at {tumbles} of the grid's"
        )),
        "{r}"
    );
    assert_eq!(r["settled"], true, "{r}");
    let flown = r["flown"].as_array().unwrap();
    assert!(!flown.is_empty() && flown.len() <= 4, "{r}");
    for f in flown {
        assert_eq!(f["truly_safe"], true, "an unsafe release was flown: {f}");
    }
    for round in r["rounds"].as_array().unwrap() {
        assert_eq!(round["false_clears"], 0, "{round}");
    }
    // The cause named: discovery beyond the catalogue finds the Cm alpha^2 term (measured
    // 2026-11-27: 20.16 +- 0.46 against the truth's 20, after 2 releases, the envelope then
    // the truth's: 7 cleared, 2 fail).
    let last = format!("outside/rounds/{:02}/diagnosis/diagnosis.json", flown.len());
    let diagnosis = json(&dir.join(last));
    let named = diagnosis["discovered"]
        .as_array()
        .unwrap()
        .iter()
        .any(|d| d["axis"] == "Cm" && d["term"] == "alpha^2");
    assert!(named, "the hidden term is not named: {diagnosis}");
}

#[test]
fn an_add_interrupted_by_sigterm_leaves_the_campaign_as_it_was() {
    use sepval_tests::{interrupt, spawn_sepval, wait_for};
    use std::time::Duration;
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // Enough samples that the new round's envelope takes seconds (about 8 s on this 2 x 2 grid,
    // 2026-11-27), on a grid small enough that `init` takes as long, not 45 s as on 5 x 5.
    init_on(
        dir,
        "c",
        ["0.6:1.0:2", "-4:8:2"],
        "25.4",
        "2000",
        &["--evaluator", "inproc", "--threads", "2"],
    );
    let r = release(dir, "r1.csv", "5");
    let before = snapshot(&dir.join("c"));
    let mut child = spawn_sepval(
        &[
            "campaign",
            "add",
            "c",
            "--data",
            &r,
            "--evaluator",
            "inproc",
            "--threads",
            "2",
        ],
        dir,
    );
    // The round is being assessed once its staging directory is there.
    let staged = dir.join("c/.staging/round");
    wait_for("the round's staging", Duration::from_secs(120), || {
        staged.exists()
    });
    interrupt(
        &mut child,
        libc::SIGTERM,
        "campaign add after SIGTERM",
        Duration::from_secs(30),
    );
    assert_eq!(
        snapshot(&dir.join("c")),
        before,
        "the interrupted add changed the campaign"
    );
}

/// The 3 x 3 grid of the narrowing tests: Mach 0.6 to 1.0, alpha -4 to 8 deg.
const GRID_3X3: [&str; 2] = ["0.6:1.0:3", "-4:8:3"];

/// When nothing is safe to fly under the default prior, `next` names the factor whose spread
/// makes the least risky condition risky and how narrow it must be known; a campaign begun
/// from that narrower prior (other draws: another seed) then has a condition safe to fly. And
/// when the prior's mean itself fails, it says that no narrowing helps.
#[test]
fn with_nothing_safe_to_fly_next_names_the_narrowing_that_makes_one_safe_and_it_does() {
    // Three envelopes of 9 conditions at 1 000 samples: 25 s on 2 threads (2026-12-01).
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let threads = ["--evaluator", "inproc", "--threads", "2"];
    init_on(dir, "wide", GRID_3X3, "112", "1000", &threads);
    ok(&sepval(&["campaign", "next", "wide"], dir));
    let next = json(&dir.join("wide/next.json"));
    assert_eq!(next["releases"].as_array().unwrap().len(), 0, "{next}");
    let n = &next["narrowing"];
    assert_eq!(n["mean_clears"], true, "{next}");
    let first = &n["factors"][0];
    let sd = first["sd_needed"]
        .as_f64()
        .expect("a factor that suffices alone");
    let factor = first["factor"].as_str().unwrap();
    let words = next["words"].as_str().unwrap();
    assert!(
        words.contains(&format!("with {factor} known to sd")),
        "{words}"
    );
    let camp = json(&dir.join("wide/campaign.json"));
    let mean = camp["settings"]["prior"]["factors"][factor]["mean"].clone();
    let prior = format!(
        r#"{{"format":"sepval-prior/1","factors":{{"{factor}":{{"mean":{mean},"sd":{sd}}}}}}}"#
    );
    std::fs::write(dir.join("narrow.json"), prior).unwrap();
    let narrow = [&threads[..], &["--prior", "narrow.json", "--seed", "2"]].concat();
    init_on(dir, "narrow", GRID_3X3, "112", "1000", &narrow);
    ok(&sepval(&["campaign", "next", "narrow"], dir));
    let next = json(&dir.join("narrow/next.json"));
    let releases = next["releases"].as_array().unwrap();
    assert!(
        !releases.is_empty(),
        "the narrowing promised did not hold: {next}"
    );
    assert!(releases[0]["p_fail"].as_f64().unwrap() <= 0.01, "{next}");
    // A criterion the prior's mean does not meet at any condition: no narrowing helps.
    init_on(dir, "far", GRID_3X3, "125", "200", &threads);
    ok(&sepval(&["campaign", "next", "far"], dir));
    let next = json(&dir.join("far/next.json"));
    assert_eq!(next["narrowing"]["mean_clears"], false, "{next}");
    assert!(
        next["words"]
            .as_str()
            .unwrap()
            .contains("even the prior's mean fails to clear"),
        "{next}"
    );
}
