//! Synthetic flight tests: a simulated trajectory plus seeded measurement noise, standing in
//! for flight data (the "flight test data" of Anderson's study; docs/model.md section 4).

use crate::effects::EffectSet;
use crate::noise::{SIGMA_ATT_DEG, SIGMA_POS_M, add_noise};
use crate::propagator::RunLog;
use crate::simulation::{SimError, Simulator};
use crate::telemetry::Trajectory;
use sepval_core::factors::Factors;

/// Noise seed of the embedded default synthetic flight test.
pub const DEFAULT_NOISE_SEED: u64 = 20_260_101;

/// A synthetic flight test: `factors` and `effects` simulated at `times_s`, with Gaussian noise
/// of the docs/model.md sigmas from `noise_seed` (none when `None`), and metadata naming how it was
/// made and its flight condition.
pub fn synthetic_flight_test(
    sim: &Simulator,
    factors: &Factors,
    effects: &EffectSet,
    times_s: &[f64],
    noise_seed: Option<u64>,
) -> Result<Trajectory, SimError> {
    synthetic_flight_test_logged(sim, factors, effects, times_s, noise_seed).map(|(t, _)| t)
}

/// [`synthetic_flight_test`] with the run's log (switch times, tables left).
pub fn synthetic_flight_test_logged(
    sim: &Simulator,
    factors: &Factors,
    effects: &EffectSet,
    times_s: &[f64],
    noise_seed: Option<u64>,
) -> Result<(Trajectory, RunLog), SimError> {
    let (mut traj, log) = sim.simulate_logged(factors, effects, times_s)?;
    let sc = sim.scenario();
    traj.push_metadata("scenario", &sc.name);
    traj.push_metadata("scenario_sha256", &sc.content_hash());
    traj.push_metadata("mach", &sc.flight.mach.to_string());
    traj.push_metadata("altitude_m", &sc.flight.altitude_m.to_string());
    traj.push_metadata("alpha_deg", &sc.flight.alpha_deg.to_string());
    traj.push_metadata("beta_deg", &sc.flight.beta_deg.to_string());
    traj.push_metadata("gamma_deg", &sc.flight.gamma_deg.to_string());
    traj.push_metadata("effects", &effects.to_string());
    match noise_seed {
        Some(seed) => {
            add_noise(&mut traj, SIGMA_POS_M, SIGMA_ATT_DEG, seed);
            traj.push_metadata("noise_seed", &seed.to_string());
            traj.push_metadata("sigma_pos_m", &SIGMA_POS_M.to_string());
            traj.push_metadata("sigma_att_deg", &SIGMA_ATT_DEG.to_string());
        }
        None => traj.push_metadata("noise", "none"),
    }
    Ok((traj, log))
}

/// The embedded default synthetic flight test: the truth factors of docs/model.md section 4 on the
/// default scenario, 201 samples at 200 Hz, noise from [`DEFAULT_NOISE_SEED`].
pub fn default_flight_test() -> Trajectory {
    let sim = Simulator::embedded_default();
    let mut t = synthetic_flight_test(
        &sim,
        &Factors::TRUTH,
        &EffectSet::NONE,
        &sim.default_times(),
        Some(DEFAULT_NOISE_SEED),
    )
    .expect("the truth factors simulate on the default scenario");
    t.comments.insert(
        0,
        "sepval embedded default synthetic flight test (truth factors + noise)".into(),
    );
    t
}
