//! `sepval campaign init` from pre-flight knowledge (docs/campaign.md, "Beginning from
//! pre-flight knowledge"): a pre-flight trajectory of a known truth narrows the prior and makes
//! a condition safe to fly where nothing was; the Eglin CFD release (when present) refused
//! without its condition and fitted with it; the store's DAVE-ML uncertainty read back as the
//! factors' means and standard deviations (written by sepval's DAVE-ML writer, and in the slow
//! tier by `update --daveml`); bad inputs refused with nothing written. Reduced samples;
//! release build.

use std::path::Path;

use sepval_common::correction::Target;
use sepval_common::scenario::Scenario;
use sepval_common::table::{Axis, Table, Tabulated, Variable};
use sepval_tests::{ok, refused, sepval};
use serde_json::Value;

/// The grid of these tests: Mach 0.6 to 1.0 and alpha -4 to 8 deg, 3 x 3, at a criterion of
/// 112 mm, where the default prior leaves nothing safe to fly (the narrowing tests' grid,
/// campaign.rs).
fn init_args<'a>(aircraft: &'a str, out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "campaign",
        "init",
        "--aircraft",
        aircraft,
        "--mach",
        "0.6:1.0:3",
        "--alpha-deg",
        "-4:8:3",
        "--samples",
        "200",
        "--clearance-mm",
        "112",
        "--generations",
        "5",
        "--evaluator",
        "inproc",
        "--threads",
        "2",
        "--out",
        out,
    ];
    args.extend(extra);
    args
}

fn aircraft() -> String {
    super::envelope::example("aircraft.toml")
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// A release of the nominal store (the default prior's mean: a truth the prior holds
/// plausible) at its scenario's condition, with noise, as `dir/name`.
fn nominal_release(dir: &Path, name: &str) {
    ok(&sepval(
        &[
            "simulate",
            "--factors",
            "nominal",
            "--noise-seed",
            "7",
            "--out",
            name,
        ],
        dir,
    ));
}

#[test]
fn a_preflight_trajectory_of_a_known_truth_narrows_the_prior_and_makes_a_condition_safe_to_fly() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let a = aircraft();
    ok(&sepval(&init_args(&a, "bare", &[]), dir));
    ok(&sepval(&["campaign", "next", "bare"], dir));
    let next = json(&dir.join("bare/next.json"));
    assert!(next["releases"].as_array().unwrap().is_empty(), "{next}");
    let before = next["least_risky"]["p_fail"].as_f64().unwrap();
    assert!(before > 0.01, "{next}");
    assert!(
        next["words"].as_str().unwrap().contains("--preflight"),
        "the narrowing says how to supply it: {next}"
    );

    nominal_release(dir, "ctt.csv");
    let said = ok(&sepval(
        &init_args(&a, "pre", &["--preflight", "ctt.csv"]),
        dir,
    ));
    assert!(said.contains("1 pre-flight trajectories fitted"), "{said}");
    let camp = json(&dir.join("pre/campaign.json"));
    let prior = &camp["settings"]["prior"];
    let sources = prior["sources"].as_array().unwrap();
    assert_eq!(sources[0]["kind"], "default");
    let pf = &sources[1];
    assert_eq!(pf["kind"], "preflight", "{prior}");
    assert_eq!(pf["allowance_m"], 0.01);
    assert_eq!(pf["allowance_deg"], 1.0);
    assert_eq!(pf["trajectories"][0]["condition"]["mach"], 0.95);
    // The fit reaches the noise the release was made with (0.003 m, 0.1 deg).
    let rms = pf["rms_pos_m"].as_f64().unwrap();
    assert!(rms < 0.005, "{pf}");
    assert!(dir.join("pre/preflight/result.json").is_file());
    // The ejector, which the release sees, is narrowed; its mean stays near the truth's.
    let f = &prior["factors"]["fwdfac"];
    assert!(f["sd"].as_f64().unwrap() < 0.5 * 0.8 / 6.0, "{f}");
    assert!((f["mean"].as_f64().unwrap() - 0.5).abs() < 3.0 * f["sd"].as_f64().unwrap());
    // The full covariance is kept, symmetric and correlated.
    let cov = prior["covariance"].as_array().unwrap();
    assert_eq!(cov.len(), 17);
    let c = |i: usize, j: usize| cov[i][j].as_f64().unwrap();
    assert!((c(0, 1) - c(1, 0)).abs() < 1e-15);
    assert!(
        (0..17)
            .any(|i| (0..17).any(|j| i != j && c(i, j).abs() > 0.1 * (c(i, i) * c(j, j)).sqrt())),
        "no correlation kept"
    );
    ok(&sepval(&["campaign", "next", "pre"], dir));
    let next = json(&dir.join("pre/next.json"));
    let releases = next["releases"].as_array().unwrap();
    assert!(!releases.is_empty(), "still nothing safe to fly: {next}");
    assert!(releases[0]["p_fail"].as_f64().unwrap() <= 0.01, "{next}");
}

/// Each refusal is exit status 2, says what is wrong, and leaves no campaign directory.
fn refused_unmade(dir: &Path, out: &str, extra: &[&str], says: &str) {
    let a = aircraft();
    refused(&sepval(&init_args(&a, out, extra), dir), says);
    assert!(!dir.join(out).exists(), "{out} was written");
}

#[test]
fn bad_preflight_inputs_are_refused_and_nothing_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    nominal_release(dir, "ctt.csv");
    let text = std::fs::read_to_string(dir.join("ctt.csv")).unwrap();
    let unstated: String = text
        .lines()
        .filter(|l| !l.starts_with("# mach") && !l.starts_with("# alpha_deg"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(dir.join("unstated.csv"), unstated).unwrap();
    std::fs::write(dir.join("broken.csv"), "t_s,x_m\n0,zero\n").unwrap();
    for (extra, says) in [
        (
            &["--preflight", "unstated.csv"][..],
            "unstated.csv does not state its condition: no `# mach = ...`",
        ),
        (&["--preflight", "broken.csv"], "--preflight broken.csv: "),
        (&["--preflight", "absent.csv"], "--preflight absent.csv: "),
        (
            &["--preflight", "ctt.csv", "--preflight", "ctt.csv"],
            "is the same trajectory as ctt.csv",
        ),
        (
            &["--preflight", "ctt.csv", "--preflight-allowance-m", "0"],
            "--preflight-allowance-m 0: expected a finite number of m above 0",
        ),
        (
            &["--preflight", "ctt.csv", "--preflight-allowance-deg=-1"],
            "--preflight-allowance-deg -1: expected a finite number of deg above 0",
        ),
        (
            &["--preflight", "ctt.csv", "--preflight-allowance-m", "NaN"],
            "--preflight-allowance-m NaN",
        ),
    ] {
        refused_unmade(dir, "c", extra, says);
    }
}

/// The Eglin CFD release of /work/shared/data (docs/campaign.md): it states no condition in
/// the campaign's form, so it is refused as given; with its stated condition (Mach 0.95,
/// 26 000 ft, alpha 0, its README) it is fitted, and the fit is recorded.
#[test]
fn the_eglin_cfd_release_is_refused_without_its_condition_and_fitted_with_it() {
    let eglin = Path::new("/work/shared/data/eglin-cfd/M095_AOA0.csv");
    if !eglin.is_file() {
        eprintln!("skipped: {} is not present", eglin.display());
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let given = eglin.display().to_string();
    refused_unmade(
        dir,
        "raw",
        &["--preflight", &given],
        "does not state its condition",
    );
    let text = std::fs::read_to_string(eglin).unwrap();
    let stated = format!("# mach = 0.95\n# altitude_m = 7924.8\n# alpha_deg = 0\n{text}");
    std::fs::write(dir.join("eglin.csv"), stated).unwrap();
    let a = aircraft();
    ok(&sepval(
        &init_args(&a, "cfd", &["--preflight", "eglin.csv"]),
        dir,
    ));
    let camp = json(&dir.join("cfd/campaign.json"));
    let pf = &camp["settings"]["prior"]["sources"][1];
    assert_eq!(pf["kind"], "preflight");
    assert_eq!(pf["trajectories"][0]["samples"], 101);
    let rms = pf["rms_pos_m"].as_f64().unwrap();
    assert!(rms > 0.0 && rms < 0.05, "{pf}");
}

/// The store of these tests with the normal-force interference as a table over distance
/// (scaled by `scale`), written to `dir/name`; returns the scenario.
fn store_with_table(dir: &Path, name: &str, scale: f64) -> Scenario {
    let mut s = Scenario::embedded_default();
    let lambda = s.interference.lambda_m;
    let d: Vec<f64> = (0..=10).map(|k| 0.3 * f64::from(k)).collect();
    let v = d
        .iter()
        .map(|&x| -0.6 * scale * (-x / lambda).exp())
        .collect();
    let axes = vec![Axis {
        variable: Variable::Distance,
        breakpoints: d,
    }];
    let t = Table::new(axes, v, sepval_common::table::Kind::Interference).unwrap();
    s.interference.dcz0 = Tabulated::table(t).unwrap();
    std::fs::write(dir.join(name), s.to_toml_string()).unwrap();
    s
}

/// `store` as DAVE-ML in `dir/name` by sepval's writer (as `update --daveml` writes it), with
/// a standard deviation of `share` of each value of its normal-force interference table.
fn daveml_of(dir: &Path, name: &str, store: &Scenario, share: f64) {
    let Some(sepval_common::table::Coefficient::Table(t)) =
        sepval_daveml::assemble::field(store, Target::Interference(2))
    else {
        panic!("a table");
    };
    let band = sepval_daveml::Band {
        target: Target::Interference(2),
        sigma: t.values().iter().map(|v| share * v.abs()).collect(),
        correlations: Vec::new(),
    };
    let prov = sepval_daveml::Provenance::now("the test".into(), Vec::new());
    sepval_daveml::write_model(&dir.join(name), store, &[band], &prov).unwrap();
}

#[test]
fn the_stores_daveml_uncertainty_becomes_the_factors_mean_and_sd() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    store_with_table(dir, "base.toml", 1.0);
    // The file's table is the campaign's scaled by 1.2, its band 10 % of each value: czintfac
    // 1.2 with sd 0.12 (the band's size over the table's).
    let file = store_with_table(dir, "file.toml", 1.2);
    daveml_of(dir, "store.dml", &file, 0.1);
    let a = aircraft();
    let said = ok(&sepval(
        &init_args(
            &a,
            "c",
            &["--scenario", "base.toml", "--prior-daveml", "store.dml"],
        ),
        dir,
    ));
    assert!(said.contains("czintfac 1.2 sd 0.12"), "{said}");
    let camp = json(&dir.join("c/campaign.json"));
    let prior = &camp["settings"]["prior"];
    let b = &prior["factors"]["czintfac"];
    assert!((b["mean"].as_f64().unwrap() - 1.2).abs() < 1e-9, "{b}");
    assert!((b["sd"].as_f64().unwrap() - 0.12).abs() < 1e-9, "{b}");
    let src = &prior["sources"][1];
    assert_eq!(src["kind"], "daveml");
    assert_eq!(src["mapped"][0]["field"], "interference.dcz0");
    assert!(
        src["mapped"][0]["element"]
            .as_str()
            .unwrap()
            .contains("<normalPDF>"),
        "{src}"
    );
    // Other factors keep the default.
    assert!((prior["factors"]["fwdfac"]["sd"].as_f64().unwrap() - 0.8 / 6.0).abs() < 1e-12);
}

#[test]
fn a_daveml_that_cannot_be_mapped_is_refused_naming_the_element() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let base = store_with_table(dir, "base.toml", 1.0);
    daveml_of(dir, "store.dml", &base, 0.1);
    let text = std::fs::read_to_string(dir.join("store.dml")).unwrap();
    let edited = |name: &str, from: &str, to: &str| {
        assert!(text.contains(from), "{from}");
        std::fs::write(dir.join(name), text.replacen(from, to, 1)).unwrap();
    };
    edited("uniform.dml", "<normalPDF numSigmas=\"1\">", "<uniformPDF>");
    std::fs::write(
        dir.join("uniform.dml"),
        std::fs::read_to_string(dir.join("uniform.dml"))
            .unwrap()
            .replacen("</normalPDF>", "</uniformPDF>", 1),
    )
    .unwrap();
    edited("nosigmas.dml", " numSigmas=\"1\"", "");
    edited("broken.dml", "</DAVEfunc>", "");
    let plain = std::fs::read_to_string(dir.join("store.dml")).unwrap();
    let cut = |s: &str| {
        let (a, rest) = s.split_once("<uncertainty").unwrap();
        let (_, b) = rest.split_once("</uncertainty>").unwrap();
        format!("{a}{b}")
    };
    std::fs::write(dir.join("certain.dml"), cut(&plain)).unwrap();
    std::fs::write(
        dir.join("twice.json"),
        r#"{"format":"sepval-prior/1","factors":{"czintfac":{"mean":1.0,"sd":0.1}}}"#,
    )
    .unwrap();
    let s = ["--scenario", "base.toml", "--prior-daveml"];
    for (file, extra, says) in [
        (
            "uniform.dml",
            &[][..],
            "<uniformPDF> (the uncertainty of sepval field interference.dcz0): a uniformPDF",
        ),
        (
            "nosigmas.dml",
            &[],
            "<normalPDF> (the uncertainty of sepval field interference.dcz0): a normalPDF without a numSigmas",
        ),
        ("broken.dml", &[], "--prior-daveml broken.dml"),
        ("certain.dml", &[], "gives no uncertainty"),
        ("absent.dml", &[], "--prior-daveml absent.dml"),
        (
            "store.dml",
            &["--prior", "twice.json"],
            "sets czintfac, which the --prior file sets too",
        ),
    ] {
        let args = [&s[..], &[file], extra].concat();
        refused_unmade(dir, "c", &args, says);
    }
}

/// The round trip through the commands: `update --daveml` writes the updated store's
/// uncertainty, `campaign init --prior-daveml` reads it back as the band's size over its
/// table's (module docs of `prior_daveml`), the tables the campaign's own (factor 1).
#[test]
fn update_daveml_round_trips_into_the_prior() {
    // An update of two releases (GA of 20 generations, then the selection): 16 s on 2 threads
    // (2026-12-02), near the fast tier's limit on a shared machine.
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // Releases of a store with a bump in its normal-force interference that the scenario's
    // exponential lacks (update.rs's truth).
    let mut truth = store_with_table(dir, "t.toml", 1.0);
    let Some(sepval_common::table::Coefficient::Table(t)) =
        sepval_daveml::assemble::field(&truth, Target::Interference(2)).cloned()
    else {
        panic!("a table");
    };
    let bumped: Vec<f64> = t.axes()[0]
        .breakpoints
        .iter()
        .zip(t.values())
        .map(|(s, v)| v + 0.5 * (-((s - 0.6) / 0.3).powi(2)).exp())
        .collect();
    let t = Table::new(
        t.axes().to_vec(),
        bumped,
        sepval_common::table::Kind::Interference,
    )
    .unwrap();
    truth.interference.dcz0 = Tabulated::table(t).unwrap();
    for (name, mach, alpha, seed) in [("a", 0.8, 0.0, "1"), ("b", 0.95, 2.0, "2")] {
        truth.flight.mach = mach;
        truth.flight.alpha_deg = alpha;
        std::fs::write(dir.join(format!("{name}.toml")), truth.to_toml_string()).unwrap();
        ok(&sepval(
            &[
                "simulate",
                "--scenario",
                &format!("{name}.toml"),
                "--t-end",
                "0.5",
                "--noise-seed",
                seed,
                "--out",
                &format!("{name}.csv"),
            ],
            dir,
        ));
    }
    ok(&sepval(
        &[
            "update",
            "--data",
            "a.csv",
            "--data",
            "b.csv",
            "--generations",
            "20",
            "--evaluator",
            "inproc",
            "--threads",
            "2",
            "--daveml",
            "--out",
            "up",
        ],
        dir,
    ));
    let dml = std::fs::read_to_string(dir.join("up/store.dml")).unwrap();
    let a = aircraft();
    // Within the Mach numbers of the updated store's tables (the releases').
    let args: Vec<&str> = init_args(
        &a,
        "c",
        &[
            "--scenario",
            "up/scenario.toml",
            "--prior-daveml",
            "up/store.dml",
        ],
    )
    .into_iter()
    .map(|x| if x == "0.6:1.0:3" { "0.8:0.95:2" } else { x })
    .collect();
    ok(&sepval(&args, dir));
    let camp = json(&dir.join("c/campaign.json"));
    let mapped = camp["settings"]["prior"]["sources"][1]["mapped"]
        .as_array()
        .unwrap()
        .clone();
    assert!(!mapped.is_empty());
    // Each uncertain table, read from the file as written: its values and its band.
    for m in &mapped {
        let field = m["field"].as_str().unwrap();
        let target = Target::table_of_field(field).unwrap();
        let id = format!("{}_table", sepval_daveml::export::output_id(target));
        let start = dml.find(&format!("gtID=\"{id}\"")).unwrap();
        let def = &dml[start..start + dml[start..].find("</griddedTableDef>").unwrap()];
        let numbers = |s: &str| -> Vec<f64> {
            s.split(|c: char| c == ',' || c.is_whitespace())
                .filter(|t| !t.is_empty())
                .map(|t| t.parse().unwrap())
                .collect()
        };
        let between = |s: &str, a: &str, b: &str| {
            let i = s.find(a).unwrap() + a.len();
            s[i..i + s[i..].find(b).unwrap()].to_string()
        };
        let bounds = numbers(&between(&between(def, "<bounds>", "</bounds>"), ">", "<"));
        let tail = &def[def.find("</uncertainty>").unwrap()..];
        let values = numbers(&between(tail, "<dataTable>", "</dataTable>"));
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let offset = matches!(target, Target::Static(_));
        let e = if offset {
            (values.len() as f64).sqrt()
        } else {
            norm(&values)
        };
        let sd = norm(&bounds) / e;
        let b = &m["belief"];
        assert!(
            (b["mean"].as_f64().unwrap() - if offset { 0.0 } else { 1.0 }).abs() < 1e-9,
            "{m}"
        );
        assert!(
            (b["sd"].as_f64().unwrap() - sd).abs() < 1e-6 * sd,
            "{m}: {sd}"
        );
    }
}
