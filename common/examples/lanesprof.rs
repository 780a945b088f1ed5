use sepval_common::goals::GoalAccumulator;
use sepval_common::propagator::{LANES, propagate_lanes};
use sepval_common::{EffectSet, Factors, Simulator};
fn main() {
    let sim = Simulator::embedded_default();
    let measured = sim
        .simulate(&Factors::NOMINAL, &EffectSet::NONE, &sim.default_times())
        .unwrap();
    let table = &sim.scenario().factors;
    let runs: Vec<_> = (0..100)
        .map(|k| {
            let mut f = Factors::TRUTH;
            for (j, v) in f.0.iter_mut().enumerate() {
                let row = &table.0[j];
                let u = ((k * 17 + j * 31) % 101) as f64 / 100.0 - 0.5;
                *v = (*v + 0.04 * u * (row.max - row.min)).clamp(row.min, row.max);
            }
            sim.run_setup(&f, &EffectSet::NONE).unwrap()
        })
        .collect();
    let t = std::time::Instant::now();
    let mut n = 0;
    for _ in 0..30 {
        for batch in runs.chunks(LANES) {
            let mut sinks: Vec<_> = batch
                .iter()
                .map(|_| GoalAccumulator::new(&measured))
                .collect();
            n += propagate_lanes(sim.model(), batch, &measured.times_s, &mut sinks).len();
        }
    }
    println!("{:.1} us/run", t.elapsed().as_secs_f64() * 1e6 / n as f64);
}
