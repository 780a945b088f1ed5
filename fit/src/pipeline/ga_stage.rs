//! The genetic stage of a fit as one solver: the study's genetic algorithm on the factors and,
//! for `ga+lm`, refinement attempts ("probes") started from its best member when it stagnates
//! or on a doubling schedule; once a probe reaches the noise floor, the stage ends. And the
//! observer that writes one checkpoint per generation.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use sepval_common::evaluation::{Candidate, Evaluation, Job};
use sepval_solve::ga::{GaSearch, GaSettings, GaState};
use sepval_solve::hill::HillSettings;
use sepval_solve::lm::{LmResult, LmSettings};
use sepval_solve::run::{Ask, Control, Observer, Progress, RunError, SearchError, Solver};

use crate::checkpoint::{CHECKPOINT_FORMAT, Checkpoint};
use crate::problem::OnModel;
use crate::refine::ModelLm;
use crate::results::Probe;
use crate::sigma::Sigma;
use crate::space::{Noise, ParamSpace};
use sepval_run::inputs::InputsRecord;

/// A refinement is tried during ga+lm when the search has stagnated (the best weighted goal
/// improved by less than 1 % over the last 10 generations) or at generations 10, 20, 40, 80,
/// ..., and at least 10 generations after the previous attempt.
pub fn refinement_due(state: &GaState, probes: &[Probe]) -> bool {
    let g = state.generation;
    if g < 10 || probes.last().is_some_and(|p| g < p.generation + 10) {
        return false;
    }
    let scheduled = (g % 10 == 0) && (g / 10).is_power_of_two();
    let h = &state.history;
    let stagnant = h.len() > 10 && {
        let then = h[h.len() - 11].best_weighted;
        let now = h[h.len() - 1].best_weighted;
        then.is_finite() && (then - now) < 0.01 * then
    };
    scheduled || stagnant
}

/// Settings of the probes (`ga+lm`).
pub struct Probing {
    /// Refinement settings of each probe.
    pub lm: LmSettings,
    /// Noise levels normalising the residuals.
    pub noise: Noise,
    /// The floor: both goals at most these (J_pos \[m\], J_att \[deg\]).
    pub floor: [f64; 2],
}

/// A probe under way: its refinement and the simulations before it.
struct Running {
    lm: ModelLm,
    before: u64,
}

/// The genetic stage of a fit.
pub struct GaStage {
    ga: GaSearch,
    space: ParamSpace,
    job: Arc<Job>,
    weights: [f64; 2],
    probing: Option<Probing>,
    probes: Vec<Probe>,
    running: Option<Running>,
    /// The probe that reached the floor, with the simulations before it.
    reached: Option<(LmResult, u64)>,
}

impl GaStage {
    /// The stage of `ga` over the factors of `job`, probing when `probing` is given and
    /// carrying the probes of a resumed run.
    pub fn new(
        ga: GaSearch,
        job: Arc<Job>,
        weights: [f64; 2],
        probing: Option<Probing>,
        probes: Vec<Probe>,
    ) -> Self {
        let space = ParamSpace::new(job.factor_table(), &sepval_common::effects::EffectSet::NONE);
        GaStage {
            ga,
            space,
            job,
            weights,
            probing,
            probes,
            running: None,
            reached: None,
        }
    }

    /// The genetic search.
    pub fn ga(&self) -> &GaSearch {
        &self.ga
    }

    /// The refinement attempts so far.
    pub fn probes(&self) -> &[Probe] {
        &self.probes
    }

    /// The stage's end: the final state, the probes, and the probe that reached the floor
    /// with the simulations before it, if one did.
    pub fn finish(self) -> (Option<GaState>, Vec<Probe>, Option<(LmResult, u64)>) {
        (self.ga.state().cloned(), self.probes, self.reached)
    }

    fn simulations(&self) -> u64 {
        self.ga.state().map_or(0, |s| s.evaluations)
            + self.probes.iter().map(|p| p.evaluations).sum::<u64>()
    }
}

impl Solver for GaStage {
    type Point = Candidate;
    type Value = Evaluation;

    fn ask(&mut self) -> Result<Option<Ask<Candidate>>, RunError> {
        loop {
            if let Some(r) = &mut self.running {
                if let Some(ask) = r.lm.ask()? {
                    return Ok(Some(ask));
                }
                let Running { lm, before } = self.running.take().expect("running");
                let lm = lm.finish();
                let probing = self.probing.as_ref().expect("probes only when probing");
                let g = lm.goals.as_array();
                let reached = g[0] <= probing.floor[0] && g[1] <= probing.floor[1];
                self.probes.push(Probe {
                    generation: self.ga.state().map_or(0, |s| s.generation),
                    evaluations_before: before,
                    evaluations: lm.evaluations,
                    goals: g,
                    reached_floor: reached,
                });
                if reached {
                    self.reached = Some((lm, before));
                }
            }
            if self.reached.is_some() || self.ga.finished() {
                return Ok(None);
            }
            if let (Some(p), Some(state)) = (&self.probing, self.ga.state()) {
                if refinement_due(state, &self.probes) {
                    let best = state
                        .best(self.weights)
                        .ok_or_else(|| RunError::Search(SearchError::NoFinishedMember))?;
                    let lm = ModelLm::new(
                        self.space.clone(),
                        Arc::clone(&self.job),
                        &best.values,
                        p.noise,
                        p.lm.clone(),
                    );
                    self.running = Some(Running {
                        lm,
                        before: self.simulations(),
                    });
                    continue;
                }
            }
            let Some(ask) = self.ga.ask()? else {
                return Ok(None);
            };
            return Ok(Some(OnModel::<GaSearch>::candidates(&self.space, ask)?));
        }
    }

    fn tell(&mut self, evaluations: Vec<Evaluation>) -> Result<Option<Progress>, RunError> {
        match &mut self.running {
            Some(r) => {
                r.lm.tell(evaluations)?;
                Ok(None)
            }
            None => self
                .ga
                .tell(evaluations.into_iter().map(|e| e.outcome).collect()),
        }
    }
}

/// Writes DIR/generations/gen-NNNN.json after every generation: the search state with its
/// generator, the probes, the settings and the hashes of the data and scenario.
pub struct Checkpointer {
    /// Run directory.
    out: PathBuf,
    /// Every checkpoint of the run but its state and probes, which each generation fills in.
    template: Checkpoint,
}

impl Checkpointer {
    /// Writes into `out`/generations checkpoints made from `template` ([`Checkpointer::template`]).
    pub fn new(out: &Path, template: Checkpoint) -> Self {
        Checkpointer {
            out: out.to_path_buf(),
            template,
        }
    }

    /// The template of a run's checkpoints: its method, settings, noise levels, the hashes of
    /// `job`'s data and scenario and where its inputs came from, with the search as it is
    /// before its first generation and no probes.
    pub fn template(
        method: &str,
        settings: &GaSettings,
        hill: &HillSettings,
        sigma: &Sigma,
        job: &Job,
        inputs: &InputsRecord,
    ) -> Checkpoint {
        Checkpoint {
            format: CHECKPOINT_FORMAT.to_string(),
            digest: None,
            arithmetic: Some(sepval_common::ARITHMETIC_VERSION),
            method: method.to_string(),
            settings: settings.clone(),
            hill: hill.clone(),
            sigma: sigma.clone(),
            data_sha256: job.data_sha256().to_string(),
            scenario_sha256: job.scenario_sha256().to_string(),
            inputs: inputs.clone(),
            state: GaState::unstarted(settings.seed),
            probes: Vec::new(),
        }
    }
}

impl Observer<GaStage> for Checkpointer {
    fn observe(&mut self, stage: &GaStage, _: &Progress) -> Result<Control, RunError> {
        let Some(state) = stage.ga().state() else {
            return Ok(Control::Continue);
        };
        let checkpoint = Checkpoint {
            state: state.clone(),
            probes: stage.probes().to_vec(),
            ..self.template.clone()
        };
        checkpoint
            .save(&Checkpoint::path(&self.out, state.generation))
            .map_err(|e| RunError::Observer {
                what: format!("writing the checkpoint of generation {}", state.generation),
                source: Box::new(e),
            })?;
        Ok(Control::Continue)
    }
}
