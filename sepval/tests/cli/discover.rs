//! `sepval diagnose` discovers causes outside the effect catalogue. Each test hides an effect in
//! flight data made by its own generator (this file's: the scenario's own aerodynamics changed,
//! or a coefficient function written here, simulated on a base that is not the default truth,
//! with this file's own Gaussian noise), never through the catalogue's or the extension's code,
//! and checks that the diagnosis names the right axis and family first, locates it, and that
//! the extension it writes brings both goals to the noise floor. Null data must name nothing.

use std::path::Path;

use sepval_common::effects::{EffectSet, MAX_EFFECT_PARAMS};
use sepval_common::model::{CoefficientFn, Coefficients, Flow, RunSetup};
use sepval_common::noise::{SIGMA_ATT_DEG, SIGMA_POS_M};
use sepval_common::propagator::{Observation, propagate};
use sepval_common::scenario::Scenario;
use sepval_common::simulation::Simulator;
use sepval_common::telemetry::Trajectory;
use sepval_core::factors::Factors;
use sepval_tests::{Gauss, REDUCED_BUDGET, ok, sepval};
use serde_json::Value;

/// Factors of the base model (not the default truth).
const BASE: &str = r#"{"fwdfac": 0.45, "aftfac": 0.65, "xinerfac": 0.98, "yinerfac": 1.03,
 "zinerfac": 0.97, "caoff": -0.02, "cyoff": 0.04, "czoff": -0.06, "cmoff": 0.1, "cnoff": -0.08,
 "cloff": -0.05, "caintfac": 1.1, "cyintfac": 1.4, "czintfac": 0.9, "cmintfac": 1.3,
 "cnintfac": 0.8, "clintfac": 1.6}"#;

/// A hidden coefficient function and its parameters.
pub(crate) type Hidden = (CoefficientFn, [f64; MAX_EFFECT_PARAMS]);

/// One release: `scenario` (its flight condition written as metadata) simulated with the base
/// factors and the hidden term, 1 s at 200 Hz, noisy.
pub(crate) fn release(scenario: &Scenario, hidden: Option<Hidden>, seed: u64) -> Trajectory {
    let sim = Simulator::new(scenario);
    let factors = Factors::from_json_str(BASE, &scenario.factors).unwrap();
    let mut run = RunSetup::new(sim.model(), &factors, &EffectSet::NONE).unwrap();
    if let Some((f, p)) = hidden {
        run.add_coefficient_term(f, p).unwrap();
    }
    let times: Vec<f64> = (0..=200).map(|k| k as f64 / 200.0).collect();
    let mut obs: Vec<Observation> = Vec::new();
    propagate(sim.model(), &run, &times, &mut obs).unwrap();
    let mut g = Gauss(0x9E37_79B9_7F4A_7C15 ^ seed.wrapping_mul(0x2545_F491_4F6C_DD1D));
    let mut t = Trajectory {
        times_s: times,
        pos_m: obs
            .iter()
            .map(|o| o.pos_m.map(|v| v + SIGMA_POS_M * g.normal()))
            .collect(),
        att_deg: obs
            .iter()
            .map(|o| o.att_deg.map(|v| v + SIGMA_ATT_DEG * g.normal()))
            .collect(),
        ..Trajectory::default()
    };
    let f = &scenario.flight;
    t.push_metadata("mach", &f.mach.to_string());
    t.push_metadata("alpha_deg", &f.alpha_deg.to_string());
    t.push_metadata("beta_deg", &f.beta_deg.to_string());
    t.push_metadata("altitude_m", &f.altitude_m.to_string());
    t.push_metadata("sigma_pos_m", &SIGMA_POS_M.to_string());
    t.push_metadata("sigma_att_deg", &SIGMA_ATT_DEG.to_string());
    t
}

/// Writes the releases, diagnoses them (the first `fit` of them fitted, the rest validated)
/// with `scenario` (the embedded default when `None`), and returns the diagnosis.
pub(crate) fn diagnose(
    dir: &Path,
    releases: &[Trajectory],
    fit: usize,
    scenario: Option<&Scenario>,
) -> Value {
    let mut args: Vec<String> = vec!["diagnose".into()];
    if let Some(s) = scenario {
        std::fs::write(dir.join("scenario.toml"), s.to_toml_string()).unwrap();
        args.extend(["--scenario".into(), "scenario.toml".into()]);
    }
    for (k, r) in releases.iter().enumerate() {
        let name = format!("release{}.csv", k + 1);
        r.write(&dir.join(&name)).unwrap();
        args.push(if k < fit { "--data" } else { "--validate" }.into());
        args.push(name);
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

/// The first discovered term; checks its axis and family, that no catalogue effect is named,
/// and that the extension written explains the data within 1.2 times the noise.
fn found_first<'a>(d: &'a Value, dir: &Path, axis: &str, family: &str) -> &'a Value {
    let first = &d["discovered"][0];
    assert_eq!(
        (first["axis"].as_str(), first["family"].as_str()),
        (Some(axis), Some(family)),
        "{}\n{}",
        d["verdict"],
        serde_json::to_string_pretty(&d["discovered"]).unwrap()
    );
    assert!(
        d["causes"].as_array().unwrap().is_empty(),
        "{}",
        d["verdict"]
    );
    assert!(
        d["verdict"]
            .as_str()
            .unwrap()
            .starts_with("not explained by the catalogue"),
        "{}",
        d["verdict"]
    );
    assert!(first["reading"].as_str().unwrap().len() > 10);
    assert!(first["std_error"].as_f64().unwrap() > 0.0, "{first}");
    let x = &d["extension"];
    assert_eq!(x["answer"], true);
    let (sp, sa) = (
        d["sigma_pos_m"].as_f64().unwrap(),
        d["sigma_att_deg"].as_f64().unwrap(),
    );
    let (jp, ja) = (
        x["model"]["j_pos_m"].as_f64().unwrap(),
        x["model"]["j_att_deg"].as_f64().unwrap(),
    );
    assert!(jp < 1.2 * sp && ja < 1.2 * sa, "{jp} {ja} vs {sp} {sa}");
    // The extension and the factors fitted with it are usable files: they read back and simulate.
    let ext = dir.join("diag/extension.toml");
    assert!(
        std::fs::read_to_string(&ext)
            .unwrap()
            .contains(&format!("family = \"{family}\""))
    );
    ok(&sepval(
        &[
            "simulate",
            "--factors",
            "diag/factors.json",
            "--extension",
            "diag/extension.toml",
            "--out",
            "ext.csv",
        ],
        dir,
    ));
    first
}

pub(crate) fn default_scenario() -> Scenario {
    Scenario::embedded_default()
}

/// A smooth test of `t >= t_on`: a hard step in the side force.
fn side_force_step(p: &[f64; MAX_EFFECT_PARAMS], flow: &Flow, k: &mut Coefficients) {
    if flow.t_s >= p[1] {
        k.cy += p[0];
    }
}

/// A roll moment oscillation p0 sin(2 pi p1 t + p2).
fn roll_buffet(p: &[f64; MAX_EFFECT_PARAMS], flow: &Flow, k: &mut Coefficients) {
    k.cl += p[0] * (std::f64::consts::TAU * p[1] * flow.t_s + p[2]).sin();
}

/// A yaw moment growing with sideslip near the aircraft: p0 beta exp(-s / p1).
fn yaw_interference_beta(p: &[f64; MAX_EFFECT_PARAMS], flow: &Flow, k: &mut Coefficients) {
    k.cn += p[0] * flow.beta_rad * (-flow.distance_m / p[1]).exp();
}

/// Axial force rising with Mach number above 0.85: p0 (M - 0.85).
fn drag_rise(p: &[f64; MAX_EFFECT_PARAMS], flow: &Flow, k: &mut Coefficients) {
    k.cx -= p[0] * (flow.mach - 0.85);
}

pub(crate) fn params(v: &[f64]) -> [f64; MAX_EFFECT_PARAMS] {
    let mut p = [0.0; MAX_EFFECT_PARAMS];
    p[..v.len()].copy_from_slice(v);
    p
}

#[test]
fn a_side_force_step_is_discovered_and_located() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let r = release(
        &default_scenario(),
        Some((side_force_step, params(&[0.2, 0.43]))),
        11,
    );
    let d = diagnose(dir.path(), &[r], 1, None);
    let first = found_first(&d, dir.path(), "CY", "step");
    let t_on = first["t_on_s"].as_f64().unwrap();
    assert!((t_on - 0.43).abs() < 0.05, "t_on {t_on}");
}

#[test]
fn a_roll_buffet_is_discovered_at_its_frequency() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let r = release(
        &default_scenario(),
        Some((roll_buffet, params(&[0.02, 6.3, 0.7]))),
        12,
    );
    let d = diagnose(dir.path(), &[r], 1, None);
    let first = found_first(&d, dir.path(), "Cl", "oscillation");
    let f = first["f_hz"].as_f64().unwrap();
    assert!((f - 6.3).abs() < 0.5, "f {f}");
}

#[test]
fn a_roll_damping_change_is_discovered_as_a_rate_term() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // The store leaves with a known roll rate (the scenario says so), and the data's roll
    // damping is twice the model's: a rate derivative, not an effect.
    let dir = tempfile::tempdir().unwrap();
    let mut model = default_scenario();
    model.initial.rates_deg_s = [120.0, 0.0, 0.0];
    let mut truth = model.clone();
    truth.aero.cl_p_per_rad = sepval_common::table::DerivativeCoefficient::constant(
        2.0 * model.aero.cl_p_per_rad.as_constant().unwrap(),
    );
    let r = release(&truth, None, 13);
    let d = diagnose(dir.path(), &[r], 1, Some(&model));
    let first = found_first(&d, dir.path(), "Cl", "rate");
    assert!(first["term"].as_str().unwrap().starts_with("p "), "{first}");
    assert!(first["coefficient"].as_f64().unwrap() < 0.0, "{first}");
}

#[test]
fn a_sideslip_dependent_interference_yaw_moment_needs_two_releases() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // A yaw moment near the aircraft growing with sideslip, in releases at +3 and -3 deg of
    // sideslip: on one release the interference factors absorb it (and nothing beyond the
    // catalogue is claimed); pooled, its sign follows the sideslip and it is found.
    let hidden = Some((yaw_interference_beta as CoefficientFn, params(&[-2.0, 0.5])));
    let releases: Vec<Trajectory> = [(3.0, 41), (-3.0, 42)]
        .into_iter()
        .map(|(beta, seed)| {
            let mut s = default_scenario();
            s.flight.beta_deg = beta;
            release(&s, hidden, seed)
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let d = diagnose(dir.path(), &releases, 2, None);
    let first = found_first(&d, dir.path(), "Cn", "interference_flow_angle");
    assert!(
        first["term"].as_str().unwrap().starts_with("beta*"),
        "{first}"
    );
    let lambda = first["lambda_m"].as_f64().unwrap();
    assert!((lambda - 0.5).abs() < 0.15, "lambda {lambda}");
    let one = tempfile::tempdir().unwrap();
    let d = diagnose(one.path(), &releases[..1], 1, None);
    assert!(
        d["discovered"].as_array().unwrap().is_empty(),
        "{}",
        d["verdict"]
    );
}

#[test]
fn an_ejector_force_falling_along_the_stroke_is_discovered() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mut s = default_scenario();
    let f0 = s.ejector.curve[0][1];
    let end = s.ejector.curve[s.ejector.curve.len() - 1][0];
    s.ejector.curve = vec![[0.0, 1.3 * f0], [end, 0.7 * f0]];
    let r = release(&s, None, 15);
    let d = diagnose(dir.path(), &[r], 1, None);
    let first = found_first(&d, dir.path(), "ejector", "ejector_stroke");
    assert!(first["coefficient"].as_f64().unwrap() < 0.0, "{first}");
}

#[test]
fn a_mach_dependent_drag_needs_two_releases_and_predicts_a_third() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    // The same store at Mach 0.95, alpha 0 and Mach 0.8, alpha 3: on one release the drag rise
    // is a constant the axial offset absorbs; pooled, it is a Mach term. A third release at
    // Mach 0.88 is predicted, not fitted.
    let dir = tempfile::tempdir().unwrap();
    let hidden = Some((drag_rise as CoefficientFn, params(&[0.5])));
    let mut a = default_scenario();
    a.flight.mach = 0.95;
    let mut b = default_scenario();
    b.flight.mach = 0.8;
    b.flight.alpha_deg = 3.0;
    let mut c = default_scenario();
    c.flight.mach = 0.88;
    let releases = [
        release(&a, hidden, 16),
        release(&b, hidden, 17),
        release(&c, hidden, 18),
    ];
    let d = diagnose(dir.path(), &releases, 2, None);
    let first = found_first(&d, dir.path(), "CA", "mach");
    assert!(first["coefficient"].as_f64().unwrap() > 0.0, "{first}");
    let v = &d["validation"][0];
    assert!(
        v["extended_j_pos_m"].as_f64().unwrap() < v["baseline_j_pos_m"].as_f64().unwrap(),
        "{v}"
    );
    // One release alone: the factors absorb it, and nothing is claimed.
    let one = tempfile::tempdir().unwrap();
    let d = diagnose(one.path(), &releases[..1], 1, None);
    assert!(
        d["discovered"].as_array().unwrap().is_empty(),
        "{}",
        d["verdict"]
    );
}

#[test]
fn null_data_name_neither_an_effect_nor_a_term() {
    if sepval_tests::skip_slow_tests() {
        return;
    }
    let mut s = default_scenario();
    for (seed, events) in [(21, 1), (23, 2)] {
        let dir = tempfile::tempdir().unwrap();
        let releases: Vec<Trajectory> = (0..events)
            .map(|k| {
                s.flight.mach = 0.95 - 0.1 * k as f64;
                release(&s, None, seed + 10 * k as u64)
            })
            .collect();
        let d = diagnose(dir.path(), &releases, events, None);
        assert!(
            d["causes"].as_array().unwrap().is_empty(),
            "{}",
            d["verdict"]
        );
        assert!(
            d["discovered"].as_array().unwrap().is_empty(),
            "{}",
            d["verdict"]
        );
        assert_eq!(d["explained"], true, "{}", d["verdict"]);
        // Null data have no answer, so nothing rivals it.
        assert_eq!(d["ambiguous"], false, "{}", d["verdict"]);
        assert!(d["rivals"].as_array().unwrap().is_empty());
        assert!(!dir.path().join("diag/extension.toml").exists());
    }
}

#[test]
fn a_malformed_extension_is_refused_with_file_line_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let good = "format = \"sepval-extension/1\"\n\n[[term]]\naxis = \"Cl\"\nfamily = \"rate\"\nregressor = \"p\"\ncoefficient = -0.5\n";
    for (name, text, needle) in [
        (
            "family",
            good.replace("\"rate\"", "\"gusts\""),
            "line 5, term 1, `family`",
        ),
        (
            "missing",
            good.replace("coefficient = -0.5\n", ""),
            "coefficient",
        ),
        ("nan", good.replace("-0.5", "nan"), "`coefficient`"),
        ("axis", good.replace("\"Cl\"", "\"Cq\""), "`axis`"),
        ("ejector", good.replace("\"Cl\"", "\"ejector\""), "`axis`"),
    ] {
        let file = format!("{name}.toml");
        std::fs::write(dir.path().join(&file), text).unwrap();
        for cmd in [
            vec!["simulate", "--extension", &file, "--out", "x.csv"],
            vec![
                "fit",
                "--extension",
                &file,
                "--generations",
                "2",
                "--out",
                "fit",
            ],
            vec!["diagnose", "--extension", &file, "--out", "diag"],
        ] {
            let out = sepval(&cmd, dir.path());
            assert!(!out.status.success(), "{name}: {cmd:?}");
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(err.contains(&file), "{name}: {err}");
            assert!(err.contains(needle), "{name}: {err}");
            assert!(!err.contains("panicked"), "{name}: {err}");
            for left in ["x.csv", "fit", "diag"] {
                assert!(
                    !dir.path().join(left).exists(),
                    "{name}: {left} left behind"
                );
            }
        }
    }
}

#[test]
fn an_extension_changes_the_simulation_and_fits_back() {
    let dir = tempfile::tempdir().unwrap();
    let ext = "format = \"sepval-extension/1\"\n\n[[term]]\naxis = \"CY\"\nfamily = \"step\"\nregressor = \"step\"\nt_on_s = 0.4\ncoefficient = 0.05\n";
    std::fs::write(dir.path().join("ext.toml"), ext).unwrap();
    ok(&sepval(
        &["simulate", "--factors", "truth", "--out", "plain.csv"],
        dir.path(),
    ));
    ok(&sepval(
        &[
            "simulate",
            "--factors",
            "truth",
            "--extension",
            "ext.toml",
            "--out",
            "ext.csv",
        ],
        dir.path(),
    ));
    let a = Trajectory::read(&dir.path().join("plain.csv")).unwrap();
    let b = Trajectory::read(&dir.path().join("ext.csv")).unwrap();
    let k = a.times_s.iter().position(|t| *t > 0.7).unwrap();
    assert!((a.pos_m[k][1] - b.pos_m[k][1]).abs() > 0.01);
    assert_eq!(a.pos_m[10], b.pos_m[10]);
}
