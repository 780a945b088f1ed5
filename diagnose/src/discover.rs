//! Discovery beyond the catalogue: what force and moment the fitted baseline lacks, which terms
//! of a documented library explain it, and what the model extended by them gains
//! (`docs/model.md` section 11).
//!
//! 1. **Sensitivities.** One batch simulates the fitted baseline with each library term added at
//!    a small probe coefficient, and with each reconstruction window; the change of the
//!    normalised residuals per unit coefficient is each term's column (`probe`). Long records
//!    use a subset of their samples here.
//! 2. **Reconstruction** (`reconstruct`): per event, the coefficient increments dCA ... dCn and
//!    the ejector increment as time histories with bands, from the window columns by a
//!    regularised output-error estimate.
//! 3. **Selection** (`stepwise`): stepwise regression of the residuals on the library's columns
//!    with the factors' sensitivities always in (what a factor change absorbs is no finding),
//!    F-to-enter and F-to-remove at 1 % family-wise and the predicted square error; correlated
//!    entries are reported as one group.
//! 4. **Locators.** Each selected term's locator (step time, frequency, decay length) is refined
//!    on a grid eight times finer than the library's, around the selected one.
//! 5. **Verification.** The baseline's 17 factors and the selected terms' coefficients (and the
//!    step times and decay lengths) are refitted together by output error on every sample
//!    (the real trajectory fit, not the regression), each candidate for at most
//!    `VERIFY_ITERATIONS`, the best on to convergence. An entry is kept when its F test against
//!    the current model (the previous step's) passes at 1 % divided by the number of library
//!    entries screened in that step, and its BIC is lower; with several terms, each is refitted
//!    out in turn, and a term whose removal is not significant leaves. The gain over the
//!    baseline is reported, not tested again.
//!
//! The sensitivities are linear about the fit: they screen, the refit decides.

use std::sync::Arc;

use nalgebra::{DMatrix, DVector};
use sepval_common::effects::EffectSet;
use sepval_common::elementary;
use sepval_common::evaluation::{Candidate, Evaluator, Job};
use sepval_common::extension::{Family, Regressor, Term};
use sepval_common::factors::FACTOR_COUNT;

use super::found::{
    DiscoveredTerm, Discovery, DiscoveryStep, Gain, GroupMember, Screened, Verified,
};
use super::library::{self, Entry};
use super::reconstruct::reconstruct;
use super::verify::{leave_one_out, refit_run};
use super::{ALPHA, DiagnoseError, Fitted, Result, probe, readings, stepwise};
use sepval_fit::refine::refine_together;
use sepval_fit::space::{FreeTerm, Noise};
use sepval_solve::identifiability::identifiability;
use sepval_solve::lm::LmSettings;

/// Per event, per axis: (times \[s\], values).
pub(super) type Curves = Vec<Vec<(Vec<f64>, Vec<f64>)>>;

/// Most iterations of a candidate's verification refit (the winner then runs on to
/// convergence).
const VERIFY_ITERATIONS: usize = 40;

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

/// The fine grid around a selected term's locator: 17 values spanning one library spacing on
/// each side, or `None` for families without one.
fn fine_grid(term: &Term) -> Option<Vec<f64>> {
    let l = term.locator[0];
    let spacing = match term.regressor.family() {
        Family::Step => library::STEP_SPACING_S,
        Family::Oscillation => library::FREQUENCY_SPACING_HZ,
        Family::Interference | Family::InterferenceFlowAngle => {
            // sepval's own pow, not the C library's: these decay lengths are simulated (and may
            // end up in DIR/extension.toml), so they must be the same bits on every host.
            return Some(
                (-8..=8)
                    .map(|k| l * elementary::pow(1.5, k as f64 / 8.0))
                    .collect(),
            );
        }
        _ => return None,
    };
    Some(
        (-8..=8)
            .map(|k| l + spacing * k as f64 / 8.0)
            .filter(|v| *v > 0.0)
            .collect(),
    )
}

/// Bounds of a refitted locator around its refined value.
fn locator_bounds(term: &Term) -> Option<(f64, f64)> {
    let l = term.locator[0];
    match term.regressor.family() {
        Family::Step => Some((
            l - library::STEP_SPACING_S / 4.0,
            l + library::STEP_SPACING_S / 4.0,
        )),
        Family::Interference | Family::InterferenceFlowAngle => Some((l / 1.2, l * 1.2)),
        _ => None,
    }
}

/// The candidate of `fitted` at its optimum.
pub(super) fn candidate_of(job: &Job, fitted: &Fitted) -> Result<Candidate> {
    Ok(fitted.space(job).candidate(&fitted.lm.x)?)
}

/// The residual rows of a fitted model and the sensitivities to its parameters (factors and
/// terms already in) that are free to move: a parameter held at a bound of its range cannot
/// absorb what lies beyond it, so its column is left out.
fn linearisation(job: &Job, f: &Fitted, rows: &[usize]) -> (DVector<f64>, DMatrix<f64>) {
    let space = f.space(job);
    let free: Vec<usize> = (0..f.lm.jacobian.ncols())
        .filter(|&c| {
            let (x, lo, hi) = (f.lm.x[c], space.params.lo[c], space.params.hi[c]);
            let tol = 1e-6 * (hi - lo);
            x > lo + tol && x < hi - tol
        })
        .collect();
    let r = DVector::from_iterator(rows.len(), rows.iter().map(|&i| f.lm.residuals[i]));
    let j = DMatrix::from_fn(rows.len(), free.len(), |i, c| {
        f.lm.jacobian[(rows[i], free[c])]
    });
    (r, j)
}

/// The entries of `picked` at the values `fitted` estimated for them.
fn entries_at(job: &Job, fitted: &Fitted, picked: &[Entry]) -> Result<Vec<Entry>> {
    let terms = fitted.space(job).terms_at(&fitted.lm.x)?;
    let mut at = 0;
    Ok(picked
        .iter()
        .map(|e| {
            let n = e.terms.len();
            let out = Entry {
                terms: terms[at..at + n].to_vec(),
            };
            at += n;
            out
        })
        .collect())
}

/// The same axis and regressor (any locator).
fn same_kind(a: &Entry, b: &Entry) -> bool {
    a.axis() == b.axis() && a.terms[0].regressor == b.terms[0].regressor
}

/// Runs discovery from the converged `baseline` (no effects, no terms): forward stepwise
/// selection, re-linearised at each step, each step's best entries verified by output-error
/// refits.
pub(super) fn discover(
    evaluator: &mut dyn Evaluator,
    job: &Arc<Job>,
    baseline: &Fitted,
    noise: Noise,
    settings: &LmSettings,
) -> Result<Discovery> {
    let mut notes = Vec::new();
    let mut evaluations = 0u64;
    let rows = probe::rows(job);
    let rate_hz = sample_rate_hz(job);
    let m = 6 * job.sample_count();
    let room = sepval_common::extension::MAX_TERMS
        - job
            .events()
            .iter()
            .map(|e| e.simulator.model().extension.len())
            .max()
            .unwrap_or(0);
    let mut current = baseline.clone();
    let mut picked: Vec<Entry> = Vec::new();
    let mut groups: Vec<Vec<GroupMember>> = Vec::new();
    let mut reconstruction = Vec::new();
    let mut steps: Vec<DiscoveryStep> = Vec::new();
    // The candidates' refits compare entries: a few dozen iterations rank them.
    let screening = LmSettings {
        max_iterations: settings.max_iterations.min(VERIFY_ITERATIONS),
        ..settings.clone()
    };
    for step in 0..stepwise::MAX_ENTRIES {
        let base = candidate_of(job, &current)?;
        let history = library::flow_history(job, &base);
        if history.iter().any(Vec::is_empty) {
            notes.push(
                "the fitted trajectory could not be simulated again: discovery stopped".into(),
            );
            break;
        }
        let used: usize = picked.iter().map(|e| e.terms.len()).sum();
        let entries: Vec<Entry> = library::library(job, &history, rate_hz)
            .into_iter()
            .filter(|e| used + e.terms.len() <= room && !picked.iter().any(|p| same_kind(p, e)))
            .collect();
        if entries.is_empty() {
            break;
        }
        let windows = if step == 0 {
            library::windows(&history)
        } else {
            Vec::new()
        };
        let (r0, fixed) = linearisation(job, &current, &rows);

        // 1. Every entry's (and, at the first step, window's) sensitivity, in one batch.
        let mut probes: Vec<Term> = Vec::new();
        let mut entry_cols: Vec<Vec<usize>> = Vec::new();
        for e in &entries {
            entry_cols.push((probes.len()..probes.len() + e.terms.len()).collect());
            probes.extend(e.terms.iter().copied());
        }
        let n_entry_cols = probes.len();
        probes.extend(windows.iter().copied());
        let cols = probe::columns(
            evaluator,
            job,
            &base,
            &probes,
            &current.lm.residuals,
            noise,
            &rows,
        )?;
        evaluations += probes.len() as u64;

        // 2. Reconstruction of the baseline's misfit, per event.
        if step == 0 {
            let win = cols.columns(n_entry_cols, windows.len()).into_owned();
            reconstruction = probe::event_rows(job, &rows)
                .into_iter()
                .zip(job.events())
                .map(|((a, b), e)| {
                    reconstruct(
                        &e.name,
                        &r0.rows(a, b - a).into_owned(),
                        &fixed.rows(a, b - a).into_owned(),
                        &win.rows(a, b - a).into_owned(),
                        &windows,
                    )
                })
                .collect();
        }

        // 3. Screening: F-to-enter against the Bonferroni threshold, and the PSE.
        let lib_cols = cols.columns(0, n_entry_cols).into_owned();
        let threshold = stepwise::ALPHA / entries.len() as f64;
        let scores = stepwise::screen(&r0, &fixed, &lib_cols, &entry_cols);
        let mut record = DiscoveryStep {
            step: step + 1,
            chi2: current.lm.cost,
            threshold,
            screened: scores
                .iter()
                .take(10)
                .map(|sc| {
                    let e = &entries[sc.entry];
                    Screened {
                        axis: e.axis().name().to_string(),
                        term: entry_formula(&e.terms),
                        f: sc.f,
                        p_value: sc.p,
                    }
                })
                .collect(),
            verified: Vec::new(),
            accepted: None,
        };
        // The entries to verify: the best by F-to-enter, one per axis and regressor, then the
        // best of each axis not yet among them, so that a misfit the regression spreads over
        // several axes has each axis's best candidate refitted.
        let passing: Vec<usize> = scores
            .iter()
            .filter(|s| s.p < threshold && s.pse_falls)
            .map(|s| s.entry)
            .collect();
        let mut best: Vec<usize> = Vec::new();
        for &e in &passing {
            if best.len() == stepwise::VERIFIED_PER_STEP {
                break;
            }
            if !best.iter().any(|&b| same_kind(&entries[b], &entries[e])) {
                best.push(e);
            }
        }
        for &e in &passing {
            if !best.iter().any(|&b| entries[b].axis() == entries[e].axis()) {
                best.push(e);
            }
        }
        if best.is_empty() {
            steps.push(record);
            notes.push(format!(
                "step {}: no library term is significant in the regression (best F-to-enter p = {:.2e}, threshold {threshold:.1e} over {} entries)",
                step + 1,
                scores.first().map_or(1.0, |s| s.p),
                entries.len()
            ));
            break;
        }

        // 4. Each candidate's locator on a finer grid and its linear coefficients.
        let mut tried: Vec<Entry> = best.iter().map(|&b| entries[b].clone()).collect();
        let mut zoom_probes = Vec::new();
        let mut zoom_of = Vec::new();
        for (k, e) in tried.iter().enumerate() {
            for l in fine_grid(&e.terms[0]).unwrap_or_default() {
                let from = zoom_probes.len();
                for t in &e.terms {
                    let mut t = *t;
                    t.locator[0] = l;
                    t.coefficient = library::probe_size(&t, &history);
                    zoom_probes.push(t);
                }
                zoom_of.push((k, l, from));
            }
        }
        let zc = if zoom_probes.is_empty() {
            DMatrix::zeros(rows.len(), 0)
        } else {
            evaluations += zoom_probes.len() as u64;
            probe::columns(
                evaluator,
                job,
                &base,
                &zoom_probes,
                &current.lm.residuals,
                noise,
                &rows,
            )?
        };
        for (k, e) in tried.iter_mut().enumerate() {
            let width = e.terms.len();
            let own: Vec<DVector<f64>> = entry_cols[best[k]]
                .iter()
                .map(|&j| lib_cols.column(j).into_owned())
                .collect();
            let (mut rss, mut coefs) = stepwise::fit_columns(&r0, &fixed, &own);
            let mut locator = e.terms[0].locator[0];
            for &(_, l, from) in zoom_of.iter().filter(|z| z.0 == k) {
                let c: Vec<DVector<f64>> = (from..from + width)
                    .map(|j| zc.column(j).into_owned())
                    .collect();
                let (r, b) = stepwise::fit_columns(&r0, &fixed, &c);
                if r < rss {
                    (rss, coefs, locator) = (r, b, l);
                }
            }
            for (t, c) in e.terms.iter_mut().zip(coefs) {
                t.locator[0] = locator;
                t.coefficient = c;
            }
        }

        // 5. Verification: each candidate refitted with the factors and the terms already in.
        // Each refit starts from the current optimum with the new entry at zero (the linear
        // estimate, which can overshoot where the response is not linear, sets its bounds).
        let now = entries_at(job, &current, &picked)?;
        let mut runs = Vec::new();
        for e in &tried {
            let mut with = now.clone();
            with.push(e.clone());
            runs.push(refit_run(job, &current, &with, noise, &screening));
        }
        refine_together(evaluator, &mut runs)?;
        let mut refits: Vec<(Entry, Fitted, usize)> = Vec::new();
        for ((e, index), run) in tried.into_iter().zip(best).zip(runs) {
            let space = run.space().clone();
            let lm = run.finish();
            evaluations += lm.evaluations;
            refits.push((
                e,
                Fitted {
                    effects: EffectSet::NONE,
                    terms: space.terms.clone(),
                    lm,
                },
                index,
            ));
        }
        refits.sort_by(|a, b| a.1.lm.cost.total_cmp(&b.1.lm.cost));
        record.verified = refits
            .iter()
            .map(|(e, f, _)| Verified {
                axis: e.axis().name().to_string(),
                term: entry_formula(&e.terms),
                chi2: f.lm.cost,
            })
            .collect();
        let Some((entry, fitted, lead)) = refits.first().cloned() else {
            steps.push(record);
            break;
        };
        // The winner's refit runs on to convergence.
        let fitted =
            super::catalogue::converge(evaluator, job, fitted, noise, settings, &mut evaluations)?;
        let p_with = fitted.space(job).len();
        let q = p_with - current.space(job).len();
        let gain = Gain::of(current.lm.cost, fitted.lm.cost, q, p_with, m);
        if !(gain.p_value < threshold && gain.delta_bic < 0.0) {
            notes.push(format!(
                "step {}: the regression's best entries ({}) do not pass once refitted by output error (best: {} {}, p = {:.2e}, threshold {threshold:.1e}, BIC change {:+.1})",
                step + 1,
                refits
                    .iter()
                    .map(|(e, _, _)| format!("{} {}", e.axis().name(), entry_formula(&e.terms)))
                    .collect::<Vec<_>>()
                    .join("; "),
                entry.axis().name(),
                entry_formula(&entry.terms),
                gain.p_value,
                gain.delta_bic
            ));
            steps.push(record);
            break;
        }
        record.accepted = Some(format!(
            "{} {}: chi-square drop {:.1}, p = {:.2e}, BIC change {:+.1}",
            entry.axis().name(),
            entry_formula(&entry.terms),
            gain.chi2_drop,
            gain.p_value,
            gain.delta_bic
        ));
        steps.push(record);
        // The group: entries the regression cannot tell from it (|rho| >= 0.95 beyond the
        // model's own sensitivities), and refitted rivals within 2 of its chi-square.
        // A member of the regression's group that was refitted and lost by more than that is
        // told apart by the data after all.
        let lost = |g: &Entry| {
            refits
                .iter()
                .any(|(e, f, _)| same_kind(e, g) && f.lm.cost - fitted.lm.cost >= 2.0)
        };
        let mut group: Vec<GroupMember> = stepwise::group(&fixed, &lib_cols, &entry_cols, lead)
            .into_iter()
            .filter(|(g, _)| !same_kind(&entries[*g], &entry) && !lost(&entries[*g]))
            .map(|(g, rho)| GroupMember {
                axis: entries[g].axis().name().to_string(),
                family: entries[g].family().name().to_string(),
                term: entry_formula(&entries[g].terms),
                correlation: Some(rho),
            })
            .collect();
        for (e, f, _) in refits.iter().skip(1) {
            if f.lm.cost - fitted.lm.cost < 2.0
                && !group.iter().any(|g| g.term == entry_formula(&e.terms))
            {
                group.push(GroupMember {
                    axis: e.axis().name().to_string(),
                    family: e.family().name().to_string(),
                    term: entry_formula(&e.terms),
                    correlation: None,
                });
            }
        }
        group.truncate(8);
        picked = entries_at(job, &fitted, &{
            let mut p = now;
            p.push(entry);
            p
        })?;
        groups.push(group);
        current = fitted;

        // 6. F-to-remove: a term whose removal is no longer significant leaves.
        if picked.len() > 1 {
            let without = leave_one_out(evaluator, job, &current, &picked, noise, settings)?;
            let p_with = current.space(job).len();
            let mut weakest: Option<(usize, f64)> = None;
            for (k, f) in without.iter().enumerate() {
                evaluations += f.lm.evaluations;
                let q = p_with - f.space(job).len();
                let g = Gain::of(f.lm.cost, current.lm.cost, q, p_with, m);
                if !g.significant(ALPHA) && weakest.is_none_or(|(_, d)| g.chi2_drop < d) {
                    weakest = Some((k, g.chi2_drop));
                }
            }
            if let Some((k, _)) = weakest {
                notes.push(format!(
                    "{} {} left again: once {} {} was in, removing it was not significant",
                    picked[k].axis().name(),
                    entry_formula(&picked[k].terms),
                    picked[picked.len() - 1].axis().name(),
                    entry_formula(&picked[picked.len() - 1].terms),
                ));
                picked.remove(k);
                groups.remove(k);
                current = without.into_iter().nth(k).ok_or_else(|| {
                    DiagnoseError::Model("a leave-one-out refit is missing".into())
                })?;
            }
        }
    }
    if picked.is_empty() {
        return Ok(Discovery {
            reconstruction,
            found: None,
            notes,
            steps,
            evaluations,
        });
    }
    let fitted = current;
    let picked = entries_at(job, &fitted, &picked)?;
    let p_with = fitted.space(job).len();
    let gain = Gain::of(
        baseline.lm.cost,
        fitted.lm.cost,
        p_with - FACTOR_COUNT,
        p_with,
        m,
    );
    let gains: Vec<Gain> = if picked.len() > 1 {
        let without = leave_one_out(evaluator, job, &fitted, &picked, noise, settings)?;
        without
            .iter()
            .map(|f| {
                evaluations += f.lm.evaluations;
                Gain::of(
                    f.lm.cost,
                    fitted.lm.cost,
                    p_with - f.space(job).len(),
                    p_with,
                    m,
                )
            })
            .collect()
    } else {
        vec![gain.clone()]
    };

    // 7. Naming: estimates with standard errors, most important first.
    let space = fitted.space(job);
    let events: Vec<usize> = job.events().iter().map(|e| e.data.len()).collect();
    let id = identifiability(
        &space.params,
        &fitted.lm.x,
        &fitted.lm.residuals,
        &fitted.lm.jacobian,
        &events,
    );
    let mut found = Vec::new();
    let mut param = FACTOR_COUNT;
    for (k, e) in picked.iter().enumerate() {
        let n = e.terms.len();
        let now = &e.terms;
        // The parameter positions of this entry's coefficients (and locator).
        let mut coef_pos = Vec::new();
        let mut loc_pos = None;
        for ft in &fitted.terms[found_terms_before(&picked, k)..][..n] {
            coef_pos.push(param);
            param += 1;
            if ft.locator.is_some() {
                loc_pos = Some(param);
                param += 1;
            }
        }
        let se = |i: usize| id.parameters.get(i).and_then(|p| p.std_error);
        let (coefficient, std_error, phase_deg) = if n == 2 {
            let (a, b) = (now[0].coefficient, now[1].coefficient);
            let amp = a.hypot(b);
            let var = match (se(coef_pos[0]), se(coef_pos[1])) {
                (Some(sa), Some(sb)) if amp > 0.0 => {
                    let rho = id
                        .correlation
                        .get(coef_pos[0])
                        .and_then(|r| r.get(coef_pos[1]))
                        .copied()
                        .unwrap_or(0.0);
                    Some(
                        ((a * a * sa * sa + b * b * sb * sb + 2.0 * a * b * rho * sa * sb)
                            / (amp * amp))
                            .max(0.0)
                            .sqrt(),
                    )
                }
                _ => None,
            };
            (amp, var, Some(b.atan2(a).to_degrees()))
        } else {
            (now[0].coefficient, se(coef_pos[0]), None)
        };
        let lead = now[0];
        let locator = lead.locator[0];
        let family = lead.regressor.family();
        found.push(DiscoveredTerm {
            axis: lead.axis.name().to_string(),
            family: family.name().to_string(),
            term: entry_formula(now),
            coefficient,
            std_error,
            phase_deg,
            t_on_s: (family == Family::Step).then_some(locator),
            f_hz: (family == Family::Oscillation).then_some(locator),
            lambda_m: matches!(family, Family::Interference | Family::InterferenceFlowAngle)
                .then_some(locator),
            mach0: (family == Family::Mach).then_some(locator),
            locator_std_error: loc_pos.and_then(se),
            gain: gains.get(k).cloned().unwrap_or_else(|| gain.clone()),
            reading: readings::reading(&lead, &job.events()[0].simulator.scenario().interference),
            group: groups[k].clone(),
        });
    }
    found.sort_by(|a, b| b.gain.chi2_drop.total_cmp(&a.gain.chi2_drop));
    Ok(Discovery {
        reconstruction,
        found: Some((fitted, found, gain)),
        notes,
        steps,
        evaluations,
    })
}

/// Terms of the entries before entry `k`.
pub(super) fn found_terms_before(picked: &[Entry], k: usize) -> usize {
    picked[..k].iter().map(|e| e.terms.len()).sum()
}

/// A readable formula of an entry: its term's, or an oscillation pair's as one sinusoid.
pub(super) fn entry_formula(terms: &[Term]) -> String {
    match terms {
        [a, b] if a.regressor == Regressor::Sin && b.regressor == Regressor::Cos => {
            format!("sin(2 pi {} Hz t + phase)", readings::fmt_num(a.locator[0]))
        }
        [t, ..] => t.formula(),
        [] => String::new(),
    }
}

/// The free terms of `picked`: coefficients bounded to ten times their estimate, step times and
/// decay lengths free near their refined values.
pub(super) fn free_terms(picked: &[Entry]) -> Vec<FreeTerm> {
    picked
        .iter()
        .flat_map(|e| {
            let single = e.terms.len() == 1;
            e.terms.iter().map(move |t| {
                let b = 10.0 * t.coefficient.abs().max(1e-12);
                FreeTerm {
                    term: *t,
                    coefficient: (-b, b),
                    locator: if single { locator_bounds(t) } else { None },
                }
            })
        })
        .collect()
}
