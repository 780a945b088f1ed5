//! The unit tests of `sepval_common::goals`.

use sepval_common::goals::*;
use sepval_common::telemetry::Trajectory;

#[test]
fn hand_worked_goals() {
    let mut data = Trajectory::default();
    let mut sim = Trajectory::default();
    for k in 0..2 {
        data.times_s.push(k as f64);
        sim.times_s.push(k as f64);
        data.pos_m.push([0.0; 3]);
        data.att_deg.push([179.0, 0.0, 0.0]);
    }
    sim.pos_m = vec![[3.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
    // 179 -> -179 is 2 deg apart once wrapped.
    sim.att_deg = vec![[-179.0, 0.0, 0.0], [179.0, 0.0, 0.0]];
    let g = goals_between(&data, &sim).unwrap();
    assert!((g.j_pos_m - (9.0f64 / 6.0).sqrt()).abs() < 1e-15);
    assert!((g.j_att_deg - (4.0f64 / 6.0).sqrt()).abs() < 1e-12);
}

#[test]
fn mismatched_times_are_refused() {
    let a = Trajectory {
        times_s: vec![0.0],
        pos_m: vec![[0.0; 3]],
        att_deg: vec![[0.0; 3]],
        ..Default::default()
    };
    let mut b = a.clone();
    b.times_s = vec![0.1];
    assert_eq!(
        goals_between(&a, &b).unwrap_err().to_string(),
        "sample 0 is at t = 0 s in one trajectory and t = 0.1 s in the other"
    );
}
