//! Verification of the integrator and the model against known solutions (issue 2, item 5).
//! Run in release: `cargo test --release -p sepval-common`.

#![allow(clippy::needless_range_loop)] // index loops over x, y, z read like the equations

use nalgebra::{Matrix3, Vector3};
use sepval_common::frames::dcm_from_quaternion;
use sepval_common::model::{Model, RunSetup, StateVector};
use sepval_common::propagator::{Observation, propagate};
use sepval_common::simulation::sample_times;
use sepval_common::{EffectSet, Factors, Scenario, Simulator};

fn states(model: &Model, run: &RunSetup, times: &[f64]) -> Vec<(Observation, StateVector)> {
    let mut out: Vec<(Observation, StateVector)> = Vec::new();
    propagate(model, run, times, &mut out).expect("finite run");
    out
}

/// A run with every force switched off except gravity (which the caller may also zero).
fn force_free(model: &Model) -> RunSetup {
    let mut run = RunSetup::new(model, &Factors::NOMINAL, &EffectSet::NONE).unwrap();
    run.half_rho_area = 0.0;
    for foot in run.feet.iter_mut() {
        foot.fac = 0.0;
    }
    run
}

#[test]
fn torque_free_motion_conserves_energy_and_angular_momentum() {
    // An asymmetric body spinning about all three axes (Euler's equations, no torque).
    let mut scenario = Scenario::embedded_default();
    scenario.store.ixx_kg_m2 = 27.0;
    scenario.store.iyy_kg_m2 = 488.0;
    scenario.store.izz_kg_m2 = 300.0;
    let model = Model::new(&scenario);
    let mut run = force_free(&model);
    run.gravity_l_m_s2 = Vector3::zeros();
    run.initial_rates_rad_s = Vector3::new(3.0, 0.7, -1.2);
    let i: Matrix3<f64> = run.inertia_kg_m2;
    let x = states(&model, &run, &sample_times(1.0, 200.0));
    let invariants = |s: &StateVector| {
        let w = Vector3::new(s[10], s[11], s[12]);
        let c = dcm_from_quaternion([s[6], s[7], s[8], s[9]]);
        (0.5 * w.dot(&(i * w)), c * (i * w))
    };
    let (e0, h0) = invariants(&x[0].1);
    for (_, s) in &x {
        let (e, h) = invariants(s);
        assert!(
            ((e - e0) / e0).abs() < 1e-9,
            "energy drift {}",
            (e - e0) / e0
        );
        assert!(
            (h - h0).norm() / h0.norm() < 1e-9,
            "momentum drift {}",
            (h - h0).norm() / h0.norm()
        );
    }
}

#[test]
fn free_fall_matches_half_g_t_squared() {
    let model = Model::new(&Scenario::embedded_default());
    let run = force_free(&model);
    let times = sample_times(1.0, 200.0);
    let x = states(&model, &run, &times);
    for ((obs, _), t) in x.iter().zip(&times) {
        let expected = 0.5 * 9.80665 * t * t;
        assert!(
            (obs.pos_m[2] - expected).abs() < 1e-12,
            "t {t}: {} vs {expected}",
            obs.pos_m[2]
        );
        assert_eq!(obs.pos_m[0], 0.0);
        assert_eq!(obs.att_deg, [0.0; 3]);
    }
}

#[test]
fn halving_the_step_changes_the_event_by_less_than_1e6() {
    let coarse = Simulator::embedded_default();
    let mut scenario = Scenario::embedded_default();
    scenario.integrator.dt_s /= 2.0;
    let fine = Simulator::new(&scenario);
    let times = [0.05, 0.1, 0.5, 1.0];
    for factors in [Factors::TRUTH, Factors::NOMINAL] {
        let a = coarse.simulate(&factors, &EffectSet::NONE, &times).unwrap();
        let b = fine.simulate(&factors, &EffectSet::NONE, &times).unwrap();
        for k in 0..times.len() {
            for j in 0..3 {
                assert!((a.pos_m[k][j] - b.pos_m[k][j]).abs() < 1e-6, "pos {k} {j}");
                assert!(
                    (a.att_deg[k][j] - b.att_deg[k][j]).abs() < 1e-6,
                    "att {k} {j}"
                );
            }
        }
    }
}

/// The stroke ends, computed independently: plain RK4 with a 100 times smaller step; a step
/// in which a foot passes the stroke is redone in two parts split at the linearly
/// interpolated crossing (no iteration), which is accurate to O(h^2).
#[test]
fn stroke_end_times_agree_with_an_independent_crossing() {
    let sim = Simulator::embedded_default();
    let model = sim.model();
    let run = sim.run_setup(&Factors::TRUTH, &EffectSet::NONE).unwrap();
    let (_, log) = sim
        .simulate_logged(&Factors::TRUTH, &EffectSet::NONE, &[0.1])
        .unwrap();
    let rk4 = |x: &StateVector, h: f64, on: [bool; 2]| -> StateVector {
        let f = |y: &StateVector| run.derivative(&model.curve, y, on);
        let k1 = f(x);
        let k2 = f(&std::array::from_fn(|j| x[j] + 0.5 * h * k1[j]));
        let k3 = f(&std::array::from_fn(|j| x[j] + 0.5 * h * k2[j]));
        let k4 = f(&std::array::from_fn(|j| x[j] + h * k3[j]));
        std::array::from_fn(|j| x[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]))
    };
    let s_of = |x: &StateVector, i: usize| {
        let c = dcm_from_quaternion([x[6], x[7], x[8], x[9]]);
        x[2] + c[(2, 0)] * run.feet[i].x_m
    };
    let h = model.dt_s / 100.0;
    let mut x = run.initial_state();
    let mut on = [true, true];
    let mut found = [None::<f64>; 2];
    let mut t = 0.0;
    while found.iter().any(Option::is_none) {
        let y = rk4(&x, h, on);
        let crossing = (0..2).find(|&i| on[i] && s_of(&y, i) > run.stroke_m);
        x = match crossing {
            Some(i) => {
                let (s0, s1) = (s_of(&x, i), s_of(&y, i));
                let h1 = h * (run.stroke_m - s0) / (s1 - s0);
                found[i] = Some(t + h1);
                let mid = rk4(&x, h1, on);
                on[i] = false;
                rk4(&mid, h - h1, on)
            }
            None => y,
        };
        t += h;
        assert!(t < 0.2, "no stroke end found");
    }
    for i in 0..2 {
        let located = log.foot_off_s[i].unwrap();
        let independent = found[i].unwrap();
        assert!(
            (located - independent).abs() < 1e-9,
            "foot {i}: {located} vs {independent}"
        );
    }
}

#[test]
fn off_grid_samples_lie_on_the_trajectory() {
    // A sample between grid points is one RK4 step from the grid state before it; it must agree
    // with the same time reached by a scenario whose grid contains it.
    let sim = Simulator::embedded_default();
    let t = 0.123_456_7;
    let a = sim
        .simulate(&Factors::TRUTH, &EffectSet::NONE, &[t])
        .unwrap();
    let b = sim
        .simulate(&Factors::TRUTH, &EffectSet::NONE, &[0.1234, 0.1235])
        .unwrap();
    for j in 0..3 {
        assert!(a.pos_m[0][j] > b.pos_m[0][j].min(b.pos_m[1][j]) - 1e-9);
        assert!(a.pos_m[0][j] < b.pos_m[0][j].max(b.pos_m[1][j]) + 1e-9);
    }
    // And an off-grid sample inside a stroke-end interval is split at the switch.
    let c = sim
        .simulate(&Factors::TRUTH, &EffectSet::NONE, &[0.05235])
        .unwrap();
    let d = sim
        .simulate(&Factors::TRUTH, &EffectSet::NONE, &[0.0523, 0.0524])
        .unwrap();
    assert!(c.pos_m[0][2] > d.pos_m[0][2] && c.pos_m[0][2] < d.pos_m[1][2]);
}

#[test]
fn divergence_is_reported_with_its_time() {
    // A wildly unstable store: huge pitch instability with a tiny pitch inertia.
    let mut scenario = Scenario::embedded_default();
    scenario.aero.cm_alpha_per_rad =
        Some(sepval_common::table::DerivativeCoefficient::constant(500.0));
    scenario.store.iyy_kg_m2 = 0.5;
    let sim = Simulator::new(&scenario);
    let err = sim
        .simulate(&Factors::TRUTH, &EffectSet::NONE, &sim.default_times())
        .unwrap_err();
    match err {
        sepval_common::simulation::SimError::Diverged(d) => {
            assert!(d.t_s > 0.0 && d.t_s < 1.0, "{}", d.t_s)
        }
        other => panic!("expected divergence, got {other}"),
    }
}

/// The run-time dispatch (an FMA build of the integrator on hosts that have the instructions)
/// changes nothing: the portable build gives the same bits, with every effect.
#[test]
fn dispatched_and_portable_builds_agree_bit_for_bit() {
    let sim = Simulator::embedded_default();
    let model = sim.model();
    let mut times = sim.default_times();
    times.extend([1.001_23, 1.05]);
    let mut sets = vec![EffectSet::NONE];
    for spec in [
        "roll_due_to_sideslip=-0.31",
        "pitch_stiffness_cubic=25",
        "cg_offset=0.07",
        "inertia_product_xz=12",
        "ejector_delay=0.0123",
        "ejector_cant=0.1",
        "release_rates=0.3,-0.2,0.1",
        "telemetry_time_offset=0.0123",
    ] {
        let mut set = EffectSet::NONE;
        set.push_spec(spec).unwrap();
        sets.push(set);
    }
    for factors in [Factors::TRUTH, Factors::NOMINAL] {
        for set in &sets {
            let run = RunSetup::new(model, &factors, set).unwrap();
            let mut portable: Vec<(Observation, StateVector)> = Vec::new();
            let log_portable =
                sepval_common::propagator::propagate_portable(model, &run, &times, &mut portable)
                    .unwrap();
            let mut dispatched: Vec<(Observation, StateVector)> = Vec::new();
            let log_dispatched = propagate(model, &run, &times, &mut dispatched).unwrap();
            assert_eq!(log_portable, log_dispatched);
            for ((_, a), (_, b)) in portable.iter().zip(&dispatched) {
                assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
            }
        }
    }
}
