//! A model as files hold it ([`ModelSpec`]) rebuilt to be refitted or moved: its candidate
//! checked against the factor table of the releases it was fitted to, its free parameters (the
//! 17 factors, the effects' parameters, each term's coefficient within
//! [`TERM_COEFFICIENT_SPAN`] times its estimate, as the diagnosis's refits of discovered terms
//! bound them, locators held), their values, and its name. `sepval plan` and `sepval predict`
//! rebuild the answer and the rivals of a diagnosis this way.

use sepval_common::evaluation::Candidate;
use sepval_core::factors::FactorTable;
use sepval_solve::identifiability::Identifiability;

use crate::space::{FreeTerm, ParamSpace};
use sepval_run::model_spec::{ModelSpec, ModelSpecError};

/// A term's coefficient may move within this many times its estimate either way (the bounds
/// of the diagnosis's refits of discovered terms).
pub const TERM_COEFFICIENT_SPAN: f64 = 10.0;

/// A model of a file that cannot be rebuilt.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RebuildError {
    /// A model record that names no model.
    #[error("{which}")]
    Spec {
        /// Which model (`the answer`, `rival N`).
        which: String,
        /// Why.
        #[source]
        source: ModelSpecError,
    },
    /// A model whose factors are outside the factor table of the inputs.
    #[error("{which}: its factors do not fit the scenario's factor table: {message}")]
    Factors {
        /// Which model (`the answer`, `rival N`).
        which: String,
        /// Why.
        message: String,
    },
}

/// A model rebuilt with its free parameters.
#[derive(Debug, Clone)]
pub struct Rebuilt {
    /// Its name in reports: its effects and terms (`baseline` when it has none).
    pub name: String,
    /// Its candidate at its estimate.
    pub candidate: Candidate,
    /// Its free parameters (names, bounds).
    pub space: ParamSpace,
    /// Their values at its estimate.
    pub x: Vec<f64>,
}

/// `spec` (named `which` in errors) rebuilt against `table`.
pub fn rebuild(
    spec: &ModelSpec,
    which: &str,
    table: &FactorTable,
) -> Result<Rebuilt, RebuildError> {
    let candidate = spec.candidate().map_err(|source| RebuildError::Spec {
        which: which.to_string(),
        source,
    })?;
    table
        .check(&candidate.factors)
        .map_err(|e| RebuildError::Factors {
            which: which.to_string(),
            message: e.to_string(),
        })?;
    let space = free_space(&candidate, table);
    let x = space.start(&candidate.factors);
    Ok(Rebuilt {
        name: model_name(&candidate),
        candidate,
        space,
        x,
    })
}

/// The free parameters of `candidate`: the factors of `table`, its effects' parameters, and its
/// terms' coefficients within [`TERM_COEFFICIENT_SPAN`] times their estimates (locators held).
pub fn free_space(candidate: &Candidate, table: &FactorTable) -> ParamSpace {
    let free: Vec<FreeTerm> = candidate
        .terms
        .iter()
        .map(|t| {
            let b = TERM_COEFFICIENT_SPAN * t.coefficient.abs().max(1e-12);
            FreeTerm::coefficient_only(*t, (-b, b))
        })
        .collect();
    ParamSpace::with_terms(table, &candidate.effects, &free)
}

/// A model in words: its effects and terms (`baseline` when it has none).
pub fn model_name(c: &Candidate) -> String {
    let mut parts: Vec<String> = c
        .effects
        .iter()
        .map(|a| a.effect().id().to_string())
        .collect();
    parts.extend(
        c.terms
            .iter()
            .map(|t| format!("{}: {}", t.axis.name(), t.formula())),
    );
    if parts.is_empty() {
        "baseline".into()
    } else {
        parts.join(" + ")
    }
}

/// `x`, the values of `space`'s parameters, at a record's estimate: each parameter that
/// `identifiability` names takes its recorded value, clamped to its bounds (a value that is not
/// finite leaves the rebuilt one). The answer of a diagnosis is flown at these values by
/// `sepval predict`, and its releases' clearance by the diagnosis.
pub fn at_estimate(space: &ParamSpace, x: &mut [f64], identifiability: &Identifiability) {
    let id = identifiability;
    for (j, name) in space.params.names.iter().enumerate() {
        if let Some(k) = id.names.iter().position(|n| n == name) {
            let v = id.parameters[k].value;
            if v.is_finite() {
                x[j] = v.clamp(space.params.lo[j], space.params.hi[j]);
            }
        }
    }
}

/// The candidate of `spec` (named `which` in errors) rebuilt against `table` at its recorded
/// estimate ([`at_estimate`], when the record holds one).
pub fn candidate_at_estimate(
    spec: &ModelSpec,
    which: &str,
    table: &FactorTable,
    identifiability: Option<&Identifiability>,
) -> Result<Candidate, RebuildError> {
    let Rebuilt { space, mut x, .. } = rebuild(spec, which, table)?;
    if let Some(id) = identifiability {
        at_estimate(&space, &mut x, id);
    }
    space.candidate(&x).map_err(|e| RebuildError::Factors {
        which: which.to_string(),
        message: e.to_string(),
    })
}
