//! Speed of one simulation of the default event (issue 2: at most 0.5 ms on one core).
//!
//! `cargo bench -p sepval-common --bench simulate -- --output-format bencher`
//!
//! `simulate_default_event`: set up the run (truth factors, no effects) and propagate the
//! default 1.0 s event (2 000 RK4 steps, 8 000 force evaluations plus the located stroke ends),
//! accumulating the goals against a 201-sample measured trajectory as a fit does.
//!
//! `simulate_default_event_tables`: the same with the default written as tables
//! (`sepval scenario --tables --interference-tables`: static coefficients over Mach, alpha and
//! beta, damping over Mach, interference over distance); issue 15 asks for at most 20 % more time than the constant form.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use sepval_common::{EffectSet, Factors, Simulator};

/// Times one fit evaluation of `sim`: the run set up at the truth factors and propagated,
/// goals accumulated against its own nominal run.
fn bench_goals(c: &mut Criterion, name: &str, sim: &Simulator) {
    let measured = sim
        .simulate(&Factors::NOMINAL, &EffectSet::NONE, &sim.default_times())
        .expect("nominal run");
    c.bench_function(name, |b| {
        b.iter(|| {
            let run = sim
                .run_setup(black_box(&Factors::TRUTH), &EffectSet::NONE)
                .expect("valid factors");
            sim.goal_sums(&run, black_box(&measured))
                .expect("finite run")
        })
    });
}

fn simulate_default_event(c: &mut Criterion) {
    bench_goals(c, "simulate_default_event", &Simulator::embedded_default());
}

fn simulate_default_event_tables(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let form =
        sepval_common::table_form::table_form(&sepval_common::Scenario::embedded_default(), true)
            .expect("the default has no tables");
    for (p, text) in &form.files {
        let path = dir.path().join(p);
        std::fs::create_dir_all(path.parent().expect("a parent")).expect("a directory");
        std::fs::write(path, text).expect("a table file");
    }
    let path = dir.path().join("scenario.toml");
    std::fs::write(&path, form.scenario.to_toml_string()).expect("the scenario");
    let sim = Simulator::new(&sepval_common::Scenario::load(&path).expect("it reads back"));
    bench_goals(c, "simulate_default_event_tables", &sim);
}

criterion_group!(
    benches,
    simulate_default_event,
    simulate_default_event_tables
);
criterion_main!(benches);
