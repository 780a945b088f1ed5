//! The stages of a refinement after its start, each a type holding what it waits for, and
//! the transition each makes when its values arrive: derivative probes to a Jacobian, the
//! Jacobian to damped steps and their curvature probes, the probes to accelerated trials, the
//! trials to an accepted step (and the next Jacobian) or a larger damping.

use std::ops::Range;

use nalgebra::{DMatrix, DVector};

use super::linear::solve_damped;
use super::{ITERATION_LIMIT, LmRun, Measure, Result};
use crate::run::{RunError, SearchError};

/// A stage's points asked in parts: the part that starts at `next` of `len` points.
#[derive(Debug, Clone, Copy)]
pub(super) struct Parts {
    next: usize,
    len: usize,
}

impl Parts {
    /// All `len` points still to ask.
    pub(super) fn new(len: usize) -> Self {
        Parts { next: 0, len }
    }

    /// The indices of the next part of at most `size` points.
    pub(super) fn range(&self, size: usize) -> Range<usize> {
        self.next..self.next.saturating_add(size).min(self.len)
    }

    /// Moves past the part of `size` just told; whether points remain.
    fn advance(&mut self, size: usize) -> bool {
        self.next = self.range(size).end;
        self.next < self.len
    }
}

/// What a refinement waits for.
pub(super) enum Stage {
    /// The start point.
    Start,
    /// Derivative probes.
    Jacobian(Differencing),
    /// Probes along each damped step for its curvature.
    Curvature(Curving),
    /// Damped (and accelerated) Gauss-Newton trials at four damping values.
    Trials(Trying),
    /// Finished.
    Done,
}

/// Derivative probes under way: `jac` has the columns of the parts told so far; the Jacobian
/// is the final one when `last`.
pub(super) struct Differencing {
    pub(super) steps: Vec<f64>,
    pub(super) last: bool,
    pub(super) parts: Parts,
    pub(super) jac: DMatrix<f64>,
}

/// Curvature probes under way: `points` has the trials of the steps told so far.
pub(super) struct Curving {
    deltas: Vec<Vec<f64>>,
    pub(super) probes: Vec<Vec<f64>>,
    mus: [f64; 4],
    free: Vec<usize>,
    jtj: DMatrix<f64>,
    pub(super) parts: Parts,
    points: Vec<Vec<f64>>,
    predicted: f64,
}

/// Trials under way: `best` is the lowest cost of the trials told so far; `predicted` is the
/// largest drop of the cost the Jacobian's linear model predicts for the damped steps.
pub(super) struct Trying {
    pub(super) points: Vec<Vec<f64>>,
    mus: [f64; 4],
    pub(super) parts: Parts,
    best: Option<BestTrial>,
    predicted: f64,
}

/// The best trial so far.
struct BestTrial {
    index: usize,
    cost: f64,
    residuals: Vec<f64>,
}

/// Probe distance of the geodesic acceleration, as a fraction of the step.
const CURVATURE_H: f64 = 0.1;

impl<M: Measure> LmRun<M> {
    /// Derivative probes told: their Jacobian columns; once complete, the damped steps (or
    /// the end, after the final Jacobian).
    pub(super) fn differenced(
        &mut self,
        mut d: Differencing,
        out: Vec<Option<Vec<f64>>>,
    ) -> Result<Stage> {
        for (i, ri) in d.parts.range(self.part).zip(out) {
            let ri = ri.ok_or_else(|| {
                RunError::Search(SearchError::ProbeDiverged {
                    parameter: self.params.names[i].clone(),
                })
            })?;
            for (k, v) in ri.iter().enumerate() {
                d.jac[(k, i)] = (v - self.at.r[k]) / d.steps[i];
            }
        }
        if d.parts.advance(self.part) {
            return Ok(Stage::Jacobian(d));
        }
        self.at.jac = d.jac;
        Ok(if d.last {
            Stage::Done
        } else {
            self.plan_trials()
        })
    }

    /// Plans the next damped steps from the current Jacobian, or stops at a limit (the
    /// Jacobian is then current).
    fn plan_trials(&mut self) -> Stage {
        let n = self.params.len();
        let at = &mut self.at;
        if at.iterations >= self.settings.max_iterations {
            at.stop = ITERATION_LIMIT.into();
            return Stage::Done;
        }
        if at.evaluations + 8 + n as u64 > self.settings.budget {
            at.stop = "simulation budget".into();
            return Stage::Done;
        }
        if let Some(stall) = self.settings.stall {
            at.recent.push_back(at.cost);
            if at.recent.len() > stall.iterations + 1 {
                at.recent.pop_front();
            }
            let then = at.recent[0];
            if at.recent.len() == stall.iterations + 1 && then - at.cost < stall.rel_drop * then {
                at.stop = format!(
                    "stalled (the last {} iterations lowered the cost by less than {:.2e} of it)",
                    stall.iterations, stall.rel_drop
                );
                return Stage::Done;
            }
        }
        at.iterations += 1;
        let (x, params, mu) = (&at.x, &self.params, at.mu);
        let jtj = at.jac.tr_mul(&at.jac);
        let g = at.jac.tr_mul(&DVector::from_column_slice(&at.r));
        // Active set: a parameter on a bound whose descent direction points out of the box
        // stays there this iteration; the step is solved for the others.
        let free: Vec<usize> = (0..n)
            .filter(|&i| {
                let at_lo = x[i] <= params.lo[i] && g[i] > 0.0;
                let at_hi = x[i] >= params.hi[i] && g[i] < 0.0;
                !(at_lo || at_hi)
            })
            .collect();
        let mus = [mu / 100.0, mu / 10.0, mu, mu * 10.0];
        let minus_g: Vec<f64> = g.iter().map(|v| -v).collect();
        let deltas: Vec<Vec<f64>> = mus
            .iter()
            .map(|&m| solve_damped(&jtj, &free, m, &minus_g))
            .collect();
        // The linear model's drop for step d: -(2 g.d + d^T J^T J d).
        let predicted = deltas
            .iter()
            .map(|d| {
                let d = DVector::from_column_slice(d);
                -(2.0 * g.dot(&d) + d.dot(&(&jtj * &d)))
            })
            .fold(0.0, f64::max);
        let probes: Vec<Vec<f64>> = deltas
            .iter()
            .map(|d| (0..n).map(|i| x[i] + CURVATURE_H * d[i]).collect())
            .collect();
        Stage::Curvature(Curving {
            parts: Parts::new(deltas.len()),
            deltas,
            probes,
            mus,
            free,
            jtj,
            points: Vec::with_capacity(4),
            predicted,
        })
    }

    /// Curvature probes told: each step's accelerated trial; once complete, the trials.
    pub(super) fn curved(&mut self, mut c: Curving, out: Vec<Option<Vec<f64>>>) -> Stage {
        for (k, rh) in c.parts.range(self.part).zip(out) {
            let trial = self.accelerated(&c.deltas[k], rh.as_deref(), c.mus[k], &c.free, &c.jtj);
            c.points.push(trial);
        }
        if c.parts.advance(self.part) {
            return Stage::Curvature(c);
        }
        Stage::Trials(Trying {
            parts: Parts::new(c.points.len()),
            points: c.points,
            mus: c.mus,
            best: None,
            predicted: c.predicted,
        })
    }

    /// Geodesic acceleration (M. K. Transtrum and J. P. Sethna, "Improvements to the
    /// Levenberg-Marquardt algorithm for nonlinear least-squares minimization", 2012): the
    /// second directional derivative of the residuals along each step, from one probe at
    /// h = 0.1 of the step, gives a curvature correction a; the trial is x + delta + a / 2 when
    /// 2 |a| <= 0.75 |delta| (range-scaled norms), else x + delta.
    ///
    /// The trial of one step `delta` (damping `mu`) from its probe's residuals `rh` (`None`:
    /// the probe was not evaluated, and the trial is the plain step); `jtj` is J^T J.
    fn accelerated(
        &self,
        delta: &[f64],
        rh: Option<&[f64]>,
        mu: f64,
        free: &[usize],
        jtj: &DMatrix<f64>,
    ) -> Vec<f64> {
        let n = self.params.len();
        let scaled = |v: &[f64]| -> f64 {
            (0..n)
                .map(|i| (v[i] / self.params.range(i)).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let (x, r, jac) = (&self.at.x, &self.at.r, &self.at.jac);
        let mut step = delta.to_vec();
        if let Some(rh) = rh {
            // Made as a vector of its own at once (a long record's residual vectors are
            // 96 MB each at 2 million samples: no second copy of it).
            let rpp = {
                let jd = jac * DVector::from_column_slice(delta);
                DVector::from_iterator(
                    rh.len(),
                    (0..rh.len())
                        .map(|j| 2.0 / CURVATURE_H * ((rh[j] - r[j]) / CURVATURE_H - jd[j])),
                )
            };
            let rhs: Vec<f64> = jac.tr_mul(&rpp).iter().map(|v| -v).collect();
            let acc = solve_damped(jtj, free, mu, &rhs);
            if 2.0 * scaled(&acc) <= 0.75 * scaled(delta) {
                for i in 0..n {
                    step[i] += 0.5 * acc[i];
                }
            }
        }
        self.params
            .clamp(&(0..n).map(|i| x[i] + step[i]).collect::<Vec<_>>())
    }

    /// Trials told: the best so far kept; once complete, the best trial accepted when it
    /// lowers the cost (then the next Jacobian), else the Jacobian made again by backward
    /// differences when the forward one predicted a drop above the tolerance (a probe that
    /// crossed a jump, module documentation), else a larger damping.
    pub(super) fn tried(&mut self, mut t: Trying, out: Vec<Option<Vec<f64>>>) -> Stage {
        for (k, rk) in t.parts.range(self.part).zip(out) {
            if let Some(rk) = rk {
                let ck: f64 = rk.iter().map(|v| v * v).sum();
                if t.best.as_ref().is_none_or(|b| ck < b.cost) {
                    t.best = Some(BestTrial {
                        index: k,
                        cost: ck,
                        residuals: rk,
                    });
                }
            }
        }
        if t.parts.advance(self.part) {
            return Stage::Trials(t);
        }
        let suspect = t.predicted > self.settings.rel_tolerance * self.at.cost;
        match t.best {
            Some(b) if b.cost < self.at.cost => self.accept(b, &t.points, &t.mus),
            _ if suspect && !self.at.backward => {
                self.at.backward = true;
                self.begin_jacobian(false)
            }
            _ => {
                self.at.mu *= 100.0;
                if self.at.mu > 1e12 {
                    self.at.stop = "converged (no further decrease)".into();
                    Stage::Done
                } else {
                    self.plan_trials()
                }
            }
        }
    }

    /// Moves to the best trial; the next Jacobian follows (the final one once three accepted
    /// steps in a row gained less than the tolerance).
    fn accept(&mut self, b: BestTrial, points: &[Vec<f64>], mus: &[f64; 4]) -> Stage {
        let at = &mut self.at;
        let gain = (at.cost - b.cost) / at.cost;
        at.x = points[b.index].clone();
        at.cost = b.cost;
        at.r = b.residuals;
        at.mu = mus[b.index].max(1e-12);
        at.backward = false;
        self.record();
        let at = &mut self.at;
        at.small_gains = if gain < self.settings.rel_tolerance {
            at.small_gains + 1
        } else {
            0
        };
        if at.small_gains >= 3 {
            at.stop = "converged (relative decrease below tolerance)".into();
            self.begin_jacobian(true)
        } else {
            self.begin_jacobian(false)
        }
    }
}
