//! The continuous parameters of a refinement and its residual vector: every sample's position
//! and attitude error divided by its noise sigma.

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{Candidate, Job};
use sepval_common::extension::{Term, TermSet};
use sepval_common::factors::{FACTOR_COUNT, Factor, FactorTable, Factors};
use sepval_common::goals::{Goals, residual};
use sepval_common::propagator::Observation;
use sepval_solve::lm::Measure;
use sepval_solve::params::Params;
use sepval_solve::run::RunError;

type Result<T> = std::result::Result<T, RunError>;

fn search_error(what: impl std::fmt::Display) -> RunError {
    RunError::Search(what.to_string())
}

/// An extension term whose coefficient (and, for the families that have one, locator) a fit
/// estimates, within bounds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreeTerm {
    /// The term (its coefficient and locator are the parameters' start values).
    pub term: Term,
    /// Bounds of the coefficient.
    pub coefficient: (f64, f64),
    /// Bounds of the locator, when it is estimated too.
    pub locator: Option<(f64, f64)>,
}

/// The continuous parameters of a fit: the 17 factors, then the effects' parameters, then the
/// extension terms' coefficients (and free locators).
#[derive(Debug, Clone)]
pub struct ParamSpace {
    /// Names (factor names; `effect.param` for effect parameters), units ("-" for factors)
    /// and bounds.
    pub params: Params,
    /// Grid step of the GA's binary encoding (factors only).
    pub grid_step: Vec<Option<f64>>,
    /// The model variant (its values are replaced by the parameter vector).
    pub effects: EffectSet,
    /// The extension terms estimated (their values are replaced by the parameter vector).
    pub terms: Vec<FreeTerm>,
}

impl ParamSpace {
    /// The space of the factor table and the effects of `effects`.
    pub fn new(table: &FactorTable, effects: &EffectSet) -> Self {
        let mut params = Params::empty();
        for (name, f) in Factor::NAMES.iter().zip(&table.0) {
            params.push(*name, "-", f.min, f.max);
        }
        let mut s = ParamSpace {
            params,
            grid_step: table.0.iter().map(|f| Some(f.step())).collect(),
            effects: *effects,
            terms: Vec::new(),
        };
        for a in effects.iter() {
            for p in a.effect().params() {
                let name = format!("{}.{}", a.effect().id(), p.name);
                s.params.push(name, p.unit, p.min, p.max);
                s.grid_step.push(None);
            }
        }
        s
    }

    /// The space of the factor table, `effects` and the extension `terms`.
    pub fn with_terms(table: &FactorTable, effects: &EffectSet, terms: &[FreeTerm]) -> Self {
        let mut s = ParamSpace::new(table, effects);
        for t in terms {
            let name = format!(
                "{}.{}",
                t.term.axis.name(),
                t.term.formula().replace(' ', "")
            );
            s.params
                .push(name.clone(), "-", t.coefficient.0, t.coefficient.1);
            s.grid_step.push(None);
            if let (Some((lo, hi)), Some(loc)) = (t.locator, t.term.regressor.family().locator()) {
                let unit = match loc {
                    "lambda_m" => "m",
                    "t_on_s" => "s",
                    "f_hz" => "Hz",
                    _ => "-",
                };
                s.params.push(format!("{name}.{loc}"), unit, lo, hi);
                s.grid_step.push(None);
            }
        }
        s.terms = terms.to_vec();
        s
    }

    /// The start vector: `factors`, the effects' current values, the terms' coefficients and
    /// free locators.
    pub fn start(&self, factors: &Factors) -> Vec<f64> {
        let mut x = self.vector(factors, &self.effects);
        for t in &self.terms {
            x.push(t.term.coefficient);
            if t.locator.is_some() {
                x.push(t.term.locator[0]);
            }
        }
        x
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.params.len()
    }

    /// Whether there are no parameters.
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// The parameter vector of factors and the effect set's current values.
    pub fn vector(&self, factors: &Factors, effects: &EffectSet) -> Vec<f64> {
        let mut x = factors.0.to_vec();
        x.extend(effects.values());
        x
    }

    /// The candidate of parameter vector `x`.
    pub fn candidate(&self, x: &[f64]) -> Result<Candidate> {
        let mut f = [0.0; FACTOR_COUNT];
        f.copy_from_slice(&x[..FACTOR_COUNT]);
        let n_effects = self.effects.param_count();
        let effects = self
            .effects
            .with_values(&x[FACTOR_COUNT..FACTOR_COUNT + n_effects])
            .map_err(search_error)?;
        let mut terms = TermSet::NONE;
        let mut i = FACTOR_COUNT + n_effects;
        for t in &self.terms {
            let mut term = t.term;
            term.coefficient = x[i];
            i += 1;
            if t.locator.is_some() {
                // Held within its bounds (which lie inside its domain): a probe of the
                // refinement may stray beyond them, and a decay length must stay positive.
                term.locator[0] = x[i].clamp(self.params.lo[i], self.params.hi[i]);
                i += 1;
            }
            terms.push(term).map_err(search_error)?;
        }
        Ok(Candidate {
            factors: Factors(f),
            effects,
            terms,
            corrections: sepval_common::correction::CorrectionValues::NONE,
        })
    }

    /// The terms at parameter vector `x`.
    pub fn terms_at(&self, x: &[f64]) -> Result<Vec<Term>> {
        Ok(self.candidate(x)?.terms.iter().copied().collect())
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

impl Measure for Noise {
    fn goals(&self, r: &[f64]) -> Goals {
        goals_of(r, *self)
    }
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
