//! The `wind` family in the equations of motion (docs/discovery.md section 11.2): a steady
//! crosswind is a changed sideslip (the analytic check at release, and the whole trajectory
//! against a scenario flown at that sideslip and airspeed), the lanes keep the bits of the
//! scalar runs when wind and windless runs share a batch, and the edges of `rise_s` simulate.

use sepval_common::effects::EffectSet;
use sepval_common::extension::locator::RISE_S;
use sepval_common::extension::{Axis, Regressor, Term, TermRecord, TermSet};
use sepval_common::model::{EquationsOfMotion, RunSetup, StateVector};
use sepval_common::propagator::{LANES, Observation, propagate, propagate_lanes};
use sepval_common::scenario::Scenario;
use sepval_common::{Factors, Simulator};

/// A gust term: the wind along `axis` starting at `t_on_s`, rising over `rise_s`, of `w_m_s`.
pub(crate) fn gust(axis: Axis, regressor: Regressor, t_on_s: f64, rise_s: f64, w_m_s: f64) -> Term {
    Term {
        axis,
        regressor,
        locator: [t_on_s, rise_s],
        coefficient: w_m_s,
    }
}

/// A wind of `w_m_s` along L's y, on since long before release.
fn steady_crosswind(w_m_s: f64) -> Term {
    gust(Axis::WindY, Regressor::WindStep, -10.0, 0.001, w_m_s)
}

#[test]
fn a_steady_crosswind_shifts_the_sideslip_by_atan_w_over_v() {
    let sim = Simulator::embedded_default();
    let still = sim.run_setup(&Factors::TRUTH, &EffectSet::NONE).unwrap();
    let x0 = still.initial_state();
    let eq = EquationsOfMotion::new(&still, &sim.model().curve);
    let calm = eq.flow(&x0, 0.0);
    for w in [5.0, -12.0] {
        let terms = TermSet::of(&[steady_crosswind(w)]).unwrap();
        let windy = sim
            .run_setup_with(&Factors::TRUTH, &EffectSet::NONE, &terms)
            .unwrap();
        let flow = EquationsOfMotion::new(&windy, &sim.model().curve).flow(&x0, 0.0);
        let v = calm.speed_m_s;
        // The air moving along +y is the store moving along -y through it.
        let expected = calm.beta_rad - (w / v).atan();
        assert!(
            (flow.beta_rad - expected).abs() < 1e-14,
            "w = {w} m/s: beta {} rad, expected {expected} rad",
            flow.beta_rad
        );
        assert!((flow.alpha_rad - calm.alpha_rad).abs() < 1e-15);
        assert!((flow.speed_m_s - v.hypot(w)).abs() < 1e-9);
    }
}

#[test]
fn a_steady_crosswind_flies_as_the_release_at_that_sideslip_and_airspeed() {
    // The default's aerodynamics do not depend on the flight Mach number, so a crosswind w at
    // airspeed V (alpha = 0) is the same release as one at beta = -atan(w/V) and
    // Mach M sqrt(1 + (w/V)^2), to rounding.
    let w = 8.0;
    let base = Scenario::embedded_default();
    let sim = Simulator::new(&base);
    let v = sim.model().v_inf_m_s;
    let mut windy = base.clone();
    windy.extension = vec![TermRecord::of(&steady_crosswind(w))];
    let mut turned = base.clone();
    turned.flight.beta_deg = -(w / v).atan().to_degrees();
    turned.flight.mach = base.flight.mach * (1.0 + (w / v) * (w / v)).sqrt();
    let times = sim.default_times();
    let fly = |s: &Scenario| {
        Simulator::new(s)
            .simulate(&Factors::TRUTH, &EffectSet::NONE, &times)
            .unwrap()
    };
    let (a, b, calm) = (fly(&windy), fly(&turned), fly(&base));
    let mut worst_m: f64 = 0.0;
    let mut moved_m: f64 = 0.0;
    for (k, t) in times.iter().enumerate() {
        for j in 0..3 {
            worst_m = worst_m.max((a.pos_m[k][j] - b.pos_m[k][j]).abs());
            moved_m = moved_m.max((a.pos_m[k][j] - calm.pos_m[k][j]).abs());
            assert!((a.att_deg[k][j] - b.att_deg[k][j]).abs() < 1e-7, "t = {t}");
        }
    }
    assert!(worst_m < 1e-7, "positions differ by {worst_m} m");
    // And the wind matters: the release without it is elsewhere.
    assert!(
        moved_m > 0.05,
        "the crosswind moved the store by only {moved_m} m"
    );
}

type Samples = Vec<(Observation, StateVector)>;

fn sample_bits(s: &Samples) -> Vec<u64> {
    s.iter()
        .flat_map(|(o, x)| o.pos_m.iter().chain(&o.att_deg).chain(x).copied())
        .map(f64::to_bits)
        .collect()
}

#[test]
fn lanes_with_and_without_wind_keep_the_bits_of_their_scalar_runs() {
    let sim = Simulator::embedded_default();
    let model = sim.model();
    let runs: Vec<RunSetup> = [
        vec![],
        vec![gust(Axis::WindY, Regressor::WindStep, 0.2, 0.1, 3.0)],
        vec![gust(Axis::WindZ, Regressor::WindPulse, 0.1, 0.15, -4.0)],
        vec![
            gust(Axis::WindY, Regressor::WindPulse, 0.3, 0.05, 2.0),
            Term {
                axis: Axis::Cn,
                regressor: Regressor::Beta,
                locator: [0.0; 2],
                coefficient: 0.1,
            },
        ],
        vec![],
    ]
    .iter()
    .map(|terms| {
        let set = TermSet::of(terms).unwrap();
        sim.run_setup_with(&Factors::TRUTH, &EffectSet::NONE, &set)
            .unwrap()
    })
    .collect();
    let times: Vec<f64> = (0..300).map(|j| -0.01 + j as f64 / 333.0).collect();
    let scalar: Vec<Vec<u64>> = runs
        .iter()
        .map(|run| {
            let mut s = Samples::new();
            propagate(model, run, &times, &mut s).unwrap();
            sample_bits(&s)
        })
        .collect();
    assert!(
        scalar[1] != scalar[0] && scalar[2] != scalar[0],
        "the winds act"
    );
    assert_eq!(scalar[0], scalar[4]);
    for start in 0..runs.len() {
        let batch: Vec<RunSetup> = (0..LANES)
            .map(|i| runs[(start + i) % runs.len()].clone())
            .collect();
        let mut sinks = vec![Samples::new(); batch.len()];
        for r in propagate_lanes(model, &batch, &times, &mut sinks) {
            r.unwrap();
        }
        for (i, s) in sinks.iter().enumerate() {
            let run = (start + i) % runs.len();
            assert!(
                sample_bits(s) == scalar[run],
                "lane {i} (run {run}) differs"
            );
        }
    }
}

#[test]
fn the_edges_of_rise_s_simulate() {
    for rise_s in [RISE_S.min, RISE_S.max] {
        for regressor in [Regressor::WindStep, Regressor::WindPulse] {
            let t = gust(Axis::WindZ, regressor, 0.3, rise_s, 10.0);
            let mut s = Scenario::embedded_default();
            s.extension = vec![TermRecord::of(&t)];
            let sim = Simulator::new(&s);
            let traj = sim
                .simulate(&Factors::TRUTH, &EffectSet::NONE, &sim.default_times())
                .unwrap_or_else(|e| panic!("{t:?} does not simulate: {e}"));
            assert!(
                traj.pos_m
                    .iter()
                    .chain(&traj.att_deg)
                    .all(|v| v.iter().all(|x| x.is_finite()))
            );
        }
        assert!(!RISE_S.contains(RISE_S.above_max()));
    }
}
