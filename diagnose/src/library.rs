//! The library of candidate terms a diagnosis tries beyond the effect catalogue
//! (`docs/discovery.md`), the time windows of the model-error reconstruction, and what
//! each term's regressor does along the fitted trajectory (which sets the size of its probe).
//!
//! Grids of the families' locators: interference decay lengths 0.2 to 2 m; the same three
//! lengths (0.3, 0.6, 1.2 m) for the interference-times-flow families; steps every 25 ms inside
//! the record; oscillations every 0.5 Hz from 1 Hz to a quarter of the sample rate (at most
//! 50 Hz), sine and cosine together; the Mach reference at the mean freestream Mach number of
//! the events; gusts (`wind`, on `wind_y` and `wind_z`) at the step times, a 1-cosine onset
//! over 0.1 s and pulses of 0.1 and 0.2 s (the 1-cosine gust of 14 CFR 25.341 with gust
//! gradients of about 30 to 60 m at the airspeeds of a release: docs/model-choices.md).

use sepval_common::evaluation::{Candidate, Job};
use sepval_common::extension::wind::DEFAULT_RISE_S;
use sepval_common::extension::{Axis, Family, Regressor, Term, TermInput};
use sepval_common::model::EquationsOfMotion;
use sepval_common::model::StateVector;
use sepval_common::propagator::{Observation, propagate};

/// Decay lengths of the `interference` family \[m\].
pub const INTERFERENCE_LAMBDAS_M: [f64; 7] = [0.2, 0.3, 0.45, 0.6, 0.9, 1.35, 2.0];
/// Decay lengths of the `interference_flow_angle` family \[m\].
pub const FLOW_LAMBDAS_M: [f64; 3] = [0.3, 0.6, 1.2];
/// Spacing of step times \[s\].
pub const STEP_SPACING_S: f64 = 0.025;
/// Spacing of oscillation frequencies \[Hz\].
pub const FREQUENCY_SPACING_HZ: f64 = 0.5;
/// Size of a probe: the largest coefficient increment (regressor times probe) it makes.
const PROBE: f64 = 1e-3;
/// Size of a wind probe: the largest air velocity it adds \[m/s\] (about 0.02 deg of flow
/// angle at the airspeed of a release: small enough to stay linear, large enough that its
/// column stands well above rounding).
const WIND_PROBE_M_S: f64 = 0.1;
/// Onset lengths of the library's gusts \[s\].
pub const WIND_ONSETS_S: [f64; 1] = [DEFAULT_RISE_S];
/// The shortest gust a refit may make \[s\]: one sample of 200 Hz telemetry (a shorter one is
/// seen only through its impulse, and its length's standard error says so).
pub const SHORTEST_GUST_S: f64 = 0.005;
/// Lengths of the library's gust pulses \[s\].
pub const WIND_PULSES_S: [f64; 2] = [0.1, 0.2];
/// Width of a reconstruction window \[s\] (at least; at most 100 windows per axis).
pub const WINDOW_S: f64 = 0.02;

/// What the store saw at one sample of the fitted trajectory.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    /// The regressors' inputs.
    pub input: TermInput,
    /// Stroke fraction of each foot (forward, aft), clamped to [0, 1].
    pub sigma: [f64; 2],
}

/// The fitted trajectory's flow, per event, at its samples.
pub fn flow_history(job: &Job, base: &Candidate) -> Vec<Vec<Sample>> {
    job.events()
        .iter()
        .map(|e| {
            let sim = &e.simulator;
            let Ok(run) = base.run_setup(sim) else {
                return Vec::new();
            };
            let mut states: Vec<(Observation, StateVector)> = Vec::new();
            if propagate(sim.model(), &run, &e.data.times_s, &mut states).is_err() {
                return Vec::new();
            }
            let eq = EquationsOfMotion::new(&run, &sim.model().curve);
            let stroke = run.stroke_m;
            states
                .iter()
                .zip(&e.data.times_s)
                .map(|((_, x), &t)| {
                    let f = eq.flow(x, t);
                    let q = [x[6], x[7], x[8], x[9]];
                    let c20 = 2.0 * (q[1] * q[3] - q[0] * q[2]);
                    let sigma = std::array::from_fn(|i| {
                        (run.foot_displacement_m(i, x[2], c20) / stroke).clamp(0.0, 1.0)
                    });
                    Sample {
                        input: TermInput {
                            t_s: t,
                            alpha_rad: f.alpha_rad,
                            beta_rad: f.beta_rad,
                            rates_hat: [f.p_hat, f.q_hat, f.r_hat],
                            mach: f.mach,
                            distance_m: f.distance_m,
                            s_end_m: run.decay.s_end_m,
                        },
                        sigma,
                    }
                })
                .collect()
        })
        .collect()
}

/// A candidate explanation: one term, or a sine-cosine pair at one frequency, each with its
/// probe coefficient.
#[derive(Debug, Clone)]
pub struct Entry {
    /// Its terms (coefficient = the probe).
    pub terms: Vec<Term>,
}

#[cfg(test)]
impl Entry {
    /// An entry of one term on `axis` of `regressor`, locators 0 and coefficient 1 (tests).
    pub(crate) fn one(axis: Axis, regressor: Regressor) -> Entry {
        Entry {
            terms: vec![Term {
                axis,
                regressor,
                locator: [0.0; 2],
                coefficient: 1.0,
            }],
        }
    }
}

impl Entry {
    /// Its family.
    pub fn family(&self) -> Family {
        self.terms[0].regressor.family()
    }

    /// Its axis.
    pub fn axis(&self) -> Axis {
        self.terms[0].axis
    }

    /// The same axis and regressor as `other` (any locator).
    pub fn same_kind(&self, other: &Entry) -> bool {
        self.axis() == other.axis() && self.terms[0].regressor == other.terms[0].regressor
    }

    /// A readable formula: its term's, or an oscillation pair's as one sinusoid.
    pub fn formula(&self) -> String {
        match self.terms.as_slice() {
            [a, b] if a.regressor == Regressor::Sin && b.regressor == Regressor::Cos => {
                format!(
                    "sin(2 pi {} Hz t + phase)",
                    super::readings::fmt_num(a.locator[0])
                )
            }
            [t, ..] => t.formula(),
            [] => String::new(),
        }
    }

    /// Its axis and formula, as the notes name it.
    pub fn label(&self) -> String {
        format!("{} {}", self.axis().name(), self.formula())
    }
}

/// The largest |regressor| of `term` along the history (ejector terms: during the stroke).
fn magnitude(term: &Term, history: &[Vec<Sample>]) -> f64 {
    history
        .iter()
        .flatten()
        .map(|s| {
            if term.axis == Axis::Ejector {
                s.sigma
                    .iter()
                    .filter(|sig| **sig < 1.0)
                    .map(|&sig| term.ejector_value(s.input.t_s, sig).abs())
                    .fold(0.0, f64::max)
            } else {
                term.regressor_value(&s.input).abs()
            }
        })
        .fold(0.0, f64::max)
}

/// `term` with its probe coefficient, or `None` when its regressor is zero along the record.
fn probed(mut term: Term, history: &[Vec<Sample>]) -> Option<Term> {
    let m = magnitude(&term, history);
    if m.is_nan() || m <= 1e-9 {
        return None;
    }
    let size = if term.axis.is_wind() {
        WIND_PROBE_M_S
    } else {
        PROBE
    };
    term.coefficient = size / m;
    Some(term)
}

/// The probe coefficient of `term` along the history (the probe itself when its regressor
/// vanishes there).
pub fn probe_size(term: &Term, history: &[Vec<Sample>]) -> f64 {
    probed(*term, history).map_or(PROBE, |t| t.coefficient)
}

/// The library's entries for a job whose fitted trajectory is `history`, sampled at `rate_hz`.
pub fn library(job: &Job, history: &[Vec<Sample>], rate_hz: f64) -> Vec<Entry> {
    let aero = [Axis::CA, Axis::CY, Axis::CZ, Axis::Cl, Axis::Cm, Axis::Cn];
    let mut plain: Vec<(Regressor, f64)> = Vec::new();
    for r in [
        Regressor::Alpha,
        Regressor::Beta,
        Regressor::Alpha2,
        Regressor::Beta2,
        Regressor::Alpha3,
        Regressor::Beta3,
        Regressor::AlphaBeta,
        Regressor::P,
        Regressor::Q,
        Regressor::R,
    ] {
        plain.push((r, 0.0));
    }
    for l in INTERFERENCE_LAMBDAS_M {
        plain.push((Regressor::F, l));
    }
    for l in FLOW_LAMBDAS_M {
        for r in [
            Regressor::FAlpha,
            Regressor::FBeta,
            Regressor::FP,
            Regressor::FQ,
            Regressor::FR,
        ] {
            plain.push((r, l));
        }
    }
    let mach0 = job
        .events()
        .iter()
        .map(|e| e.simulator.scenario().flight.mach)
        .sum::<f64>()
        / job.events().len() as f64;
    plain.push((Regressor::Dm, mach0));
    plain.push((Regressor::Dm2, mach0));
    let t_ons = step_times(history);
    for &t_on in &t_ons {
        plain.push((Regressor::Step, t_on));
    }
    let mut entries = Vec::new();
    for axis in aero {
        for &(regressor, locator) in &plain {
            let term = Term {
                axis,
                regressor,
                locator: [locator, 0.0],
                coefficient: 0.0,
            };
            if let Some(t) = probed(term, history) {
                entries.push(Entry { terms: vec![t] });
            }
        }
    }
    for regressor in [Regressor::Stroke, Regressor::Stroke2] {
        let term = Term {
            axis: Axis::Ejector,
            regressor,
            locator: [0.0; 2],
            coefficient: 0.0,
        };
        if let Some(t) = probed(term, history) {
            entries.push(Entry { terms: vec![t] });
        }
    }
    let f_max = (rate_hz / 4.0).min(50.0);
    let mut f = 1.0;
    while f <= f_max + 1e-9 {
        for axis in aero {
            let pair: Vec<Term> = [Regressor::Sin, Regressor::Cos]
                .into_iter()
                .filter_map(|regressor| {
                    probed(
                        Term {
                            axis,
                            regressor,
                            locator: [f, 0.0],
                            coefficient: 0.0,
                        },
                        history,
                    )
                })
                .collect();
            if pair.len() == 2 {
                entries.push(Entry { terms: pair });
            }
        }
        f += FREQUENCY_SPACING_HZ;
    }
    entries.extend(gusts(&t_ons, history));
    entries
}

/// The step times: every [`STEP_SPACING_S`] from the record's start plus one spacing to its end
/// less one, to the microsecond.
fn step_times(history: &[Vec<Sample>]) -> Vec<f64> {
    let (t0, t1) = span(history);
    let mut out = Vec::new();
    let mut t_on = t0 + STEP_SPACING_S;
    while t_on < t1 - STEP_SPACING_S + 1e-9 {
        out.push((t_on * 1e6).round() / 1e6);
        t_on += STEP_SPACING_S;
    }
    out
}

/// The `wind` entries: on each wind axis, an onset and the pulses at each step time.
fn gusts(t_ons: &[f64], history: &[Vec<Sample>]) -> Vec<Entry> {
    let shapes = WIND_ONSETS_S
        .map(|t| (Regressor::WindStep, t))
        .into_iter()
        .chain(WIND_PULSES_S.map(|t| (Regressor::WindPulse, t)));
    let mut entries = Vec::new();
    for (regressor, rise_s) in shapes {
        for axis in Axis::WIND {
            for &t_on in t_ons {
                let term = Term {
                    axis,
                    regressor,
                    locator: [t_on, rise_s],
                    coefficient: 0.0,
                };
                if let Some(t) = probed(term, history) {
                    entries.push(Entry { terms: vec![t] });
                }
            }
        }
    }
    entries
}

/// Earliest and latest sample times of the record.
pub fn span(history: &[Vec<Sample>]) -> (f64, f64) {
    let times = history.iter().flatten().map(|s| s.input.t_s);
    let t0 = times.clone().fold(f64::INFINITY, f64::min).max(0.0);
    let t1 = times.fold(f64::NEG_INFINITY, f64::max);
    (t0, t1)
}

/// Reconstruction windows: for each aerodynamic axis, consecutive windows over the record; for
/// the ejector, windows over the stroke (half as wide). Each term's coefficient is its probe.
pub fn windows(history: &[Vec<Sample>]) -> Vec<Term> {
    let (t0, t1) = span(history);
    let width = WINDOW_S.max((t1 - t0) / 100.0);
    let edges = |from: f64, to: f64, w: f64| -> Vec<[f64; 2]> {
        let n = ((to - from) / w).ceil().max(1.0) as usize;
        (0..n)
            .map(|k| {
                [
                    from + k as f64 * w,
                    if k + 1 == n {
                        to + 1e-9
                    } else {
                        from + (k + 1) as f64 * w
                    },
                ]
            })
            .collect()
    };
    let mut out = Vec::new();
    for axis in [Axis::CA, Axis::CY, Axis::CZ, Axis::Cl, Axis::Cm, Axis::Cn] {
        for locator in edges(t0, t1, width) {
            out.push(Term {
                axis,
                regressor: Regressor::Window,
                locator,
                coefficient: PROBE,
            });
        }
    }
    // The stroke: while either foot is below the stroke end.
    let stroke_end = history
        .iter()
        .flatten()
        .filter(|s| s.sigma.iter().any(|sig| *sig < 1.0))
        .map(|s| s.input.t_s)
        .fold(f64::NEG_INFINITY, f64::max);
    if stroke_end > t0 {
        for locator in edges(t0, stroke_end + width / 2.0, width / 2.0) {
            out.push(Term {
                axis: Axis::Ejector,
                regressor: Regressor::Window,
                locator,
                coefficient: PROBE,
            });
        }
    }
    out
}
