//! `sepval simulate` in process, for the test binaries that make releases as the command does
//! (included by `#[path]` in `diagnose/tests/catalogue`, `diagnose/tests/discovery` and
//! `plan/tests/closing`): the model, factors and effects read by `sepval_run::inputs`, simulated
//! and noised by `sepval_common::synthetic`, written by `Trajectory::write`, as
//! `sepval/src/command/simulate.rs` calls them. The lines that command adds to the file for
//! people (the command line, and an extension's file and terms) are not written: a diagnosis
//! reads only a release's samples, flight condition and store fields, and the binary's own test
//! (`sepval/tests/cli/gust.rs`) checks those lines.

use std::path::Path;

use sepval_common::simulation::{Simulator, sample_times};
use sepval_common::synthetic::synthetic_flight_test_logged;
use sepval_common::telemetry::Trajectory;
use sepval_run::inputs;

/// The flags of one `sepval simulate` run (files by their paths).
#[derive(Default)]
pub struct Simulate<'a> {
    /// `--factors`: a factors file, or `truth` or `nominal`.
    pub factors: &'a str,
    /// `--scenario` (the embedded default when `None`).
    pub scenario: Option<&'a Path>,
    /// `--extension`.
    pub extension: Option<&'a Path>,
    /// `--effect`, each `id=values`.
    pub effects: &'a [&'a str],
    /// `--noise-seed` (no noise when `None`).
    pub noise_seed: Option<u64>,
}

impl Simulate<'_> {
    /// `sepval simulate ... --out out` (the scenario's own duration and rate); returns the
    /// release written.
    pub fn run(&self, out: &Path) -> Trajectory {
        let specs: Vec<String> = self.effects.iter().map(|e| e.to_string()).collect();
        let effects = inputs::effects(&specs).unwrap();
        let scenario = inputs::scenario(self.scenario, self.extension).unwrap();
        let factors = inputs::factors(self.factors, &scenario.factors).unwrap();
        let sim = Simulator::new(&scenario);
        let times = sample_times(scenario.integrator.t_end_s, scenario.integrator.rate_hz);
        let (traj, _) =
            synthetic_flight_test_logged(&sim, &factors, &effects, &times, self.noise_seed)
                .unwrap();
        traj.write(out).unwrap();
        traj
    }
}
