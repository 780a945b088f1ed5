//! The synthetic cases of the calibration, made by this file's own generator: a random base
//! (every factor uniform in the middle half of its range), two or three releases at random
//! conditions (Mach 0.6-0.95, aircraft alpha -2 to 4 deg, beta -4 to 4 deg) simulated with a
//! hidden cause (a catalogue effect, a coefficient function written here that no model of the
//! fit has, or nothing), with Gaussian noise of the docs/model.md sigmas from ChaCha8; the
//! baseline model's factors fitted to them (Levenberg-Marquardt from the base moved by up to 5 %
//! of each range, as a converged `ga+lm` fit ends), and a release at another random condition
//! predicted against its noise-free truth.

use std::sync::Arc;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use sepval_common::effects::{EffectSet, MAX_EFFECT_PARAMS};
use sepval_common::evaluation::{Candidate, Event, InProcess, Job};
use sepval_common::model::{CoefficientFn, Coefficients, Flow, RunSetup};
use sepval_common::noise::{SIGMA_ATT_DEG, SIGMA_POS_M};
use sepval_common::propagator::{Observation, propagate};
use sepval_common::scenario::{Flight, Scenario};
use sepval_common::simulation::Simulator;
use sepval_common::telemetry::Trajectory;
use sepval_core::factors::{FACTOR_COUNT, Factors};
use sepval_fit::problem::Evaluate;
use sepval_fit::refine::ModelLm;
use sepval_fit::space::{Noise, ParamSpace};
use sepval_predict::source::{Source, SourceKind, SourceModel};
use sepval_predict::{Flown, Prediction, Prepared, Settings, predict, prepare};
use sepval_run::inputs::InputsRecord;
use sepval_run::model_spec::ModelSpec;
use sepval_solve::identifiability::identifiability;
use sepval_solve::lm::LmSettings;
use sepval_solve::run::{NoProgress, run};

/// A cause hidden in the releases.
#[derive(Debug, Clone, Copy)]
pub enum Cause {
    /// Nothing: the fitted model is the true one.
    Null,
    /// A catalogue effect (`id=value`), which the baseline fitted lacks.
    Catalogue(&'static str),
    /// A coefficient function no model of the fit has.
    Term(&'static str, CoefficientFn, [f64; MAX_EFFECT_PARAMS]),
}

impl Cause {
    /// Its name in the table.
    pub fn name(&self) -> String {
        match self {
            Cause::Null => "null".into(),
            Cause::Catalogue(s) => format!("catalogue {s}"),
            Cause::Term(n, _, _) => format!("term {n}"),
        }
    }
}

/// A yaw moment growing with sideslip near the aircraft: p0 beta exp(-s / p1).
fn yaw_interference_beta(p: &[f64; MAX_EFFECT_PARAMS], flow: &Flow, k: &mut Coefficients) {
    k.cn += p[0] * flow.beta_rad * (-flow.distance_m / p[1]).exp();
}

/// Axial force rising with Mach number above 0.75: p0 (M - 0.75).
fn drag_rise(p: &[f64; MAX_EFFECT_PARAMS], flow: &Flow, k: &mut Coefficients) {
    k.cx -= p[0] * (flow.mach - 0.75);
}

/// A pitching moment growing with the angle of attack squared: p0 alpha^2.
fn pitch_alpha_squared(p: &[f64; MAX_EFFECT_PARAMS], flow: &Flow, k: &mut Coefficients) {
    k.cm += p[0] * flow.alpha_rad * flow.alpha_rad;
}

fn params(v: &[f64]) -> [f64; MAX_EFFECT_PARAMS] {
    let mut p = [0.0; MAX_EFFECT_PARAMS];
    p[..v.len()].copy_from_slice(v);
    p
}

/// The causes the cases cycle through.
pub fn causes() -> Vec<Cause> {
    vec![
        Cause::Null,
        Cause::Catalogue("roll_due_to_sideslip=-0.3"),
        Cause::Term(
            "Cn beta exp(-s/0.5)",
            yaw_interference_beta,
            params(&[-2.0, 0.5]),
        ),
        Cause::Catalogue("pitch_stiffness_cubic=40"),
        Cause::Term("Cx (M - 0.75)", drag_rise, params(&[0.5])),
        Cause::Null,
        Cause::Catalogue("interference_decay=0.4"),
        Cause::Term("Cm alpha^2", pitch_alpha_squared, params(&[-3.0])),
    ]
}

/// One case.
#[derive(Debug, Clone)]
pub struct Case {
    /// The hidden cause.
    pub cause: Cause,
    /// The factors of the truth.
    pub base: Factors,
    /// The conditions of the releases fitted.
    pub fitted: Vec<Flight>,
    /// The condition predicted.
    pub predicted: Flight,
    /// The seed of its noise and of the prediction.
    pub seed: u64,
}

fn flight(rng: &mut ChaCha8Rng) -> Flight {
    let mut f = Scenario::embedded_default().flight;
    f.mach = rng.random_range(0.6..0.95);
    f.alpha_deg = rng.random_range(-2.0..4.0);
    f.beta_deg = rng.random_range(-4.0..4.0);
    f
}

/// Case `seed` with `cause` and `releases` releases fitted.
pub fn case(cause: Cause, releases: usize, seed: u64) -> Case {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5EED ^ seed.wrapping_mul(0x9E37_79B9));
    let table = Scenario::embedded_default().factors;
    let mut base = [0.0; FACTOR_COUNT];
    for (b, f) in base.iter_mut().zip(&table.0) {
        let w = f.max - f.min;
        *b = f.min + w * rng.random_range(0.25..0.75);
    }
    Case {
        cause,
        base: Factors(base),
        fitted: (0..releases).map(|_| flight(&mut rng)).collect(),
        predicted: flight(&mut rng),
        seed,
    }
}

fn scenario(f: &Flight) -> Scenario {
    let mut s = Scenario::embedded_default();
    s.flight = f.clone();
    s
}

/// The truth at `f`, noise-free, 1 s at 200 Hz.
pub fn truth(case: &Case, f: &Flight) -> Trajectory {
    let s = scenario(f);
    let sim = Simulator::new(&s);
    let mut effects = EffectSet::NONE;
    if let Cause::Catalogue(spec) = case.cause {
        effects.push_spec(spec).unwrap();
    }
    let mut run = RunSetup::new(sim.model(), &case.base, &effects).unwrap();
    if let Cause::Term(_, func, p) = case.cause {
        run.add_coefficient_term(func, p).unwrap();
    }
    let times: Vec<f64> = (0..=200).map(|k| k as f64 / 200.0).collect();
    let mut obs: Vec<Observation> = Vec::new();
    propagate(sim.model(), &run, &times, &mut obs).unwrap();
    let mut t = Trajectory {
        times_s: times,
        pos_m: obs.iter().map(|o| o.pos_m).collect(),
        att_deg: obs.iter().map(|o| o.att_deg).collect(),
        ..Trajectory::default()
    };
    t.push_metadata("mach", &f.mach.to_string());
    t.push_metadata("alpha_deg", &f.alpha_deg.to_string());
    t.push_metadata("beta_deg", &f.beta_deg.to_string());
    t
}

/// `t` with noise of the docs/model.md sigmas from `seed`.
pub fn noisy(mut t: Trajectory, seed: u64) -> Trajectory {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut n = || -> f64 { StandardNormal.sample(&mut rng) };
    for k in 0..t.times_s.len() {
        t.pos_m[k] = t.pos_m[k].map(|v| v + SIGMA_POS_M * n());
        t.att_deg[k] = t.att_deg[k].map(|v| v + SIGMA_ATT_DEG * n());
    }
    t
}

/// The releases fitted, noisy.
pub fn fitted_job(case: &Case) -> Job {
    let events = case
        .fitted
        .iter()
        .enumerate()
        .map(|(i, f)| Event {
            name: format!("release {}", i + 1),
            simulator: Simulator::new(&scenario(f)),
            data: noisy(truth(case, f), case.seed * 31 + i as u64),
        })
        .collect();
    Job::new(events).unwrap()
}

/// The baseline's factors fitted to `job` and the source a `sepval fit --method ga+lm` would
/// write of them.
pub fn fitted_source(case: &Case, job: &Arc<Job>) -> Source {
    let noise = Noise {
        pos_m: SIGMA_POS_M,
        att_deg: SIGMA_ATT_DEG,
    };
    let space = ParamSpace::new(job.factor_table(), &EffectSet::NONE);
    let mut rng = ChaCha8Rng::seed_from_u64(case.seed ^ 0xF17);
    let x0: Vec<f64> = (0..space.len())
        .map(|i| {
            let r = space.params.range(i);
            (case.base.0[i] + 0.05 * r * rng.random_range(-1.0..1.0))
                .clamp(space.params.lo[i], space.params.hi[i])
        })
        .collect();
    let settings = LmSettings {
        budget: 4000,
        ..LmSettings::default()
    };
    let mut lm = ModelLm::new(space.clone(), Arc::clone(job), &x0, noise, settings);
    let mut ev = InProcess::new(Arc::clone(job), 2);
    run(&mut lm, &mut Evaluate(&mut ev), &mut []).unwrap();
    let r = lm.finish();
    let samples: Vec<usize> = job.events().iter().map(|e| e.data.len()).collect();
    let id = identifiability(&space.params, &r.x, &r.residuals, &r.jacobian, &samples);
    let candidate: Candidate = space.candidate(&r.x).unwrap();
    Source {
        kind: SourceKind::Fit,
        dir: "calibration".into(),
        models: vec![SourceModel {
            spec: ModelSpec::of(&candidate),
            delta_bic: 0.0,
        }],
        identifiability: id,
        noise,
        inputs: InputsRecord {
            data: Vec::new(),
            scenario: None,
            extension: None,
            outliers: Default::default(),
        },
        held_out: Vec::new(),
        data_sha256: None,
    }
}

/// What one case measured.
#[derive(Debug, Clone)]
pub struct Measured {
    /// The fraction of (time, channel) points where the noise-free truth is inside the bands.
    pub coverage: f64,
    /// The mean over channels of the RMS half-width over the RMS error of the median against
    /// the truth (about 1.96 for a calibrated normal 95 % band).
    pub width_ratio: f64,
    /// The model form's share.
    pub form_share: f64,
}

/// Prepares case `case` with `samples` samples (a flown release to check when `flown`).
pub fn prepared(case: &Case, samples: usize, flown: Option<Flown>) -> Prepared {
    prepared_at(case, samples, 0.95, flown)
}

/// [`prepared`] with bands at `level`.
pub fn prepared_at(case: &Case, samples: usize, level: f64, flown: Option<Flown>) -> Prepared {
    let job = Arc::new(fitted_job(case));
    let source = fitted_source(case, &job);
    let settings = Settings {
        samples,
        level,
        seed: case.seed,
        with_noise: false,
        threads: 2,
    };
    prepare(
        source,
        (*job).clone(),
        scenario(&case.predicted),
        Vec::new(),
        flown,
        settings,
    )
    .unwrap()
}

/// Runs a prepared case on `threads` in-process threads.
pub fn predicted(p: &Prepared, threads: usize) -> Prediction {
    let mut ev = InProcess::new(Arc::new(p.job.clone()), threads);
    predict(p, &mut ev, &mut NoProgress).unwrap()
}

/// Runs case `case` with `samples` samples and measures it against its truth.
pub fn measure(case: &Case, samples: usize) -> Measured {
    let p = prepared(case, samples, None);
    let pred = predicted(&p, 2);
    let truth = truth(case, &case.predicted);
    let truth = sepval_predict::simulate::data_on_grid(&truth, &p.grid);
    let (mut inside, mut all) = (0usize, 0usize);
    let mut ratio = 0.0;
    for (c, b) in pred.bands.channels.iter().enumerate() {
        let (mut hw, mut err) = (0.0, 0.0);
        for (k, t) in truth.iter().enumerate() {
            all += 1;
            if t[c] >= b.lo[k] && t[c] <= b.hi[k] {
                inside += 1;
            }
            hw += (0.5 * (b.hi[k] - b.lo[k])).powi(2);
            err += (b.mid[k] - t[c]).powi(2);
        }
        ratio += (hw / err.max(1e-300)).sqrt() / 6.0;
    }
    let s = &pred.bands.shares;
    let form: f64 = (0..6).map(|c| s.rivals[c] + s.discrepancy[c]).sum::<f64>() / 6.0;
    Measured {
        coverage: inside as f64 / all as f64,
        width_ratio: ratio,
        form_share: form,
    }
}
