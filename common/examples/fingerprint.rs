//! Temporary: a hash of many trajectories' bits, to compare builds.
use sepval_common::effects::{CATALOGUE, EffectSet};
use sepval_common::{Factors, Simulator};
use std::hash::{Hash, Hasher};

fn main() {
    let sim = Simulator::embedded_default();
    let mut h = std::collections::hash_map::DefaultHasher::new();
    let grid = sim.default_times();
    let off: Vec<f64> = (0..300).map(|j| -0.01 + j as f64 / 333.0).collect();
    let bases = [
        Factors::NOMINAL,
        Factors::TRUTH,
        Factors([
            0.45, 0.65, 0.98, 1.03, 0.97, -0.02, 0.04, -0.06, 0.1, -0.08, -0.05, 1.1, 1.4, 0.9,
            1.3, 0.8, 1.6,
        ]),
    ];
    let mut sets = vec![EffectSet::NONE];
    for (i, e) in CATALOGUE.iter().enumerate() {
        for m in [1.0, 2.5] {
            let v: Vec<f64> = e.params().iter().map(|p| p.neutral + m * p.scale).collect();
            let mut s = EffectSet::NONE;
            s.push(i, &v).unwrap();
            sets.push(s);
        }
    }
    let mut n = 0;
    for b in &bases {
        for s in &sets {
            for times in [&grid, &off] {
                match sim.simulate_logged(b, s, times) {
                    Ok((t, log)) => {
                        for p in t.pos_m.iter().chain(t.att_deg.iter()) {
                            for v in p {
                                v.to_bits().hash(&mut h);
                            }
                        }
                        format!("{log:?}").hash(&mut h);
                    }
                    Err(e) => format!("{e}").hash(&mut h),
                }
                n += 1;
            }
        }
    }
    println!("{n} runs: {:016x}", h.finish());
}
