//! The flowfield interference model (docs/model.md section 3b): a uniform field is a change of
//! the store's flow angle, the loads agree with the independent reference implementation
//! (`scripts/reference_model.py`) at a state off carriage and along a whole release, the lanes
//! keep the scalar runs' bits, and a scenario that asks for what the field cannot do is refused
//! naming the field.

use sepval_common::model::{Coefficients, EquationsOfMotion, FlowfieldRun};
use sepval_common::scenario::Scenario;
use sepval_common::{EffectSet, Factors, Simulator};

/// The guide's example store under a field (`examples/flowfield-store/scenario.toml`): the
/// default with its six decay increments 0 and docs/model.md section 3b's conformance field.
pub(crate) const EXAMPLE: &str = include_str!("../../../examples/flowfield-store/scenario.toml");

/// The conformance scenario: [`EXAMPLE`].
pub(crate) fn conformance_scenario() -> Scenario {
    Scenario::from_toml_str(EXAMPLE, "flowfield").unwrap()
}

/// [`EXAMPLE`] with `from` (which it holds) replaced by `to`.
pub(crate) fn example_with(from: &str, to: &str) -> String {
    assert!(EXAMPLE.contains(from), "the example has `{from}`");
    EXAMPLE.replacen(from, to, 1)
}

pub(crate) fn refusal(text: &str) -> String {
    Scenario::from_toml_str(text, "f.toml")
        .unwrap_err()
        .to_string()
}

/// The largest difference in position \[m\] and attitude \[deg\] between the releases of
/// `a` and `b` at `factors` (the default event's samples).
pub(crate) fn largest_difference(a: &Scenario, b: &Scenario, factors: &Factors) -> (f64, f64) {
    use sepval_common::propagator::{Observation, propagate};
    let fly = |s: &Scenario| {
        let sim = Simulator::new(s);
        let run = sim.run_setup(factors, &EffectSet::NONE).unwrap();
        let mut samples: Vec<Observation> = Vec::new();
        propagate(sim.model(), &run, &sim.default_times(), &mut samples).unwrap();
        samples
    };
    let (a, b) = (fly(a), fly(b));
    let (mut pos_m, mut att_deg) = (0.0f64, 0.0f64);
    for (a, b) in a.iter().zip(&b) {
        for j in 0..3 {
            pos_m = pos_m.max((a.pos_m[j] - b.pos_m[j]).abs());
            att_deg = att_deg.max((a.att_deg[j] - b.att_deg[j]).abs());
        }
    }
    (pos_m, att_deg)
}

#[test]
fn a_uniform_field_is_a_change_of_flow_angle() {
    // No gradient, no change of dynamic pressure, the store level at carriage: every station
    // sees the same upwash and sidewash, and the loads are the store's own derivatives times
    // them (docs/model.md section 3b).
    let text = example_with("upwash_gradient_deg_per_m = -1.0", "")
        .replace("sidewash_gradient_deg_per_m = 0.5", "")
        .replace("dynamic_pressure_ratio = 0.9", "");
    let scenario = Scenario::from_toml_str(&text, "uniform").unwrap();
    let sim = Simulator::new(&scenario);
    let run = sim.run_setup(&Factors::TRUTH, &EffectSet::NONE).unwrap();
    let f: FlowfieldRun = run.flowfield.expect("the scenario has a field");
    let [alpha_i, beta_i, eta] = f.at([0.0, 0.0, 0.0]);
    assert!(eta == 1.0 && alpha_i > 0.01 && beta_i < -0.005);
    let a = &sim.model().aero_at_mach;
    for (alpha, beta) in [(0.0, 0.0), (0.05, -0.02)] {
        let k = f.add_loads(
            [0.0; 3],
            [1.0, 0.0, 0.0],
            0.0,
            alpha,
            beta,
            Coefficients::default(),
        );
        let close = |got: f64, want: f64| (got - want).abs() < 1e-15 * want.abs().max(1.0);
        assert!(close(k.cz, a.cz_alpha_per_rad * alpha_i), "{k:?}");
        assert!(close(k.cm, a.cm_alpha_per_rad * alpha_i), "{k:?}");
        assert!(close(k.cy, a.cy_beta_per_rad * beta_i), "{k:?}");
        assert!(close(k.cn, a.cn_beta_per_rad * beta_i), "{k:?}");
        assert!(k.cx == 0.0);
    }
}

#[test]
fn a_scenario_without_a_field_is_unchanged_and_one_with_a_field_moves_the_store() {
    let default = Scenario::embedded_default();
    assert!(default.flowfield.is_none());
    let text = toml::to_string(&default).unwrap();
    assert!(!text.contains("flowfield"), "no [flowfield] is written");
    let sim = Simulator::new(&conformance_scenario());
    let run = sim.run_setup(&Factors::TRUTH, &EffectSet::NONE).unwrap();
    let x0 = run.initial_state();
    let with = EquationsOfMotion::new(&run, &sim.model().curve).derivative(&x0, 0.0, [true; 2]);
    let mut still = run;
    still.flowfield = None;
    let without =
        EquationsOfMotion::new(&still, &sim.model().curve).derivative(&x0, 0.0, [true; 2]);
    // At carriage the field pushes the store (upwash: up, CZ_alpha < 0) and pitches it.
    assert!(with[5] < without[5], "dw/dt {} vs {}", with[5], without[5]);
    assert!(with[11] != without[11]);
}

#[test]
fn lanes_equal_scalar_runs_bit_for_bit_with_a_field() {
    // Every catalogue effect (interference_decay scales the field's depth, cg_offset moves its
    // stations) on three bases, with diverging runs, through the lanes.
    let sim = Simulator::new(&conformance_scenario());
    crate::lanes::check_lanes_against_scalar(&sim, &sim.default_times());
}

#[test]
fn what_the_field_cannot_do_is_refused_naming_the_field() {
    let cases = [
        (
            example_with("dcx0 = 0.0", "dcx0 = -0.10"),
            "interference.dcx0",
            "must be the constant 0",
        ),
        (
            example_with("stations = 5", "stations = 1"),
            "flowfield.stations",
            "expected 2 to 16",
        ),
        (
            example_with("upwash_deg = 3.0", "upwash_deg = 1e300"),
            "flowfield.upwash_deg",
            "= 1e300: expected a finite angle within +-45 deg",
        ),
        (
            example_with("tail_x_m = -1.5", "tail_x_m = 2.0"),
            "flowfield.nose_x_m",
            "nose ahead of the tail",
        ),
        (
            example_with("tail_x_m = -1.5", "tail_x_m = 1.4999999999999998"),
            "flowfield.nose_x_m",
            "- tail_x_m = 2.220446049250313e-16 m: expected a store from 0.001 to 1000 m long",
        ),
        (
            example_with("half_depth_m = 0.8", "half_depth_m = 0.0"),
            "flowfield.half_depth_m",
            "> 0",
        ),
        (
            example_with("reversal_m = 2.0", "reversal_m = -1.0"),
            "flowfield.reversal_m",
            "> 0",
        ),
        (
            example_with("upwash_deg = 3.0", "upwash_deg = 60.0"),
            "flowfield.upwash_deg",
            "within +-45 deg",
        ),
        (
            example_with("reference_mach = 0.85\n", ""),
            "reference_mach",
            "missing field",
        ),
        (
            EXAMPLE.to_string() + "upwash_rad = 1.0\n",
            "upwash_rad",
            "unknown field",
        ),
        (
            example_with("cz_alpha_per_rad = -6.0", "cz_alpha_per_rad = 0.0"),
            "aero.cz_alpha_per_rad",
            "non-zero",
        ),
    ];
    for (text, field, reason) in cases {
        let message = refusal(&text);
        assert!(
            message.contains(field) && message.contains(reason),
            "expected `{field}` ... `{reason}`, got: {message}"
        );
    }
}

/// docs/model.md section 3b's conformance values, from `scripts/reference_model.py`: t, x, y,
/// z [m], roll, pitch, yaw [deg], truth factors, noise-free.
const CONFORMANCE: [[f64; 7]; 5] = [
    [
        0.05,
        -0.005668503,
        0.000689392,
        0.087214708,
        0.0595522,
        1.6834109,
        -0.0015095,
    ],
    [
        0.10,
        -0.023216448,
        0.002549419,
        0.276410306,
        0.2548666,
        4.9496899,
        0.0055412,
    ],
    [
        0.25,
        -0.159723987,
        0.011851506,
        0.934190771,
        1.9096580,
        13.7934004,
        0.2582104,
    ],
    [
        0.50,
        -0.766511492,
        0.033976789,
        2.191378463,
        8.6287325,
        26.4977215,
        2.1234767,
    ],
    [
        1.00,
        -4.443177434,
        0.215661244,
        4.590611029,
        37.6955178,
        48.3406935,
        16.0366532,
    ],
];

#[test]
fn the_conformance_case_agrees_with_the_independent_implementation() {
    assert_flies(&conformance_scenario(), &CONFORMANCE);
}

/// `scenario` at the truth factors, noise-free, flies through `rows` (t, x, y, z [m], roll,
/// pitch, yaw [deg]) to their printed digits: 2e-9 m and 2e-7 deg.
pub(crate) fn assert_flies(scenario: &Scenario, rows: &[[f64; 7]]) {
    let sim = Simulator::new(scenario);
    let times: Vec<f64> = rows.iter().map(|row| row[0]).collect();
    let traj = sim
        .simulate(&Factors::TRUTH, &EffectSet::NONE, &times)
        .unwrap();
    for (k, row) in rows.iter().enumerate() {
        for j in 0..3 {
            let d = (traj.pos_m[k][j] - row[1 + j]).abs();
            assert!(d < 2e-9, "t = {} s, position {j}: off by {d} m", row[0]);
            let d = (traj.att_deg[k][j] - row[4 + j]).abs();
            assert!(d < 2e-7, "t = {} s, angle {j}: off by {d} deg", row[0]);
        }
    }
}

#[test]
fn the_loads_off_carriage_agree_with_the_independent_implementation() {
    let expected = [
        0.09979289137980427,
        0.09475866791346009,
        -0.07356666360226327,
        -0.007995998999499687,
        -0.039486893089889764,
        -0.019190245628808625,
    ];
    let got = loads_at_the_reference_test_state(&conformance_scenario());
    for (name, (g, e)) in ["dCX", "dCY", "dCZ", "dCl", "dCm", "dCn"]
        .iter()
        .zip(got.iter().zip(expected))
    {
        assert!((g - e).abs() < 1e-13, "{name}: {g} vs the reference's {e}");
    }
}

/// The field's increments (dCX ... dCn) of `scenario` at the reference's test state
/// (`scripts/reference_model.py --json`): the store below and beside carriage, pitched, yawed
/// and rolled, moving and turning; truth factors.
pub(crate) fn loads_at_the_reference_test_state(scenario: &Scenario) -> [f64; 6] {
    let n = [0.99_f64, 0.02, 0.08, -0.03];
    let norm = n.iter().map(|v| v * v).sum::<f64>().sqrt();
    let q = n.map(|v| v / norm);
    let x = [
        0.3, -0.1, 0.6, 1.0, 0.5, 8.0, q[0], q[1], q[2], q[3], 0.2, 0.5, -0.3,
    ];
    let sim = Simulator::new(scenario);
    let run = sim.run_setup(&Factors::TRUTH, &EffectSet::NONE).unwrap();
    let flow = EquationsOfMotion::new(&run, &sim.model().curve).flow(&x, 0.0);
    let c = sepval_common::frames::dcm_from_quaternion(q);
    let base = Coefficients {
        cx: run.aero.cx0,
        ..Coefficients::default()
    };
    let k = run.flowfield.unwrap().add_loads(
        [x[0], x[1], x[2]],
        [c[(0, 0)], c[(1, 0)], c[(2, 0)]],
        0.0,
        flow.alpha_rad,
        flow.beta_rad,
        base,
    );
    [k.cx - base.cx, k.cy, k.cz, k.cl, k.cm, k.cn]
}

#[test]
fn small_changes_of_the_field_give_small_trajectory_changes() {
    // continuity.rs's test for the field (issue 36's property): each interference factor
    // (the field's upwash, gradient, sidewash, its gradient, dynamic pressure, rolling moment)
    // at several values, the second difference of the trajectory small beside its change.
    use sepval_common::Factor;
    use sepval_common::propagator::{Observation, propagate};
    let sim = Simulator::new(&conformance_scenario());
    let times = sim.default_times();
    let fly = |factor: Factor, u: f64| {
        let mut f = Factors::TRUTH;
        f.0[factor as usize] *= 1.0 + u;
        let run = sim.run_setup(&f, &EffectSet::NONE).unwrap();
        let mut samples: Vec<Observation> = Vec::new();
        propagate(sim.model(), &run, &times, &mut samples).unwrap();
        samples
    };
    let mut failures = Vec::new();
    for factor in [
        Factor::Czintfac,
        Factor::Cmintfac,
        Factor::Cyintfac,
        Factor::Cnintfac,
        Factor::Caintfac,
        Factor::Clintfac,
    ] {
        for start in [-0.2, 0.0, 0.1] {
            let step = 1e-6;
            let [a, b, c] = [0.0, 1.0, 2.0].map(|k| fly(factor, start + k * step));
            let (mut second, mut change) = (0.0f64, 0.0f64);
            for k in 0..a.len() {
                for j in 0..3 {
                    let d2 = |v: fn(&Observation) -> [f64; 3]| {
                        (v(&c[k])[j] - 2.0 * v(&b[k])[j] + v(&a[k])[j]).abs()
                    };
                    second = second.max(d2(|o| o.pos_m)).max(d2(|o| o.att_deg));
                    change = change
                        .max((c[k].pos_m[j] - a[k].pos_m[j]).abs())
                        .max((c[k].att_deg[j] - a[k].att_deg[j]).abs());
                }
            }
            if second > 1e-3 * change + 1e-12 {
                failures.push(format!(
                    "{factor:?} at 1 + {start}: second difference {second:.3e}, change {change:.3e}"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn lanes_whose_fields_differ_in_kind_keep_the_scalar_runs_bits() {
    // One scenario gives every run the same field; a run whose field was taken away by hand
    // (RunSetup's fields are public) sends the batch through the lane-by-lane path instead.
    use sepval_common::propagator::{LANES, Observation, propagate, propagate_lanes};
    let sim = Simulator::new(&conformance_scenario());
    let times = sim.default_times();
    let mut runs: Vec<_> = [
        Factors::TRUTH,
        Factors::NOMINAL,
        Factors::TRUTH,
        Factors::NOMINAL,
    ]
    .iter()
    .map(|f| sim.run_setup(f, &EffectSet::NONE).unwrap())
    .collect();
    runs[1].flowfield = None;
    runs[2].flowfield = None;
    assert_eq!(runs.len(), LANES);
    let bits = |s: &[Observation]| -> Vec<u64> {
        s.iter()
            .flat_map(|o| o.pos_m.iter().chain(&o.att_deg).map(|v| v.to_bits()))
            .collect()
    };
    let mut sinks = vec![Vec::<Observation>::new(); LANES];
    for r in propagate_lanes(sim.model(), &runs, &times, &mut sinks) {
        r.unwrap();
    }
    for (i, run) in runs.iter().enumerate() {
        let mut alone = Vec::<Observation>::new();
        propagate(sim.model(), run, &times, &mut alone).unwrap();
        assert!(
            bits(&sinks[i]) == bits(&alone),
            "lane {i} differs from its scalar run"
        );
    }
    assert!(
        bits(&sinks[0]) != bits(&sinks[2]),
        "the field moves the store"
    );
}

#[test]
fn lanes_equal_scalar_runs_bit_for_bit_with_corrections_of_the_fields_shape() {
    use sepval_common::correction::CorrectionValues;
    use sepval_common::extension::TermSet;
    use sepval_common::model::RunSetup;
    use sepval_common::propagator::{LANES, propagate, propagate_lanes};
    // docs/update.md section 15.3a: an update's refits carry the shape's corrections, each
    // candidate its own.
    let text = format!(
        "{EXAMPLE}\n[[correction]]\nfield = \"flowfield.half_depth_m\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n\
         \n[[correction]]\nfield = \"flowfield.reversal_m\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n"
    );
    let sim = Simulator::new(&Scenario::from_toml_str(&text, "shape").unwrap());
    let times = sim.default_times();
    let runs: Vec<RunSetup> = [[0.0, 0.0], [0.4, -0.2], [-0.6, 0.3], [1.5, 0.0], [0.1, 0.9]]
        .iter()
        .map(|v| {
            let values = CorrectionValues::of(v).unwrap();
            let none = (&EffectSet::NONE, &TermSet::NONE);
            RunSetup::with_corrections(sim.model(), &Factors::TRUTH, none.0, none.1, &values)
                .unwrap()
        })
        .collect();
    for batch in runs.chunks(LANES) {
        let mut sinks = vec![crate::lanes::Samples::new(); batch.len()];
        let results = propagate_lanes(sim.model(), batch, &times, &mut sinks);
        for (i, run) in batch.iter().enumerate() {
            let mut s = crate::lanes::Samples::new();
            let r = propagate(sim.model(), run, &times, &mut s);
            assert!(
                crate::lanes::bits(&s, &r) == crate::lanes::bits(&sinks[i], &results[i]),
                "lane {i} differs from its scalar run"
            );
        }
    }
    // A shape corrected to the field's own at another reversal depth flies as that field (to
    // the rounding of the inverse).
    let mut s2 = crate::lanes::Samples::new();
    let corrected = &runs[1];
    propagate(sim.model(), corrected, &times, &mut s2).unwrap();
    let to = format!("reversal_m = {}", 1.0 / (0.5 - 0.2));
    let as_given = Scenario::from_toml_str(&example_with("reversal_m = 2.0", &to), "z_r").unwrap();
    let other = Simulator::new(&as_given);
    let mut run = other.run_setup(&Factors::TRUTH, &EffectSet::NONE).unwrap();
    let field = run.flowfield.as_mut().unwrap();
    field.half_depth_m = 1.0 / (1.0 / 0.8 + 0.4);
    let mut s3 = crate::lanes::Samples::new();
    propagate(other.model(), &run, &times, &mut s3).unwrap();
    let last = |s: &crate::lanes::Samples| s.last().unwrap().0;
    for (a, b) in last(&s2).pos_m.iter().zip(last(&s3).pos_m) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
}
