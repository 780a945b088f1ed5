//! The records of what the prior was made of, as campaign.json keeps them
//! (docs/campaign.md, "Beginning from pre-flight knowledge"): each factor's belief, and each
//! source: the default, a `--prior` file, the store's DAVE-ML ([`crate::prior_daveml`]), the
//! estimate from its shape ([`crate::prior_shape`]),
//! pre-flight trajectories ([`crate::preflight`]). Kept apart from the code that makes them so
//! that the settings' record depends on no reader.

use serde::{Deserialize, Serialize};

use sepval_predict::record::ConditionRecord;

/// One factor's belief.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Belief {
    /// The mean.
    pub mean: f64,
    /// The standard deviation (0: held at the mean).
    pub sd: f64,
}

/// One source of the prior, as campaign.json records it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum PriorSource {
    /// The default prior (module docs).
    Default,
    /// A `--prior` file.
    File {
        /// The file (absolute).
        path: String,
        /// Its SHA-256.
        sha256: String,
        /// The factors it set.
        factors: Vec<String>,
    },
    /// A `--prior-daveml` file ([`crate::prior_daveml`]).
    Daveml {
        /// The file (absolute).
        path: String,
        /// Its SHA-256.
        sha256: String,
        /// Each uncertain element and the factor it set.
        mapped: Vec<Mapped>,
    },
    /// The `--preflight` trajectories fitted together ([`crate::preflight`]).
    Preflight(PreflightRecord),
    /// A `--prior-from-shape` store TOML, its estimate mapped ([`crate::prior_shape`]).
    Shape {
        /// The file (absolute).
        path: String,
        /// Its SHA-256.
        sha256: String,
        /// The points (condition and flow angle) the estimate was read at.
        points: usize,
        /// The store's flow angle either side of the aircraft's \[deg\].
        excursion_deg: f64,
        /// Each static coefficient and the offset it set.
        mapped: Vec<Mapped>,
    },
}

/// An uncertain element of the file and the factor it set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mapped {
    /// The element (file, line, tag).
    pub element: String,
    /// The sepval field, e.g. `aero.cm`.
    pub field: String,
    /// The factor.
    pub factor: String,
    /// Its belief from the file.
    pub belief: Belief,
}

/// A pre-flight trajectory as campaign.json records it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrajectoryRecord {
    /// The file given (absolute).
    pub given: String,
    /// The SHA-256 of its bytes.
    pub sha256: String,
    /// Its condition, from its metadata.
    pub condition: ConditionRecord,
    /// Its samples fitted.
    pub samples: usize,
    /// What was said of it (a condition outside the grid, ...).
    pub notes: Vec<String>,
}

/// One factor before and after the pre-flight trajectories.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FactorChange {
    /// The factor.
    pub factor: String,
    /// The prior's belief.
    pub before: Belief,
    /// The fit's best value.
    pub fitted: f64,
    /// The posterior's (its marginal).
    pub after: Belief,
}

/// The pre-flight fit as campaign.json records it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PreflightRecord {
    /// The trajectories, in the order given.
    pub trajectories: Vec<TrajectoryRecord>,
    /// The model-form allowance of positions \[m\].
    pub allowance_m: f64,
    /// Of attitudes \[deg\].
    pub allowance_deg: f64,
    /// The measurement noise estimated from the trajectories: positions \[m\].
    pub noise_pos_m: f64,
    /// Attitudes \[deg\].
    pub noise_att_deg: f64,
    /// The fit's root-mean-square residual: positions \[m\].
    pub rms_pos_m: f64,
    /// Attitudes \[deg\].
    pub rms_att_deg: f64,
    /// The fit's directory in the campaign (its result.json).
    pub fit_dir: String,
    /// Every factor with a spread, before and after.
    pub factors: Vec<FactorChange>,
}

impl PriorSource {
    /// What this source made of the prior, in a line or two for `init` to say (none for the
    /// default).
    pub fn lines(&self) -> Vec<String> {
        match self {
            Self::Default => Vec::new(),
            Self::File { path, factors, .. } => vec![format!("{path} set {}", factors.join(", "))],
            Self::Daveml { path, mapped, .. } | Self::Shape { path, mapped, .. } => {
                let each: Vec<String> = mapped
                    .iter()
                    .map(|m| {
                        format!(
                            "{} {} sd {} (from {})",
                            m.factor,
                            number(m.belief.mean),
                            number(m.belief.sd),
                            m.field
                        )
                    })
                    .collect();
                vec![format!("{path} set {}", each.join(", "))]
            }
            Self::Preflight(p) => p.lines(),
        }
    }
}

impl PreflightRecord {
    /// What the fit of the pre-flight trajectories made of the prior: the fit, then the
    /// factors it narrowed by a tenth or more, most narrowed first.
    fn lines(&self) -> Vec<String> {
        let fit = format!(
            "{} pre-flight trajectories fitted (RMS {} m, {} deg; allowance {} m, {} deg in quadrature with their noise {} m, {} deg; the fit in {}/)",
            self.trajectories.len(),
            number(self.rms_pos_m),
            number(self.rms_att_deg),
            number(self.allowance_m),
            number(self.allowance_deg),
            number(self.noise_pos_m),
            number(self.noise_att_deg),
            self.fit_dir
        );
        let mut narrowed: Vec<&FactorChange> = self
            .factors
            .iter()
            .filter(|f| f.after.sd < 0.9 * f.before.sd)
            .collect();
        narrowed.sort_by(|a, b| (a.after.sd / a.before.sd).total_cmp(&(b.after.sd / b.before.sd)));
        let each: Vec<String> = narrowed
            .iter()
            .map(|f| {
                format!(
                    "{} {} sd {} (was {} sd {})",
                    f.factor,
                    number(f.after.mean),
                    number(f.after.sd),
                    number(f.before.mean),
                    number(f.before.sd)
                )
            })
            .collect();
        let narrowing = if each.is_empty() {
            "no factor narrowed by a tenth or more: the trajectories do not see them within the allowance".into()
        } else {
            format!("narrowed: {}", each.join(", "))
        };
        vec![fit, narrowing]
    }
}

/// A number in six significant digits, as the campaign's pages write them (`page::number`,
/// which this module cannot use: page reads the records, sources are part of them).
fn number(v: f64) -> String {
    sepval_report::words::significant(v, 6)
}
