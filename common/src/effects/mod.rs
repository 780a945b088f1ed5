//! The effect catalogue: physics the baseline model leaves out, as optional extensions.
//!
//! Source: `docs/model.md` section 7. Each effect is one small type in its own file
//! implementing [`Effect`], registered once in [`CATALOGUE`]; adding an effect means adding one
//! file and one line there. An effect changes a run through the knobs of
//! [`RunSetup`] (inertia tensor, ejector direction and start time, moment
//! reference point, initial rates, measurement offsets) or by adding a coefficient term that is
//! evaluated at every force evaluation. Every effect at its neutral parameters leaves the run
//! bit-for-bit equal to the baseline.
//!
//! Parameters are in the units of the docs/model.md table (radians, metres, seconds), in its order.
//! Each parameter also carries a search range and a typical magnitude, used when a fit
//! estimates it (the ranges are sepval's choice: generous physical limits, documented in
//! `sepval effects`).

mod attitude_bias;
mod cg_offset;
mod ejector_cant;
mod ejector_delay;
mod inertia_product_xz;
mod interference_decay;
mod pitch_stiffness_cubic;
mod release_rates;
mod roll_due_to_sideslip;
mod telemetry_time_offset;
mod tracked_point_offset;

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::model::RunSetup;

pub use crate::effect_error::{EffectError, MAX_EFFECT_PARAMS};
/// Most effects active in one run.
pub const MAX_ACTIVE_EFFECTS: usize = 4;

/// One parameter of an effect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSpec {
    /// Name as in docs/model.md section 7.
    pub name: &'static str,
    /// Unit, as in docs/model.md section 7.
    pub unit: &'static str,
    /// Value at which the effect is absent.
    pub neutral: f64,
    /// Lower end of the range a fit searches.
    pub min: f64,
    /// Upper end of the range a fit searches.
    pub max: f64,
    /// Typical magnitude (finite-difference and reporting scale).
    pub scale: f64,
}

/// An extension of the baseline model (docs/model.md section 7).
pub trait Effect: Send + Sync {
    /// Identifier, as in docs/model.md section 7.
    fn id(&self) -> &'static str;
    /// What it adds, in one line.
    fn adds(&self) -> &'static str;
    /// Its parameters, in docs/model.md order.
    fn params(&self) -> &'static [ParamSpec];
    /// Applies the effect with parameters `p` (as many as [`Effect::params`], finite) to a run.
    fn apply(&self, p: &[f64], run: &mut RunSetup) -> Result<(), EffectError>;
    /// The extension term it equals, when it is one term of the library (`docs/discovery.md`
    /// section 11): its first parameter is then that term's coefficient. A diagnosis does not
    /// call the two rivals: they are one explanation in two vocabularies.
    fn as_term(&self) -> Option<(crate::extension::Axis, crate::extension::Regressor)> {
        None
    }
}

/// Every effect, in docs/model.md order: the one place to register an effect.
pub static CATALOGUE: [&dyn Effect; 11] = [
    &roll_due_to_sideslip::RollDueToSideslip,
    &pitch_stiffness_cubic::PitchStiffnessCubic,
    &cg_offset::CgOffset,
    &inertia_product_xz::InertiaProductXz,
    &ejector_delay::EjectorDelay,
    &ejector_cant::EjectorCant,
    &interference_decay::InterferenceDecayFactor,
    &release_rates::ReleaseRates,
    &telemetry_time_offset::TelemetryTimeOffset,
    &attitude_bias::AttitudeBias,
    &tracked_point_offset::TrackedPointOffset,
];

/// Index of the effect `id` in [`CATALOGUE`].
pub fn find(id: &str) -> Option<usize> {
    CATALOGUE.iter().position(|e| e.id() == id)
}

/// A fingerprint of the catalogue (ids and parameter names in order), so that two processes
/// can check they number effects the same way.
pub fn catalogue_fingerprint() -> String {
    let mut text = String::new();
    for e in CATALOGUE.iter() {
        text.push_str(e.id());
        for p in e.params() {
            text.push(':');
            text.push_str(p.name);
        }
        text.push(';');
    }
    crate::scenario::hex_sha256(text.as_bytes())
}

/// One active effect: its catalogue index and parameter values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActiveEffect {
    /// Index in [`CATALOGUE`].
    pub index: usize,
    /// Parameter values (the first `CATALOGUE[index].params().len()` are used).
    pub params: [f64; MAX_EFFECT_PARAMS],
}

impl ActiveEffect {
    /// The effect.
    pub fn effect(&self) -> &'static dyn Effect {
        CATALOGUE[self.index]
    }

    /// The parameters in use.
    pub fn values(&self) -> &[f64] {
        &self.params[..self.effect().params().len()]
    }
}

/// The effects active in one run (fixed capacity, `Copy`: no allocation).
#[derive(Clone, Copy, PartialEq, Default)]
pub struct EffectSet {
    len: usize,
    items: [Option<ActiveEffect>; MAX_ACTIVE_EFFECTS],
}

impl EffectSet {
    /// The baseline: no effects.
    pub const NONE: EffectSet = EffectSet {
        len: 0,
        items: [None; MAX_ACTIVE_EFFECTS],
    };

    /// Adds effect `index` with `values` (checked: count, finiteness, duplicates).
    pub fn push(&mut self, index: usize, values: &[f64]) -> Result<(), EffectError> {
        let effect = CATALOGUE.get(index).ok_or(EffectError::BadIndex {
            index,
            len: CATALOGUE.len(),
        })?;
        let specs = effect.params();
        if values.len() != specs.len() {
            return Err(EffectError::ParamCount {
                id: effect.id(),
                expected: specs.len(),
                names: specs
                    .iter()
                    .map(|p| format!("{} [{}]", p.name, p.unit))
                    .collect::<Vec<_>>()
                    .join(", "),
                given: values.len(),
            });
        }
        for (spec, &value) in specs.iter().zip(values) {
            if !value.is_finite() {
                return Err(EffectError::NotFinite {
                    id: effect.id(),
                    name: spec.name,
                    value,
                });
            }
        }
        if self.iter().any(|a| a.index == index) {
            return Err(EffectError::Duplicate { id: effect.id() });
        }
        if self.len == MAX_ACTIVE_EFFECTS {
            return Err(EffectError::TooMany {
                max: MAX_ACTIVE_EFFECTS,
            });
        }
        let mut params = [0.0; MAX_EFFECT_PARAMS];
        params[..values.len()].copy_from_slice(values);
        self.items[self.len] = Some(ActiveEffect { index, params });
        self.len += 1;
        Ok(())
    }

    /// Adds the effect named `id` with `values`.
    pub fn push_id(&mut self, id: &str, values: &[f64]) -> Result<(), EffectError> {
        let index = find(id).ok_or_else(|| EffectError::Unknown { id: id.to_string() })?;
        self.push(index, values)
    }

    /// Parses `ID=V1,V2,...` (the `--effect` flag) and adds it.
    pub fn push_spec(&mut self, spec: &str) -> Result<(), EffectError> {
        let syntax = |reason: String| EffectError::Syntax {
            spec: spec.to_string(),
            reason,
        };
        let (id, list) = spec.split_once('=').ok_or_else(|| {
            syntax("expected ID=V1,V2,... (for example roll_due_to_sideslip=-0.3)".into())
        })?;
        let id = id.trim();
        if id.is_empty() {
            return Err(syntax(
                "no effect ID before `=` (expected ID=V1,V2,..., for example roll_due_to_sideslip=-0.3)"
                    .into(),
            ));
        }
        let mut values = Vec::new();
        for (k, text) in list.split(',').enumerate() {
            let v: f64 = text.trim().parse().map_err(|_| {
                syntax(format!("value {} `{}` is not a number", k + 1, text.trim()))
            })?;
            values.push(v);
        }
        self.push_id(id, &values)
    }

    /// Number of active effects.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no effect is active.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The active effects in order.
    pub fn iter(&self) -> impl Iterator<Item = &ActiveEffect> {
        self.items[..self.len].iter().flatten()
    }

    /// Total number of effect parameters.
    pub fn param_count(&self) -> usize {
        self.iter().map(|a| a.effect().params().len()).sum()
    }

    /// The same effects with new parameter values (`values` holds all of them, in order).
    pub fn with_values(&self, values: &[f64]) -> Result<EffectSet, EffectError> {
        let mut out = EffectSet::NONE;
        let mut pos = 0;
        for a in self.iter() {
            let n = a.effect().params().len();
            let slice = values.get(pos..pos + n).ok_or(EffectError::ParamCount {
                id: a.effect().id(),
                expected: n,
                names: String::new(),
                given: values.len().saturating_sub(pos),
            })?;
            out.push(a.index, slice)?;
            pos += n;
        }
        Ok(out)
    }

    /// All parameter values, in order.
    pub fn values(&self) -> Vec<f64> {
        self.iter()
            .flat_map(|a| a.values().iter().copied())
            .collect()
    }

    /// Applies every effect to `run` in order.
    pub fn apply(&self, run: &mut RunSetup) -> Result<(), EffectError> {
        for a in self.iter() {
            a.effect().apply(a.values(), run)?;
        }
        Ok(())
    }
}

impl fmt::Debug for EffectSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{self}")
    }
}

impl fmt::Display for EffectSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_empty() {
            return f.write_str("baseline");
        }
        for (k, a) in self.iter().enumerate() {
            if k > 0 {
                f.write_str(" ")?;
            }
            write!(f, "{}=", a.effect().id())?;
            for (j, v) in a.values().iter().enumerate() {
                if j > 0 {
                    f.write_str(",")?;
                }
                write!(f, "{v}")?;
            }
        }
        Ok(())
    }
}

/// A file form of one active effect: `{ "id": "...", "values": [...] }`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NamedEffect {
    /// Effect id.
    pub id: String,
    /// Parameter values in docs/model.md units and order.
    pub values: Vec<f64>,
}

impl Serialize for EffectSet {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let list: Vec<NamedEffect> = self
            .iter()
            .map(|a| NamedEffect {
                id: a.effect().id().to_string(),
                values: a.values().to_vec(),
            })
            .collect();
        list.serialize(s)
    }
}

impl<'de> Deserialize<'de> for EffectSet {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let list = Vec::<NamedEffect>::deserialize(d)?;
        let mut set = EffectSet::NONE;
        for e in list {
            set.push_id(&e.id, &e.values)
                .map_err(serde::de::Error::custom)?;
        }
        Ok(set)
    }
}

/// Checks that `value` of parameter `k` of `effect` lies within `[lo, hi]` (physical domain).
pub(crate) fn require(
    effect: &dyn Effect,
    k: usize,
    value: f64,
    ok: bool,
    reason: &'static str,
) -> Result<(), EffectError> {
    if ok {
        Ok(())
    } else {
        Err(EffectError::OutOfDomain {
            id: effect.id(),
            name: effect.params()[k].name,
            value,
            reason,
        })
    }
}
