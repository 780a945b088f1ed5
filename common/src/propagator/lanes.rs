//! Four runs at once, one per lane of an [`F64x4`]: the propagator of [`super`] in lockstep.
//!
//! Source: `docs/model.md` sections 1, 2, 3 and 3a, as in [`super`]; each lane's result has the
//! bits of [`super::propagate`] of its run (docs/model.md section 9 and the rule of
//! [`crate::lanes`]). How:
//! - the lanes share the nominal grid t_k = k dt (it depends on the scenario alone), so a full
//!   grid step is one RK4 step of the four lanes with [`LaneEquations`], whose lane `i` is the
//!   scalar step of run `i` to the bit;
//! - switching events are each lane's own: before a step, a lane whose mode is due to switch or
//!   whose ejector start time falls inside the step, and after it, a lane one of whose pushing
//!   feet ended its stroke inside the step, takes that step again through the scalar
//!   [`Engine::advance`] from its state at t_k (the located switch, the part-steps, the log), and
//!   the result goes back into the lane; such steps are a handful per run, during the stroke;
//! - samples are each lane's own too (a telemetry time offset moves them): at each grid point a
//!   lane records the samples it takes there, and takes an off-grid sample with the scalar
//!   one-step [`Engine::advance`] from the grid state, as [`super::propagate`] does;
//! - a lane that diverges or has recorded its last sample is done: it keeps stepping with the
//!   others (its values unused) until every lane is done;
//! - with tables (section 3), each lane looks its tables up with its own scratch (interval
//!   cursors and excursion counts); a lane that takes a step again through the scalar integrator
//!   first puts its scratch back to t_k, so that its cursors have the history of the scalar run
//!   (the interval chosen for an input on a breakpoint depends on it) and its counts are those
//!   of one pass.
//!
//! Choices: a batch of one run takes the scalar path, and so does an x86-64 host without AVX2
//! and FMA units (there a fused multiply-add is a call to the C library in either path, and four
//! lanes are four scalar operations each, so the scalar path is the faster). AArch64 hosts run
//! the lanes as two 2-lane NEON instructions per operation (FMA is part of the base instruction
//! set).

use crate::lanes::{F64x4, Real, gather, lane};
use crate::model::{LaneEquations, Model, RunSetup, STATE_LEN, StateVector};
use crate::table::TableState;

use super::{
    Cursor, Diverged, Engine, FootMode, GRID_MATCH_TOLERANCE_S, LanesHeld, MAX_RATE_RAD_S, RunLog,
    SampleSink, grid_target, observe, propagate, pushing, rk4,
};

/// Runs per lane batch: the lanes of an [`F64x4`] (four doubles in an AVX2 register).
pub const LANES: usize = 4;

/// Propagates one to [`LANES`] runs of `model` at the same telemetry times `times_s` (strictly
/// increasing), run `i` recording into `sinks[i]`, and returns each run's log or divergence.
///
/// Result `i` and the samples `sinks[i]` receives are bit for bit those of
/// [`propagate`]`(model, &runs[i], times_s, &mut sinks[i])`. On x86-64 hosts with AVX2 and FMA
/// units (chosen at run time) and on AArch64 (NEON, two lanes per instruction) the runs advance
/// in lockstep, one per lane; elsewhere, and for a batch of one, one after another (see the
/// module documentation).
///
/// # Panics
/// If `runs` is empty or longer than [`LANES`], or `sinks` is not as long as `runs`.
pub fn propagate_lanes<S: SampleSink>(
    model: &Model,
    runs: &[RunSetup],
    times_s: &[f64],
    sinks: &mut [S],
) -> Vec<Result<RunLog, Diverged>> {
    check_batch(runs, sinks);
    lanes_dyn(model, runs, times_s, &mut dyn_sinks(sinks))
}

/// The sinks behind pointers: the lane propagator is compiled once, in this crate, for
/// `&mut dyn SampleSink` (as [`propagate`] is, and for the same reason).
fn dyn_sinks<S: SampleSink>(sinks: &mut [S]) -> Vec<&mut dyn SampleSink> {
    sinks.iter_mut().map(|s| s as &mut dyn SampleSink).collect()
}

/// [`propagate_lanes`] for sinks behind pointers: the one compiled copy.
fn lanes_dyn(
    model: &Model,
    runs: &[RunSetup],
    times_s: &[f64],
    sinks: &mut [&mut dyn SampleSink],
) -> Vec<Result<RunLog, Diverged>> {
    #[cfg(target_arch = "x86_64")]
    if runs.len() > 1
        && std::arch::is_x86_feature_detected!("fma")
        && std::arch::is_x86_feature_detected!("avx2")
    {
        // SAFETY: the CPU supports the features `lanes_fma` is compiled for.
        return unsafe { lanes_fma(model, runs, times_s, sinks) };
    }
    // AArch64 has NEON and fused multiply-adds in its base instruction set: each F64x4
    // operation is two 2-lane instructions.
    #[cfg(target_arch = "aarch64")]
    if runs.len() > 1 {
        return lanes_inline(model, runs, times_s, sinks);
    }
    run_by_run(runs, sinks, |run, sink| {
        propagate(model, run, times_s, sink)
    })
}

/// [`propagate_lanes`] without run-time dispatch, in lockstep on any host (four scalar
/// operations per lane operation where the build has no vector units): the same results bit for
/// bit.
///
/// # Panics
/// As [`propagate_lanes`].
pub fn propagate_lanes_portable<S: SampleSink>(
    model: &Model,
    runs: &[RunSetup],
    times_s: &[f64],
    sinks: &mut [S],
) -> Vec<Result<RunLog, Diverged>> {
    check_batch(runs, sinks);
    lanes_portable_dyn(model, runs, times_s, &mut dyn_sinks(sinks))
}

/// [`propagate_lanes_portable`] for sinks behind pointers: the one compiled copy.
fn lanes_portable_dyn(
    model: &Model,
    runs: &[RunSetup],
    times_s: &[f64],
    sinks: &mut [&mut dyn SampleSink],
) -> Vec<Result<RunLog, Diverged>> {
    lanes_inline(model, runs, times_s, sinks)
}

/// Each run through the scalar propagator `one`, one after another.
fn run_by_run<S>(
    runs: &[RunSetup],
    sinks: &mut [S],
    mut one: impl FnMut(&RunSetup, &mut S) -> Result<RunLog, Diverged>,
) -> Vec<Result<RunLog, Diverged>> {
    runs.iter()
        .zip(sinks)
        .map(|(run, sink)| one(run, sink))
        .collect()
}

fn check_batch<S>(runs: &[RunSetup], sinks: &[S]) {
    assert!(
        (1..=LANES).contains(&runs.len()) && sinks.len() == runs.len(),
        "a lane batch is 1 to {LANES} runs with one sink each ({} runs, {} sinks)",
        runs.len(),
        sinks.len()
    );
}

/// [`propagate_lanes`] compiled for x86-64 hosts with AVX2 and FMA units.
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn lanes_fma<S: SampleSink>(
    model: &Model,
    runs: &[RunSetup],
    times_s: &[f64],
    sinks: &mut [S],
) -> Vec<Result<RunLog, Diverged>> {
    lanes_inline(model, runs, times_s, sinks)
}

/// One lane's run: where it is, which sample it takes next, and how it ended.
struct Lane {
    cursor: Cursor,
    /// Index of the next sample to record.
    next: usize,
    /// The grid point at which the next sample is taken (checked again there).
    next_k: u64,
    /// Set when the run is done: its log, or where it diverged.
    result: Option<Result<RunLog, Diverged>>,
}

/// How a lane takes the step from t_k to t_k+1.
#[derive(Clone, Copy, PartialEq)]
enum Step {
    /// Done: the lane's values are not used.
    Idle,
    /// Both feet off: the lockstep step is the step.
    Coast,
    /// The lockstep step is the step unless a pushing foot ends its stroke inside it.
    Trial,
    /// A switch is due at the start or the ejector starts inside the step: the scalar step.
    Scalar,
}

/// Lane `i` of the lanes' state.
#[inline(always)]
fn state_of(x: &[F64x4; STATE_LEN], i: usize) -> StateVector {
    std::array::from_fn(|j| lane(x[j], i))
}

/// Sets lane `i` of the lanes' state to `s`.
#[inline(always)]
fn set_state(x: &mut [F64x4; STATE_LEN], i: usize, s: &StateVector) {
    for (v, &s) in x.iter_mut().zip(s) {
        v.0[i] = s;
    }
}

/// The lanes whose state fails the divergence test of [`super::check_divergence`] (a non-finite
/// component, or |omega| > 100 rad/s), with the same arithmetic: |omega|^2 summed as there, and
/// a component non-finite exactly when `v - v` is NaN.
#[inline(always)]
fn diverged(y: &[F64x4; STATE_LEN]) -> [bool; LANES] {
    let mut nan = F64x4::splat(0.0);
    for &v in y {
        // v - v: 0 for a finite v, NaN for an infinite or NaN one.
        #[allow(clippy::eq_op)]
        let zero_if_finite = v - v;
        nan = nan + zero_if_finite;
    }
    let rate2 = y[10] * y[10] + y[11] * y[11] + y[12] * y[12];
    let bad = nan.is_nan() | rate2.gt(F64x4::splat(MAX_RATE_RAD_S * MAX_RATE_RAD_S));
    std::array::from_fn(|i| bad.0[i] != 0)
}

/// The body of [`propagate_lanes`] in lockstep, inlined into each compiled copy.
///
/// A numeric kernel kept as one function on purpose (over the house limit of about 100 lines):
/// it is the inner loop of every lane run (about 96 us each on the development machine, the
/// `simulate_lanes` bench), `#[inline(always)]` into each compiled copy, and its per-step state
/// (lane masks, saved table states, the four states in flight) lives in locals the compiler
/// keeps in registers; split into functions that pass that state by reference, it would go
/// through memory at every step.
// shape: long (the lane propagator's inner loop, kept whole for speed: see above)
#[inline(always)]
fn lanes_inline<S: SampleSink>(
    model: &Model,
    runs: &[RunSetup],
    times_s: &[f64],
    sinks: &mut [S],
) -> Vec<Result<RunLog, Diverged>> {
    let n = runs.len();
    // Lanes beyond the batch repeat its last run and record nothing (done from the start).
    let run_of = |i: usize| &runs[i.min(n - 1)];
    // Each lane's table scratch; `saved` holds a lane's as it was before a step that the lane
    // may take again through the scalar integrator.
    let tables = model.tables.in_evaluation();
    let table_states: [TableState; LANES] = Default::default();
    let mut saved: [Option<TableState>; LANES] = Default::default();
    let mut engines: [Engine; LANES] =
        std::array::from_fn(|i| Engine::new(model, run_of(i), &table_states[i]));
    let equations = LaneEquations::new(std::array::from_fn(|i| engines[i].equations.parts()));
    let mut lanes: [Lane; LANES] = std::array::from_fn(|i| {
        let cursor = engines[i].start();
        Lane {
            cursor,
            next: 0,
            next_k: 0,
            result: (i >= n).then_some(Ok(RunLog::default())),
        }
    });
    let mut x: [F64x4; STATE_LEN] =
        std::array::from_fn(|j| gather::<F64x4>(|i| lanes[i].cursor.x[j]));
    let dt_s = model.dt_s;
    let mut k: u64 = 0;
    loop {
        // The samples each lane takes at t_k.
        for i in 0..n {
            let lane = &mut lanes[i];
            if lane.result.is_some() || lane.next_k != k {
                continue;
            }
            lane.cursor.x = state_of(&x, i);
            match record_due(&mut engines[i], lane, k, times_s, &mut sinks[i]) {
                Ok(Some(next_k)) => lane.next_k = next_k,
                Ok(None) => {
                    if tables {
                        engines[i].log.tables = table_states[i].excursions();
                    }
                    lane.result = Some(Ok(engines[i].log));
                }
                Err(d) => lane.result = Some(Err(d)),
            }
        }
        if lanes.iter().all(|l| l.result.is_some()) {
            break;
        }
        // The step from t_k to t_k+1, as each lane takes it.
        let t_s = k as f64 * dt_s;
        let t_next = (k + 1) as f64 * dt_s;
        let h = t_next - t_s;
        let mut on = [[false; 2]; LANES];
        let mut steps = [Step::Idle; LANES];
        for i in 0..n {
            let lane = &mut lanes[i];
            if lane.result.is_some() {
                continue;
            }
            steps[i] = if lane.cursor.modes == [FootMode::Off; 2] {
                Step::Coast
            } else {
                lane.cursor.x = state_of(&x, i);
                if tables {
                    saved[i] = Some(table_states[i].clone());
                }
                if engines[i].event_at_start(&lane.cursor, h) {
                    Step::Scalar
                } else {
                    on[i] = pushing(lane.cursor.modes);
                    Step::Trial
                }
            };
        }
        let mut y = rk4(
            &LanesHeld {
                equations: &equations,
                on,
            },
            &x,
            F64x4::splat(t_s),
            F64x4::splat(h),
        );
        let bad = diverged(&y);
        for i in 0..n {
            let lane = &mut lanes[i];
            let engine = &mut engines[i];
            let mut step = steps[i];
            if step == Step::Trial && engine.stroke_ends_in(&lane.cursor, &state_of(&y, i)) {
                step = Step::Scalar;
            }
            match step {
                Step::Idle => {}
                Step::Coast | Step::Trial => {
                    engine.log.steps += 1;
                    lane.cursor.t_s = t_next;
                    if bad[i] {
                        lane.result = Some(Err(Diverged { t_s: t_next }));
                    }
                }
                Step::Scalar => {
                    // From the table scratch of t_k, as if the lockstep step had not been (saved
                    // when this step was planned).
                    if let Some(before) = saved[i].take() {
                        table_states[i].restore(&before);
                    }
                    match engine.advance(lane.cursor, t_next, true) {
                        Ok(c) => {
                            lane.cursor = c;
                            set_state(&mut y, i, &c.x);
                        }
                        Err(d) => lane.result = Some(Err(d)),
                    }
                }
            }
        }
        x = y;
        k += 1;
    }
    lanes
        .into_iter()
        .take(n)
        .map(|l| l.result.expect("every lane is done"))
        .collect()
}

/// Records the samples `lane` takes at grid point `k` (its cursor there), as
/// [`super::propagate`] does: before release the carriage state, on the grid the grid state,
/// between grid points one step from it. Returns the grid point of the next sample, or `None`
/// after the last.
#[inline(always)]
fn record_due<S: SampleSink>(
    engine: &mut Engine,
    lane: &mut Lane,
    k: u64,
    times_s: &[f64],
    sink: &mut S,
) -> Result<Option<u64>, Diverged> {
    let run = engine.run;
    while let Some(&t_label) = times_s.get(lane.next) {
        let index = lane.next;
        let t = t_label + run.time_offset_s;
        if t < -GRID_MATCH_TOLERANCE_S {
            let initial = run.initial_state();
            sink.record(index, &observe(run, &initial), &initial);
            lane.next += 1;
            continue;
        }
        let (target_k, on_grid) = grid_target(t, engine.dt_s);
        if target_k > k {
            return Ok(Some(target_k));
        }
        if on_grid {
            sink.record(index, &observe(run, &lane.cursor.x), &lane.cursor.x);
        } else {
            let off_grid = engine.advance(lane.cursor, t, false)?;
            sink.record(index, &observe(run, &off_grid.x), &off_grid.x);
        }
        lane.next += 1;
    }
    Ok(None)
}
