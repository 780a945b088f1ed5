//! The continuous parameters of a refinement and its residual vector: every sample's position
//! and attitude error divided by its noise sigma.

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{Candidate, Job};
use sepval_common::factors::{FACTOR_COUNT, Factor, FactorTable, Factors};
use sepval_common::goals::{Goals, residual};
use sepval_common::propagator::Observation;

use super::{Result, search_error};

/// The continuous parameters of a fit: the 17 factors, then the effects' parameters.
#[derive(Debug, Clone)]
pub struct ParamSpace {
    /// Names (factor names; `effect.param` for effect parameters).
    pub names: Vec<String>,
    /// Units ("-" for factors).
    pub units: Vec<String>,
    /// Lower bounds.
    pub lo: Vec<f64>,
    /// Upper bounds.
    pub hi: Vec<f64>,
    /// Grid step of the GA's binary encoding (factors only).
    pub grid_step: Vec<Option<f64>>,
    /// The model variant (its values are replaced by the parameter vector).
    pub effects: EffectSet,
}

impl ParamSpace {
    /// The space of the factor table and the effects of `effects`.
    pub fn new(table: &FactorTable, effects: &EffectSet) -> Self {
        let mut s = ParamSpace {
            names: Factor::NAMES.iter().map(|n| n.to_string()).collect(),
            units: vec!["-".to_string(); FACTOR_COUNT],
            lo: table.0.iter().map(|f| f.min).collect(),
            hi: table.0.iter().map(|f| f.max).collect(),
            grid_step: table.0.iter().map(|f| Some(f.step())).collect(),
            effects: *effects,
        };
        for a in effects.iter() {
            for p in a.effect().params() {
                s.names.push(format!("{}.{}", a.effect().id(), p.name));
                s.units.push(p.unit.to_string());
                s.lo.push(p.min);
                s.hi.push(p.max);
                s.grid_step.push(None);
            }
        }
        s
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Whether there are no parameters.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Width of parameter `i`'s range.
    pub fn range(&self, i: usize) -> f64 {
        self.hi[i] - self.lo[i]
    }

    /// The parameter vector of factors and the effect set's current values.
    pub fn vector(&self, factors: &Factors, effects: &EffectSet) -> Vec<f64> {
        let mut x = factors.0.to_vec();
        x.extend(effects.values());
        x
    }

    /// Projects `x` onto the bounds.
    pub fn clamp(&self, x: &[f64]) -> Vec<f64> {
        x.iter()
            .enumerate()
            .map(|(i, v)| v.clamp(self.lo[i], self.hi[i]))
            .collect()
    }

    /// The candidate of parameter vector `x`.
    pub fn candidate(&self, x: &[f64]) -> Result<Candidate> {
        let mut f = [0.0; FACTOR_COUNT];
        f.copy_from_slice(&x[..FACTOR_COUNT]);
        Ok(Candidate {
            factors: Factors(f),
            effects: self
                .effects
                .with_values(&x[FACTOR_COUNT..])
                .map_err(search_error)?,
        })
    }
}

/// Noise levels normalising the residuals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    /// Position \[m\].
    pub pos_m: f64,
    /// Attitude \[deg\].
    pub att_deg: f64,
}

/// The normalised residual vector of simulated samples against the job's data: per event, per
/// sample, (dx, dy, dz) / sigma_pos and (droll, dpitch, dyaw) / sigma_att.
pub fn residual_vector(job: &Job, samples: &[Vec<Observation>], noise: Noise) -> Vec<f64> {
    let mut r = Vec::with_capacity(6 * job.sample_count());
    for (e, sim) in job.events().iter().zip(samples) {
        for (k, o) in sim.iter().enumerate() {
            let (p, a) = residual(o, &e.data.pos_m[k], &e.data.att_deg[k]);
            r.extend(p.iter().map(|v| v / noise.pos_m));
            r.extend(a.iter().map(|v| v / noise.att_deg));
        }
    }
    r
}

/// The goals of a normalised residual vector.
pub fn goals_of(r: &[f64], noise: Noise) -> Goals {
    let (mut p, mut a, mut n) = (0.0, 0.0, 0usize);
    for s in r.chunks_exact(6) {
        p += s[..3].iter().map(|v| v * v).sum::<f64>();
        a += s[3..].iter().map(|v| v * v).sum::<f64>();
        n += 1;
    }
    let n3 = 3.0 * n.max(1) as f64;
    Goals {
        j_pos_m: noise.pos_m * (p / n3).sqrt(),
        j_att_deg: noise.att_deg * (a / n3).sqrt(),
    }
}
