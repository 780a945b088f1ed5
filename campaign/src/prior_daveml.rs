//! The store's data with uncertainty taken into the prior (`sepval campaign init
//! --prior-daveml FILE.xml`, docs/campaign.md "Beginning from pre-flight knowledge"): a DAVE-ML
//! 2.0 model whose tables carry a `normalPDF` uncertainty, as `sepval update --daveml` writes
//! them (its bounds one standard deviation per table value, `numSigmas="1"`,
//! [`sepval_daveml::export`]), read with the default map ([`sepval_daveml::Map`]).
//!
//! Each uncertain field is mapped back to the factor that moves it in the model (docs/model.md
//! section 3: CX = -(CA0 + caoff) + caintfac dCX0 f(s), ...): a static coefficient's table
//! (`aero.ca0`, `aero.cy`, `aero.cz`, `aero.cl`, `aero.cm`, `aero.cn`) to its offset (caoff,
//! cyoff, czoff, cloff, cmoff, cnoff), an interference increment's (`interference.dcx0` ...
//! `dcn0`) to its multiplier (caintfac ... cnintfac). With e_i the factor's effect on the
//! table's value i (1 for an offset, the campaign scenario's table T_i there for a multiplier),
//! d_i the file's value less the scenario's, and s_i the value's standard deviation, the
//! factor's belief is the least-squares projection of the file onto that effect (the factor
//! that moves the scenario's table nearest to the file's, and the spread that moves it by the
//! band's root-mean-square):
//!
//!   mean = nominal + sum(e_i d_i) / sum(e_i^2),   sd = |s| / |e|
//!
//! (Euclidean norms over the table's values; the band's values are correlated, interpolated
//! from a correction's few breakpoints, docs/daveml.md, so the sd is the band's size, not a
//! measurement of it per value, which would shrink it with the table's resolution). Anything
//! uncertain that cannot be mapped is refused naming the element: a derivative's table (no
//! factor scales a derivative), a `uniformPDF`, a `normalPDF` without `numSigmas` or with
//! bounds of another shape, a multiplier's table that is 0 everywhere, a mean outside the
//! factor's range, a scenario table over a variable the file's is not. A file with no
//! uncertainty is refused too: it gives the prior nothing.

use std::path::Path;

use sepval_common::correction::Target;
use sepval_common::scenario::Scenario;
use sepval_common::table::{Coefficient, Table};
use sepval_core::factors::{Factor, FactorTable};
use sepval_daveml::import::{FieldValue, ImportedField};

use crate::CampaignError;
use crate::prior::{Belief, Prior, PriorSource};
pub use crate::sources::Mapped;

/// The factor that moves `t`, and whether it is an offset (else a multiplier).
pub(crate) fn factor_of(t: Target) -> Option<(Factor, bool)> {
    let name = match t {
        Target::Static(k) => ["caoff", "cyoff", "czoff", "cloff", "cmoff", "cnoff"].get(k),
        Target::Interference(k) => [
            "caintfac", "cyintfac", "czintfac", "clintfac", "cmintfac", "cnintfac",
        ]
        .get(k),
        _ => None,
    }?;
    Factor::from_name(name).map(|f| (f, matches!(t, Target::Static(_))))
}

/// `prior` with the factors the uncertain fields of the DAVE-ML file `path` map to set (module
/// docs); `scenario` the campaign's. A factor `prior` took from a `--prior` file is refused:
/// two sources would give it.
pub fn read(path: &Path, scenario: &Scenario, prior: &Prior) -> Result<Prior, CampaignError> {
    let name = path.display().to_string();
    let daveml = |e: sepval_daveml::DavemlError| CampaignError::Daveml {
        path: name.clone(),
        source: Box::new(e),
    };
    let map = sepval_daveml::load_map(None).map_err(daveml)?;
    let model = sepval_daveml::read_model(path, &map, scenario).map_err(daveml)?;
    let refuse = |reason: PriorDavemlError| CampaignError::PriorDaveml {
        path: name.clone(),
        reason: Box::new(reason),
    };
    let from_file: Vec<&String> = prior
        .sources
        .iter()
        .filter_map(|s| match s {
            PriorSource::File { factors, .. } => Some(factors),
            _ => None,
        })
        .flatten()
        .collect();
    let mut out = prior.clone();
    let mut mapped: Vec<Mapped> = Vec::new();
    for f in model.given.iter().filter(|f| f.spread.is_some()) {
        let m = map_field(f, scenario, &scenario.factors).map_err(&refuse)?;
        if let Some(prev) = mapped.iter().find(|p| p.factor == m.factor) {
            return Err(refuse(PriorDavemlError::Twice {
                first: prev.element.clone(),
                second: m.element.clone(),
                factor: m.factor.clone(),
            }));
        }
        if from_file.contains(&&m.factor) {
            return Err(refuse(PriorDavemlError::AlsoInPriorFile {
                element: m.element.clone(),
                factor: m.factor.clone(),
            }));
        }
        out.factors.insert(m.factor.clone(), m.belief);
        mapped.push(m);
    }
    if mapped.is_empty() {
        return Err(refuse(PriorDavemlError::NoUncertainty));
    }
    let bytes = std::fs::read(path).map_err(|e| crate::record::record_error(path, e))?;
    let absolute = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    out.source = format!("{} and {name}", prior.source);
    out.sources.push(PriorSource::Daveml {
        path: absolute.display().to_string(),
        sha256: sepval_common::scenario::hex_sha256(&bytes),
        mapped,
    });
    Ok(out)
}

/// The factor's belief from one uncertain field (module docs), or why it cannot be mapped.
fn map_field(
    f: &ImportedField,
    scenario: &Scenario,
    table: &FactorTable,
) -> Result<Mapped, PriorDavemlError> {
    let spread = f.spread.as_ref().expect("an uncertain field");
    let element = spread.place.to_string();
    let field = f.target.field();
    let refuse = |reason: FieldRefusal| PriorDavemlError::Field {
        element: element.clone(),
        field: field.clone(),
        reason,
    };
    if let Some(why) = &spread.unusable {
        return Err(refuse(FieldRefusal::Unusable { why: why.clone() }));
    }
    let Some((factor, offset)) = factor_of(f.target) else {
        return Err(refuse(FieldRefusal::NoFactor));
    };
    let (values, base) = values_and_base(f, scenario).map_err(&refuse)?;
    let sd: Vec<f64> = (0..values.len())
        .map(|i| spread.sd[if spread.sd.len() == 1 { 0 } else { i }])
        .collect();
    let at = Points {
        values: &values,
        base: &base,
        sd: &sd,
    };
    let belief = belief(factor, offset, &at, table, &field).map_err(&refuse)?;
    Ok(Mapped {
        element,
        field,
        factor: factor.name().to_string(),
        belief,
    })
}

/// A field's values at its points: the source's, the campaign scenario's and the source's
/// standard deviation at each.
pub(crate) struct Points<'a> {
    /// The source's values.
    pub values: &'a [f64],
    /// The campaign scenario's at the same points.
    pub base: &'a [f64],
    /// The source's standard deviation at each.
    pub sd: &'a [f64],
}

/// The belief of `factor` (an offset, else a multiplier) from a field's values at its points
/// (module docs: the least-squares projection onto the factor's effect, the band's size over
/// the effect's), refused when it scales nothing or falls outside the factor's range. The one
/// mapping of a store's data with uncertainty onto the factors: `--prior-daveml`'s and
/// `--prior-from-shape`'s ([`crate::prior_shape`]).
pub(crate) fn belief(
    factor: Factor,
    offset: bool,
    at: &Points<'_>,
    table: &FactorTable,
    field: &str,
) -> Result<Belief, FieldRefusal> {
    let (values, base) = (at.values, at.base);
    let effect: Vec<f64> = if offset {
        vec![1.0; base.len()]
    } else {
        base.to_vec()
    };
    let e2: f64 = effect.iter().map(|e| e * e).sum();
    if !(e2 > 0.0 && e2.is_finite()) {
        return Err(FieldRefusal::ScalesNothing {
            field: field.to_string(),
            factor: factor.name(),
        });
    }
    let ed: f64 = (0..values.len())
        .map(|i| effect[i] * (values[i] - base[i]))
        .sum();
    let s2: f64 = at.sd.iter().map(|s| s * s).sum();
    // The factor's value at which the model's table is the scenario's: an offset's 0, a
    // multiplier's 1.
    let unmoved = if offset { 0.0 } else { 1.0 };
    let belief = Belief {
        mean: unmoved + ed / e2,
        sd: (s2 / e2).sqrt(),
    };
    let spec = table.spec(factor);
    if !(belief.mean.is_finite() && spec.contains(belief.mean) && belief.sd.is_finite()) {
        return Err(FieldRefusal::OutOfRange {
            factor: factor.name(),
            mean: belief.mean,
            sd: belief.sd,
            min: spec.min,
            max: spec.max,
        });
    }
    Ok(belief)
}

/// The file's values of a field and the campaign scenario's at the same points.
fn values_and_base(f: &ImportedField, s: &Scenario) -> Result<(Vec<f64>, Vec<f64>), FieldRefusal> {
    let base = sepval_daveml::assemble::field(s, f.target);
    let constant = |c: Option<&Coefficient>| match c {
        None => Some(0.0),
        Some(Coefficient::Constant(v)) => Some(*v),
        _ => None,
    };
    match &f.value {
        FieldValue::Constant(v) => match constant(base) {
            Some(b) => Ok((vec![*v], vec![b])),
            None => Err(FieldRefusal::ConstantForTable),
        },
        FieldValue::Table(t) => {
            let points = grid_points(t);
            let b: Vec<f64> = match (constant(base), base) {
                (Some(b), _) => vec![b; points.len()],
                (None, Some(Coefficient::Table(bt))) => {
                    let mut at = Vec::with_capacity(points.len());
                    for x in &points {
                        at.push(base_at(bt, t, x)?);
                    }
                    at
                }
                _ => return Err(FieldRefusal::TableNotRead),
            };
            Ok((t.values().to_vec(), b))
        }
    }
}

/// The coordinates of every value of `t`, row-major.
fn grid_points(t: &Table) -> Vec<Vec<f64>> {
    let mut points = vec![Vec::new()];
    for a in t.axes() {
        points = points
            .into_iter()
            .flat_map(|p| {
                a.breakpoints.iter().map(move |b| {
                    let mut q = p.clone();
                    q.push(*b);
                    q
                })
            })
            .collect();
    }
    points
}

/// The scenario's table `base` at the point `x` of the file's table `t`.
fn base_at(base: &Table, t: &Table, x: &[f64]) -> Result<f64, FieldRefusal> {
    let mut at = Vec::with_capacity(base.axes().len());
    for a in base.axes() {
        let k = t
            .axes()
            .iter()
            .position(|b| b.variable == a.variable)
            .ok_or(FieldRefusal::OtherAxis {
                variable: a.variable,
            })?;
        at.push(x[k]);
    }
    Ok(base.value_at(&at))
}

/// Store data with uncertainty (`--prior-daveml`) that cannot be taken into the prior.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PriorDavemlError {
    /// Two fields mapped to one factor.
    #[error("{first} and {second} both map to {factor}: give the store's data once")]
    Twice {
        /// The first field's element.
        first: String,
        /// The second's.
        second: String,
        /// The factor.
        factor: String,
    },
    /// A factor the `--prior` file sets too.
    #[error(
        "{element} sets {factor}, which the --prior file sets too: give each factor's belief once"
    )]
    AlsoInPriorFile {
        /// The field's element.
        element: String,
        /// The factor.
        factor: String,
    },
    /// A factor an earlier source of the prior sets (`--prior-from-shape` after `--prior` or
    /// `--prior-daveml`).
    #[error(
        "{element} sets {factor}, which an earlier source (--prior or --prior-daveml) sets too: give each factor's belief once"
    )]
    SetBefore {
        /// The field's element.
        element: String,
        /// The factor.
        factor: String,
    },
    /// A file without uncertainty sepval reads.
    #[error(
        "gives no uncertainty (no normalPDF on a table or constant sepval reads): nothing to take into the prior"
    )]
    NoUncertainty,
    /// One uncertain field that cannot be mapped to a factor.
    #[error("{element} (the uncertainty of sepval field {field}): {reason}")]
    Field {
        /// The element that gives the uncertainty (file, line and element).
        element: String,
        /// The sepval field.
        field: String,
        /// Why.
        reason: FieldRefusal,
    },
}

/// Why one uncertain field cannot be mapped to a factor.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FieldRefusal {
    /// An uncertainty the DAVE-ML reader could not use (its words).
    #[error("{why}")]
    Unusable {
        /// Why, as the reader says it.
        why: String,
    },
    /// A field no factor moves.
    #[error(
        "no factor of the 17 offsets or scales this field (a factor offsets a static coefficient or scales an interference increment), so its uncertainty cannot be mapped to the prior"
    )]
    NoFactor,
    /// A constant in the file where the scenario has a table.
    #[error(
        "the file gives a constant where the campaign's scenario has a table: its uncertainty cannot be compared point by point"
    )]
    ConstantForTable,
    /// A table of the scenario that was not read.
    #[error("the campaign scenario's table is not read")]
    TableNotRead,
    /// An axis of the scenario's table that the file's table lacks.
    #[error(
        "the campaign's scenario tabulates the field over {}, which the file's table is not: the two cannot be compared point by point",
        variable.csv_name()
    )]
    OtherAxis {
        /// The axis's variable.
        variable: sepval_common::table::Variable,
    },
    /// A multiplier of a field that is 0 everywhere.
    #[error(
        "the scenario's {field} is 0 everywhere, so {factor} scales nothing and the uncertainty cannot be mapped to it"
    )]
    ScalesNothing {
        /// The field.
        field: String,
        /// The factor.
        factor: &'static str,
    },
    /// A belief outside the factor's range.
    #[error(
        "maps to {factor} = {mean} (sd {sd}), outside the factor's range {min} to {max}: the file's table is not the scenario's moved by that factor"
    )]
    OutOfRange {
        /// The factor.
        factor: &'static str,
        /// The belief's mean.
        mean: f64,
        /// Its standard deviation.
        sd: f64,
        /// The factor's lower bound.
        min: f64,
        /// Its upper bound.
        max: f64,
    },
}
