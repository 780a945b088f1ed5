//! The effect catalogue (docs/model.md section 7), each effect tested from its definition.

#![allow(clippy::needless_range_loop)] // index loops over x, y, z read like the equations

use nalgebra::{Matrix3, Vector3};
use sepval_common::effects::{CATALOGUE, EffectSet};
use sepval_common::frames::{
    dcm_from_quaternion, euler_321_deg, quaternion_from_euler_321, wrap_deg,
};
use sepval_common::model::{RunSetup, StateVector};
use sepval_common::propagator::{Observation, propagate};
use sepval_common::{Factors, Simulator, Trajectory};

/// A base that is not the default truth.
const BASE: Factors = Factors([
    0.45, 0.65, 0.98, 1.03, 0.97, -0.02, 0.04, -0.06, 0.1, -0.08, -0.05, 1.1, 1.4, 0.9, 1.3, 0.8,
    1.6,
]);

fn effects(spec: &str) -> EffectSet {
    let mut set = EffectSet::NONE;
    set.push_spec(spec).unwrap();
    set
}

fn run_of(sim: &Simulator, set: &EffectSet) -> RunSetup {
    sim.run_setup(&BASE, set).unwrap()
}

/// A state in flight with incidence, sideslip, rates and a displaced CG.
fn flying_state() -> StateVector {
    let q = quaternion_from_euler_321(0.2, 0.15, -0.1);
    [
        0.3, -0.1, 1.2, -2.0, 1.5, 6.0, q[0], q[1], q[2], q[3], 0.4, -0.3, 0.2,
    ]
}

fn trajectory(sim: &Simulator, set: &EffectSet, times: &[f64]) -> Trajectory {
    sim.simulate(&BASE, set, times).unwrap()
}

#[test]
fn every_effect_at_its_neutral_value_reproduces_the_baseline_exactly() {
    let sim = Simulator::embedded_default();
    let times = sim.default_times();
    let baseline = trajectory(&sim, &EffectSet::NONE, &times);
    for (index, effect) in CATALOGUE.iter().enumerate() {
        let neutral: Vec<f64> = effect.params().iter().map(|p| p.neutral).collect();
        let mut set = EffectSet::NONE;
        set.push(index, &neutral).unwrap();
        let t = trajectory(&sim, &set, &times);
        assert_eq!(t.pos_m, baseline.pos_m, "{}", effect.id());
        assert_eq!(t.att_deg, baseline.att_deg, "{}", effect.id());
    }
}

#[test]
fn every_effect_changes_the_trajectory_away_from_neutral() {
    let sim = Simulator::embedded_default();
    let times = sim.default_times();
    let baseline = trajectory(&sim, &EffectSet::NONE, &times);
    for (index, effect) in CATALOGUE.iter().enumerate() {
        let values: Vec<f64> = effect
            .params()
            .iter()
            .map(|p| p.neutral + p.scale)
            .collect();
        let mut set = EffectSet::NONE;
        set.push(index, &values).unwrap();
        let t = trajectory(&sim, &set, &times);
        let g = sepval_common::goals::goals_between(&baseline, &t).unwrap();
        assert!(
            g.j_pos_m > 1e-4 || g.j_att_deg > 1e-3,
            "{}: {g:?}",
            effect.id()
        );
    }
}

/// Derivative difference with and without an effect, at a flying state.
fn derivative_change(sim: &Simulator, spec: &str, x: &StateVector) -> (StateVector, StateVector) {
    let base = run_of(sim, &EffectSet::NONE).derivative(&sim.model().curve, x, [false; 2]);
    let with = run_of(sim, &effects(spec)).derivative(&sim.model().curve, x, [false; 2]);
    (base, with)
}

/// Flow angles, qbar S and C_LB of a state, computed here from docs/model.md section 3.
fn flow(sim: &Simulator, x: &StateVector) -> (f64, f64, f64, Matrix3<f64>) {
    let run = run_of(sim, &EffectSet::NONE);
    let c = dcm_from_quaternion([x[6], x[7], x[8], x[9]]);
    let air = Vector3::new(x[3], x[4], x[5]) + run.v_aircraft_air_l_m_s;
    let b = c.transpose() * air;
    let speed = air.norm();
    (
        b.z.atan2(b.x),
        (b.y / speed).asin(),
        run.half_rho_area * speed * speed,
        c,
    )
}

#[test]
fn roll_due_to_sideslip_adds_cl_beta_times_beta() {
    let sim = Simulator::embedded_default();
    let x = flying_state();
    let (base, with) = derivative_change(&sim, "roll_due_to_sideslip=-0.31", &x);
    let (_, beta, qs, _) = flow(&sim, &x);
    let run = run_of(&sim, &EffectSet::NONE);
    let expected = qs * run.diameter_m * (-0.31 * beta) / run.inertia_kg_m2[(0, 0)];
    assert!(((with[10] - base[10]) - expected).abs() < 1e-9 * expected.abs().max(1.0));
    assert_eq!(with[11], base[11]);
    assert_eq!(with[3..6], base[3..6]);
}

#[test]
fn pitch_stiffness_cubic_adds_cm_alpha3_times_alpha_cubed() {
    let sim = Simulator::embedded_default();
    let x = flying_state();
    let (base, with) = derivative_change(&sim, "pitch_stiffness_cubic=25", &x);
    let (alpha, _, qs, _) = flow(&sim, &x);
    let run = run_of(&sim, &EffectSet::NONE);
    let expected = qs * run.diameter_m * 25.0 * alpha.powi(3) / run.inertia_kg_m2[(1, 1)];
    assert!(((with[11] - base[11]) - expected).abs() < 1e-9 * expected.abs().max(1.0));
    assert_eq!(with[10], base[10]);
}

#[test]
fn cg_offset_moves_moments_and_foot_arms_to_the_true_cg() {
    let sim = Simulator::embedded_default();
    let x = flying_state();
    let dx = 0.07;
    let base_run = run_of(&sim, &EffectSet::NONE);
    let run = run_of(&sim, &effects("cg_offset=0.07"));
    for i in 0..2 {
        assert_eq!(run.feet[i].x_m, base_run.feet[i].x_m - dx);
    }
    let (base, with) = derivative_change(&sim, "cg_offset=0.07", &x);
    // Forces unchanged; Cm += CZ dx/d, Cn -= CY dx/d, i.e. M += (-dx, 0, 0) x F_B.
    assert_eq!(with[3..6], base[3..6]);
    let (_, _, _, c) = flow(&sim, &x);
    let m = 1.0 / base_run.inv_mass_per_kg;
    let f_l = (Vector3::new(base[3], base[4], base[5]) - base_run.gravity_l_m_s2) * m;
    let f_b = c.transpose() * f_l;
    let d_my = dx * f_b.z / base_run.inertia_kg_m2[(1, 1)];
    let d_mz = -dx * f_b.y / base_run.inertia_kg_m2[(2, 2)];
    assert!(((with[11] - base[11]) - d_my).abs() < 1e-9);
    assert!(((with[12] - base[12]) - d_mz).abs() < 1e-9);
    // The ejector stroke of each foot is measured at its new arm.
    let x0 = run.initial_state();
    let ejected = run.derivative(&sim.model().curve, &x0, [true, true]);
    let coasting = run.derivative(&sim.model().curve, &x0, [false, false]);
    let lever: f64 = run.feet.iter().map(|f| f.x_m * f.fac).sum();
    let force = sim.model().curve.force_n(0.0);
    let expected_q_dot = -force * lever / base_run.inertia_kg_m2[(1, 1)];
    let got = ejected[11] - coasting[11];
    assert!(
        (got - expected_q_dot).abs() < 1e-9 * expected_q_dot.abs(),
        "{got} vs {expected_q_dot}"
    );
}

#[test]
fn inertia_product_xz_uses_the_full_tensor() {
    let sim = Simulator::embedded_default();
    let x = flying_state();
    let ixz = 12.0;
    let base_run = run_of(&sim, &EffectSet::NONE);
    let (base, with) = derivative_change(&sim, "inertia_product_xz=12", &x);
    // Recover the moment from the baseline: M = I dw + w x (I w).
    let w = Vector3::new(x[10], x[11], x[12]);
    let i0 = base_run.inertia_kg_m2;
    let m = i0 * Vector3::new(base[10], base[11], base[12]) + w.cross(&(i0 * w));
    let mut i1 = i0;
    i1[(0, 2)] = -ixz;
    i1[(2, 0)] = -ixz;
    let expected = i1.try_inverse().unwrap() * (m - w.cross(&(i1 * w)));
    for k in 0..3 {
        assert!((with[10 + k] - expected[k]).abs() < 1e-9, "axis {k}");
    }
    // Too large a product makes the tensor indefinite: refused.
    let e = sim
        .run_setup(&BASE, &effects("inertia_product_xz=500"))
        .err()
        .unwrap();
    assert!(e.to_string().contains("not positive definite"), "{e}");
}

#[test]
fn ejector_delay_lets_the_store_fall_freely_until_tau() {
    let sim = Simulator::embedded_default();
    let tau = 0.012_3;
    let set = effects("ejector_delay=0.0123");
    let (_, log) = sim.simulate_logged(&BASE, &set, &[0.2]).unwrap();
    assert_eq!(log.foot_on_s, [Some(tau), Some(tau)]);
    // Before tau the motion is that of a store without ejector.
    let times = [0.004, 0.008, 0.012];
    let delayed = sim.simulate(&BASE, &set, &times).unwrap();
    let model = sim.model();
    let mut run = sim.run_setup(&BASE, &EffectSet::NONE).unwrap();
    run.feet[0].fac = 0.0;
    run.feet[1].fac = 0.0;
    let mut free: Vec<Observation> = Vec::new();
    propagate(model, &run, &times, &mut free).unwrap();
    for k in 0..times.len() {
        assert_eq!(delayed.pos_m[k], free[k].pos_m);
    }
    // Negative delays are refused.
    let mut bad = EffectSet::NONE;
    bad.push_spec("ejector_delay=-0.01").unwrap();
    let err = sim.run_setup(&BASE, &bad).err().unwrap().to_string();
    assert_eq!(
        err,
        "effect `ejector_delay`: parameter tau = -0.01 must be >= 0"
    );
}

#[test]
fn ejector_cant_turns_the_force_about_launch_x() {
    let sim = Simulator::embedded_default();
    let kappa: f64 = 0.1;
    let run = run_of(&sim, &effects("ejector_cant=0.1"));
    let x = run.initial_state();
    let d = run.derivative(&sim.model().curve, &x, [true, true]);
    let base = run_of(&sim, &EffectSet::NONE).derivative(&sim.model().curve, &x, [true, true]);
    // At carriage (no aero difference) the ejector's L-frame acceleration turns by kappa.
    let g = run.gravity_l_m_s2;
    let a_base = Vector3::new(base[3], base[4], base[5]) - g;
    let a = Vector3::new(d[3], d[4], d[5]) - g;
    let ej = a - a_base; // difference is only the turned ejector part
    let total_ej = run.feet.iter().map(|f| f.fac).sum::<f64>()
        * sim.model().curve.force_n(0.0)
        * run.inv_mass_per_kg;
    assert!((ej.y - (-kappa.sin() * total_ej)).abs() < 1e-9);
    assert!((ej.z - ((kappa.cos() - 1.0) * total_ej)).abs() < 1e-9);
}

#[test]
fn interference_decay_scales_lambda() {
    let sim = Simulator::embedded_default();
    let run = run_of(&sim, &effects("interference_decay=1.5"));
    assert!((run.decay.lambda_m - 0.9).abs() < 1e-15);
    assert_eq!(run.decay.s_end_m, 9.144);
    let s: f64 = 1.7;
    let e_end = (-9.144f64 / 0.9).exp();
    let expected = ((-s / 0.9).exp() - e_end) / (1.0 - e_end);
    assert!((run.decay.factor(s) - expected).abs() < 1e-15);
}

#[test]
fn release_rates_set_the_initial_body_rates() {
    let sim = Simulator::embedded_default();
    let run = run_of(&sim, &effects("release_rates=0.3,-0.2,0.1"));
    let x = run.initial_state();
    assert_eq!(&x[10..13], &[0.3, -0.2, 0.1]);
    // The attitude starts moving at once: roll ~ p0 t.
    let t = sim
        .simulate(&BASE, &effects("release_rates=0.3,-0.2,0.1"), &[0.001])
        .unwrap();
    let b = sim.simulate(&BASE, &EffectSet::NONE, &[0.001]).unwrap();
    let d_roll = (t.att_deg[0][0] - b.att_deg[0][0]).to_radians();
    assert!((d_roll - 0.3e-3).abs() < 2e-5, "{d_roll}");
}

#[test]
fn telemetry_time_offset_shifts_the_clock() {
    let sim = Simulator::embedded_default();
    let dt_tm = 0.01; // 20 grid steps: the shifted samples fall on the grid
    let times = sim.default_times();
    let shifted = trajectory(&sim, &effects("telemetry_time_offset=0.01"), &times);
    let later: Vec<f64> = times.iter().map(|t| t + dt_tm).collect();
    let reference = trajectory(&sim, &EffectSet::NONE, &later);
    assert_eq!(shifted.pos_m, reference.pos_m);
    assert_eq!(shifted.att_deg, reference.att_deg);
    // A negative offset shows the carriage state before release.
    let early = trajectory(&sim, &effects("telemetry_time_offset=-0.02"), &times);
    assert_eq!(early.pos_m[0], [0.0; 3]);
    assert_eq!(early.pos_m[3], [0.0; 3]);
    assert_ne!(early.pos_m[5], [0.0; 3]);
}

#[test]
fn attitude_bias_adds_to_the_measured_angles() {
    let sim = Simulator::embedded_default();
    let times = sim.default_times();
    let base = trajectory(&sim, &EffectSet::NONE, &times);
    let b: [f64; 3] = [0.01, -0.02, 3.1];
    let biased = trajectory(&sim, &effects("attitude_bias=0.01,-0.02,3.1"), &times);
    for k in 0..times.len() {
        assert_eq!(biased.pos_m[k], base.pos_m[k]);
        let e = [
            wrap_deg(base.att_deg[k][0] + b[0].to_degrees()),
            base.att_deg[k][1] + b[1].to_degrees(),
            wrap_deg(base.att_deg[k][2] + b[2].to_degrees()),
        ];
        for j in 0..3 {
            assert!((biased.att_deg[k][j] - e[j]).abs() < 1e-12);
        }
        assert!(biased.att_deg[k][2] > -180.0 && biased.att_deg[k][2] <= 180.0);
    }
}

#[test]
fn tracked_point_offset_reports_a_body_point() {
    let sim = Simulator::embedded_default();
    let times = sim.default_times();
    let l = 0.4;
    let set = effects("tracked_point_offset=0.4");
    let tracked = trajectory(&sim, &set, &times);
    let run = run_of(&sim, &EffectSet::NONE);
    let mut states: Vec<(Observation, StateVector)> = Vec::new();
    propagate(sim.model(), &run, &times, &mut states).unwrap();
    for (k, (obs, x)) in states.iter().enumerate() {
        let c = dcm_from_quaternion([x[6], x[7], x[8], x[9]]);
        let p = Vector3::new(x[0], x[1], x[2]) + c * Vector3::new(l, 0.0, 0.0)
            - Vector3::new(l, 0.0, 0.0);
        for j in 0..3 {
            assert!((tracked.pos_m[k][j] - p[j]).abs() < 1e-15);
        }
        assert_eq!(tracked.att_deg[k], obs.att_deg);
        assert_eq!(obs.att_deg, euler_321_deg(&c).map(|a| a + 0.0));
    }
}

#[test]
fn an_effect_that_names_its_term_is_that_term() {
    // `Effect::as_term`: the diagnosis does not call the two rivals, so they must simulate
    // the same release (the same sum in the same coefficient; the order of two additions may
    // differ, so to rounding).
    use sepval_common::extension::{Term, TermSet};
    let sim = Simulator::embedded_default();
    let times = sim.default_times();
    let mut checked = 0;
    for effect in CATALOGUE.iter() {
        let Some((axis, regressor)) = effect.as_term() else {
            continue;
        };
        let value = 0.4 * effect.params()[0].scale;
        let set = effects(&format!("{}={value}", effect.id()));
        let by_effect = trajectory(&sim, &set, &times);
        let mut terms = TermSet::NONE;
        terms
            .push(Term {
                axis,
                regressor,
                locator: [0.0; 2],
                coefficient: value,
            })
            .unwrap();
        let run = sim.run_setup_with(&BASE, &EffectSet::NONE, &terms).unwrap();
        let mut obs: Vec<Observation> = Vec::new();
        propagate(sim.model(), &run, &times, &mut obs).unwrap();
        let baseline = trajectory(&sim, &EffectSet::NONE, &times);
        let mut moved = 0.0_f64;
        for (k, o) in obs.iter().enumerate() {
            for i in 0..3 {
                let d = (o.att_deg[i] - by_effect.att_deg[k][i]).abs();
                assert!(d < 1e-9, "{} at sample {k}: {d}", effect.id());
                assert!((o.pos_m[i] - by_effect.pos_m[k][i]).abs() < 1e-9);
                moved = moved.max((o.att_deg[i] - baseline.att_deg[k][i]).abs());
            }
        }
        assert!(moved > 1e-3, "{} does not move the store", effect.id());
        checked += 1;
    }
    assert_eq!(checked, 2, "roll_due_to_sideslip and pitch_stiffness_cubic");
}
