//! Speed of one simulation of the default event (issue 2: at most 0.5 ms on one core).
//!
//! `cargo bench -p sepval-common --bench simulate -- --output-format bencher`
//!
//! `simulate_default_event`: set up the run (truth factors, no effects) and propagate the
//! default 1.0 s event (2 000 RK4 steps, 8 000 force evaluations plus the located stroke ends),
//! accumulating the goals against a 201-sample measured trajectory as a fit does.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use sepval_common::{EffectSet, Factors, Simulator};

fn simulate_default_event(c: &mut Criterion) {
    let sim = Simulator::embedded_default();
    let measured = sim
        .simulate(&Factors::NOMINAL, &EffectSet::NONE, &sim.default_times())
        .expect("nominal run");
    c.bench_function("simulate_default_event", |b| {
        b.iter(|| {
            let run = sim
                .run_setup(black_box(&Factors::TRUTH), &EffectSet::NONE)
                .expect("valid factors");
            sim.goal_sums(&run, black_box(&measured))
                .expect("finite run")
        })
    });
}

criterion_group!(benches, simulate_default_event);
criterion_main!(benches);
