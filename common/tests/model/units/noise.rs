//! The unit tests of `sepval_common::noise`.

use sepval_common::noise::*;
use sepval_common::telemetry::Trajectory;

fn flat(n: usize) -> Trajectory {
    Trajectory {
        times_s: (0..n).map(|k| k as f64 * 0.005).collect(),
        pos_m: vec![[0.0; 3]; n],
        att_deg: vec![[0.0; 3]; n],
        ..Trajectory::default()
    }
}

#[test]
fn same_seed_same_noise_and_right_size() {
    let mut a = flat(2000);
    let mut b = flat(2000);
    add_noise(&mut a, SIGMA_POS_M, SIGMA_ATT_DEG, 7);
    add_noise(&mut b, SIGMA_POS_M, SIGMA_ATT_DEG, 7);
    assert_eq!(a, b);
    let rms = |v: &Vec<[f64; 3]>| {
        (v.iter().flatten().map(|x| x * x).sum::<f64>() / (3 * v.len()) as f64).sqrt()
    };
    assert!((rms(&a.pos_m) / SIGMA_POS_M - 1.0).abs() < 0.05);
    assert!((rms(&a.att_deg) / SIGMA_ATT_DEG - 1.0).abs() < 0.05);
    let (sp, sa) = estimate_noise(&a).unwrap();
    assert!((sp / SIGMA_POS_M - 1.0).abs() < 0.1, "{sp}");
    assert!((sa / SIGMA_ATT_DEG - 1.0).abs() < 0.1, "{sa}");
}
