//! Small parameter changes give small trajectory changes (docs/model.md section 3a: the
//! trajectory is continuous in every parameter; issue 36). For each family of the extension's
//! terms (its coefficient and, where it has one, its locator), for the ejector factors (which
//! move the located stroke ends) and on two conditions (the default, and one with angle of
//! attack and sideslip), at several values of the parameter: the trajectory at p + 2d less
//! twice that at p + d plus that at p (a second difference) is small beside the change from p
//! to p + 2d. A jump anywhere in [p, p + 2d] (a switch that moves by a step, a regressor with an
//! edge the integrator straddles) makes the second difference as large as the jump and fails.
//! Deterministic: a fixed grid of values, no random draws.
//!
//! What it found (issue 36's "jump in a trajectory"): stroke ends located to a bracket of
//! 1e-12 s made second differences of about 1e-9 (deg, after 1 s) for every parameter, the
//! stopping point of the search moving by a step of the bracket as the parameter moved; located
//! to the last bit (docs/model.md section 3a, arithmetic version 3) they are rounding.

use sepval_common::effects::EffectSet;
use sepval_common::extension::{Axis, Regressor, Term, TermSet};
use sepval_common::propagator::{Observation, propagate};
use sepval_common::scenario::Scenario;
use sepval_common::{Factor, Factors, Simulator};

type Trajectory = Vec<Observation>;

/// Relative step of the perturbations (of the parameter's scale).
const STEP: f64 = 1e-6;

/// One parameter to move: the term (its coefficient or its locator) or a factor.
#[derive(Clone, Copy, Debug)]
enum Knob {
    Coefficient(Term),
    Locator(Term, usize),
    Factor(Factor),
}

fn term(axis: Axis, regressor: Regressor, locator: [f64; 2], coefficient: f64) -> Term {
    Term {
        axis,
        regressor,
        locator,
        coefficient,
    }
}

/// Every family, each with a coefficient large enough to move the store visibly.
fn terms() -> Vec<Term> {
    vec![
        term(Axis::Cn, Regressor::Beta, [0.0; 2], 0.1),
        term(Axis::Cm, Regressor::Alpha2, [0.0; 2], 2.0),
        term(Axis::Cl, Regressor::P, [0.0; 2], -0.2),
        term(Axis::CZ, Regressor::F, [0.9, 0.0], 0.05),
        term(Axis::CY, Regressor::FBeta, [0.6, 0.0], 0.3),
        term(Axis::CA, Regressor::Dm, [0.9, 0.0], 0.05),
        term(Axis::CZ, Regressor::Step, [0.5, 0.0], 0.02),
        term(Axis::Cm, Regressor::Sin, [7.0, 0.0], 0.01),
        term(Axis::CZ, Regressor::Window, [0.3, 0.4], 0.02),
        term(Axis::WindY, Regressor::WindStep, [0.3, 0.1], 3.0),
        term(Axis::WindZ, Regressor::WindPulse, [0.2, 0.05], -4.0),
        term(Axis::Ejector, Regressor::Stroke, [0.0; 2], 0.1),
    ]
}

/// The knobs: every term's coefficient, every locator a fit may move (a step's or gust's time,
/// a gust's length, a frequency, a decay length, a reference Mach number) and the ejector
/// factors.
fn knobs() -> Vec<Knob> {
    let mut k = Vec::new();
    for t in terms() {
        k.push(Knob::Coefficient(t));
        match t.regressor {
            Regressor::F | Regressor::FBeta | Regressor::Dm | Regressor::Step | Regressor::Sin => {
                k.push(Knob::Locator(t, 0))
            }
            Regressor::WindStep | Regressor::WindPulse => {
                k.push(Knob::Locator(t, 0));
                k.push(Knob::Locator(t, 1));
            }
            _ => {}
        }
    }
    k.extend([Knob::Factor(Factor::Fwdfac), Knob::Factor(Factor::Aftfac)]);
    k
}

/// The trajectory with the knob's parameter at `scale * (1 + u)`, `scale` its value in
/// [`terms`] (or the nominal factor).
fn fly(sim: &Simulator, knob: Knob, u: f64, times: &[f64]) -> Trajectory {
    let mut factors = Factors::NOMINAL;
    let term = match knob {
        Knob::Coefficient(mut t) => {
            t.coefficient *= 1.0 + u;
            Some(t)
        }
        Knob::Locator(mut t, i) => {
            t.locator[i] *= 1.0 + u;
            Some(t)
        }
        Knob::Factor(f) => {
            factors.0[f as usize] *= 1.0 + u;
            None
        }
    };
    let set = TermSet::of(&term.into_iter().collect::<Vec<_>>()).unwrap();
    let run = sim
        .run_setup_with(&factors, &EffectSet::NONE, &set)
        .unwrap();
    let mut samples = Trajectory::new();
    propagate(sim.model(), &run, times, &mut samples).unwrap();
    samples
}

/// The largest |second difference| and |change| over every sample and channel (m and deg
/// alike: both are within a few of each other's scale here).
fn differences(a: &Trajectory, b: &Trajectory, c: &Trajectory) -> (f64, f64) {
    let (mut second, mut change) = (0.0f64, 0.0f64);
    for k in 0..a.len() {
        let rows = |t: &Trajectory| -> [f64; 6] {
            let (p, q) = (t[k].pos_m, t[k].att_deg);
            [p[0], p[1], p[2], q[0], q[1], q[2]]
        };
        let (ra, rb, rc) = (rows(a), rows(b), rows(c));
        for j in 0..6 {
            second = second.max((rc[j] - 2.0 * rb[j] + ra[j]).abs());
            change = change.max((rc[j] - ra[j]).abs());
        }
    }
    (second, change)
}

#[test]
fn small_parameter_changes_give_small_trajectory_changes() {
    let default = Scenario::embedded_default();
    let mut turned = default.clone();
    turned.flight.alpha_deg = 4.0;
    turned.flight.beta_deg = -3.0;
    let mut failures = Vec::new();
    for scenario in [&default, &turned] {
        let sim = Simulator::new(scenario);
        let times = sim.default_times();
        for knob in knobs() {
            // Several places along the parameter: a jump lies between some of them.
            for start in [-0.3, -0.1, 0.0, 0.07, 0.2] {
                let (a, b, c) = (
                    fly(&sim, knob, start, &times),
                    fly(&sim, knob, start + STEP, &times),
                    fly(&sim, knob, start + 2.0 * STEP, &times),
                );
                let (second, change) = differences(&a, &b, &c);
                // Smooth: the second difference is of order STEP times the change (plus
                // rounding); a jump of J makes it about J.
                if second > 1e-3 * change + 1e-12 {
                    failures.push(format!(
                        "{knob:?} at 1 + {start}: second difference {second:.3e}, change {change:.3e}"
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
