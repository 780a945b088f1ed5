//! Conformance with `docs/model.md` section 8: the trajectories an independent
//! implementation gives, noise-free, at the truth and nominal factors. Agreement to the last
//! printed digit is expected (1e-9 m and 1e-7 deg as printed; the contract's tolerance is 1e-6).

#![allow(clippy::needless_range_loop)] // index loops over x, y, z read like the equations

use sepval_common::{EffectSet, Factors, Simulator};

const TIMES: [f64; 5] = [0.05, 0.10, 0.25, 0.50, 1.00];

/// docs/model.md section 8, truth factors: t, x, y, z [m], roll, pitch, yaw [deg].
const TRUTH: [[f64; 7]; 5] = [
    [
        0.05,
        -0.007996041,
        0.002637173,
        0.084149232,
        0.0696217,
        1.3578848,
        -0.2021000,
    ],
    [
        0.10,
        -0.032006330,
        0.009616448,
        0.268513472,
        0.2823073,
        3.8298127,
        -0.7492023,
    ],
    [
        0.25,
        -0.201028757,
        0.037695785,
        0.902721556,
        1.8912844,
        8.2227826,
        -3.5091034,
    ],
    [
        0.50,
        -0.818273015,
        0.008861278,
        2.223099913,
        7.7242762,
        11.0027200,
        -8.8583816,
    ],
    [
        1.00,
        -3.483192474,
        -0.841172108,
        5.780992554,
        26.0943588,
        10.2253145,
        -18.4888641,
    ],
];

/// docs/model.md section 8, nominal factors.
const NOMINAL: [[f64; 7]; 5] = [
    [
        0.05,
        -0.007598985,
        0.003696050,
        0.081935277,
        -0.1725823,
        0.0813256,
        -0.2000838,
    ],
    [
        0.10,
        -0.030219109,
        0.013646588,
        0.269450386,
        -0.6174301,
        -0.0292963,
        -0.7466058,
    ],
    [
        0.25,
        -0.185112624,
        0.057964714,
        0.955148995,
        -2.4945555,
        -3.4935136,
        -3.5700165,
    ],
    [
        0.50,
        -0.740680134,
        0.064258998,
        2.632646012,
        -4.3657017,
        -12.6884271,
        -9.6550232,
    ],
    [
        1.00,
        -3.486647644,
        -0.724227577,
        8.820999541,
        0.0011021,
        -32.8338845,
        -25.9918562,
    ],
];

fn check(factors: &Factors, table: &[[f64; 7]; 5]) {
    let sim = Simulator::embedded_default();
    let traj = sim.simulate(factors, &EffectSet::NONE, &TIMES).unwrap();
    for (k, row) in table.iter().enumerate() {
        for j in 0..3 {
            let got = traj.pos_m[k][j];
            assert!(
                (got - row[1 + j]).abs() <= 0.6e-9,
                "t = {} position {j}: {got:.12} vs {}",
                row[0],
                row[1 + j]
            );
            let got = traj.att_deg[k][j];
            assert!(
                (got - row[4 + j]).abs() <= 0.6e-7,
                "t = {} angle {j}: {got:.10} vs {}",
                row[0],
                row[4 + j]
            );
        }
    }
}

#[test]
fn truth_factors_match_model_md_section_8() {
    check(&Factors::TRUTH, &TRUTH);
}

#[test]
fn nominal_factors_match_model_md_section_8() {
    check(&Factors::NOMINAL, &NOMINAL);
}

#[test]
fn stroke_ends_match_model_md_section_8() {
    let sim = Simulator::embedded_default();
    let (_, log) = sim
        .simulate_logged(&Factors::TRUTH, &EffectSet::NONE, &sim.default_times())
        .unwrap();
    let [fwd, aft] = log.foot_off_s.map(Option::unwrap);
    assert!((aft - 0.052295685).abs() < 0.6e-9, "aft {aft:.12}");
    assert!((fwd - 0.056199540).abs() < 0.6e-9, "fwd {fwd:.12}");
}
