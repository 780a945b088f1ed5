//! The flowfield's cost against the default model's, side by side (issue 37: a 1-s release with
//! the flowfield at 5 stations costs at most 1.5 times today's simulation, lanes included).
//!
//! `cargo run --release -p sepval-common --example flowfield_cost [ROUNDS]`
//!
//! Each round times a batch of 100 runs of the default event (truth factors moved by up to 2 %
//! of each factor's range, goals accumulated against the nominal run, as the criterion bench
//! `simulate` does) with the default model, then the same batch with the flowfield of
//! docs/model.md section 3b's conformance case, one run at a time (scalar) and four at a time
//! (lanes); then with the guide's surveyed field (tables over position). The rounds interleave the two models, so that a machine whose speed drifts slows
//! both alike; the ratio of each round is printed, and their median, which is the figure to
//! quote (criterion's separate timings of `simulate_default_event_flowfield` and
//! `simulate_default_event` are taken minutes apart, and this machine's speed changes by more
//! than the difference).

use std::time::Instant;

use sepval_common::goals::GoalAccumulator;
use sepval_common::model::RunSetup;
use sepval_common::propagator::{LANES, propagate_lanes};
use sepval_common::{EffectSet, Factors, Scenario, Simulator};

/// The guide's example store under a field: the default with docs/model.md section 3b's
/// conformance field (5 stations) in place of its decay increments.
fn flowfield() -> Scenario {
    let text = include_str!("../../examples/flowfield-store/scenario.toml");
    Scenario::from_toml_str(text, "flowfield").expect("a valid field")
}

/// The guide's surveyed field (`examples/flowfield-store/grid.toml`): the field as tables over
/// position, 4 x 3 x 8 points, evaluated one run at a time in the lanes.
fn survey() -> Scenario {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/flowfield-store/grid.toml");
    Scenario::load(&path).expect("a valid field")
}

/// 100 runs around the truth (the criterion bench's spread).
fn runs(sim: &Simulator) -> Vec<RunSetup> {
    let table = &sim.scenario().factors;
    (0..100)
        .map(|k| {
            let mut f = Factors::TRUTH;
            for (j, v) in f.0.iter_mut().enumerate() {
                let row = &table.0[j];
                let u = ((k * 17 + j * 31) % 101) as f64 / 100.0 - 0.5;
                *v = (*v + 0.04 * u * (row.max - row.min)).clamp(row.min, row.max);
            }
            sim.run_setup(&f, &EffectSet::NONE).expect("valid factors")
        })
        .collect()
}

/// Seconds for the batch: one at a time, or four at a time through the lanes.
fn time_batch(sim: &Simulator, runs: &[RunSetup], lanes: bool) -> f64 {
    let measured = sim
        .simulate(&Factors::NOMINAL, &EffectSet::NONE, &sim.default_times())
        .expect("nominal run");
    let start = Instant::now();
    if lanes {
        for batch in runs.chunks(LANES) {
            let mut sinks: Vec<_> = batch
                .iter()
                .map(|_| GoalAccumulator::new(&measured))
                .collect();
            std::hint::black_box(propagate_lanes(
                sim.model(),
                batch,
                &measured.times_s,
                &mut sinks,
            ));
        }
    } else {
        for run in runs {
            std::hint::black_box(sim.goal_sums(run, &measured).ok());
        }
    }
    start.elapsed().as_secs_f64()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let rounds: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(21);
    let default = Simulator::embedded_default();
    let default_runs = runs(&default);
    for (field_name, scenario) in [
        ("analytic field", flowfield()),
        ("surveyed field", survey()),
    ] {
        let field = Simulator::new(&scenario);
        let field_runs = runs(&field);
        for (name, lanes) in [("scalar", false), ("lanes", true)] {
            let mut ratios = Vec::new();
            let mut per_run = (Vec::new(), Vec::new());
            for _ in 0..rounds {
                let d = time_batch(&default, &default_runs, lanes);
                let f = time_batch(&field, &field_runs, lanes);
                ratios.push(f / d);
                per_run.0.push(d / 100.0);
                per_run.1.push(f / 100.0);
            }
            println!(
                "{field_name}, {name}: flowfield / default = {:.3} (median of {rounds} interleaved rounds; min {:.3}, max {:.3}); per run {:.0} us vs {:.0} us",
                median(ratios.clone()),
                ratios.iter().copied().fold(f64::INFINITY, f64::min),
                ratios.iter().copied().fold(0.0, f64::max),
                1e6 * median(per_run.1),
                1e6 * median(per_run.0),
            );
        }
    }
}
