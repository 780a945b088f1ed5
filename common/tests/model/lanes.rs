//! The lane propagator (issue 16): each lane's run has the bits of the scalar propagator's run
//! of the same candidate, whatever its neighbours do.

use sepval_common::effects::{CATALOGUE, EffectSet};
use sepval_common::model::{RunSetup, StateVector};
use sepval_common::propagator::{
    LANES, Observation, propagate, propagate_lanes, propagate_lanes_portable,
};
use sepval_common::scenario::{DEFAULT_SCENARIO_TOML, Scenario};
use sepval_common::{Factors, Simulator};

/// A base that is not the default truth.
const BASE: Factors = Factors([
    0.45, 0.65, 0.98, 1.03, 0.97, -0.02, 0.04, -0.06, 0.1, -0.08, -0.05, 1.1, 1.4, 0.9, 1.3, 0.8,
    1.6,
]);

pub(crate) type Samples = Vec<(Observation, StateVector)>;

/// Every bit of a run's samples and outcome, for exact comparison (NaN payloads aside: a
/// diverged run records no sample after its divergence).
pub(crate) fn bits(
    samples: &Samples,
    result: &Result<sepval_common::propagator::RunLog, sepval_common::propagator::Diverged>,
) -> Vec<u64> {
    let mut out: Vec<u64> = Vec::new();
    for (o, x) in samples {
        out.extend(
            o.pos_m
                .iter()
                .chain(&o.att_deg)
                .chain(x)
                .map(|v| v.to_bits()),
        );
    }
    match result {
        Ok(log) => {
            out.push(log.steps);
            for t in log.foot_on_s.iter().chain(&log.foot_off_s) {
                out.push(t.map_or(u64::MAX, f64::to_bits));
            }
            let t = &log.tables;
            out.push(t.evaluations);
            out.extend(t.count);
            out.extend(t.worst.iter().flatten().map(|v| v.to_bits()));
        }
        Err(d) => out.extend([u64::MAX - 1, d.t_s.to_bits()]),
    }
    out
}

/// Runs mixing every catalogue effect (two values each, both sides of neutral where the range
/// allows: different stroke ends, ejector delays, time offsets), three bases, and runs that
/// diverge at different times.
fn mixed_runs(sim: &Simulator) -> Vec<RunSetup> {
    let mut runs = Vec::new();
    for (f, base) in [Factors::NOMINAL, Factors::TRUTH, BASE].iter().enumerate() {
        runs.push(sim.run_setup(base, &EffectSet::NONE).unwrap());
        for (index, effect) in CATALOGUE.iter().enumerate() {
            for m in [1.0, -2.5] {
                let values: Vec<f64> = effect
                    .params()
                    .iter()
                    .map(|p| (p.neutral + (m + f as f64) * p.scale).clamp(p.min, p.max))
                    .collect();
                let mut set = EffectSet::NONE;
                set.push(index, &values).unwrap();
                runs.push(sim.run_setup(base, &set).unwrap());
            }
        }
    }
    // Diverging runs: a roll inertia far below its bound under a rolling moment offset
    // (xinerfac is factor 2, cloff factor 10): |omega| passes 100 rad/s at different times.
    for (k, scale) in [1e-5, 3e-5, 1e-4].into_iter().enumerate() {
        let mut f = BASE;
        f.0[2] = scale;
        f.0[10] = 0.5 + 0.25 * k as f64;
        runs.push(RunSetup::new_unchecked_bounds(sim.model(), &f, &EffectSet::NONE).unwrap());
    }
    // Interleave, so that each batch mixes kinds: a fixed stride through the list.
    let n = runs.len();
    let stride = 7;
    assert!(n % stride != 0);
    (0..n).map(|j| runs[(j * stride) % n].clone()).collect()
}

pub(crate) fn check_lanes_against_scalar(sim: &Simulator, times: &[f64]) {
    let model = sim.model();
    let runs = mixed_runs(sim);
    let mut diverged = 0;
    // Batches of LANES, then a last batch of one to three (padded lanes).
    for batch in runs.chunks(LANES).chain([&runs[..1], &runs[1..3]]) {
        let expected: Vec<Vec<u64>> = batch
            .iter()
            .map(|run| {
                let mut s = Samples::new();
                let r = propagate(model, run, times, &mut s);
                diverged += usize::from(r.is_err());
                bits(&s, &r)
            })
            .collect();
        for name in ["dispatched", "portable"] {
            let mut sinks = vec![Samples::new(); batch.len()];
            let results = if name == "portable" {
                propagate_lanes_portable(model, batch, times, &mut sinks)
            } else {
                propagate_lanes(model, batch, times, &mut sinks)
            };
            for (i, (r, s)) in results.iter().zip(&sinks).enumerate() {
                assert!(
                    bits(s, r) == expected[i],
                    "{name}: lane {i} of a batch of {} differs from its scalar run",
                    batch.len()
                );
            }
        }
    }
    assert!(
        diverged >= 3,
        "the batches include diverging runs ({diverged})"
    );
}

#[test]
fn lanes_equal_scalar_runs_bit_for_bit_on_the_grid() {
    let sim = Simulator::embedded_default();
    check_lanes_against_scalar(&sim, &sim.default_times());
}

#[test]
fn lanes_equal_scalar_runs_bit_for_bit_with_tables() {
    // CZ over alpha within +-1 deg, a breakpoint at 0 (where every run starts: the interval an
    // input on a breakpoint takes depends on the cursors' history) and excursions beyond.
    let from = "cz_alpha_per_rad = -6.0";
    assert!(DEFAULT_SCENARIO_TOML.contains(from));
    let narrow = Scenario::from_toml_str(
        &DEFAULT_SCENARIO_TOML.replace(
            from,
            "cz = { alpha_deg = [-1.0, 0.0, 1.0], values = [0.10471975511965977, 0.0, \
             -0.10471975511965977] }",
        ),
        "narrow",
    )
    .unwrap();
    let sim = Simulator::new(&narrow);
    check_lanes_against_scalar(&sim, &sim.default_times());
    // The default's aerodynamics and interference written as tables.
    let dir = tempfile::tempdir().unwrap();
    let sim = Simulator::new(&crate::tables::write_and_load(dir.path(), true));
    let times: Vec<f64> = (0..300).map(|j| -0.01 + j as f64 / 333.0).collect();
    check_lanes_against_scalar(&sim, &times);
}

#[test]
fn lanes_equal_scalar_runs_bit_for_bit_off_the_grid_and_before_release() {
    // 333 Hz from t = -10 ms: samples before release, between grid points, and (with the
    // time-offset effect) moved differently in each lane.
    let sim = Simulator::embedded_default();
    let times: Vec<f64> = (0..300).map(|j| -0.01 + j as f64 / 333.0).collect();
    check_lanes_against_scalar(&sim, &times);
}
