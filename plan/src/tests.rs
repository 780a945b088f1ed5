//! The plan's stages on the embedded default release: what a factor absorbs does not separate,
//! the top condition is the argmax of an independent brute-force computation of the same
//! separation, the ranking rule with rivals (pairs separated, then the hardest pair, then
//! information), and the information gain is positive and larger where the trajectory is more
//! sensitive.

use std::sync::Arc;

use nalgebra::{DMatrix, DVector};
use sepval_common::evaluation::{Candidate, InProcess, Job};
use sepval_common::propagator::Observation;
use sepval_common::scenario::Scenario;
use sepval_common::synthetic::default_flight_test;
use sepval_core::factors::{Factor, Factors};
use sepval_fit::space::Noise;
use sepval_run::model_spec::{EffectValues, ModelSpec};
use sepval_solve::run::NoProgress;

use super::*;
use crate::models::PlanModel;
use crate::separation::{PairSeparation, SEPARATION_THRESHOLD};

const NOISE: Noise = Noise {
    pos_m: 0.003,
    att_deg: 0.1,
};

fn flown() -> Job {
    Job::single(
        "flown",
        &Scenario::embedded_default(),
        default_flight_test(),
    )
}

fn spec(factors: Factors, effects: &[(&str, f64)]) -> ModelSpec {
    ModelSpec {
        factors,
        effects: effects
            .iter()
            .map(|(id, v)| EffectValues {
                id: (*id).into(),
                values: vec![*v],
            })
            .collect(),
        terms: Vec::new(),
    }
}

/// The stages from the grid to the ranking, in process.
struct Run {
    models: Models,
    conditions: Conditions,
    job: Job,
    separations: separation::Separations,
    information: information::Information,
    ranking: Ranking,
}

fn run(specs: &[(ModelSpec, f64)], ranges: &[Range], points: usize) -> Run {
    let flown = flown();
    let models = Models::new(specs, flown.factor_table()).unwrap();
    let base = flown.events()[0].simulator.scenario();
    let conditions = Conditions::grid(base, ranges, points).unwrap();
    let job = simulate::plan_job(&flown, &conditions).unwrap();
    let mut evaluator = InProcess::new(Arc::new(job.clone()), 2);
    let sims = simulate::simulate(&models, 1, NOISE, &mut evaluator, &mut NoProgress).unwrap();
    let separations = separation::separations(&models, &sims);
    let information = information::information(&sims);
    let left = tables::tables_left(&job, 1, &models);
    let ranking = ranking::rank(
        &conditions,
        &separations,
        &information,
        &left,
        models.has_rivals(),
    );
    Run {
        models,
        conditions,
        job,
        separations,
        information,
        ranking,
    }
}

fn beta(lo: f64, hi: f64) -> Range {
    Range {
        quantity: Quantity::BetaDeg,
        lo,
        hi,
    }
}

#[test]
fn a_difference_a_factor_absorbs_does_not_separate_and_a_real_one_does() {
    let cmoff = Factor::NAMES.iter().position(|n| *n == "cmoff").unwrap();
    let mut moved = Factors::TRUTH;
    // 0.5 % of cmoff's range: the trajectories differ by many noise sigmas, yet a refit of
    // either model moves cmoff and absorbs it all (to its second-order remainder).
    let table = *flown().factor_table();
    moved.0[cmoff] += 0.005 * (table.0[cmoff].max - table.0[cmoff].min);
    let r = run(
        &[
            (spec(Factors::TRUTH, &[]), 0.0),
            (spec(moved, &[]), 0.0),
            (spec(Factors::TRUTH, &[("roll_due_to_sideslip", -0.3)]), 0.0),
        ],
        &[beta(-6.0, 6.0)],
        3,
    );
    assert_eq!(r.conditions.list.len(), 3);
    let mut real = 0.0f64;
    for k in 0..3 {
        let pairs = r.separations.conditions[k].as_ref().unwrap();
        let absorbed = pairs.iter().find(|p| p.models == [0, 1]).unwrap();
        assert!(
            absorbed.chi2.iter().all(|c| *c < 0.1),
            "condition {k}: {absorbed:?}"
        );
        assert!(!absorbed.separated());
        let other = pairs.iter().find(|p| p.models == [0, 2]).unwrap();
        real = real.max(other.chi2[0].min(other.chi2[1]));
    }
    assert!(real > 50.0, "{real}");
    // The pair a factor absorbs is the hardest: it decides every condition's separation.
    for k in 0..3 {
        assert!(r.separations.of(k).unwrap() < SEPARATION_THRESHOLD);
    }
}

/// The samples of `c` at one event of `job`, simulated alone.
fn alone(job: &Job, event: usize, c: &Candidate) -> Vec<Observation> {
    let one = Job::new(vec![job.events()[event].clone()]).unwrap();
    one.evaluate_with_samples(c).samples.unwrap().remove(0)
}

/// The stacked sensitivities of `m` (range-scaled, over the noise) at `events`, and its
/// trajectories there.
fn jacobian(job: &Job, events: &[usize], m: &PlanModel) -> (DMatrix<f64>, Vec<Vec<Observation>>) {
    let nominal: Vec<Vec<Observation>> = events
        .iter()
        .map(|&e| alone(job, e, &m.candidate))
        .collect();
    let rows: usize = nominal.iter().map(|n| 6 * n.len()).sum();
    let mut j = DMatrix::zeros(rows, m.parameters());
    for (col, probe) in m.probes()[1..].iter().enumerate() {
        let scale = m.space.params.range(col) / m.steps[col];
        let mut row = 0;
        for (&e, y) in events.iter().zip(&nominal) {
            for v in simulate::difference(&alone(job, e, probe), y, NOISE, scale) {
                j[(row, col)] = v;
                row += 1;
            }
        }
    }
    (j, nominal)
}

/// min |v - J d|^2 + |d|^2, solved as the augmented least-squares problem [J; I] d = [v; 0]
/// by SVD (not through the normal equations the plan uses).
fn ridge_chi2(j: &DMatrix<f64>, v: &DVector<f64>) -> f64 {
    let (r, p) = j.shape();
    let mut a = DMatrix::zeros(r + p, p);
    a.view_mut((0, 0), (r, p)).copy_from(j);
    a.view_mut((r, 0), (p, p)).fill_with_identity();
    let mut b = DVector::zeros(r + p);
    b.rows_mut(0, r).copy_from(v);
    let d = a.clone().svd(true, true).solve(&b, 1e-14).unwrap();
    (&a * d - b).norm_squared()
}

#[test]
fn the_top_condition_is_the_argmax_of_a_brute_force_separation() {
    let specs = [
        (spec(Factors::TRUTH, &[]), 0.0),
        (spec(Factors::TRUTH, &[("roll_due_to_sideslip", -0.3)]), 1.0),
    ];
    let mach = Range {
        quantity: Quantity::Mach,
        lo: 0.6,
        hi: 0.9,
    };
    let r = run(&specs, &[mach, beta(-5.0, 5.0)], 3);
    // Brute force: each model's stacked Jacobian at the release flown and the condition, each
    // refit solved whole.
    let brute: Vec<f64> = (0..r.conditions.list.len())
        .map(|k| {
            let events = [0, 1 + k];
            let (a, b) = (&r.models.list[0], &r.models.list[1]);
            let (ja, ya) = jacobian(&r.job, &events, a);
            let (jb, yb) = jacobian(&r.job, &events, b);
            let diff = |x: &[Vec<Observation>], y: &[Vec<Observation>]| {
                DVector::from_iterator(
                    ja.nrows(),
                    x.iter()
                        .zip(y)
                        .flat_map(|(x, y)| simulate::difference(x, y, NOISE, 1.0)),
                )
            };
            let m = (ja.nrows() as f64).ln();
            let (pa, pb) = (a.parameters() as f64, b.parameters() as f64);
            let a_true = ridge_chi2(&jb, &diff(&ya, &yb)) + (pb - pa) * m;
            let b_true = ridge_chi2(&ja, &diff(&yb, &ya)) + (pa - pb) * m;
            a_true.min(b_true)
        })
        .collect();
    let argmax = (0..brute.len())
        .max_by(|&i, &j| brute[i].total_cmp(&brute[j]))
        .unwrap();
    let top = &r.ranking.conditions[0];
    assert_eq!(
        top.index, argmax,
        "brute force {brute:?}, plan {:?}",
        r.ranking
    );
    for (k, b) in brute.iter().enumerate() {
        let s = r.separations.of(k).unwrap();
        assert!(
            (s - b).abs() <= 1e-6 * b.abs().max(1.0),
            "condition {k}: {s} against {b}"
        );
    }
    // The effect acts through sideslip: the separation grows away from beta 0.
    assert!(r.conditions.list[top.index].flight.beta_deg.abs() > 1.0);
}

#[test]
fn with_no_rivals_the_information_gain_is_positive_and_larger_where_the_release_is_more_sensitive()
{
    // The release flown is at Mach 0.95: a release there adds least, and of two releases as
    // far from it, the one at the higher dynamic pressure (every aerodynamic factor moves the
    // trajectory more) adds more.
    let mach = Range {
        quantity: Quantity::Mach,
        lo: 0.65,
        hi: 1.25,
    };
    let r = run(&[(spec(Factors::TRUTH, &[]), 0.0)], &[mach], 3);
    let gains: Vec<f64> = r
        .information
        .gains
        .iter()
        .map(|g| *g.as_ref().unwrap())
        .collect();
    assert!(gains.iter().all(|g| *g > 0.0), "{gains:?}");
    assert!(gains[2] > gains[0] && gains[0] > gains[1], "{gains:?}");
    assert!(r.separations.of(0).is_none());
    let best = gains.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let top = r.ranking.conditions[0].information_gain.unwrap();
    assert!((top - best).abs() < 1e-12, "{top} against {gains:?}");
}

#[test]
fn with_rivals_the_pairs_separated_rank_first_then_the_hardest_pair_then_information() {
    // Three models (three pairs) at three conditions: the first two separate two pairs and
    // leave the third at 1, the last separates none but leaves its hardest pair at 2. The
    // smallest separation alone would recommend the last; the count puts it last, and the
    // information gain decides between the equal first two.
    let pairs = |seps: [f64; 3]| -> Result<Vec<PairSeparation>, crate::simulate::Missing> {
        let models = [[0, 1], [0, 2], [1, 2]];
        Ok(models
            .iter()
            .zip(seps)
            .map(|(&models, s)| PairSeparation {
                models,
                chi2: [s, s],
                margins: [s, s],
                separation: s,
            })
            .collect())
    };
    let separations = separation::Separations {
        flown: Vec::new(),
        conditions: vec![
            pairs([50.0, 50.0, 1.0]),
            pairs([50.0, 1.0, 50.0]),
            pairs([5.0, 5.0, 2.0]),
        ],
    };
    let information = information::Information {
        flown_log_det: 0.0,
        gains: vec![Ok(1.0), Ok(2.0), Ok(3.0)],
    };
    let flown = flown();
    let conditions = Conditions::grid(
        flown.events()[0].simulator.scenario(),
        &[beta(-6.0, 6.0)],
        3,
    )
    .unwrap();
    let left = vec![Vec::new(); 3];
    let r = ranking::rank(&conditions, &separations, &information, &left, true);
    let order: Vec<(usize, usize)> = r
        .conditions
        .iter()
        .map(|c| (c.index, c.separated_pairs))
        .collect();
    assert_eq!(order, [(1, 2), (0, 2), (2, 0)]);
    // Without rivals the information gain alone ranks.
    let r = ranking::rank(&conditions, &separations, &information, &left, false);
    let order: Vec<usize> = r.conditions.iter().map(|c| c.index).collect();
    assert_eq!(order, [2, 1, 0]);
}

/// A model with a located term (a step's time, a frequency, a gust's time, a decay length) is
/// marked, so that plan.json and the page say its separations hold the locator the diagnosis
/// refits; a flow-angle term has no locator and is not.
#[test]
fn models_with_located_terms_are_marked() {
    use sepval_common::extension::{Axis, Regressor, Term, TermRecord};
    let with = |regressor: Regressor, locator: [f64; 2]| {
        let mut s = spec(Factors::TRUTH, &[]);
        s.terms = vec![TermRecord::of(&Term {
            axis: if regressor == Regressor::WindPulse {
                Axis::WindY
            } else {
                Axis::Cn
            },
            regressor,
            locator,
            coefficient: 0.01,
        })];
        (s, 1.0)
    };
    let specs = [
        (spec(Factors::TRUTH, &[]), 0.0),
        with(Regressor::Beta, [0.0; 2]),
        with(Regressor::Step, [0.5, 0.0]),
        with(Regressor::Sin, [30.5, 0.0]),
        with(Regressor::WindPulse, [0.3, 0.1]),
        with(Regressor::F, [0.9, 0.0]),
    ];
    let models = Models::new(&specs, flown().factor_table()).unwrap();
    let located: Vec<bool> = models.list.iter().map(PlanModel::located).collect();
    assert_eq!(located, [false, false, true, true, true, true]);
}
