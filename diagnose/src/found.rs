//! What discovery reports (docs/discovery.md section 11.7): the gain of a model change, the terms
//! found with their groups of indistinguishable alternatives, and each stepwise step's screening
//! and verification.

use serde::{Deserialize, Serialize};

use super::reconstruct::Reconstruction;
use super::{Fitted, bic};
use sepval_solve::stats::f_test;

/// The gain of a model change, by nested least squares.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Gain {
    /// Chi-square drop.
    pub chi2_drop: f64,
    /// Parameters added.
    pub parameters: usize,
    /// F statistic of the added parameters.
    pub f: f64,
    /// Its p-value.
    pub p_value: f64,
    /// BIC change (negative: better even after charging the parameters).
    pub delta_bic: f64,
}

impl Gain {
    /// The gain of `with` (chi-square, `p_with` parameters) over `without` (chi-square, `q`
    /// parameters fewer), on `m` residuals.
    pub fn of(without: f64, with: f64, q: usize, p_with: usize, m: usize) -> Gain {
        let (f, p_value) = f_test(without, with, q, m, p_with);
        Gain {
            chi2_drop: without - with,
            parameters: q,
            f,
            p_value,
            delta_bic: bic(with, p_with, m) - bic(without, p_with - q, m),
        }
    }

    /// Significant at `alpha` and better by BIC.
    pub fn significant(&self, alpha: f64) -> bool {
        self.p_value < alpha && self.delta_bic < 0.0
    }
}

/// A library entry the data cannot tell from a discovered one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroupMember {
    /// Its axis.
    pub axis: String,
    /// Its family.
    pub family: String,
    /// Its formula.
    pub term: String,
    /// Correlation of its sensitivity with the discovered one's (beyond the model's own
    /// sensitivities); null for a rival whose output-error refit came within 2 of its
    /// chi-square.
    pub correlation: Option<f64>,
}

/// One discovered term (an oscillation: its sine-cosine pair as one amplitude and phase).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DiscoveredTerm {
    /// `CA`, `CY`, `CZ`, `Cl`, `Cm`, `Cn`, `ejector`, `wind_y` or `wind_z`.
    pub axis: String,
    /// The library family.
    pub family: String,
    /// A readable formula.
    pub term: String,
    /// Its coefficient (an oscillation: its amplitude).
    pub coefficient: f64,
    /// The coefficient's standard error (null when the data do not determine it).
    pub std_error: Option<f64>,
    /// An oscillation's phase \[deg\]: A sin(2 pi f t + phase).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase_deg: Option<f64>,
    /// A step's or a gust's time \[s\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t_on_s: Option<f64>,
    /// A gust's onset or pulse length \[s\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rise_s: Option<f64>,
    /// An oscillation's frequency \[Hz\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub f_hz: Option<f64>,
    /// An interference decay length \[m\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lambda_m: Option<f64>,
    /// The Mach reference of a Mach term.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mach0: Option<f64>,
    /// The locator's standard error, when the refit estimates it; for a gust, of its middle
    /// `t_on_s + rise_s / 2` (the data place a gust's middle far better than its onset).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub locator_std_error: Option<f64>,
    /// A gust's length's standard error \[s\], when the refit estimates it and the data
    /// determine it (narrower than its range; a short gust is seen only through its impulse,
    /// and then `rise_s` is one length among many that fit as well).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rise_std_error: Option<f64>,
    /// Its locations estimated, each with its 95 % interval (`docs/discovery.md` section 11.5,
    /// step 13): a step's onset; a gust's onset, middle and length; an oscillation's frequency
    /// and phase. Empty for the families without a location in time or frequency.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub locations: Vec<Location>,
    /// What it brings: the refit without it against the refit with it (with one term: the
    /// baseline against the extension).
    pub gain: Gain,
    /// A plain-language physical reading (`docs/discovery.md` section 11.4).
    pub reading: String,
    /// Entries the data cannot tell from it (|correlation| >= 0.95).
    pub group: Vec<GroupMember>,
}

/// One location of a discovered term estimated: its value with its standard error and 95 %
/// interval, or, when the data do not determine it, the interval the profile of the cost
/// allows and no standard error (`docs/discovery.md` section 11.5, step 13).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Location {
    /// What is located: `t_on_s` (a step's or a gust's onset), `t_mid_s` (a gust's middle),
    /// `rise_s` (a gust's length), `f_hz` (a frequency) or `phase_deg` (an oscillation's phase).
    pub quantity: String,
    /// The estimate: the value in the answer's model.
    pub value: f64,
    /// Its standard error from the refit's Jacobian (corrected for coloured residuals); null when
    /// the refit holds it or the data do not determine it.
    pub std_error: Option<f64>,
    /// The 95 % interval's lower end.
    pub low: f64,
    /// The 95 % interval's upper end.
    pub high: f64,
    /// Whether the data determine it: its 95 % set lies inside the range the profile tried.
    pub determined: bool,
    /// How the interval was formed, in words.
    pub basis: String,
}

/// A verified extension: the refitted model, its terms (most important first) and its gain over
/// the baseline.
pub(super) struct Found {
    /// The model extended by the terms, refitted.
    pub fitted: Fitted,
    /// Its terms, most important first.
    pub terms: Vec<DiscoveredTerm>,
    /// Its gain over the baseline.
    pub gain: Gain,
}

/// What discovery found.
pub(super) struct Discovery {
    /// Per event, the reconstructed increments.
    pub reconstruction: Vec<Reconstruction>,
    /// The verified extension, when one is significant.
    pub found: Option<Found>,
    /// What happened (why nothing was found, or what was dropped).
    pub notes: Vec<String>,
    /// Each step of the selection: what the regression ranked, what the refits gave.
    pub steps: Vec<DiscoveryStep>,
    /// The first step's refits and the library's mimics of the catalogue's answer, for the
    /// rival search.
    pub contenders: Vec<crate::contender::Contender>,
    /// Refits that did not simulate and were left out.
    pub skipped: Vec<crate::SkippedRefit>,
    /// The first step's rival classes.
    pub classes: Vec<crate::classes::ClassInfo>,
    /// Why discovery could not run at all (the term budget full), if it could not.
    pub blocked: Option<String>,
}

/// One library entry as the regression ranked it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Screened {
    /// Its axis.
    pub axis: String,
    /// Its formula.
    pub term: String,
    /// F-to-enter.
    pub f: f64,
    /// Its p-value.
    pub p_value: f64,
}

/// One entry refitted by output error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Verified {
    /// Its axis.
    pub axis: String,
    /// Its formula (locator as refined).
    pub term: String,
    /// Chi-square of the refit.
    pub chi2: f64,
}

/// One step of the forward selection.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DiscoveryStep {
    /// The step (1: against the baseline).
    pub step: usize,
    /// Chi-square of the model the step starts from.
    pub chi2: f64,
    /// The Bonferroni-corrected F-to-enter threshold.
    pub threshold: f64,
    /// The ten best entries by F-to-enter.
    pub screened: Vec<Screened>,
    /// The entries refitted, best first.
    pub verified: Vec<Verified>,
    /// The entry that entered, with its gain; none when the step ended the selection.
    pub accepted: Option<String>,
}
