//! Refinement to the noise floor: a bounded Levenberg-Marquardt fit of the continuous
//! parameters (the 17 factors and any effect parameters) on the residual vector, every sample's
//! position and attitude error divided by its noise sigma.
//!
//! Sources: K. Levenberg (1944) and D. W. Marquardt (1963) with Marquardt's diagonal scaling
//! (J^T J + mu diag(J^T J)) delta = -J^T r, converged after three consecutive accepted steps that
//! lower the cost by less than the tolerance; bounds by projection onto the box after each step
//! (as in bounded variants such as Kanzow, Yamashita and Fukushima, 2004). The Jacobian is a
//! forward difference, one batch of simulations per iteration through the [`Evaluator`]; each
//! iteration also tries four damping values in one batch (mu/100, mu/10, mu, 10 mu) and keeps
//! the best as the next mu, so the workers stay busy and the damping adapts in one iteration.
//! Each step carries Transtrum and Sethna's geodesic acceleration (one probe per step), which
//! follows the narrow curved valleys of strongly compensating parameters.

use nalgebra::{DMatrix, DVector};
use sepval_common::evaluation::{Candidate, Evaluation, Evaluator, Job};

use sepval_common::goals::Goals;
use sepval_common::propagator::Observation;

use crate::run::{Ask, Evaluate, Progress, RunError, Solver, run};

mod space;
pub use space::{FreeTerm, Noise, ParamSpace, goals_of, residual_vector};

type Result<T> = std::result::Result<T, RunError>;

fn search_error(what: impl std::fmt::Display) -> RunError {
    RunError::Search(what.to_string())
}

/// Settings of the refinement.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LmSettings {
    /// Most iterations.
    pub max_iterations: usize,
    /// Most simulations.
    pub budget: u64,
    /// Forward-difference step, as a fraction of each parameter's range.
    pub fd_step: f64,
    /// Stop when an accepted step lowers the cost by less than this fraction.
    pub rel_tolerance: f64,
}

impl Default for LmSettings {
    fn default() -> Self {
        LmSettings {
            max_iterations: 400,
            budget: 5_000,
            fd_step: 1e-6,
            rel_tolerance: 1e-7,
        }
    }
}

/// The result of a refinement.
#[derive(Debug, Clone)]
pub struct LmResult {
    /// The refined parameters.
    pub x: Vec<f64>,
    /// Their goals.
    pub goals: Goals,
    /// Chi-square: the sum of squared normalised residuals.
    pub cost: f64,
    /// Simulations run.
    pub evaluations: u64,
    /// Iterations done.
    pub iterations: usize,
    /// The normalised residuals at `x`.
    pub residuals: Vec<f64>,
    /// d(residual)/d(parameter) at `x` (rows: residuals; columns: parameters, physical units).
    pub jacobian: DMatrix<f64>,
    /// The simulated samples at `x`.
    pub samples: Vec<Vec<Observation>>,
    /// (simulations so far, goals) after each accepted step.
    pub history: Vec<(u64, Goals)>,
    /// Why it stopped.
    pub stop: String,
}

/// Forward-difference steps at `x`: `fd_step` of each range, inward at the upper bound.
fn fd_steps(space: &ParamSpace, x: &[f64], fd_step: f64) -> Vec<f64> {
    (0..space.len())
        .map(|i| {
            let h = fd_step * space.range(i);
            if x[i] + h <= space.hi[i] { h } else { -h }
        })
        .collect()
}

/// Probe distance of the geodesic acceleration, as a fraction of the step.
const CURVATURE_H: f64 = 0.1;

/// Solves (J^T J + mu diag(J^T J)) d = rhs for the free parameters (zero for the others).
fn solve_damped(jtj: &DMatrix<f64>, free: &[usize], mu: f64, rhs: &[f64]) -> Vec<f64> {
    let nf = free.len();
    let mut a = DMatrix::zeros(nf, nf);
    let mut b = DVector::zeros(nf);
    for (p, &i) in free.iter().enumerate() {
        b[p] = rhs[i];
        for (q, &j) in free.iter().enumerate() {
            a[(p, q)] = jtj[(i, j)];
        }
        a[(p, p)] += mu * jtj[(i, i)].max(1e-12);
    }
    let d = solve_bounded(a, b);
    let mut full = vec![0.0; jtj.nrows()];
    for (p, &i) in free.iter().enumerate() {
        full[i] = d[p];
    }
    full
}

/// Most sweeps of the singular value decomposition that backs up a failed Cholesky factorisation
/// (it converges in a few dozen on any finite matrix; this bound stops it on a pathological one
/// instead of spinning for ever).
const MAX_SVD_ITERATIONS: usize = 1000;

/// Solves `a d = b` (`a` symmetric): Cholesky, else a bounded SVD pseudo-inverse, else (a
/// non-finite or pathological system) no step at all.
fn solve_bounded(a: DMatrix<f64>, b: DVector<f64>) -> DVector<f64> {
    let n = b.len();
    if !(a.iter().all(|v| v.is_finite()) && b.iter().all(|v| v.is_finite())) {
        return DVector::zeros(n);
    }
    if let Some(c) = a.clone().cholesky() {
        return c.solve(&b);
    }
    nalgebra::SVD::try_new(a, true, true, f64::EPSILON, MAX_SVD_ITERATIONS)
        .and_then(|svd| svd.solve(&b, 1e-14).ok())
        .filter(|d| d.iter().all(|v| v.is_finite()))
        .unwrap_or_else(|| DVector::zeros(n))
}

/// What a refinement waits for.
enum Stage {
    /// The start point.
    Start,
    /// Derivative probes (then the final Jacobian is complete when `last`): `jac` has the
    /// columns before `next`.
    Jacobian {
        steps: Vec<f64>,
        last: bool,
        next: usize,
        jac: DMatrix<f64>,
    },
    /// Probes along each damped step for its curvature: `points` has the trials of the steps
    /// before `next`.
    Curvature {
        deltas: Vec<Vec<f64>>,
        probes: Vec<Vec<f64>>,
        mus: [f64; 4],
        free: Vec<usize>,
        jtj: DMatrix<f64>,
        next: usize,
        points: Vec<Vec<f64>>,
    },
    /// Damped (and accelerated) Gauss-Newton trials at four damping values: `best` is the
    /// lowest cost of the trials before `next` (index, cost, residuals, samples).
    Trials {
        points: Vec<Vec<f64>>,
        mus: [f64; 4],
        next: usize,
        best: Option<Best>,
    },
    /// Finished.
    Done,
}

/// The best trial so far: its index, cost, residuals and samples.
type Best = (usize, f64, Vec<f64>, Vec<Vec<Observation>>);

/// One refinement as a sequence of batches: [`LmRun::request`] gives the next parameter
/// vectors to simulate, [`LmRun::absorb`] takes their samples. Several refinements can so share
/// each batch sent to the workers ([`refine_together`]).
pub struct LmRun {
    space: ParamSpace,
    job: std::sync::Arc<Job>,
    noise: Noise,
    settings: LmSettings,
    x: Vec<f64>,
    r: Vec<f64>,
    cost: f64,
    samples: Vec<Vec<Observation>>,
    jac: DMatrix<f64>,
    mu: f64,
    iterations: usize,
    evaluations: u64,
    history: Vec<(u64, Goals)>,
    stage: Stage,
    stop: String,
    /// Consecutive accepted steps that lowered the cost by less than the tolerance.
    small_gains: usize,
    /// Most points asked at once: a stage's points go in parts within
    /// [`crate::run::SAMPLE_BUDGET`] samples, each part's trajectories reduced and dropped
    /// before the next part is asked (a long record's are 96 MB each at 2 million samples).
    part: usize,
}

impl LmRun {
    /// A refinement of `x0` (projected onto the bounds) in `space`.
    pub fn new(
        space: ParamSpace,
        job: std::sync::Arc<Job>,
        x0: &[f64],
        noise: Noise,
        settings: LmSettings,
    ) -> Self {
        let x = space.clamp(x0);
        let part = (crate::run::SAMPLE_BUDGET / job.sample_count().max(1)).max(1);
        LmRun {
            space,
            job,
            noise,
            settings,
            x,
            r: Vec::new(),
            cost: f64::INFINITY,
            samples: Vec::new(),
            jac: DMatrix::zeros(0, 0),
            mu: 1e-3,
            iterations: 0,
            evaluations: 0,
            history: Vec::new(),
            stage: Stage::Start,
            stop: String::new(),
            small_gains: 0,
            part,
        }
    }

    /// The parameter space.
    pub fn space(&self) -> &ParamSpace {
        &self.space
    }

    /// The candidates to simulate next (with samples), or `None` when finished.
    pub fn request(&self) -> Result<Option<Vec<Candidate>>> {
        let points: Vec<Vec<f64>> = match &self.stage {
            Stage::Start => vec![self.x.clone()],
            Stage::Jacobian { steps, next, .. } => (*next..self.part_end(*next, self.space.len()))
                .map(|i| {
                    let mut p = self.x.clone();
                    p[i] += steps[i];
                    p
                })
                .collect(),
            Stage::Curvature { probes, next, .. } => {
                probes[*next..self.part_end(*next, probes.len())].to_vec()
            }
            Stage::Trials { points, next, .. } => {
                points[*next..self.part_end(*next, points.len())].to_vec()
            }
            Stage::Done => return Ok(None),
        };
        Ok(Some(
            points
                .iter()
                .map(|x| self.space.candidate(x))
                .collect::<Result<_>>()?,
        ))
    }

    /// The end of the part that starts at `next` of `len` points.
    fn part_end(&self, next: usize, len: usize) -> usize {
        next.saturating_add(self.part).min(len)
    }

    /// Takes the samples of the last request (`None` for runs that did not finish).
    pub fn absorb(&mut self, out: Vec<Option<Vec<Vec<Observation>>>>) -> Result<()> {
        self.evaluations += out.len() as u64;
        match std::mem::replace(&mut self.stage, Stage::Done) {
            Stage::Start => {
                let s = out.into_iter().next().flatten().ok_or_else(|| {
                    search_error("the refinement's start does not simulate (diverged or invalid)")
                })?;
                self.r = residual_vector(&self.job, &s, self.noise);
                self.cost = self.r.iter().map(|v| v * v).sum();
                self.samples = s;
                self.history
                    .push((self.evaluations, goals_of(&self.r, self.noise)));
                self.begin_jacobian(false);
            }
            Stage::Jacobian {
                steps,
                last,
                next,
                mut jac,
            } => {
                for (i, s) in (next..).zip(out) {
                    let s = s.ok_or_else(|| {
                        search_error(format!(
                            "the derivative probe of {} did not simulate",
                            self.space.names[i]
                        ))
                    })?;
                    let ri = residual_vector(&self.job, &s, self.noise);
                    for (k, v) in ri.iter().enumerate() {
                        jac[(k, i)] = (v - self.r[k]) / steps[i];
                    }
                }
                let next = self.part_end(next, self.space.len());
                if next < self.space.len() {
                    self.stage = Stage::Jacobian {
                        steps,
                        last,
                        next,
                        jac,
                    };
                    return Ok(());
                }
                self.jac = jac;
                if !last {
                    self.plan_trials();
                }
            }
            Stage::Curvature {
                deltas,
                probes,
                mus,
                free,
                jtj,
                next,
                mut points,
            } => {
                for (k, s) in (next..).zip(out) {
                    points.push(self.accelerated(&deltas[k], s.as_deref(), mus[k], &free, &jtj));
                }
                let next = self.part_end(next, deltas.len());
                self.stage = if next < deltas.len() {
                    Stage::Curvature {
                        deltas,
                        probes,
                        mus,
                        free,
                        jtj,
                        next,
                        points,
                    }
                } else {
                    Stage::Trials {
                        points,
                        mus,
                        next: 0,
                        best: None,
                    }
                };
            }
            Stage::Trials {
                points,
                mus,
                next,
                mut best,
            } => {
                for (k, s) in (next..).zip(out) {
                    if let Some(s) = s {
                        let rk = residual_vector(&self.job, &s, self.noise);
                        let ck: f64 = rk.iter().map(|v| v * v).sum();
                        if best.as_ref().is_none_or(|b| ck < b.1) {
                            best = Some((k, ck, rk, s));
                        }
                    }
                }
                let next = self.part_end(next, points.len());
                if next < points.len() {
                    self.stage = Stage::Trials {
                        points,
                        mus,
                        next,
                        best,
                    };
                    return Ok(());
                }
                match best {
                    Some((k, ck, rk, sk)) if ck < self.cost => {
                        let gain = (self.cost - ck) / self.cost;
                        self.x = points[k].clone();
                        self.cost = ck;
                        self.r = rk;
                        self.samples = sk;
                        self.mu = mus[k].max(1e-12);
                        self.history
                            .push((self.evaluations, goals_of(&self.r, self.noise)));
                        self.small_gains = if gain < self.settings.rel_tolerance {
                            self.small_gains + 1
                        } else {
                            0
                        };
                        if self.small_gains >= 3 {
                            self.stop = "converged (relative decrease below tolerance)".into();
                            self.begin_jacobian(true);
                        } else {
                            self.begin_jacobian(false);
                        }
                    }
                    _ => {
                        self.mu *= 100.0;
                        if self.mu > 1e12 {
                            self.stop = "converged (no further decrease)".into();
                        } else {
                            self.plan_trials();
                        }
                    }
                }
            }
            Stage::Done => return Err(search_error("a finished refinement received samples")),
        }
        Ok(())
    }

    fn begin_jacobian(&mut self, last: bool) {
        // The previous Jacobian is not used again: it goes before the new one is made (6 x
        // samples x parameters doubles each, 1.6 GB at 2 million samples and 17 parameters).
        self.jac = DMatrix::zeros(0, 0);
        self.stage = Stage::Jacobian {
            steps: fd_steps(&self.space, &self.x, self.settings.fd_step),
            last,
            next: 0,
            jac: DMatrix::zeros(self.r.len(), self.space.len()),
        };
    }

    /// Plans the next damped steps from the current Jacobian, or stops at a limit (the
    /// Jacobian is then current).
    fn plan_trials(&mut self) {
        let n = self.space.len();
        if self.iterations >= self.settings.max_iterations {
            self.stop = "iteration limit".into();
            return;
        }
        if self.evaluations + 8 + n as u64 > self.settings.budget {
            self.stop = "simulation budget".into();
            return;
        }
        self.iterations += 1;
        let (x, space, mu) = (&self.x, &self.space, self.mu);
        let jtj = self.jac.tr_mul(&self.jac);
        let g = self.jac.tr_mul(&DVector::from_column_slice(&self.r));
        // Active set: a parameter on a bound whose descent direction points out of the box
        // stays there this iteration; the step is solved for the others.
        let free: Vec<usize> = (0..n)
            .filter(|&i| {
                let at_lo = x[i] <= space.lo[i] && g[i] > 0.0;
                let at_hi = x[i] >= space.hi[i] && g[i] < 0.0;
                !(at_lo || at_hi)
            })
            .collect();
        let mus = [mu / 100.0, mu / 10.0, mu, mu * 10.0];
        let minus_g: Vec<f64> = g.iter().map(|v| -v).collect();
        let deltas: Vec<Vec<f64>> = mus
            .iter()
            .map(|&m| solve_damped(&jtj, &free, m, &minus_g))
            .collect();
        let probes: Vec<Vec<f64>> = deltas
            .iter()
            .map(|d| (0..n).map(|i| x[i] + CURVATURE_H * d[i]).collect())
            .collect();
        self.stage = Stage::Curvature {
            deltas,
            probes,
            mus,
            free,
            jtj,
            next: 0,
            points: Vec::with_capacity(4),
        };
    }

    /// Geodesic acceleration (M. K. Transtrum and J. P. Sethna, "Improvements to the
    /// Levenberg-Marquardt algorithm for nonlinear least-squares minimization", 2012): the
    /// second directional derivative of the residuals along each step, from one probe at
    /// h = 0.1 of the step, gives a curvature correction a; the trial is x + delta + a / 2 when
    /// 2 |a| <= 0.75 |delta| (range-scaled norms), else x + delta.
    ///
    /// The trial of one step `delta` (damping `mu`) from its probe's samples (`None`: the
    /// probe did not finish, and the trial is the plain step); `jtj` is J^T J.
    fn accelerated(
        &self,
        delta: &[f64],
        probe: Option<&[Vec<Observation>]>,
        mu: f64,
        free: &[usize],
        jtj: &DMatrix<f64>,
    ) -> Vec<f64> {
        let n = self.space.len();
        let scaled = |v: &[f64]| -> f64 {
            (0..n)
                .map(|i| (v[i] / self.space.range(i)).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let mut step = delta.to_vec();
        if let Some(s) = probe {
            // Made as a vector of its own at once (a long record's residual vectors are
            // 96 MB each at 2 million samples: no second copy of it).
            let rpp = {
                let rh = residual_vector(&self.job, s, self.noise);
                let jd = &self.jac * DVector::from_column_slice(delta);
                DVector::from_iterator(
                    rh.len(),
                    (0..rh.len())
                        .map(|j| 2.0 / CURVATURE_H * ((rh[j] - self.r[j]) / CURVATURE_H - jd[j])),
                )
            };
            let rhs: Vec<f64> = self.jac.tr_mul(&rpp).iter().map(|v| -v).collect();
            let acc = solve_damped(jtj, free, mu, &rhs);
            if 2.0 * scaled(&acc) <= 0.75 * scaled(delta) {
                for i in 0..n {
                    step[i] += 0.5 * acc[i];
                }
            }
        }
        self.space
            .clamp(&(0..n).map(|i| self.x[i] + step[i]).collect::<Vec<_>>())
    }

    /// The result (after [`LmRun::request`] returned `None`).
    pub fn finish(self) -> LmResult {
        LmResult {
            goals: goals_of(&self.r, self.noise),
            x: self.x,
            cost: self.cost,
            evaluations: self.evaluations,
            iterations: self.iterations,
            residuals: self.r,
            jacobian: self.jac,
            samples: self.samples,
            history: self.history,
            stop: self.stop,
        }
    }
}

impl Solver for LmRun {
    type Point = Candidate;

    fn ask(&mut self) -> Result<Option<Ask<Candidate>>> {
        Ok(self.request()?.map(|points| Ask {
            points,
            with_samples: true,
        }))
    }

    fn tell(&mut self, evaluations: Vec<Evaluation>) -> Result<Option<Progress>> {
        let accepted = self.history.len();
        self.absorb(evaluations.into_iter().map(|e| e.samples).collect())?;
        Ok((self.history.len() > accepted).then(|| Progress {
            step: self.iterations,
            steps: Some(self.settings.max_iterations),
            evaluations: self.evaluations,
            best: goals_of(&self.r, self.noise).as_array(),
        }))
    }
}

/// Several refinements driven together: each ask joins the requests of every unfinished run
/// into one batch, so that the workers stay busy.
pub struct Together<'a> {
    runs: &'a mut [LmRun],
    owners: Vec<(usize, usize)>,
}

impl Solver for Together<'_> {
    type Point = Candidate;

    fn ask(&mut self) -> Result<Option<Ask<Candidate>>> {
        let mut points = Vec::new();
        self.owners.clear();
        for (k, run) in self.runs.iter().enumerate() {
            if let Some(c) = run.request()? {
                self.owners.push((k, c.len()));
                points.extend(c);
            }
        }
        Ok((!points.is_empty()).then_some(Ask {
            points,
            with_samples: true,
        }))
    }

    fn tell(&mut self, evaluations: Vec<Evaluation>) -> Result<Option<Progress>> {
        let mut out = evaluations.into_iter();
        for &(k, len) in &self.owners {
            let part: Vec<Option<Vec<Vec<Observation>>>> =
                out.by_ref().take(len).map(|e| e.samples).collect();
            self.runs[k].absorb(part)?;
        }
        Ok(None)
    }
}

/// Drives several refinements together: each round, the requests of all unfinished runs go to
/// the evaluator as one batch.
pub fn refine_together(evaluator: &mut dyn Evaluator, runs: &mut [LmRun]) -> Result<()> {
    let mut together = Together {
        runs,
        owners: Vec::new(),
    };
    run(&mut together, &mut Evaluate(evaluator), &mut [])
}

/// Refines `x0` (projected onto the bounds).
pub fn levenberg_marquardt(
    evaluator: &mut dyn Evaluator,
    space: &ParamSpace,
    x0: &[f64],
    noise: Noise,
    settings: &LmSettings,
) -> Result<LmResult> {
    let job = std::sync::Arc::clone(evaluator.job());
    let mut lm = LmRun::new(space.clone(), job, x0, noise, settings.clone());
    run(&mut lm, &mut Evaluate(evaluator), &mut [])?;
    Ok(lm.finish())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pathological_systems_give_no_step_at_once() {
        let huge = DMatrix::from_element(3, 3, 1e308);
        let d = solve_bounded(huge.clone() * 10.0, DVector::from_element(3, 1.0));
        assert!(d.iter().all(|v| *v == 0.0), "{d}");
        let d = solve_bounded(
            DMatrix::from_element(3, 3, f64::NAN),
            DVector::from_element(3, 1.0),
        );
        assert!(d.iter().all(|v| *v == 0.0), "{d}");
        // Singular but finite: the pseudo-inverse.
        let singular = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
        let d = solve_bounded(singular, DVector::from_row_slice(&[2.0, 2.0]));
        assert!(
            (d[0] - 1.0).abs() < 1e-12 && (d[1] - 1.0).abs() < 1e-12,
            "{d}"
        );
        let d = solve_bounded(huge, DVector::from_element(3, 1e-300));
        assert!(d.iter().all(|v| v.is_finite()));
    }
}
