//! The tests' own generator of releases with a hidden cause (included by `#[path]` in
//! `diagnose/tests/discovery`, `plan/tests/closing` and `sepval/tests/cli`): the scenario's own
//! aerodynamics or initial state changed, or a coefficient function the test writes, simulated
//! on a base that is not the default truth, with the generator's own Gaussian noise
//! ([`sepval_tests::Gauss`]), never through the catalogue's or the extension's code; and the
//! releases written as `sepval diagnose` is given them.

use std::path::Path;

use sepval_common::effects::{EffectSet, MAX_EFFECT_PARAMS};
use sepval_common::model::{CoefficientFn, RunSetup};
use sepval_common::noise::{SIGMA_ATT_DEG, SIGMA_POS_M};
use sepval_common::propagator::{Observation, propagate};
use sepval_common::scenario::Scenario;
use sepval_common::simulation::Simulator;
use sepval_common::telemetry::Trajectory;
use sepval_core::factors::Factors;
use sepval_tests::Gauss;

/// Factors of the base model (not the default truth).
pub const BASE: &str = r#"{"fwdfac": 0.45, "aftfac": 0.65, "xinerfac": 0.98, "yinerfac": 1.03,
 "zinerfac": 0.97, "caoff": -0.02, "cyoff": 0.04, "czoff": -0.06, "cmoff": 0.1, "cnoff": -0.08,
 "cloff": -0.05, "caintfac": 1.1, "cyintfac": 1.4, "czintfac": 0.9, "cmintfac": 1.3,
 "cnintfac": 0.8, "clintfac": 1.6}"#;

/// A hidden coefficient function and its parameters.
pub type Hidden = (CoefficientFn, [f64; MAX_EFFECT_PARAMS]);

/// One release: `scenario` (its flight condition written as metadata) simulated with the base
/// factors and the hidden term, 1 s at 200 Hz, noisy.
pub fn release(scenario: &Scenario, hidden: Option<Hidden>, seed: u64) -> Trajectory {
    let factors = Factors::from_json_str(BASE, &scenario.factors).unwrap();
    release_on(scenario, &factors, hidden, seed)
}

/// [`release`] on the base `factors` (not the tests' default base).
#[allow(dead_code)]
pub fn release_on(
    scenario: &Scenario,
    factors: &Factors,
    hidden: Option<Hidden>,
    seed: u64,
) -> Trajectory {
    let sim = Simulator::new(scenario);
    let mut run = RunSetup::new(sim.model(), factors, &EffectSet::NONE).unwrap();
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

/// Writes the releases into `dir` (`release1.csv`, ...), and `scenario` (the model fitted,
/// when not the embedded default) to `dir/scenario.toml`; returns the flags of `sepval
/// diagnose` that give them, each with its file's name in `dir`: `--scenario`, then `--data`
/// for the first `fit` releases and `--validate` for the rest.
pub fn write(
    dir: &Path,
    releases: &[Trajectory],
    fit: usize,
    scenario: Option<&Scenario>,
) -> Vec<(&'static str, String)> {
    let mut flags = Vec::new();
    if let Some(s) = scenario {
        std::fs::write(dir.join("scenario.toml"), s.to_toml_string()).unwrap();
        flags.push(("--scenario", "scenario.toml".to_string()));
    }
    for (k, r) in releases.iter().enumerate() {
        let name = format!("release{}.csv", k + 1);
        r.write(&dir.join(&name)).unwrap();
        flags.push((if k < fit { "--data" } else { "--validate" }, name));
    }
    flags
}

/// The embedded default scenario (the model the tests fit).
pub fn default_scenario() -> Scenario {
    Scenario::embedded_default()
}
