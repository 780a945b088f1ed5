//! The fit's results file, DIR/result.json, and the per-channel residual summary.

use std::collections::BTreeMap;

use sepval_common::evaluation::Job;
use sepval_common::goals::residual;
use sepval_common::propagator::Observation;
use sepval_core::factors::Factors;
use sepval_run::clearance::ReleaseClearance;
use sepval_run::inputs::InputsRecord;
use sepval_solve::best::BestSoFar;
use serde::{Deserialize, Serialize};

/// Format tag of result files.
pub const RESULT_FORMAT: &str = "sepval-fit-result/1";

/// DIR/result.json. Everything except `run` and the `wall_s` fields is a deterministic function
/// of the inputs and settings (whatever the evaluator and worker count).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitResult {
    /// [`RESULT_FORMAT`].
    pub format: String,
    /// The events fitted.
    pub events: Vec<EventInfo>,
    /// SHA-256 of the measured data.
    pub data_sha256: String,
    /// SHA-256 of the scenario(s).
    pub scenario_sha256: String,
    /// Position noise used to weight J_pos \[m\].
    pub sigma_pos_m: f64,
    /// Attitude noise used to weight J_att \[deg\].
    pub sigma_att_deg: f64,
    /// Where the sigmas came from.
    pub sigma_source: String,
    /// The true factors, when known (synthetic data).
    pub truth: Option<Factors>,
    /// The noise floor the refinement aims at: 1.1 sigma on each goal.
    pub floor: FloorInfo,
    /// One entry per method run (`ga`, `hill`, `ga+lm`, ...).
    pub methods: BTreeMap<String, MethodResult>,
    /// How sure each parameter of the best refined fit is (refined methods only).
    pub identifiability: Option<sepval_solve::identifiability::Identifiability>,
    /// What one grid step of each factor does at the best fit.
    pub resolution: Vec<ResolutionRow>,
    /// Where the inputs came from: data, scenario and extension file (absent in files written
    /// before it was recorded), so that `sepval predict --from DIR` rebuilds the releases
    /// fitted, as diagnosis.json's `inputs` does.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inputs: Option<InputsRecord>,
    /// The clearance to the aircraft of the best fit's trajectory of each release, when the
    /// fit was given `--aircraft` (docs/envelope.md section 14.2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance: Option<Vec<ReleaseClearance>>,
    /// How this run was executed (not part of the deterministic result).
    pub run: RunInfo,
}

/// The noise floor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FloorInfo {
    /// 1.1 sigma_pos \[m\].
    pub j_pos_m: f64,
    /// 1.1 sigma_att \[deg\].
    pub j_att_deg: f64,
}

/// The effect of one grid step of one factor at the best fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResolutionRow {
    /// The factor.
    pub factor: String,
    /// Its grid step ((max - min) / (2^bits - 1)).
    pub step: f64,
    /// Change of J_pos \[m\] (null when the step did not simulate).
    pub d_j_pos_m: Option<f64>,
    /// Change of J_att \[deg\] (null when the step did not simulate).
    pub d_j_att_deg: Option<f64>,
    /// RMS change of the simulated positions \[m\] (null when the step did not simulate).
    pub traj_rms_pos_m: Option<f64>,
    /// RMS change of the simulated angles \[deg\] (null when the step did not simulate).
    pub traj_rms_att_deg: Option<f64>,
    /// Whether one step moves the trajectory by more than the noise.
    pub coarse: bool,
}

/// A refinement attempt during the genetic search (ga+lm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Probe {
    /// Generation after which it ran.
    pub generation: usize,
    /// Simulations of the search before it.
    pub evaluations_before: u64,
    /// Its simulations.
    pub evaluations: u64,
    /// Goals it reached: J_pos \[m\], J_att \[deg\].
    pub goals: [f64; 2],
    /// Whether it reached the floor.
    pub reached_floor: bool,
}

/// The refinement stage of a method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Refinement {
    /// Goals before it: J_pos \[m\], J_att \[deg\].
    pub start_goals: [f64; 2],
    /// Its simulations (final refinement only).
    pub evaluations: u64,
    /// Its iterations.
    pub iterations: usize,
    /// Why it stopped.
    pub stop: String,
    /// Attempts made during the search.
    pub probes: Vec<Probe>,
}

/// One event of the fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventInfo {
    /// Its name (data file).
    pub name: String,
    /// Its number of samples.
    pub samples: usize,
    /// The scenario tables the best fit's run of this event left (held at the edge; docs/model.md
    /// section 3); absent when it left none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub tables_left: Vec<sepval_common::table::TableExcursion>,
}

/// How the run was executed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunInfo {
    /// The evaluator ("inproc, 2 thread(s)").
    pub evaluator: String,
    /// Wall time of the whole fit \[s\].
    pub wall_s: f64,
    /// sepval version.
    pub version: String,
}

/// The result of one method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodResult {
    /// The Pareto member with the smallest J_pos/sigma_pos + J_att/sigma_att.
    pub best: Best,
    /// The final Pareto front (non-dominated set of everything the method evaluated), by J_pos.
    pub pareto_front: Vec<FrontPoint>,
    /// The best goals per generation (GA) or iteration (hill climber).
    pub history: Vec<HistoryPoint>,
    /// Why the method stopped.
    pub stop: String,
    /// Simulations (search and refinement) needed to get within 1.1x of the noise floor on
    /// both goals; null if it never did.
    pub evaluations_to_floor: Option<u64>,
    /// The refinement stage, for `+lm` methods.
    pub refinement: Option<Refinement>,
}

/// The best member of a method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Best {
    /// The 17 factors by name.
    pub factors: Factors,
    /// RMS position error \[m\].
    pub j_pos_m: f64,
    /// RMS attitude error \[deg\].
    pub j_att_deg: f64,
    /// J_pos/sigma_pos + J_att/sigma_att.
    pub weighted: f64,
    /// Simulations the method ran.
    pub evaluations: u64,
    /// Wall time of the method \[s\].
    pub wall_s: f64,
    /// RMS residual per channel.
    pub channel_rms: ChannelRms,
}

/// One point of a Pareto front.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrontPoint {
    /// The factors.
    pub factors: Factors,
    /// RMS position error \[m\].
    pub j_pos_m: f64,
    /// RMS attitude error \[deg\].
    pub j_att_deg: f64,
}

/// The best goals after one generation or iteration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HistoryPoint {
    /// Generation (GA) or iteration (hill climber) number.
    pub step: usize,
    /// The best so far: for the GA the smallest goals in the population, for the hill climber
    /// the point itself (`"inf"` when no member finished).
    #[serde(flatten)]
    pub best: BestSoFar,
}

/// RMS residual (simulated minus measured) per channel, pooled over events.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ChannelRms {
    /// Downrange \[m\].
    pub x_m: f64,
    /// Crossrange \[m\].
    pub y_m: f64,
    /// Down \[m\].
    pub z_m: f64,
    /// Roll \[deg\].
    pub roll_deg: f64,
    /// Pitch \[deg\].
    pub pitch_deg: f64,
    /// Yaw \[deg\].
    pub yaw_deg: f64,
}

impl ChannelRms {
    /// The six values in order x, y, z, roll, pitch, yaw.
    pub fn as_array(&self) -> [f64; 6] {
        [
            self.x_m,
            self.y_m,
            self.z_m,
            self.roll_deg,
            self.pitch_deg,
            self.yaw_deg,
        ]
    }
}

/// Sums of the squared residuals of each channel, sample by sample (pooled over events in the
/// order the samples come): (dx, dy, dz \[m\], droll, dpitch, dyaw \[deg\]), angle
/// differences wrapped.
#[derive(Debug, Clone, Copy, Default)]
pub struct ChannelSums {
    sums: [f64; 6],
    n: usize,
}

impl ChannelSums {
    /// Adds the residuals of the simulated sample `sim` against a measured one.
    #[inline]
    pub fn add(&mut self, sim: &Observation, pos_m: &[f64; 3], att_deg: &[f64; 3]) {
        let (p, a) = residual(sim, pos_m, att_deg);
        for (s, r) in self.sums.iter_mut().zip(p.iter().chain(&a)) {
            *s += r * r;
        }
        self.n += 1;
    }

    /// The RMS of each channel.
    pub fn rms(&self) -> ChannelRms {
        rms_of(self.sums, self.n)
    }
}

/// RMS of each channel of the residuals of simulated samples against the job's data, pooled
/// over events: (dx, dy, dz \[m\], droll, dpitch, dyaw \[deg\]), angle differences wrapped.
/// Streams the samples: a long record's residuals are never held at once.
pub fn residual_rms(job: &Job, samples: &[Vec<Observation>]) -> ChannelRms {
    let mut sums = ChannelSums::default();
    for (e, sim) in job.events().iter().zip(samples) {
        for (k, o) in sim.iter().enumerate() {
            sums.add(o, &e.data.pos_m[k], &e.data.att_deg[k]);
        }
    }
    sums.rms()
}

/// RMS of each channel of residuals pooled over events.
pub fn channel_rms(residuals: &[Vec<[f64; 6]>]) -> ChannelRms {
    let mut sums = [0.0; 6];
    let mut n = 0usize;
    for r in residuals.iter().flatten() {
        for j in 0..6 {
            sums[j] += r[j] * r[j];
        }
        n += 1;
    }
    rms_of(sums, n)
}

/// Channel RMS from sums of squares over `n` samples.
fn rms_of(sums: [f64; 6], n: usize) -> ChannelRms {
    let v = sums.map(|s| (s / n.max(1) as f64).sqrt());
    ChannelRms {
        x_m: v[0],
        y_m: v[1],
        z_m: v[2],
        roll_deg: v[3],
        pitch_deg: v[4],
        yaw_deg: v[5],
    }
}

impl FitResult {
    /// The tables the best fit left, one line per event and table.
    pub fn tables_left(&self) -> Vec<String> {
        self.events
            .iter()
            .flat_map(|e| {
                e.tables_left
                    .iter()
                    .map(move |x| format!("{}: {x}", e.name))
            })
            .collect()
    }

    /// The terminal summary: the releases and the noise levels, then one line per method (its
    /// best J_pos, J_att and weighted goal, simulations and wall time).
    pub fn summary(&self) -> String {
        let names: Vec<&str> = self.events.iter().map(|e| e.name.as_str()).collect();
        let mut s = format!(
            "fit of {} ({} samples), sigma_pos {:.4} m, sigma_att {:.4} deg ({})\n",
            names.join(", "),
            self.events.iter().map(|e| e.samples).sum::<usize>(),
            self.sigma_pos_m,
            self.sigma_att_deg,
            self.sigma_source
        );
        s.push_str(&format!(
            "{:<6} {:>12} {:>12} {:>10} {:>12} {:>9}\n",
            "method", "J_pos [m]", "J_att [deg]", "weighted", "simulations", "wall [s]"
        ));
        for (name, m) in &self.methods {
            s.push_str(&format!(
                "{:<6} {:>12.6} {:>12.5} {:>10.3} {:>12} {:>9.1}\n",
                name,
                m.best.j_pos_m,
                m.best.j_att_deg,
                m.best.weighted,
                m.best.evaluations,
                m.best.wall_s
            ));
        }
        s
    }
}
