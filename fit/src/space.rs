//! The continuous parameters of a refinement and its residual vector: every sample's position
//! and attitude error divided by its noise sigma.

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{Candidate, Job};
use sepval_common::extension::{Family, Term, TermSet};
use sepval_common::goals::{Goals, residual};
use sepval_common::propagator::Observation;
use sepval_core::factors::{FACTOR_COUNT, Factor, FactorTable, Factors};
use sepval_solve::lm::Measure;
use sepval_solve::params::Params;
use sepval_solve::run::{RunError, SearchError};

type Result<T> = std::result::Result<T, RunError>;

/// A point of the space that is not a valid model: the model's own error.
fn search_error(e: impl std::error::Error + Send + Sync + 'static) -> RunError {
    RunError::Search(SearchError::Point(std::sync::Arc::new(e)))
}

/// An extension term whose coefficient (and, for the families that have them, locators) a fit
/// estimates, within bounds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreeTerm {
    /// The term (its coefficient and locators are the parameters' start values).
    pub term: Term,
    /// Bounds of the coefficient.
    pub coefficient: (f64, f64),
    /// Bounds of the locator, when it is estimated too: a step's time, a frequency, a decay
    /// length (`locator[0]`); for a gust, its middle `t_on + rise_s / 2`, which the data place
    /// far better than its onset when its length is uncertain (the parameter `t_mid_s`).
    pub locator: Option<(f64, f64)>,
    /// Bounds of a gust's length (`locator[1]`, `rise_s`), when it is estimated too.
    pub length: Option<(f64, f64)>,
    /// Whether its locator is the term before it's (the cosine of an oscillation takes the
    /// frequency its sine carries): no parameter of its own.
    pub tied: bool,
}

impl FreeTerm {
    /// A term whose coefficient alone is estimated, within `coefficient`.
    pub fn coefficient_only(term: Term, coefficient: (f64, f64)) -> Self {
        FreeTerm {
            term,
            coefficient,
            locator: None,
            length: None,
            tied: false,
        }
    }

    /// How many parameters it has: its coefficient, then its locator and its length when they
    /// are estimated.
    pub fn param_count(&self) -> usize {
        1 + usize::from(self.locator.is_some()) + usize::from(self.length.is_some())
    }

    /// Its parameters' start values, in the order of [`FreeTerm::param_count`].
    pub fn start(&self) -> Vec<f64> {
        let mut x = vec![self.term.coefficient];
        if self.locator.is_some() {
            x.push(self.locator_value());
        }
        if self.length.is_some() {
            x.push(self.term.locator[1]);
        }
        x
    }

    /// Whether its locator parameter is a gust's middle.
    fn is_gust(&self) -> bool {
        self.term.regressor.family() == Family::Wind
    }

    /// The value of its locator parameter at its term.
    fn locator_value(&self) -> f64 {
        let [l, rise_s] = self.term.locator;
        if self.is_gust() { l + rise_s / 2.0 } else { l }
    }
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
                let loc = if t.is_gust() { "t_mid_s" } else { loc };
                let unit = match loc {
                    "lambda_m" => "m",
                    "t_on_s" | "t_mid_s" => "s",
                    "f_hz" => "Hz",
                    _ => "-",
                };
                s.params.push(format!("{name}.{loc}"), unit, lo, hi);
                s.grid_step.push(None);
            }
            if let Some((lo, hi)) = t.length {
                s.params.push(format!("{name}.rise_s"), "s", lo, hi);
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
            x.extend(t.start());
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
        let mut previous: Option<Term> = None;
        for t in &self.terms {
            let mut term = t.term;
            term.coefficient = x[i];
            i += 1;
            // Each locator held within its bounds (which lie inside its domain): a probe of the
            // refinement may stray beyond them, and a decay length or a gust's length must stay
            // positive.
            let locator = t
                .locator
                .map(|_| x[i].clamp(self.params.lo[i], self.params.hi[i]));
            i += usize::from(locator.is_some());
            if t.length.is_some() {
                term.locator[1] = x[i].clamp(self.params.lo[i], self.params.hi[i]);
                i += 1;
            }
            match locator {
                Some(middle) if t.is_gust() => term.locator[0] = middle - term.locator[1] / 2.0,
                Some(l) => term.locator[0] = l,
                None => {}
            }
            if let (true, Some(p)) = (t.tied, previous) {
                term.locator[0] = p.locator[0];
            }
            terms.push(term).map_err(search_error)?;
            previous = Some(term);
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

#[cfg(test)]
mod tests {
    use sepval_common::extension::{Axis, Regressor};

    use super::*;

    /// A gust's locator parameter is its middle: the start vector holds t_on + T/2, and a
    /// vector that moves the length keeps the middle where the parameter puts it; an
    /// oscillation's cosine takes the frequency of the sine before it.
    #[test]
    fn a_gust_is_estimated_by_its_middle_and_a_tied_term_follows_its_lead() {
        let gust = Term {
            axis: Axis::WindY,
            regressor: Regressor::WindPulse,
            locator: [0.3, 0.1],
            coefficient: 8.0,
        };
        let sin = Term {
            axis: Axis::Cn,
            regressor: Regressor::Sin,
            locator: [7.0, 0.0],
            coefficient: 0.01,
        };
        let cos = Term {
            regressor: Regressor::Cos,
            ..sin
        };
        let terms = [
            FreeTerm {
                locator: Some((0.3, 0.4)),
                length: Some((0.005, 0.4)),
                ..FreeTerm::coefficient_only(gust, (-80.0, 80.0))
            },
            FreeTerm {
                locator: Some((6.5, 7.5)),
                ..FreeTerm::coefficient_only(sin, (-1.0, 1.0))
            },
            FreeTerm {
                tied: true,
                ..FreeTerm::coefficient_only(cos, (-1.0, 1.0))
            },
        ];
        let space = ParamSpace::with_terms(&FactorTable::default(), &EffectSet::NONE, &terms);
        assert_eq!(space.len(), FACTOR_COUNT + 6);
        assert_eq!(
            space.params.names[FACTOR_COUNT + 1],
            "wind_y.pulse(t-0.3s;0.1s).t_mid_s"
        );
        let mut x = space.start(&Factors::NOMINAL);
        assert_eq!(&x[FACTOR_COUNT..FACTOR_COUNT + 3], &[8.0, 0.35, 0.1]);
        let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() + (a[1] - b[1]).abs() < 1e-12;
        assert!(close(space.terms_at(&x).unwrap()[0].locator, [0.3, 0.1]));
        x[FACTOR_COUNT + 2] = 0.02;
        x[FACTOR_COUNT + 4] = 7.25;
        let at = space.terms_at(&x).unwrap();
        assert!(close(at[0].locator, [0.34, 0.02]), "{:?}", at[0].locator);
        assert_eq!((at[1].locator[0], at[2].locator[0]), (7.25, 7.25));
    }
}
