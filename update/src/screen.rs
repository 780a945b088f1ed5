//! Which coefficients need a correction, and over which variable: estimation before modelling
//! (docs/update.md section 15.3.1). The missing force and moment are reconstructed per release
//! as coefficient increments on time windows (section 11.6, `sepval_diagnose::
//! reconstruct_misfit`), whose linear model of the residuals is r0 + J a + W u (J the free
//! factors' sensitivities, W the windows'). A correction proposed for an axis
//! ([`crate::explored::proposals`]) is an increment history u = X v of its values v, X the
//! mean over each window's samples of each breakpoint's interpolation weight (times the
//! regressor of a derivative, times the interference multiplier and the sign of CX for an
//! increment), so its sensitivities are W X: the reconstruction's windows carried over to the
//! states the store went through. Each is scored by the chi-square it predicts for a release it
//! was not fitted to, the linearised form of the output-error cross-validation of section 15.5:
//!
//! ```text
//! min |r0 + J a + W X v|^2 + lambda sum_blocks s_b (|D2 v_b|^2 + RIDGE |v_b|^2)   on the rows kept
//! ```
//!
//! (D2 the second difference within a correction, s_b the mean of its columns' squared norms,
//! lambda among 10^-5, 10^-4.5, ..., 10^3), each release left out in turn (one release: each of
//! [`TIME_BLOCKS`] contiguous blocks of its rows), the chi-square of the rows left out summed,
//! at the best lambda, which the proposal keeps as its smoothness. The [`PICKS`] best go on to
//! the round's output-error refit when each lowers the current score by more than [`GAIN_MIN`]
//! and [`GAIN_FRACTION`] of it; an axis holds at most [`MAX_PER_AXIS`] corrections.

use nalgebra::{DMatrix, DVector};
use sepval_common::correction::{Derivative, Target, weights};
use sepval_common::evaluation::Job;
use sepval_common::extension::Axis;
use sepval_common::table::Variable;
use sepval_core::factors::Factors;
use sepval_diagnose::{Linear, Misfit, Sample};
use serde::{Deserialize, Serialize};

use crate::explored::{Explored, Proposal, proposals};
use crate::space::MULTIPLIERS;

/// The smallest drop of the cross-validated chi-square for which a correction is taken.
pub const GAIN_MIN: f64 = 10.0;
/// The smallest drop of the cross-validated chi-square for which a correction is taken, as a
/// fraction of the chi-square it starts from.
pub const GAIN_FRACTION: f64 = 0.02;
/// Contiguous blocks of rows of the cross-validation of a single release.
pub const TIME_BLOCKS: usize = 5;
/// Most corrections a round refits to choose among (the best of the screening).
pub const PICKS: usize = 3;
/// Most corrections per axis.
pub const MAX_PER_AXIS: usize = 2;

const AXES: [&str; 6] = ["CA", "CY", "CZ", "Cl", "Cm", "Cn"];
const WINDOW_AXES: [Axis; 6] = [Axis::CA, Axis::CY, Axis::CZ, Axis::Cl, Axis::Cm, Axis::Cn];

/// One proposal's score.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scored {
    /// Its name, e.g. `Cm over alpha`.
    pub correction: String,
    /// The field it corrects.
    pub field: String,
    /// Its variable (`distance_m`, `alpha_deg`, `beta_deg`, `mach`).
    pub variable: String,
    /// The cross-validated chi-square with it (with the corrections taken before it on its
    /// axis).
    pub cv_chi2: f64,
    /// How much lower that is than without it.
    pub gain: f64,
}

/// The screening of one axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AxisScreen {
    /// `CA`, ..., `Cn`.
    pub axis: String,
    /// The cross-validated chi-square of the factors alone (linearised).
    pub null_chi2: f64,
    /// Every proposal's score for the first correction, best first.
    pub scored: Vec<Scored>,
    /// The corrections of this axis among those the round refits.
    pub taken: Vec<String>,
}

/// The correction a round takes.
#[derive(Debug, Clone)]
pub struct Pick {
    /// The correction.
    pub proposal: Proposal,
    /// The drop of the (linearised) cross-validated chi-square it makes.
    pub gain: f64,
    /// Its penalty weight, chosen by that cross-validation.
    pub lambda: f64,
    /// The penalty's scale: its values' mean information.
    pub scale: f64,
}

/// One round's screening of every axis, with the correction it takes.
#[derive(Debug, Clone)]
pub struct Screening {
    /// Per axis.
    pub axes: Vec<AxisScreen>,
    /// The best corrections whose gain passes (at most [`PICKS`]), best first.
    pub picks: Vec<Pick>,
    /// The cross-validated chi-square of the current model (linearised).
    pub null_chi2: f64,
    /// How the rows were cross-validated: `leave one release out` or `contiguous blocks of
    /// one release`.
    pub folds: String,
}

/// The linear problem of one screening: the residuals, the factors' columns, the folds.
struct Problem<'a> {
    linear: &'a Linear,
    history: &'a [Vec<Sample>],
    /// Per event, its flight Mach.
    machs: Vec<f64>,
    /// The fitted interference multipliers.
    multipliers: [f64; 6],
    /// Per row, its fold.
    fold: Vec<usize>,
    folds: usize,
}

impl Problem<'_> {
    /// The sensitivity columns of proposal `p` on axis `axis`: per event, the windows' columns
    /// of its rows times the proposal's design on that event's windows.
    fn columns(&self, axis: usize, p: &Proposal) -> DMatrix<f64> {
        let l = self.linear;
        let windows: Vec<usize> = (0..l.terms.len())
            .filter(|&k| l.terms[k].axis == WINDOW_AXES[axis])
            .collect();
        let mut out = DMatrix::zeros(l.r0.len(), p.free_values());
        for (e, &(a, b)) in l.event_rows.iter().enumerate() {
            let mut x = DMatrix::zeros(windows.len(), p.free_values());
            for (w, &k) in windows.iter().enumerate() {
                let [t0, t1] = l.terms[k].locator;
                let inside: Vec<&Sample> = self.history[e]
                    .iter()
                    .filter(|s| s.input.t_s >= t0 && s.input.t_s < t1)
                    .collect();
                for s in &inside {
                    let r = regressors(p, s, self.machs[e], self.multipliers[axis]);
                    for (j, v) in r.into_iter().enumerate() {
                        x[(w, j)] += v / inside.len() as f64;
                    }
                }
            }
            let block = l
                .windows
                .view((a, 0), (b - a, l.windows.ncols()))
                .select_columns(&windows)
                * x;
            out.view_mut((a, 0), (b - a, p.free_values()))
                .copy_from(&block);
        }
        out
    }

    /// The cross-validated chi-square of the factors and the columns `c` (one proposal, or
    /// none), at the best lambda among [`lambda_grid`]: (chi-square, lambda, the penalty's
    /// scale s).
    fn cross_validated(&self, c: &DMatrix<f64>, b: &[f64]) -> (f64, f64, f64) {
        let l = self.linear;
        let nf = l.fixed.ncols();
        let n = nf + c.ncols();
        let mut a = DMatrix::zeros(l.r0.len(), n);
        a.columns_mut(0, nf).copy_from(&l.fixed);
        a.columns_mut(nf, c.ncols()).copy_from(c);
        let info = a.tr_mul(&a);
        let (pen, s) = penalty(&info, nf, b);
        let scale = (0..n).map(|k| info[(k, k)]).fold(0.0, f64::max).max(1e-300);
        // Each fold's normal equations: the whole's less its own rows'.
        let r0 = &l.r0;
        let atr = a.tr_mul(r0);
        let folds: Vec<(DMatrix<f64>, DVector<f64>, Vec<usize>)> = (0..self.folds)
            .map(|f| {
                let test: Vec<usize> = (0..r0.len()).filter(|&i| self.fold[i] == f).collect();
                let af = a.select_rows(&test);
                let rf = DVector::from_iterator(test.len(), test.iter().map(|&i| r0[i]));
                (&info - af.tr_mul(&af), &atr - af.tr_mul(&rf), test)
            })
            .collect();
        let grid: Vec<f64> = if c.ncols() == 0 {
            vec![0.0]
        } else {
            lambda_grid().to_vec()
        };
        let mut best = (f64::INFINITY, f64::NAN, s);
        for lambda in grid {
            let mut total = 0.0;
            for (ata, atr, test) in &folds {
                let mut sys = ata + &pen * lambda;
                for d in 0..n {
                    sys[(d, d)] += 1e-10 * scale;
                }
                let Some(chol) = sys.cholesky() else {
                    total = f64::INFINITY;
                    break;
                };
                let beta = -chol.solve(atr);
                for &i in test {
                    let e = r0[i] + (a.row(i) * &beta)[(0, 0)];
                    total += e * e;
                }
            }
            if total < best.0 {
                best = (total, lambda, s);
            }
        }
        best
    }
}

/// The penalty weights tried: 10^-5, 10^-4.5, ..., 10^3.
pub fn lambda_grid() -> [f64; 17] {
    std::array::from_fn(|k| 10f64.powf(-5.0 + 0.5 * k as f64))
}

/// The smoothness penalty of the last columns of `info`, those of a correction's free
/// breakpoints `b` (second differences and a ridge, `crate::space::penalty_root`, times s,
/// their mean information in `info`), and s.
fn penalty(info: &DMatrix<f64>, nf: usize, b: &[f64]) -> (DMatrix<f64>, f64) {
    let len = b.len();
    let n = nf + len;
    let mut p = DMatrix::zeros(n, n);
    let s = (nf..n).map(|c| info[(c, c)]).sum::<f64>() / len.max(1) as f64;
    let s = if s > 0.0 { s } else { 1.0 };
    let root = crate::space::penalty_root(b);
    let block = root.tr_mul(&root) * s;
    p.view_mut((nf, nf), (len, len)).copy_from(&block);
    (p, s)
}

/// What a proposal's value at each free breakpoint contributes to its axis's increment at one
/// sample (CA positive aft), of an event at flight Mach `mach` whose fitted interference
/// multiplier on the axis is `multiplier`.
fn regressors(p: &Proposal, s: &Sample, mach: f64, multiplier: f64) -> Vec<f64> {
    let i = &s.input;
    let (x, scale) = match (p.target, p.variable) {
        (Target::Interference(k), _) => {
            (i.distance_m, if k == 0 { -multiplier } else { multiplier })
        }
        (Target::Static(_), Variable::Alpha) => (i.alpha_rad.to_degrees(), 1.0),
        (Target::Static(_), Variable::Beta) => (i.beta_rad.to_degrees(), 1.0),
        (Target::Derivative(d), _) => (
            mach,
            match d {
                Derivative::CzAlpha | Derivative::CmAlpha => i.alpha_rad,
                Derivative::CyBeta | Derivative::CnBeta => i.beta_rad,
                Derivative::ClP => i.rates_hat[0],
                Derivative::CmQ => i.rates_hat[1],
                Derivative::CnR => i.rates_hat[2],
            },
        ),
        (Target::Static(_), _) => (mach, 1.0),
        // Not screened: the field is refitted on its own stage (section 15.3a).
        (Target::Field(_) | Target::ShapeTable, _) => (mach, 0.0),
    };
    weights(&p.breakpoints, x)
        .into_iter()
        .zip(&p.pinned)
        .filter(|(_, pinned)| !**pinned)
        .map(|(w, _)| w * scale)
        .collect()
}

/// The screening of one round about the current model (the factors and the corrections
/// `chosen`, whose columns are among the linear model's fixed ones): every correction the
/// explored ranges allow (at most [`MAX_PER_AXIS`] per axis, one per field and variable) scored
/// against the current model's, and the best one when its gain passes.
pub fn screen(
    job: &Job,
    misfit: &Misfit,
    factors: &Factors,
    explored: &Explored,
    chosen: &[Proposal],
) -> Screening {
    let l = &misfit.linear;
    let (fold, folds) = row_folds(l);
    let problem = Problem {
        linear: l,
        history: &misfit.history,
        machs: job
            .events()
            .iter()
            .map(|e| e.simulator.scenario().flight.mach)
            .collect(),
        multipliers: MULTIPLIERS.map(|f| factors.get(f)),
        fold,
        folds,
    };
    let (null_chi2, _, _) = problem.cross_validated(&DMatrix::zeros(l.r0.len(), 0), &[]);
    let per_axis = |a: usize| chosen.iter().filter(|p| p.target.axis() == a).count();
    let candidates: Vec<(usize, Proposal)> = (0..AXES.len())
        .filter(|&a| per_axis(a) < MAX_PER_AXIS)
        .flat_map(|a| proposals(a, explored).into_iter().map(move |p| (a, p)))
        .filter(|(_, p)| {
            !chosen
                .iter()
                .any(|q| q.target == p.target && q.variable == p.variable)
        })
        .collect();
    let mut scored: Vec<(usize, (f64, f64, f64))> = candidates
        .iter()
        .enumerate()
        .map(|(k, (a, p))| {
            let score = problem.cross_validated(&problem.columns(*a, p), &p.free_breakpoints());
            (k, score)
        })
        .collect();
    scored.sort_by(|a, b| a.1.0.total_cmp(&b.1.0));
    let mut axes: Vec<AxisScreen> = AXES
        .iter()
        .map(|name| AxisScreen {
            axis: name.to_string(),
            null_chi2,
            scored: Vec::new(),
            taken: Vec::new(),
        })
        .collect();
    for &(k, (cv, _, _)) in &scored {
        let (a, p) = &candidates[k];
        axes[*a].scored.push(Scored {
            correction: p.name(),
            field: p.target.field(),
            variable: p.variable.key().to_string(),
            cv_chi2: cv,
            gain: null_chi2 - cv,
        });
    }
    let mut picks = Vec::new();
    for &(k, (cv, lambda, scale)) in scored.iter().take(PICKS) {
        if null_chi2 - cv <= gain_needed(null_chi2) {
            break;
        }
        let (axis, proposal) = &candidates[k];
        axes[*axis].taken.push(proposal.name());
        picks.push(Pick {
            proposal: proposal.clone(),
            gain: null_chi2 - cv,
            lambda,
            scale,
        });
    }
    Screening {
        axes,
        picks,
        null_chi2,
        folds: if l.event_rows.len() > 1 {
            "leave one release out".into()
        } else {
            format!("{TIME_BLOCKS} contiguous blocks of the one release")
        },
    }
}

/// Each row's fold: its release's index, or with one release its block of [`TIME_BLOCKS`]
/// (whole samples, 6 rows each); and the number of folds.
fn row_folds(l: &Linear) -> (Vec<usize>, usize) {
    let mut fold = vec![0; l.r0.len()];
    if l.event_rows.len() > 1 {
        for (e, &(a, b)) in l.event_rows.iter().enumerate() {
            fold[a..b].fill(e);
        }
        return (fold, l.event_rows.len());
    }
    let samples = l.r0.len().div_ceil(6).max(1);
    for (i, f) in fold.iter_mut().enumerate() {
        *f = (i / 6) * TIME_BLOCKS / samples;
    }
    (fold, TIME_BLOCKS)
}

/// The drop of the cross-validated chi-square a correction must make from `current`: at least
/// [`GAIN_MIN`] and [`GAIN_FRACTION`] of it.
fn gain_needed(current: f64) -> f64 {
    GAIN_MIN.max(GAIN_FRACTION * current)
}

/// The reconstruction's windows as evidence for correction `p` (over distance, alpha or beta):
/// per window of each release, the mean of its variable over the window's samples, and the
/// window's reconstructed increment and standard deviation in the correction's units (an
/// interference increment's divided by its fitted multiplier, and by -1 on CA, where CX
/// carries it).
pub fn evidence(p: &Proposal, misfit: &Misfit, factors: &Factors) -> Vec<(f64, f64, f64)> {
    let axis = p.target.axis();
    let scale = match p.target {
        Target::Interference(k) => {
            let m = factors.get(MULTIPLIERS[k]);
            if k == 0 { -m } else { m }
        }
        _ => 1.0,
    };
    if scale.abs() < 1e-12 {
        return Vec::new();
    }
    let mut out = Vec::new();
    for (r, history) in misfit.reconstructions.iter().zip(&misfit.history) {
        let Some(s) = r.increments.iter().find(|s| s.axis == AXES[axis]) else {
            continue;
        };
        let half = if s.t_s.len() > 1 {
            0.5 * (s.t_s[1] - s.t_s[0])
        } else {
            f64::INFINITY
        };
        for ((&t, &u), &sd) in s.t_s.iter().zip(&s.value).zip(&s.std) {
            let inside: Vec<f64> = history
                .iter()
                .filter(|x| x.input.t_s >= t - half && x.input.t_s < t + half)
                .map(|x| match p.variable {
                    Variable::Distance => x.input.distance_m,
                    Variable::Alpha => x.input.alpha_rad.to_degrees(),
                    _ => x.input.beta_rad.to_degrees(),
                })
                .collect();
            if !inside.is_empty() {
                let x = inside.iter().sum::<f64>() / inside.len() as f64;
                out.push((x, u / scale, sd / scale.abs()));
            }
        }
    }
    out
}
