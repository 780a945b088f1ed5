//! The answer of a diagnosis, decided once: the baseline, the catalogue's effects, or the
//! discovered extension, each carrying its model and the rival that lost to it. The catalogue's
//! effects stay the answer unless the discovered extension beats them by more than
//! [`BIC_MARGIN`] in BIC (R. E. Kass and A. E. Raftery, JASA 90, 1995: a difference above 6 is
//! strong evidence); with no catalogue effect significant, a significant discovered extension is
//! the answer; with neither, the baseline is.

use std::sync::Arc;

use sepval_common::effects::CATALOGUE;
use sepval_common::evaluation::{Candidate, Job};
use sepval_fit::FitOptions;
use sepval_fit::pipeline::FLOOR_FACTOR;
use sepval_fit::space::Noise;

use crate::found::Found;
use crate::{BIC_MARGIN, Fitted, Result, bic};

/// What every stage after the baseline fit shares.
pub(super) struct Setting {
    /// The job of the diagnosis.
    pub job: Arc<Job>,
    /// The noise (sigmas) the residuals are normalised by.
    pub noise: Noise,
    /// The noise floor of the goals: 1.1 sigma.
    pub floor: [f64; 2],
    /// Samples per event.
    pub events: Vec<usize>,
    /// Residuals of a fit (6 per sample).
    pub m: usize,
}

impl Setting {
    /// The setting of a diagnosis of `job` with the fit options `fit`.
    pub fn new(job: Arc<Job>, fit: &FitOptions) -> Setting {
        let noise = fit.sigma.noise();
        let events = job.events().iter().map(|e| e.data.len()).collect();
        let m = 6 * job.sample_count();
        Setting {
            job,
            noise,
            floor: [FLOOR_FACTOR * noise.pos_m, FLOOR_FACTOR * noise.att_deg],
            events,
            m,
        }
    }

    /// The BIC of a fitted model.
    pub fn bic(&self, f: &Fitted) -> f64 {
        bic(f.lm.cost, f.space(&self.job).len(), self.m)
    }
}

/// The catalogue's effects chosen by forward selection, and the model with them.
pub(super) struct Selected {
    /// The model with the chosen effects.
    pub fitted: Fitted,
    /// The chosen effects' catalogue indices, in the order chosen (never empty).
    pub chosen: Vec<usize>,
}

impl Selected {
    /// The chosen effects' ids.
    pub fn names(&self) -> Vec<String> {
        self.chosen
            .iter()
            .map(|&i| CATALOGUE[i].id().to_string())
            .collect()
    }
}

/// Which model answers, with its data.
pub(super) enum Answer {
    /// Neither a catalogue effect nor a discovered term is significant.
    Baseline,
    /// The catalogue's effects; a discovered extension that does not beat them is a rival.
    Catalogue {
        /// The effects and their model.
        selected: Selected,
        /// The discovered extension that did not beat them.
        rival: Option<Found>,
    },
    /// The discovered extension; the catalogue's effects, when significant too, are a mimic.
    Discovered {
        /// The extension.
        found: Found,
        /// The catalogue's effects it beat.
        mimic: Option<Selected>,
    },
}

/// A model that lost to the answer, as the validation and the alternatives list it.
pub(super) enum Rival<'a> {
    /// The catalogue's effects.
    Catalogue(&'a Selected),
    /// A discovered extension.
    Discovered(&'a Found),
}

impl Answer {
    /// The decision between what the catalogue selected and what discovery found.
    pub fn decide(setting: &Setting, selected: Option<Selected>, found: Option<Found>) -> Answer {
        match (selected, found) {
            (None, None) => Answer::Baseline,
            (Some(selected), None) => Answer::Catalogue {
                selected,
                rival: None,
            },
            (None, Some(found)) => Answer::Discovered { found, mimic: None },
            (Some(selected), Some(found)) => {
                if setting.bic(&found.fitted) < setting.bic(&selected.fitted) - BIC_MARGIN {
                    Answer::Discovered {
                        found,
                        mimic: Some(selected),
                    }
                } else {
                    Answer::Catalogue {
                        selected,
                        rival: Some(found),
                    }
                }
            }
        }
    }

    /// What it names: the catalogue's causes, or the discovered terms (one of the two is
    /// empty; both for the baseline).
    pub fn named(&self) -> (Vec<String>, Vec<crate::DiscoveredTerm>) {
        match self {
            Answer::Catalogue { selected, .. } => (selected.names(), Vec::new()),
            Answer::Discovered { found, .. } => (Vec::new(), found.terms.clone()),
            Answer::Baseline => (Vec::new(), Vec::new()),
        }
    }

    /// The level of the test the answer met, where it is not the library's: a catalogue
    /// answer's effects entered at 1 % over the catalogue's first round
    /// ([`crate::catalogue_level`]); a discovered answer met the library's own.
    pub fn level(&self) -> Option<f64> {
        match self {
            Answer::Catalogue { .. } => Some(crate::catalogue_level()),
            Answer::Discovered { .. } | Answer::Baseline => None,
        }
    }

    /// The answer's model.
    pub fn model<'a>(&'a self, baseline: &'a Fitted) -> &'a Fitted {
        match self {
            Answer::Baseline => baseline,
            Answer::Catalogue { selected, .. } => &selected.fitted,
            Answer::Discovered { found, .. } => &found.fitted,
        }
    }

    /// The catalogue's effects, the answer or not.
    pub fn selected(&self) -> Option<&Selected> {
        match self {
            Answer::Catalogue { selected, .. } => Some(selected),
            Answer::Discovered { mimic, .. } => mimic.as_ref(),
            Answer::Baseline => None,
        }
    }

    /// The discovered extension, the answer or not.
    pub fn found(&self) -> Option<&Found> {
        match self {
            Answer::Discovered { found, .. } => Some(found),
            Answer::Catalogue { rival, .. } => rival.as_ref(),
            Answer::Baseline => None,
        }
    }

    /// The model that lost to the answer, if any.
    pub fn rival(&self) -> Option<Rival<'_>> {
        match self {
            Answer::Catalogue {
                rival: Some(found), ..
            } => Some(Rival::Discovered(found)),
            Answer::Discovered {
                mimic: Some(selected),
                ..
            } => Some(Rival::Catalogue(selected)),
            _ => None,
        }
    }
}

impl Rival<'_> {
    /// Its model.
    pub fn fitted(&self) -> &Fitted {
        match self {
            Rival::Catalogue(s) => &s.fitted,
            Rival::Discovered(f) => &f.fitted,
        }
    }

    /// Its model as a contender of the rival search (it passed its own pool's tests).
    pub fn contender(&self) -> crate::contender::Contender {
        let origin = match self {
            Rival::Catalogue(_) => "the catalogue's selection",
            Rival::Discovered(_) => "the discovered extension",
        };
        crate::contender::Contender::new(self.fitted(), 1, origin.to_string())
    }

    /// How the validation names it, and its candidate.
    pub fn prediction(&self, job: &Job) -> Result<(String, Candidate)> {
        let name = match self {
            Rival::Catalogue(s) => format!("catalogue: {}", s.names().join(" + ")),
            Rival::Discovered(f) => format!(
                "discovered: {}",
                f.terms
                    .iter()
                    .map(|t| format!("{} {}", t.axis, t.term))
                    .collect::<Vec<_>>()
                    .join(" + ")
            ),
        };
        Ok((name, self.fitted().candidate(job)?))
    }
}
