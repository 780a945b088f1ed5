//! Refinement to the noise floor: a bounded Levenberg-Marquardt fit of the continuous
//! parameters (the 17 factors and any effect parameters) on the residual vector, every sample's
//! position and attitude error divided by its noise sigma.
//!
//! Sources: K. Levenberg (1944) and D. W. Marquardt (1963) with Marquardt's diagonal scaling
//! (J^T J + mu diag(J^T J)) delta = -J^T r; bounds by projection onto the box after each step
//! (as in bounded variants such as Kanzow, Yamashita and Fukushima, 2004). The Jacobian is a
//! forward difference, one batch of simulations per iteration through the [`Evaluator`]; each
//! iteration also tries three damping values in one batch (mu/10, mu, 10 mu) and keeps the
//! best, so the workers stay busy.

use anyhow::{Context, Result, bail};
use nalgebra::{DMatrix, DVector};
use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{Candidate, Evaluation, Evaluator, Job};
use sepval_common::factors::{FACTOR_COUNT, Factor, FactorTable, Factors};
use sepval_common::goals::{Goals, residual};
use sepval_common::propagator::Observation;

/// The continuous parameters of a fit: the 17 factors, then the effects' parameters.
#[derive(Debug, Clone)]
pub struct ParamSpace {
    /// Names (factor names; `effect.param` for effect parameters).
    pub names: Vec<String>,
    /// Units ("-" for factors).
    pub units: Vec<String>,
    /// Lower bounds.
    pub lo: Vec<f64>,
    /// Upper bounds.
    pub hi: Vec<f64>,
    /// Grid step of the GA's binary encoding (factors only).
    pub grid_step: Vec<Option<f64>>,
    /// The model variant (its values are replaced by the parameter vector).
    pub effects: EffectSet,
}

impl ParamSpace {
    /// The space of the factor table and the effects of `effects`.
    pub fn new(table: &FactorTable, effects: &EffectSet) -> Self {
        let mut s = ParamSpace {
            names: Factor::NAMES.iter().map(|n| n.to_string()).collect(),
            units: vec!["-".to_string(); FACTOR_COUNT],
            lo: table.0.iter().map(|f| f.min).collect(),
            hi: table.0.iter().map(|f| f.max).collect(),
            grid_step: table.0.iter().map(|f| Some(f.step())).collect(),
            effects: *effects,
        };
        for a in effects.iter() {
            for p in a.effect().params() {
                s.names.push(format!("{}.{}", a.effect().id(), p.name));
                s.units.push(p.unit.to_string());
                s.lo.push(p.min);
                s.hi.push(p.max);
                s.grid_step.push(None);
            }
        }
        s
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Whether there are no parameters.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Width of parameter `i`'s range.
    pub fn range(&self, i: usize) -> f64 {
        self.hi[i] - self.lo[i]
    }

    /// The parameter vector of factors and the effect set's current values.
    pub fn vector(&self, factors: &Factors, effects: &EffectSet) -> Vec<f64> {
        let mut x = factors.0.to_vec();
        x.extend(effects.values());
        x
    }

    /// Projects `x` onto the bounds.
    pub fn clamp(&self, x: &[f64]) -> Vec<f64> {
        x.iter()
            .enumerate()
            .map(|(i, v)| v.clamp(self.lo[i], self.hi[i]))
            .collect()
    }

    /// The candidate of parameter vector `x`.
    pub fn candidate(&self, x: &[f64]) -> Result<Candidate> {
        let mut f = [0.0; FACTOR_COUNT];
        f.copy_from_slice(&x[..FACTOR_COUNT]);
        Ok(Candidate {
            factors: Factors(f),
            effects: self.effects.with_values(&x[FACTOR_COUNT..])?,
        })
    }
}

/// Noise levels normalising the residuals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    /// Position [m].
    pub pos_m: f64,
    /// Attitude [deg].
    pub att_deg: f64,
}

/// The normalised residual vector of simulated samples against the job's data: per event, per
/// sample, (dx, dy, dz) / sigma_pos and (droll, dpitch, dyaw) / sigma_att.
pub fn residual_vector(job: &Job, samples: &[Vec<Observation>], noise: Noise) -> Vec<f64> {
    let mut r = Vec::with_capacity(6 * job.sample_count());
    for (e, sim) in job.events().iter().zip(samples) {
        for (k, o) in sim.iter().enumerate() {
            let (p, a) = residual(o, &e.data.pos_m[k], &e.data.att_deg[k]);
            r.extend(p.iter().map(|v| v / noise.pos_m));
            r.extend(a.iter().map(|v| v / noise.att_deg));
        }
    }
    r
}

/// The goals of a normalised residual vector.
pub fn goals_of(r: &[f64], noise: Noise) -> Goals {
    let (mut p, mut a, mut n) = (0.0, 0.0, 0usize);
    for s in r.chunks_exact(6) {
        p += s[..3].iter().map(|v| v * v).sum::<f64>();
        a += s[3..].iter().map(|v| v * v).sum::<f64>();
        n += 1;
    }
    let n3 = 3.0 * n.max(1) as f64;
    Goals {
        j_pos_m: noise.pos_m * (p / n3).sqrt(),
        j_att_deg: noise.att_deg * (a / n3).sqrt(),
    }
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

/// Runs parameter vectors and returns their samples (`None` for a run that did not finish).
fn run(
    evaluator: &mut dyn Evaluator,
    space: &ParamSpace,
    xs: &[Vec<f64>],
    evaluations: &mut u64,
) -> Result<Vec<Option<Vec<Vec<Observation>>>>> {
    let batch: Vec<Candidate> = xs
        .iter()
        .map(|x| space.candidate(x))
        .collect::<Result<_>>()?;
    *evaluations += batch.len() as u64;
    Ok(evaluator
        .evaluate(&batch, true)?
        .into_iter()
        .map(|e: Evaluation| e.samples)
        .collect())
}

/// The forward-difference Jacobian of the normalised residuals at `x` (residuals `r`): one
/// batch, each step `fd_step` of the parameter's range, taken inward at the upper bound.
#[allow(clippy::too_many_arguments)]
fn jacobian(
    evaluator: &mut dyn Evaluator,
    space: &ParamSpace,
    job: &Job,
    x: &[f64],
    r: &[f64],
    noise: Noise,
    fd_step: f64,
    evaluations: &mut u64,
) -> Result<DMatrix<f64>> {
    let n = space.len();
    let steps: Vec<f64> = (0..n)
        .map(|i| {
            let h = fd_step * space.range(i);
            if x[i] + h <= space.hi[i] { h } else { -h }
        })
        .collect();
    let probes: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            let mut p = x.to_vec();
            p[i] += steps[i];
            p
        })
        .collect();
    let mut jac = DMatrix::zeros(r.len(), n);
    for (i, s) in run(evaluator, space, &probes, evaluations)?
        .into_iter()
        .enumerate()
    {
        let s = s.with_context(|| {
            format!(
                "the derivative probe of {} did not simulate",
                space.names[i]
            )
        })?;
        let ri = residual_vector(job, &s, noise);
        for (k, v) in ri.iter().enumerate() {
            jac[(k, i)] = (v - r[k]) / steps[i];
        }
    }
    Ok(jac)
}

/// Refines `x0` (projected onto the bounds).
pub fn levenberg_marquardt(
    evaluator: &mut dyn Evaluator,
    space: &ParamSpace,
    x0: &[f64],
    noise: Noise,
    settings: &LmSettings,
    observe: &mut dyn FnMut(u64, &Goals),
) -> Result<LmResult> {
    let n = space.len();
    let mut evaluations = 0u64;
    let mut x = space.clamp(x0);
    let first = run(evaluator, space, std::slice::from_ref(&x), &mut evaluations)?.remove(0);
    let Some(mut samples) = first else {
        bail!("the refinement's start does not simulate (diverged or invalid)");
    };
    let job = evaluator.job().clone();
    let mut r = residual_vector(&job, &samples, noise);
    let mut cost: f64 = r.iter().map(|v| v * v).sum();
    let mut history = vec![(evaluations, goals_of(&r, noise))];
    observe(evaluations, &history[0].1);
    let mut mu = 1e-3;
    let mut iterations = 0;
    let mut jac = DMatrix::zeros(r.len(), n);
    let mut stale_jacobian = true;
    let stop = loop {
        if stale_jacobian {
            jac = jacobian(
                evaluator,
                space,
                &job,
                &x,
                &r,
                noise,
                settings.fd_step,
                &mut evaluations,
            )?;
            stale_jacobian = false;
        }
        if iterations >= settings.max_iterations {
            break "iteration limit".to_string();
        }
        if evaluations + 3 + n as u64 > settings.budget {
            break "simulation budget".to_string();
        }
        iterations += 1;
        let jtj = jac.tr_mul(&jac);
        let g = jac.tr_mul(&DVector::from_column_slice(&r));
        // Active set: a parameter on a bound whose descent direction points out of the box
        // stays there this iteration; the step is solved for the others.
        let free: Vec<usize> = (0..n)
            .filter(|&i| {
                let at_lo = x[i] <= space.lo[i] && g[i] > 0.0;
                let at_hi = x[i] >= space.hi[i] && g[i] < 0.0;
                !(at_lo || at_hi)
            })
            .collect();
        let nf = free.len();
        let mus = [mu / 10.0, mu, mu * 10.0];
        let trials: Vec<Vec<f64>> = mus
            .iter()
            .map(|&m| {
                let mut a = DMatrix::zeros(nf, nf);
                let mut b = DVector::zeros(nf);
                for (p, &i) in free.iter().enumerate() {
                    b[p] = -g[i];
                    for (q, &j) in free.iter().enumerate() {
                        a[(p, q)] = jtj[(i, j)];
                    }
                    a[(p, p)] += m * jtj[(i, i)].max(1e-12);
                }
                let delta = a
                    .clone()
                    .cholesky()
                    .map(|c| c.solve(&b))
                    .unwrap_or_else(|| {
                        a.svd(true, true)
                            .solve(&b, 1e-14)
                            .unwrap_or_else(|_| DVector::zeros(nf))
                    });
                let mut xt = x.clone();
                for (p, &i) in free.iter().enumerate() {
                    xt[i] += delta[p];
                }
                space.clamp(&xt)
            })
            .collect();
        let out = run(evaluator, space, &trials, &mut evaluations)?;
        // (trial index, cost, residuals, samples) of the best trial.
        type Trial = (usize, f64, Vec<f64>, Vec<Vec<Observation>>);
        let mut best: Option<Trial> = None;
        for (k, s) in out.into_iter().enumerate() {
            if let Some(s) = s {
                let rk = residual_vector(&job, &s, noise);
                let ck: f64 = rk.iter().map(|v| v * v).sum();
                if best.as_ref().is_none_or(|b| ck < b.1) {
                    best = Some((k, ck, rk, s));
                }
            }
        }
        match best {
            Some((k, ck, rk, s)) if ck < cost => {
                let gain = (cost - ck) / cost;
                x = trials[k].clone();
                cost = ck;
                r = rk;
                samples = s;
                mu = (mus[k] / 3.0).max(1e-12);
                stale_jacobian = true;
                history.push((evaluations, goals_of(&r, noise)));
                observe(evaluations, &history.last().expect("pushed").1);
                if gain < settings.rel_tolerance {
                    break "converged (relative decrease below tolerance)".to_string();
                }
            }
            _ => {
                mu *= 100.0;
                if mu > 1e12 {
                    break "converged (no further decrease)".to_string();
                }
            }
        }
    };
    // The Jacobian at the final point (for identifiability), if the last step moved.
    if stale_jacobian {
        jac = jacobian(
            evaluator,
            space,
            &job,
            &x,
            &r,
            noise,
            settings.fd_step,
            &mut evaluations,
        )?;
    }
    Ok(LmResult {
        goals: goals_of(&r, noise),
        x,
        cost,
        evaluations,
        iterations,
        residuals: r,
        jacobian: jac,
        samples,
        history,
        stop,
    })
}
