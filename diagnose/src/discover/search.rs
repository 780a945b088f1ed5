//! What every step of discovery shares: the job, the noise, the refinement settings, the
//! residual rows the sensitivities use, and the room left for terms (`docs/discovery.md`).

use std::sync::Arc;

use nalgebra::DVector;
use sepval_common::evaluation::Job;
use sepval_fit::space::Noise;
use sepval_solve::lm::LmSettings;

use super::picked::Picked;
use crate::Fitted;
use crate::found::DiscoveryStep;
use crate::probe;

/// Most iterations of a candidate's verification refit (the winner then runs on to
/// convergence).
const VERIFY_ITERATIONS: usize = 40;

/// The fixed setting of one discovery.
pub(super) struct Search<'a> {
    /// The job of the diagnosis.
    pub job: &'a Arc<Job>,
    /// The noise that normalises the residuals.
    pub noise: Noise,
    /// Refinement settings of a model that runs to convergence.
    pub settings: &'a LmSettings,
    /// Refinement settings of a candidate's verification refit: a few dozen iterations rank
    /// the candidates.
    pub screening: LmSettings,
    /// The residual rows the sensitivities use (long records: a subset of their samples).
    pub rows: Vec<usize>,
    /// The data's sample rate \[Hz\].
    pub rate_hz: f64,
    /// Residuals of a fit (6 per sample).
    pub m: usize,
    /// Extension terms the model can still take.
    pub room: usize,
}

impl<'a> Search<'a> {
    /// The setting of a discovery on `job`.
    pub fn new(job: &'a Arc<Job>, noise: Noise, settings: &'a LmSettings) -> Search<'a> {
        let room = sepval_common::extension::MAX_TERMS
            - job
                .events()
                .iter()
                .map(|e| e.simulator.model().extension.len())
                .max()
                .unwrap_or(0);
        Search {
            job,
            noise,
            settings,
            screening: LmSettings {
                max_iterations: settings.max_iterations.min(VERIFY_ITERATIONS),
                ..settings.clone()
            },
            rows: probe::rows(job),
            rate_hz: sample_rate_hz(job),
            m: 6 * job.sample_count(),
            room,
        }
    }

    /// A full residual vector (6 per sample) on the rows the sensitivities use.
    pub fn on_rows(&self, full: &[f64]) -> DVector<f64> {
        DVector::from_iterator(self.rows.len(), self.rows.iter().map(|&i| full[i]))
    }
}

/// The data's sample rate \[Hz\] (of the first event with two samples).
fn sample_rate_hz(job: &Job) -> f64 {
    job.events()
        .iter()
        .find_map(|e| {
            let t = &e.data.times_s;
            (t.len() > 1).then(|| (t.len() - 1) as f64 / (t[t.len() - 1] - t[0]))
        })
        .filter(|r| r.is_finite() && *r > 0.0)
        .unwrap_or(100.0)
}

/// The model the selection has reached: its fit, the entries in it, and the group of
/// indistinguishable entries of each.
#[derive(Clone)]
pub(super) struct Selection {
    /// The current model (the converged baseline at the start).
    pub current: Fitted,
    /// Its entries.
    pub picked: Picked,
    /// Per entry, the entries the data cannot tell from it.
    pub groups: Vec<Vec<crate::GroupMember>>,
    /// Per entry, the alternatives its exchanges try (`exchange`).
    pub near: Vec<Near>,
    /// The refits of `current` without each of its entries, when F-to-remove made them and
    /// kept every entry: the gains of the entries of the final model are read from them rather
    /// than refitted again (the same refits from the same optimum).
    pub without: Option<Vec<Option<Fitted>>>,
}

/// The alternatives of one entry of the model.
#[derive(Debug, Clone, Default)]
pub(crate) struct Near {
    /// Entries whose refit at the step it entered came within the margin of its chi-square.
    pub entries: Vec<crate::library::Entry>,
    /// How many entries that step screened (the pool of their significance test).
    pub pool: usize,
}

/// What discovery records as it goes.
#[derive(Default)]
pub(super) struct Trail {
    /// What happened (why nothing was found, or what was dropped).
    pub notes: Vec<String>,
    /// Each step's screening and refits.
    pub steps: Vec<DiscoveryStep>,
    /// The first step's refits (and mimics), for the rival search.
    pub contenders: Vec<crate::contender::Contender>,
    /// Refits that did not simulate and were left out.
    pub skipped: Vec<crate::SkippedRefit>,
    /// The first step's rival classes (`crate::classes`).
    pub classes: Vec<crate::classes::ClassInfo>,
}

impl Trail {
    /// Records a refit of `model` at `stage` that did not simulate (`reason`), left out: in the
    /// notes and among the skipped refits.
    pub fn skip(&mut self, stage: String, model: String, reason: String) {
        self.notes.push(format!(
            "{stage}: the refit of {model} was left out: {reason}"
        ));
        self.skipped.push(crate::SkippedRefit {
            stage,
            model,
            reason,
        });
    }
}
