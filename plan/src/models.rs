//! The models a plan compares: the diagnosis's answer and each of its rivals, rebuilt from
//! DIR/diagnosis.json (`model`, and each rival's `model`: `sepval_run::model_spec`), each with
//! the free parameters a refit would move (the 17 factors, its effects' parameters, its terms'
//! coefficients: the parameters of the diagnosis's own refits, `sepval_fit::space`, locators
//! held) and the forward-difference steps of its sensitivities.

use sepval_common::evaluation::Candidate;
use sepval_common::extension::Family;
use sepval_core::factors::FactorTable;
use sepval_diagnose::Diagnosis;
use sepval_fit::rebuild::{Rebuilt, rebuild};
use sepval_fit::space::ParamSpace;
use sepval_run::model_spec::ModelSpec;

/// Forward-difference step of a sensitivity, as a fraction of the parameter's range (the
/// refinement's own, `sepval_solve::lm::LmSettings::fd_step`).
pub const FD_STEP: f64 = 1e-6;
/// A model of a diagnosis that cannot be rebuilt.
pub use sepval_fit::rebuild::RebuildError as ModelsError;

/// One model with what its refit may move.
#[derive(Debug, Clone)]
pub struct PlanModel {
    /// Its name in reports: its effects and terms (`baseline` when it has none).
    pub name: String,
    /// Whether it is the diagnosis's answer (else a rival).
    pub answer: bool,
    /// Its BIC minus the answer's on the releases flown (0 for the answer).
    pub delta_bic: f64,
    /// The model as files hold it.
    pub spec: ModelSpec,
    /// Its candidate.
    pub candidate: Candidate,
    /// Its free parameters (names, bounds).
    pub space: ParamSpace,
    /// Their values.
    pub x: Vec<f64>,
    /// The forward-difference step of each \[parameter's unit\].
    pub steps: Vec<f64>,
}

impl PlanModel {
    fn new(
        which: String,
        spec: &ModelSpec,
        table: &FactorTable,
        answer: bool,
        delta_bic: f64,
    ) -> Result<PlanModel, ModelsError> {
        let Rebuilt {
            name,
            candidate,
            space,
            x,
        } = rebuild(spec, &which, table)?;
        let steps = (0..x.len())
            .map(|i| {
                let h = FD_STEP * space.params.range(i);
                // Inward at the upper bound, as the refinement steps.
                if x[i] + h > space.params.hi[i] { -h } else { h }
            })
            .collect();
        Ok(PlanModel {
            name,
            answer,
            delta_bic,
            spec: spec.clone(),
            candidate,
            space,
            x,
            steps,
        })
    }

    /// Whether it has a located term whose locator the diagnosis refits (a step's or gust's
    /// time, a gust's length, a frequency, a decay length) and the plan holds at its value
    /// (its linearised refit moves coefficients and factors only).
    pub fn located(&self) -> bool {
        self.candidate.terms.iter().any(|t| {
            matches!(
                t.regressor.family(),
                Family::Step
                    | Family::Wind
                    | Family::Oscillation
                    | Family::Interference
                    | Family::InterferenceFlowAngle
            )
        })
    }

    /// Its number of free parameters.
    pub fn parameters(&self) -> usize {
        self.x.len()
    }

    /// The candidates of its sensitivities: itself, then one step along each parameter.
    pub fn probes(&self) -> Vec<Candidate> {
        let mut out = vec![self.candidate];
        for (j, h) in self.steps.iter().enumerate() {
            let mut x = self.x.clone();
            x[j] += h;
            out.push(
                self.space
                    .candidate(&x)
                    .expect("a step within the bounds of the model's own space"),
            );
        }
        out
    }
}

/// The models of a diagnosis: the answer first, then the rivals, best first.
#[derive(Debug, Clone)]
pub struct Models {
    /// The models.
    pub list: Vec<PlanModel>,
}

impl Models {
    /// The answer and the rivals of `d`, their factors checked against `table` (the factor
    /// table of the releases flown).
    pub fn of(d: &Diagnosis, table: &FactorTable) -> Result<Models, ModelsError> {
        let mut specs = vec![(d.model.clone(), 0.0)];
        specs.extend(d.rivals.iter().map(|r| (r.model.clone(), r.delta_bic)));
        Models::new(&specs, table)
    }

    /// The models of `specs` (each with its BIC minus the answer's): the answer first.
    pub fn new(specs: &[(ModelSpec, f64)], table: &FactorTable) -> Result<Models, ModelsError> {
        let mut list = Vec::with_capacity(specs.len());
        for (i, (spec, delta_bic)) in specs.iter().enumerate() {
            let which = if i == 0 {
                "the answer".to_string()
            } else {
                format!("rival {i}")
            };
            list.push(PlanModel::new(which, spec, table, i == 0, *delta_bic)?);
        }
        // Two models of the same description (a rival differing only in values) are told
        // apart by their position.
        for i in 1..list.len() {
            if list[..i].iter().any(|m| m.name == list[i].name) {
                list[i].name = format!("{} (rival {i})", list[i].name);
            }
        }
        Ok(Models { list })
    }

    /// The answer.
    pub fn answer(&self) -> &PlanModel {
        &self.list[0]
    }

    /// Whether there is anything to separate.
    pub fn has_rivals(&self) -> bool {
        self.list.len() > 1
    }
}
