//! The 17 model factors of Anderson's study, their bounds and binary resolution.
//!
//! Source: `docs/model.md` section 4 (Anderson, Table 1) for names, bounds and bits; the
//! truth factors of the default synthetic flight test and the nominal factors
//! (fwdfac 0.5, aftfac 0.5, inertia factors 1, offsets 0, interference multipliers 1) from the
//! same section and from issue 2.
//!
//! Factors are always held in table order (the order of [`Factor::ALL`]); files name them.

use std::collections::BTreeMap;
use std::fmt;

use serde::de::Error as _;
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// Number of factors in the study's table.
pub const FACTOR_COUNT: usize = 17;

/// One of the 17 factors, in the order of docs/model.md section 4.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum Factor {
    /// Forward ejector force multiplier.
    Fwdfac,
    /// Aft ejector force multiplier.
    Aftfac,
    /// Roll inertia multiplier (Ixx).
    Xinerfac,
    /// Pitch inertia multiplier (Iyy).
    Yinerfac,
    /// Yaw inertia multiplier (Izz).
    Zinerfac,
    /// Axial force coefficient offset (added to CA0).
    Caoff,
    /// Side force coefficient offset.
    Cyoff,
    /// Normal force coefficient offset.
    Czoff,
    /// Pitching moment coefficient offset.
    Cmoff,
    /// Yawing moment coefficient offset.
    Cnoff,
    /// Rolling moment coefficient offset.
    Cloff,
    /// Interference axial force multiplier.
    Caintfac,
    /// Interference side force multiplier.
    Cyintfac,
    /// Interference normal force multiplier.
    Czintfac,
    /// Interference pitching moment multiplier.
    Cmintfac,
    /// Interference yawing moment multiplier.
    Cnintfac,
    /// Interference rolling moment multiplier.
    Clintfac,
}

impl Factor {
    /// All factors in table order.
    pub const ALL: [Factor; FACTOR_COUNT] = [
        Factor::Fwdfac,
        Factor::Aftfac,
        Factor::Xinerfac,
        Factor::Yinerfac,
        Factor::Zinerfac,
        Factor::Caoff,
        Factor::Cyoff,
        Factor::Czoff,
        Factor::Cmoff,
        Factor::Cnoff,
        Factor::Cloff,
        Factor::Caintfac,
        Factor::Cyintfac,
        Factor::Czintfac,
        Factor::Cmintfac,
        Factor::Cnintfac,
        Factor::Clintfac,
    ];

    /// Names as used in the paper, in files and on the command line.
    pub const NAMES: [&'static str; FACTOR_COUNT] = [
        "fwdfac", "aftfac", "xinerfac", "yinerfac", "zinerfac", "caoff", "cyoff", "czoff", "cmoff",
        "cnoff", "cloff", "caintfac", "cyintfac", "czintfac", "cmintfac", "cnintfac", "clintfac",
    ];

    /// Index in table order.
    #[inline]
    pub const fn index(self) -> usize {
        self as usize
    }

    /// The factor's name.
    pub const fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// Looks a factor up by name (exact, lower case).
    pub fn from_name(name: &str) -> Option<Factor> {
        Self::NAMES
            .iter()
            .position(|n| *n == name)
            .map(|i| Self::ALL[i])
    }

    /// What the factor scales or offsets, for reports.
    pub const fn meaning(self) -> &'static str {
        match self {
            Factor::Fwdfac => "forward ejector force multiplier",
            Factor::Aftfac => "aft ejector force multiplier",
            Factor::Xinerfac => "roll inertia multiplier",
            Factor::Yinerfac => "pitch inertia multiplier",
            Factor::Zinerfac => "yaw inertia multiplier",
            Factor::Caoff => "axial force coefficient offset",
            Factor::Cyoff => "side force coefficient offset",
            Factor::Czoff => "normal force coefficient offset",
            Factor::Cmoff => "pitching moment coefficient offset",
            Factor::Cnoff => "yawing moment coefficient offset",
            Factor::Cloff => "rolling moment coefficient offset",
            Factor::Caintfac => "interference axial force multiplier",
            Factor::Cyintfac => "interference side force multiplier",
            Factor::Czintfac => "interference normal force multiplier",
            Factor::Cmintfac => "interference pitching moment multiplier",
            Factor::Cnintfac => "interference yawing moment multiplier",
            Factor::Clintfac => "interference rolling moment multiplier",
        }
    }
}

impl fmt::Display for Factor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Errors in factor values or factor tables.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum FactorError {
    /// A name that is not one of the 17 factors.
    #[error("unknown factor `{name}` (expected one of: {})", Factor::NAMES.join(", "))]
    UnknownName {
        /// The name given.
        name: String,
    },
    /// A factor missing from a set that must name all 17.
    #[error("factor `{name}` is missing (all 17 factors must be given)")]
    Missing {
        /// The missing factor.
        name: &'static str,
    },
    /// A value that is NaN or infinite.
    #[error("factor `{name}` = {value} is not a finite number")]
    NotFinite {
        /// The factor.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// A value outside the table's bounds.
    #[error("factor `{name}` = {value} is outside its bounds [{min}, {max}]")]
    OutOfBounds {
        /// The factor.
        name: &'static str,
        /// The value given.
        value: f64,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// A table entry whose bounds or bits make no sense.
    #[error("factor `{name}`: {reason}")]
    BadSpec {
        /// The factor.
        name: &'static str,
        /// What is wrong.
        reason: String,
    },
}

/// The values of the 17 factors, in table order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Factors(pub [f64; FACTOR_COUNT]);

impl Factors {
    /// The nominal model: fwdfac 0.5, aftfac 0.5, inertia factors 1, offsets 0, interference
    /// multipliers 1 (issue 2; docs/model.md section 8 "nominal factors").
    pub const NOMINAL: Factors = Factors([
        0.5, 0.5, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0,
    ]);

    /// The truth factors of the default synthetic flight test (docs/model.md section 4).
    pub const TRUTH: Factors = Factors([
        0.25, 0.80, 1.04, 0.96, 1.02, 0.03, -0.05, 0.08, -0.14, 0.10, 0.03, 1.30, 0.80, 1.50, 0.70,
        1.20, 0.60,
    ]);

    /// Value of one factor.
    #[inline]
    pub fn get(&self, factor: Factor) -> f64 {
        self.0[factor.index()]
    }

    /// Sets one factor.
    #[inline]
    pub fn set(&mut self, factor: Factor, value: f64) {
        self.0[factor.index()] = value;
    }

    /// Builds a complete set from (name, value) pairs: every one of the 17 names exactly once,
    /// every value finite and within `table`'s bounds.
    pub fn from_named<'a>(
        pairs: impl IntoIterator<Item = (&'a str, f64)>,
        table: &FactorTable,
    ) -> Result<Factors, FactorError> {
        let mut values = [None; FACTOR_COUNT];
        for (name, value) in pairs {
            let factor = Factor::from_name(name).ok_or_else(|| FactorError::UnknownName {
                name: name.to_string(),
            })?;
            values[factor.index()] = Some(value);
        }
        let mut out = [0.0; FACTOR_COUNT];
        for (i, v) in values.iter().enumerate() {
            out[i] = v.ok_or(FactorError::Missing {
                name: Factor::NAMES[i],
            })?;
        }
        let factors = Factors(out);
        table.check(&factors)?;
        Ok(factors)
    }

    /// Parses the JSON object `{ "fwdfac": 0.25, ... }` naming all 17 factors.
    pub fn from_json_str(text: &str, table: &FactorTable) -> Result<Factors, FactorsFileError> {
        let Entries(entries) = serde_json::from_str(text).map_err(FactorsFileError::Json)?;
        let mut map: BTreeMap<String, serde_json::Value> = BTreeMap::new();
        let mut repeated = None;
        for (name, value) in entries {
            if map.contains_key(&name) && repeated.is_none() {
                repeated = Some(name.clone());
            }
            map.insert(name, value);
        }
        let mut pairs = Vec::with_capacity(map.len());
        for (name, value) in &map {
            let number = value.as_f64().ok_or_else(|| FactorsFileError::NotANumber {
                name: name.clone(),
                found: value.to_string(),
            })?;
            pairs.push((name.as_str(), number));
        }
        let factors = Factors::from_named(pairs.iter().map(|(n, v)| (*n, *v)), table)
            .map_err(FactorsFileError::Factor)?;
        // A repeated name is refused too (reported after the other problems of the file).
        match repeated {
            Some(name) => Err(FactorsFileError::Duplicate { name }),
            None => Ok(factors),
        }
    }
}

/// Errors reading a factors JSON file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FactorsFileError {
    /// Not a JSON object of names to numbers.
    #[error("expected a JSON object mapping the 17 factor names to numbers")]
    Json(#[source] serde_json::Error),
    /// A value that is not a number.
    #[error("factor `{name}`: expected a number, found {found}")]
    NotANumber {
        /// The factor name.
        name: String,
        /// What was found.
        found: String,
    },
    /// A name given twice.
    #[error("factor `{name}` is given twice")]
    Duplicate {
        /// The factor name.
        name: String,
    },
    /// A bad name or value.
    #[error(transparent)]
    Factor(FactorError),
}

/// The entries of a JSON object in file order, duplicates kept (serde_json's maps keep only
/// the last of a repeated key, which would hide a mistake).
struct Entries(Vec<(String, serde_json::Value)>);

impl<'de> Deserialize<'de> for Entries {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Entries;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a JSON object")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut m: A,
            ) -> Result<Entries, A::Error> {
                let mut out = Vec::new();
                while let Some(entry) = m.next_entry()? {
                    out.push(entry);
                }
                Ok(Entries(out))
            }
        }
        deserializer.deserialize_map(V)
    }
}

impl Serialize for Factors {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(FACTOR_COUNT))?;
        for (name, value) in Factor::NAMES.iter().zip(self.0.iter()) {
            map.serialize_entry(name, value)?;
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for Factors {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let map = BTreeMap::<String, f64>::deserialize(deserializer)?;
        let mut out = [f64::NAN; FACTOR_COUNT];
        let mut seen = [false; FACTOR_COUNT];
        for (name, value) in map {
            let factor = Factor::from_name(&name)
                .ok_or_else(|| D::Error::custom(FactorError::UnknownName { name }))?;
            out[factor.index()] = value;
            seen[factor.index()] = true;
        }
        if let Some(i) = seen.iter().position(|s| !s) {
            return Err(D::Error::custom(FactorError::Missing {
                name: Factor::NAMES[i],
            }));
        }
        Ok(Factors(out))
    }
}

/// Bounds and binary resolution of one factor (one row of Table 1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FactorSpec {
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
    /// Bits of the gene (1 to 52).
    pub bits: u32,
}

impl FactorSpec {
    /// Grid step of the gene: (max - min) / (2^bits - 1) (docs/model.md section 4).
    #[inline]
    pub fn step(&self) -> f64 {
        (self.max - self.min) / self.levels_minus_one() as f64
    }

    /// 2^bits - 1, the largest integer of the gene.
    #[inline]
    pub fn levels_minus_one(&self) -> u64 {
        (1u64 << self.bits) - 1
    }

    /// Width of the range.
    #[inline]
    pub fn range(&self) -> f64 {
        self.max - self.min
    }

    /// Whether `value` lies within the bounds.
    #[inline]
    pub fn contains(&self, value: f64) -> bool {
        value >= self.min && value <= self.max
    }
}

/// The factor table: bounds and bits of all 17 factors, in table order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FactorTable(pub [FactorSpec; FACTOR_COUNT]);

impl Default for FactorTable {
    /// Anderson's Table 1 (docs/model.md section 4): 93 bits in all.
    fn default() -> Self {
        const fn s(min: f64, max: f64, bits: u32) -> FactorSpec {
            FactorSpec { min, max, bits }
        }
        FactorTable([
            s(0.2, 1.0, 5),
            s(0.2, 1.0, 5),
            s(0.9, 1.1, 4),
            s(0.9, 1.1, 4),
            s(0.9, 1.1, 4),
            s(-0.1, 0.1, 5),
            s(-0.2, 0.2, 6),
            s(-0.2, 0.2, 6),
            s(-0.5, 0.5, 6),
            s(-0.5, 0.5, 6),
            s(-0.5, 0.5, 6),
            s(0.25, 2.0, 6),
            s(0.25, 2.0, 6),
            s(0.25, 2.0, 6),
            s(0.25, 2.0, 6),
            s(0.25, 2.0, 6),
            s(0.25, 2.0, 6),
        ])
    }
}

impl FactorTable {
    /// The paper's nominal resolution column (informative only; the actual step is
    /// [`FactorSpec::step`]).
    pub const PAPER_RESOLUTION: [f64; FACTOR_COUNT] = [
        0.025, 0.025, 0.02, 0.02, 0.02, 0.01, 0.01, 0.01, 0.02, 0.02, 0.02, 0.05, 0.05, 0.05, 0.05,
        0.05, 0.05,
    ];

    /// Spec of one factor.
    #[inline]
    pub fn spec(&self, factor: Factor) -> &FactorSpec {
        &self.0[factor.index()]
    }

    /// Total chromosome length in bits.
    pub fn total_bits(&self) -> usize {
        self.0.iter().map(|s| s.bits as usize).sum()
    }

    /// Checks every spec: finite bounds with min < max, bits in 1..=52.
    pub fn validate(&self) -> Result<(), FactorError> {
        for (i, s) in self.0.iter().enumerate() {
            let name = Factor::NAMES[i];
            if !(s.min.is_finite() && s.max.is_finite()) {
                return Err(FactorError::BadSpec {
                    name,
                    reason: format!("bounds [{}, {}] must be finite", s.min, s.max),
                });
            }
            if s.min >= s.max {
                return Err(FactorError::BadSpec {
                    name,
                    reason: format!("min {} must be below max {}", s.min, s.max),
                });
            }
            if !(1..=52).contains(&s.bits) {
                return Err(FactorError::BadSpec {
                    name,
                    reason: format!("bits = {} must be between 1 and 52", s.bits),
                });
            }
        }
        Ok(())
    }

    /// Checks that every value is finite and within bounds.
    pub fn check(&self, factors: &Factors) -> Result<(), FactorError> {
        for (i, (&value, spec)) in factors.0.iter().zip(self.0.iter()).enumerate() {
            let name = Factor::NAMES[i];
            if !value.is_finite() {
                return Err(FactorError::NotFinite { name, value });
            }
            if !spec.contains(value) {
                return Err(FactorError::OutOfBounds {
                    name,
                    value,
                    min: spec.min,
                    max: spec.max,
                });
            }
        }
        Ok(())
    }

    /// Clamps every value into its bounds.
    pub fn clamp(&self, factors: &Factors) -> Factors {
        let mut out = *factors;
        for (v, s) in out.0.iter_mut().zip(self.0.iter()) {
            *v = v.clamp(s.min, s.max);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_one_has_93_bits() {
        assert_eq!(FactorTable::default().total_bits(), 93);
        FactorTable::default().validate().unwrap();
    }

    #[test]
    fn truth_and_nominal_are_within_bounds() {
        let t = FactorTable::default();
        t.check(&Factors::TRUTH).unwrap();
        t.check(&Factors::NOMINAL).unwrap();
    }

    #[test]
    fn names_round_trip() {
        for f in Factor::ALL {
            assert_eq!(Factor::from_name(f.name()), Some(f));
        }
        assert_eq!(Factor::from_name("FWDFAC"), None);
    }

    #[test]
    fn json_refusals_name_the_problem() {
        let t = FactorTable::default();
        let full = serde_json::to_string(&Factors::TRUTH).unwrap();
        assert_eq!(Factors::from_json_str(&full, &t).unwrap(), Factors::TRUTH);

        let unknown = full.replacen("\"fwdfac\"", "\"fwdfactor\"", 1);
        let e = Factors::from_json_str(&unknown, &t)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("unknown factor `fwdfactor`"), "{e}");

        let missing = full.replacen("\"clintfac\":0.6", "", 1).replace(",}", "}");
        let e = Factors::from_json_str(&missing, &t)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "factor `clintfac` is missing (all 17 factors must be given)"
        );

        let out = full.replacen("\"aftfac\":0.8", "\"aftfac\":1.5", 1);
        let e = Factors::from_json_str(&out, &t).unwrap_err().to_string();
        assert_eq!(e, "factor `aftfac` = 1.5 is outside its bounds [0.2, 1]");

        let text = full.replacen("\"aftfac\":0.8", "\"aftfac\":\"x\"", 1);
        let e = Factors::from_json_str(&text, &t).unwrap_err().to_string();
        assert_eq!(e, "factor `aftfac`: expected a number, found \"x\"");

        let twice = full.replacen("\"aftfac\":0.8", "\"aftfac\":0.8,\"aftfac\":0.9", 1);
        let e = Factors::from_json_str(&twice, &t).unwrap_err().to_string();
        assert_eq!(e, "factor `aftfac` is given twice");
    }
}
