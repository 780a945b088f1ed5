//! A bounded Levenberg-Marquardt least-squares refinement of a residual vector, as ask and tell:
//! it asks for parameter vectors and is told their residual vectors (what the parameters mean
//! and how the residuals are made is the caller's: for a fit, every sample's position and
//! attitude error divided by its noise sigma).
//!
//! Sources: K. Levenberg (1944) and D. W. Marquardt (1963) with Marquardt's diagonal scaling
//! (J^T J + mu diag(J^T J)) delta = -J^T r, converged after three consecutive accepted steps that
//! lower the cost by less than the tolerance; bounds by projection onto the box after each step
//! (as in bounded variants such as Kanzow, Yamashita and Fukushima, 2004). The Jacobian is a
//! forward difference, one batch per iteration; each iteration also tries four damping values in
//! one batch (mu/100, mu/10, mu, 10 mu) and keeps the best as the next mu, so the evaluators stay
//! busy and the damping adapts in one iteration. When every trial from a forward-difference
//! Jacobian raises the cost although that Jacobian predicted a drop above the tolerance, the
//! Jacobian is made again at the same point by backward differences (once per point, the damping
//! unchanged): a forward probe that steps across a jump of the residuals (a simulation whose
//! response to a parameter is discontinuous there) gives a column of jump / step, thousands of
//! times the true slope, that spoils every damped step and, the damping grown, leaves only gains
//! below the tolerance (sepval's own rule, 2026-11-25; seen in discovery's refits). Each step carries Transtrum and Sethna's
//! geodesic acceleration (one probe per step), which follows the narrow curved valleys of
//! strongly compensating parameters.
//!
//! A refinement moves through explicit stages, each a type of its own holding what it waits
//! for: the start point, the derivative probes (`Differencing`), the curvature probes
//! (`Curving`), the damped trials (`Trying`), then the next Jacobian or the end. Each
//! stage's points are asked in parts of at most the run's part size, so that a long record's
//! residual vectors are reduced and dropped part by part.

mod linear;
mod stages;

use nalgebra::DMatrix;
use sepval_core::outcome::Goals;

use crate::params::Params;
use crate::run::{Ask, Progress, RunError, SearchError, Solver};
use linear::fd_steps;
use stages::{Differencing, Parts, Stage};

type Result<T> = std::result::Result<T, RunError>;

/// [`LmResult::stop`] of a refinement that ran out of iterations before it converged or
/// stalled: its cost is then only an upper bound of its optimum's.
pub const ITERATION_LIMIT: &str = "iteration limit";

/// Settings of the refinement.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LmSettings {
    /// Most iterations.
    pub max_iterations: usize,
    /// Most evaluations.
    pub budget: u64,
    /// Forward-difference step, as a fraction of each parameter's range.
    pub fd_step: f64,
    /// Stop when an accepted step lowers the cost by less than this fraction.
    pub rel_tolerance: f64,
    /// Stop when the refinement stalls (none: run to the tolerance or a limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stall: Option<Stall>,
}

/// When a refinement has stalled: its last `iterations` iterations (accepted or not) together
/// lowered the cost by less than the fraction `rel_drop` of the cost they started from. A
/// refinement that creeps (each accepted step a gain just above the tolerance, hundreds of
/// iterations) stops there, at the resolution its user needs: the diagnosis sets `rel_drop` to
/// a tenth of a unit of its BIC (docs/discovery.md section 11.5).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Stall {
    /// The iterations looked back over.
    pub iterations: usize,
    /// The smallest fraction of the cost they must lower it by for the refinement to go on.
    pub rel_drop: f64,
}

impl Default for LmSettings {
    fn default() -> Self {
        LmSettings {
            max_iterations: 400,
            budget: 5_000,
            fd_step: 1e-6,
            rel_tolerance: 1e-7,
            stall: None,
        }
    }
}

/// What a residual vector means to whoever watches the refinement: its goals (for a fit,
/// J_pos \[m\] and J_att \[deg\]), reported after each accepted step.
pub trait Measure {
    /// The goals of the residual vector `r`.
    fn goals(&self, r: &[f64]) -> Goals;
}

/// The result of a refinement.
#[derive(Debug, Clone)]
pub struct LmResult {
    /// The refined parameters.
    pub x: Vec<f64>,
    /// Their goals.
    pub goals: Goals,
    /// Chi-square: the sum of squared residuals.
    pub cost: f64,
    /// Evaluations made.
    pub evaluations: u64,
    /// Iterations done.
    pub iterations: usize,
    /// The residuals at `x`.
    pub residuals: Vec<f64>,
    /// d(residual)/d(parameter) at `x` (rows: residuals; columns: parameters).
    pub jacobian: DMatrix<f64>,
    /// (evaluations so far, goals) after each accepted step.
    pub history: Vec<(u64, Goals)>,
    /// Why it stopped.
    pub stop: String,
}

impl LmResult {
    /// Whether it stopped at its iteration limit ([`ITERATION_LIMIT`]), neither converged nor
    /// stalled.
    pub fn cut_off(&self) -> bool {
        self.stop == ITERATION_LIMIT
    }
}

/// Where a refinement is: its point, residuals and Jacobian, damping and counters.
struct Position {
    x: Vec<f64>,
    r: Vec<f64>,
    cost: f64,
    jac: DMatrix<f64>,
    mu: f64,
    iterations: usize,
    evaluations: u64,
    history: Vec<(u64, Goals)>,
    stop: String,
    /// Consecutive accepted steps that lowered the cost by less than the tolerance.
    small_gains: usize,
    /// The cost at the start of each of the last iterations, oldest first (at most the stall
    /// rule's iterations plus one).
    recent: std::collections::VecDeque<f64>,
    /// The Jacobian at `x` is made of backward differences: its forward one's damped steps
    /// all failed while it predicted a drop (a probe that crossed a jump of the residuals).
    backward: bool,
}

/// One refinement as a sequence of batches: [`LmRun::request`] gives the next parameter
/// vectors to evaluate, [`LmRun::absorb`] takes their residual vectors. Several refinements can
/// so share each batch sent to the evaluators.
pub struct LmRun<M> {
    params: Params,
    measure: M,
    settings: LmSettings,
    at: Position,
    stage: Stage,
    /// Most points asked at once: a stage's points go in parts of this size.
    part: usize,
}

impl<M: Measure> LmRun<M> {
    /// A refinement of `x0` (projected onto the bounds of `params`), its residuals measured by
    /// `measure`, asking for at most `part` points at once.
    pub fn new(params: Params, x0: &[f64], measure: M, settings: LmSettings, part: usize) -> Self {
        let x = params.clamp(x0);
        LmRun {
            params,
            measure,
            settings,
            at: Position {
                x,
                r: Vec::new(),
                cost: f64::INFINITY,
                jac: DMatrix::zeros(0, 0),
                mu: 1e-3,
                iterations: 0,
                evaluations: 0,
                history: Vec::new(),
                stop: String::new(),
                small_gains: 0,
                recent: std::collections::VecDeque::new(),
                backward: false,
            },
            stage: Stage::Start,
            part: part.max(1),
        }
    }

    /// The parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The measure of its residuals.
    pub fn measure(&self) -> &M {
        &self.measure
    }

    /// The parameter vectors to evaluate next, or `None` when finished.
    pub fn request(&self) -> Option<Vec<Vec<f64>>> {
        let x = &self.at.x;
        Some(match &self.stage {
            Stage::Start => vec![x.clone()],
            Stage::Jacobian(d) => d
                .parts
                .range(self.part)
                .map(|i| {
                    let mut p = x.clone();
                    p[i] += d.steps[i];
                    p
                })
                .collect(),
            Stage::Curvature(c) => c.probes[c.parts.range(self.part)].to_vec(),
            Stage::Trials(t) => t.points[t.parts.range(self.part)].to_vec(),
            Stage::Done => return None,
        })
    }

    /// Takes the residual vectors of the last request (`None` for points that could not be
    /// evaluated). A refinement that fails is finished.
    pub fn absorb(&mut self, out: Vec<Option<Vec<f64>>>) -> Result<()> {
        self.at.evaluations += out.len() as u64;
        let stage = std::mem::replace(&mut self.stage, Stage::Done);
        self.stage = match stage {
            Stage::Start => self.started(out)?,
            Stage::Jacobian(d) => self.differenced(d, out)?,
            Stage::Curvature(c) => self.curved(c, out),
            Stage::Trials(t) => self.tried(t, out),
            Stage::Done => {
                return Err(RunError::Search(SearchError::Protocol(
                    "a finished refinement received values",
                )));
            }
        };
        Ok(())
    }

    /// The start point's residuals: the first Jacobian follows.
    fn started(&mut self, out: Vec<Option<Vec<f64>>>) -> Result<Stage> {
        let r = out
            .into_iter()
            .next()
            .flatten()
            .ok_or_else(|| RunError::Search(SearchError::StartDiverged))?;
        self.at.cost = r.iter().map(|v| v * v).sum();
        self.at.r = r;
        self.record();
        Ok(self.begin_jacobian(false))
    }

    /// Records the goals after an accepted step.
    fn record(&mut self) {
        let g = self.measure.goals(&self.at.r);
        self.at.history.push((self.at.evaluations, g));
    }

    /// The derivative probes, from the current point, for a Jacobian (the final one when
    /// `last`).
    fn begin_jacobian(&mut self, last: bool) -> Stage {
        // The previous Jacobian is not used again: it goes before the new one is made (6 x
        // samples x parameters doubles each, 1.6 GB at 2 million samples and 17 parameters).
        self.at.jac = DMatrix::zeros(0, 0);
        Stage::Jacobian(Differencing {
            steps: fd_steps(
                &self.params,
                &self.at.x,
                self.settings.fd_step,
                self.at.backward,
            ),
            last,
            parts: Parts::new(self.params.len()),
            jac: DMatrix::zeros(self.at.r.len(), self.params.len()),
        })
    }

    /// The result (after [`LmRun::request`] returned `None`).
    pub fn finish(self) -> LmResult {
        let at = self.at;
        LmResult {
            goals: self.measure.goals(&at.r),
            x: at.x,
            cost: at.cost,
            evaluations: at.evaluations,
            iterations: at.iterations,
            residuals: at.r,
            jacobian: at.jac,
            history: at.history,
            stop: at.stop,
        }
    }
}

impl<M: Measure> Solver for LmRun<M> {
    type Point = Vec<f64>;
    type Value = Option<Vec<f64>>;

    fn ask(&mut self) -> Result<Option<Ask<Vec<f64>>>> {
        Ok(self.request().map(|points| Ask {
            points,
            with_samples: true,
        }))
    }

    fn tell(&mut self, residuals: Vec<Option<Vec<f64>>>) -> Result<Option<Progress>> {
        let accepted = self.at.history.len();
        self.absorb(residuals)?;
        Ok((self.at.history.len() > accepted).then(|| Progress {
            step: self.at.iterations,
            steps: Some(self.settings.max_iterations),
            evaluations: self.at.evaluations,
            best: self.measure.goals(&self.at.r).as_array(),
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::{Problem, run};

    /// Goals of a residual vector: its RMS, twice.
    struct Rms;

    impl Measure for Rms {
        fn goals(&self, r: &[f64]) -> Goals {
            let rms = (r.iter().map(|v| v * v).sum::<f64>() / r.len().max(1) as f64).sqrt();
            Goals {
                j_pos_m: rms,
                j_att_deg: rms,
            }
        }
    }

    /// Rosenbrock's valley as residuals (10 (y - x^2), 1 - x), minimum at (1, 1).
    struct Rosenbrock;

    impl Problem<Vec<f64>, Option<Vec<f64>>> for Rosenbrock {
        fn evaluate(&mut self, p: &[Vec<f64>], _: bool) -> Result<Vec<Option<Vec<f64>>>> {
            Ok(p.iter()
                .map(|x| Some(vec![10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]]))
                .collect())
        }
    }

    fn params() -> Params {
        let mut p = Params::empty();
        p.push("x", "-", -2.0, 2.0);
        p.push("y", "-", -1.0, 3.0);
        p
    }

    #[test]
    fn finds_the_bottom_of_a_curved_valley_in_parts_of_any_size() {
        let mut answers = Vec::new();
        for part in [1, 2, 100] {
            let mut lm = LmRun::new(params(), &[-1.2, 1.0], Rms, LmSettings::default(), part);
            run(&mut lm, &mut Rosenbrock, &mut []).unwrap();
            let r = lm.finish();
            assert!(
                (r.x[0] - 1.0).abs() < 1e-6 && (r.x[1] - 1.0).abs() < 1e-6,
                "{r:?}"
            );
            assert!(r.cost < 1e-12, "{}", r.cost);
            assert!(r.stop.starts_with("converged"), "{}", r.stop);
            assert!(
                r.history
                    .windows(2)
                    .all(|w| w[1].1.j_pos_m <= w[0].1.j_pos_m)
            );
            answers.push(r.x);
        }
        // The parts change how the points travel, never the arithmetic.
        assert!(answers.windows(2).all(|w| w[0] == w[1]));
    }

    #[test]
    fn a_refinement_out_of_iterations_is_cut_off_and_one_converged_is_not() {
        let few = LmSettings {
            max_iterations: 2,
            ..LmSettings::default()
        };
        let mut lm = LmRun::new(params(), &[-1.2, 1.0], Rms, few, 100);
        run(&mut lm, &mut Rosenbrock, &mut []).unwrap();
        let r = lm.finish();
        assert!(r.cut_off(), "{}", r.stop);
        assert!(r.cost > 1e-6, "{}", r.cost);
        let mut lm = LmRun::new(params(), &[-1.2, 1.0], Rms, LmSettings::default(), 100);
        run(&mut lm, &mut Rosenbrock, &mut []).unwrap();
        assert!(!lm.finish().cut_off());
    }

    #[test]
    fn a_bound_holds_the_optimum_on_it() {
        let mut p = params();
        p.hi[0] = 0.5;
        let mut lm = LmRun::new(p, &[-1.2, 1.0], Rms, LmSettings::default(), 100);
        run(&mut lm, &mut Rosenbrock, &mut []).unwrap();
        let r = lm.finish();
        assert!(r.x[0] <= 0.5 && (r.x[0] - 0.5).abs() < 1e-9, "{:?}", r.x);
        assert!((r.x[1] - 0.25).abs() < 1e-6, "{:?}", r.x);
    }

    #[test]
    fn a_stalled_refinement_stops_with_its_jacobian_current() {
        let plain = {
            let mut lm = LmRun::new(params(), &[-1.2, 1.0], Rms, LmSettings::default(), 100);
            run(&mut lm, &mut Rosenbrock, &mut []).unwrap();
            lm.finish()
        };
        // A drop of nothing is always enough to go on: the same refinement, bit for bit.
        let never = LmSettings {
            stall: Some(Stall {
                iterations: 3,
                rel_drop: 0.0,
            }),
            ..LmSettings::default()
        };
        let mut lm = LmRun::new(params(), &[-1.2, 1.0], Rms, never, 100);
        run(&mut lm, &mut Rosenbrock, &mut []).unwrap();
        let same = lm.finish();
        assert_eq!(
            (same.x, same.cost.to_bits()),
            (plain.x, plain.cost.to_bits())
        );
        // Three iterations that must halve the cost: the valley's slow stretch stops it early.
        let halve = LmSettings {
            stall: Some(Stall {
                iterations: 3,
                rel_drop: 0.5,
            }),
            ..LmSettings::default()
        };
        let mut lm = LmRun::new(params(), &[-1.2, 1.0], Rms, halve, 100);
        run(&mut lm, &mut Rosenbrock, &mut []).unwrap();
        let r = lm.finish();
        assert!(r.stop.starts_with("stalled"), "{}", r.stop);
        assert!(
            r.iterations < plain.iterations && r.cost > plain.cost,
            "{r:?}"
        );
        assert_eq!(r.jacobian.shape(), (2, 2));
        assert_eq!(r.residuals.len(), 2);
    }

    /// One residual, b - 1 plus a jump of 3 once a exceeds 0.5 + 1e-9: the optimum is b = 1
    /// with a anywhere below the jump, and a starts just below it.
    struct JumpAbove;

    impl Problem<Vec<f64>, Option<Vec<f64>>> for JumpAbove {
        fn evaluate(&mut self, p: &[Vec<f64>], _: bool) -> Result<Vec<Option<Vec<f64>>>> {
            Ok(p.iter()
                .map(|x| {
                    let jump = if x[0] > 0.5 + 1e-9 { 3.0 } else { 0.0 };
                    Some(vec![x[1] - 1.0 + jump])
                })
                .collect())
        }
    }

    #[test]
    fn a_forward_probe_across_a_jump_does_not_stop_the_refinement() {
        // The forward probe of a (4e-6 of its range) crosses the jump: its column is 3 / 4e-6,
        // every damped step then crosses it too. Without the backward Jacobian the damping
        // grows until the steps are too small to gain and b stays near its start (b = 7.5e-4
        // after 32 iterations), as discovery's step-2 refits on two gust releases did.
        let settings = LmSettings {
            max_iterations: 40,
            ..LmSettings::default()
        };
        let mut lm = LmRun::new(params(), &[0.5, 0.0], Rms, settings, 100);
        run(&mut lm, &mut JumpAbove, &mut []).unwrap();
        let r = lm.finish();
        assert!((r.x[1] - 1.0).abs() < 1e-6, "{r:?}");
        assert!(r.x[0] <= 0.5 + 1e-9, "{:?}", r.x);
        assert!(r.cost < 1e-12, "{}", r.cost);
    }

    #[test]
    fn a_start_that_cannot_be_evaluated_ends_the_refinement() {
        struct Nothing;
        impl Problem<Vec<f64>, Option<Vec<f64>>> for Nothing {
            fn evaluate(&mut self, p: &[Vec<f64>], _: bool) -> Result<Vec<Option<Vec<f64>>>> {
                Ok(vec![None; p.len()])
            }
        }
        let mut lm = LmRun::new(params(), &[0.0, 0.0], Rms, LmSettings::default(), 10);
        let e = run(&mut lm, &mut Nothing, &mut []).unwrap_err();
        assert!(e.to_string().contains("start does not simulate"), "{e}");
        assert!(lm.request().is_none());
    }
}
