//! The prior: what is believed of the 17 factors before any release is flown (docs/campaign.md,
//! "The prior"). By default each factor is normal about its nominal value (the model as built,
//! docs/model.md section 4) with a standard deviation of a sixth of the study's range, the
//! range read as +-3 sigma (M. B. Anderson's Table 1 bounds what the factors may be); the draws
//! are truncated to the range ([`sepval_predict::sampling`]). Why the nominal and not the
//! range's middle: the model as built is the engineer's estimate before the test, and it is
//! what makes the most benign conditions safe to fly first (the middle of `fwdfac`'s range is a
//! stronger ejector than the nominal, `czintfac`'s a weaker interference, neither of them
//! anybody's belief).
//!
//! `--prior FILE` gives means and standard deviations (format `sepval-prior/1`):
//!
//! ```json
//! { "format": "sepval-prior/1",
//!   "factors": { "fwdfac": { "mean": 0.5, "sd": 0.1 }, "czintfac": { "mean": 1.2, "sd": 0.2 } } }
//! ```
//!
//! A factor the file does not name keeps the default; a mean outside the factor's range, a
//! standard deviation that is negative or not finite, or an unknown name is refused. A standard
//! deviation of 0 holds the factor at its mean.
//!
//! Two more sources of what engineers know before flight narrow it (`sepval campaign init`,
//! docs/campaign.md "Beginning from pre-flight knowledge"): the store's data with uncertainty in
//! DAVE-ML (`--prior-daveml`, [`crate::prior_daveml`]) sets the factors its uncertain tables map
//! to, and pre-flight trajectories (`--preflight`, [`crate::preflight`]) make the prior the
//! Laplace approximation of the posterior, whose factors are correlated: its full covariance
//! is kept ([`Prior::covariance`]) and a draw is mean + L z with L its Cholesky factor
//! (Golub and Van Loan, *Matrix Computations*, 4th ed., 2013, section 4.2), each factor's
//! `Belief` its marginal. [`Prior::sources`] records what it was made of, in order.

use std::collections::BTreeMap;
use std::path::Path;

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use sepval_common::effects::EffectSet;
use sepval_core::factors::{FACTOR_COUNT, Factor, FactorTable, Factors};
use sepval_fit::space::ParamSpace;
use sepval_predict::sampling::ParameterDistribution;

pub use crate::sources::{Belief, PriorSource};

/// The format of a prior file.
pub const PRIOR_FORMAT: &str = "sepval-prior/1";
/// The standard deviations of the default prior: this share of each factor's range.
pub const RANGE_SHARE: f64 = 1.0 / 6.0;
/// The largest prior file read \[bytes\].
const MAX_PRIOR_BYTES: u64 = 1 << 20;

/// A prior that cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PriorError {
    /// The file cannot be read or is not the format.
    #[error("--prior {path}: {message}")]
    File {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
}

/// The prior of the 17 factors, in table order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Prior {
    /// Where it came from: `default` or the file.
    pub source: String,
    /// Each factor's mean and standard deviation (its marginal, when correlated), by name.
    pub factors: BTreeMap<String, Belief>,
    /// The factors' covariance in table order (17 x 17) when they are correlated (a pre-flight
    /// fit's posterior); none: independent, each with its belief's standard deviation. Absent
    /// from campaigns begun before 2026-12-02.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub covariance: Option<Vec<Vec<f64>>>,
    /// What the prior was made of, in the order applied (empty in campaigns begun before
    /// 2026-12-02: `source` says).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sources: Vec<PriorSource>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PriorFile {
    format: String,
    #[serde(deserialize_with = "in_file_order")]
    factors: Vec<(String, Belief)>,
}

/// The entries of the `factors` object in file order, a name given twice refused (serde_json's
/// maps keep the last of a repeated key, which would hide a mistake; before 2026-12-01 the last
/// won here, as factors files already refused it).
fn in_file_order<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<Vec<(String, Belief)>, D::Error> {
    struct V;
    impl<'de> serde::de::Visitor<'de> for V {
        type Value = Vec<(String, Belief)>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("an object of factors, each {\"mean\": M, \"sd\": S}")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut m: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out: Vec<(String, Belief)> = Vec::new();
            while let Some((name, b)) = m.next_entry::<String, Belief>()? {
                if out.iter().any(|(n, _)| *n == name) {
                    return Err(serde::de::Error::custom(format!(
                        "factor `{name}` is given twice"
                    )));
                }
                out.push((name, b));
            }
            Ok(out)
        }
    }
    d.deserialize_map(V)
}

impl Prior {
    /// The default prior of `table` (module docs).
    pub fn default_of(table: &FactorTable) -> Prior {
        let factors = Factor::NAMES
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let spec = &table.0[i];
                let mean = Factors::NOMINAL.0[i].clamp(spec.min, spec.max);
                (
                    (*name).to_string(),
                    Belief {
                        mean,
                        sd: RANGE_SHARE * spec.range(),
                    },
                )
            })
            .collect();
        Prior {
            source: "default".into(),
            factors,
            covariance: None,
            sources: vec![PriorSource::Default],
        }
    }

    /// The default prior of `table` with the factors `path` names replaced, checked.
    pub fn read(path: &Path, table: &FactorTable) -> Result<Prior, PriorError> {
        let bad = |message: String| PriorError::File {
            path: path.display().to_string(),
            message,
        };
        let text = sepval_core::input_file::read_string(path, "prior file", MAX_PRIOR_BYTES)
            .map_err(|e| bad(e.to_string()))?;
        let file: PriorFile = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
        if file.format != PRIOR_FORMAT {
            return Err(bad(format!(
                "format `{}`, expected `{PRIOR_FORMAT}`",
                file.format
            )));
        }
        let mut prior = Prior::default_of(table);
        prior.source = path.display().to_string();
        let absolute = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        let mut named = Vec::new();
        for (name, b) in file.factors {
            let Some(f) = Factor::from_name(&name) else {
                return Err(bad(format!(
                    "`{name}` is not a factor (expected one of {})",
                    Factor::NAMES.join(", ")
                )));
            };
            let spec = table.spec(f);
            if !(b.mean.is_finite() && spec.contains(b.mean)) {
                return Err(bad(format!(
                    "{name}.mean = {}: outside the factor's range {} to {}",
                    b.mean, spec.min, spec.max
                )));
            }
            if !(b.sd.is_finite() && b.sd >= 0.0) {
                return Err(bad(format!(
                    "{name}.sd = {}: expected a finite number, 0 or more",
                    b.sd
                )));
            }
            named.push(name.clone());
            prior.factors.insert(name, b);
        }
        prior.sources.push(PriorSource::File {
            path: absolute.display().to_string(),
            sha256: sepval_common::scenario::hex_sha256(text.as_bytes()),
            factors: named,
        });
        Ok(prior)
    }

    /// What the prior was made of, a line per source beyond the default, for `init` to say.
    pub fn lines(&self) -> Vec<String> {
        self.sources.iter().flat_map(PriorSource::lines).collect()
    }

    /// The factor-only parameter space of `table` and the prior as its distribution, truncated
    /// to the factors' ranges: independent, or correlated by [`Prior::covariance`].
    pub fn distribution(&self, table: &FactorTable) -> (ParamSpace, ParameterDistribution) {
        let space = ParamSpace::new(table, &EffectSet::NONE);
        let at = |name: &str| self.factors.get(name).copied();
        let mean: Vec<f64> = space
            .params
            .names
            .iter()
            .zip(&space.params.lo)
            .map(|(n, lo)| at(n).map_or(*lo, |b| b.mean))
            .collect();
        let std: Vec<f64> = space
            .params
            .names
            .iter()
            .map(|n| at(n).map_or(0.0, |b| b.sd))
            .collect();
        debug_assert_eq!(mean.len(), FACTOR_COUNT);
        let factor = self
            .covariance
            .as_ref()
            .and_then(|c| cholesky_of_spread(c, &std))
            .unwrap_or_else(|| DMatrix::from_diagonal(&nalgebra::DVector::from_vec(std.clone())));
        let distribution = ParameterDistribution {
            mean,
            factor,
            lo: space.params.lo.clone(),
            hi: space.params.hi.clone(),
            std,
        };
        (space, distribution)
    }
}

/// The lower Cholesky factor of the covariance `c` over the factors with a spread (`std` > 0),
/// the others' rows and columns 0 (held); none when `c` is not 17 x 17 or not positive
/// definite there.
pub fn cholesky_of_spread(c: &[Vec<f64>], std: &[f64]) -> Option<DMatrix<f64>> {
    let n = std.len();
    if c.len() != n || c.iter().any(|r| r.len() != n) {
        return None;
    }
    let free: Vec<usize> = (0..n).filter(|&i| std[i] > 0.0).collect();
    let m = free.len();
    let sub = DMatrix::from_fn(m, m, |a, b| c[free[a]][free[b]]);
    let l = nalgebra::Cholesky::new(sub)?.unpack();
    let mut out = DMatrix::zeros(n, n);
    for a in 0..m {
        for b in 0..=a {
            out[(free[a], free[b])] = l[(a, b)];
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_is_the_nominal_with_a_sixth_of_the_range() {
        let t = FactorTable::default();
        let p = Prior::default_of(&t);
        let f = p.factors["fwdfac"];
        assert!((f.mean - 0.5).abs() < 1e-12 && (f.sd - 0.8 / 6.0).abs() < 1e-12);
        let (space, d) = p.distribution(&t);
        assert_eq!(space.len(), FACTOR_COUNT);
        assert!((d.std[0] - 0.8 / 6.0).abs() < 1e-12);
    }

    #[test]
    fn a_prior_file_replaces_what_it_names_and_refuses_what_is_wrong() {
        let t = FactorTable::default();
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("p.json");
        std::fs::write(
            &p,
            r#"{"format":"sepval-prior/1","factors":{"czintfac":{"mean":1.2,"sd":0.1}}}"#,
        )
        .unwrap();
        let prior = Prior::read(&p, &t).unwrap();
        assert_eq!(prior.factors["czintfac"], Belief { mean: 1.2, sd: 0.1 });
        assert!((prior.factors["fwdfac"].mean - 0.5).abs() < 1e-12);
        for (text, says) in [
            (r#"{"format":"x","factors":{}}"#, "format `x`"),
            (
                r#"{"format":"sepval-prior/1","factors":{"nope":{"mean":1,"sd":0}}}"#,
                "`nope` is not a factor",
            ),
            (
                r#"{"format":"sepval-prior/1","factors":{"fwdfac":{"mean":3,"sd":0}}}"#,
                "outside the factor's range",
            ),
            (
                r#"{"format":"sepval-prior/1","factors":{"fwdfac":{"mean":0.5,"sd":-1}}}"#,
                "fwdfac.sd = -1",
            ),
            (
                r#"{"format":"sepval-prior/1","factors":{"fwdfac":{"mean":0.5,"sd":0.1},"fwdfac":{"mean":0.6,"sd":0.1}}}"#,
                "factor `fwdfac` is given twice at line 1",
            ),
        ] {
            std::fs::write(&p, text).unwrap();
            let e = Prior::read(&p, &t).unwrap_err().to_string();
            assert!(e.contains(says), "{e}");
        }
    }
}
