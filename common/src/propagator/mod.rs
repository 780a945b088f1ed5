//! Classic RK4 with located switching events, and sampling at telemetry times.
//!
//! Source: `docs/model.md` sections 1 (integrator), 2 (renormalisation), 3 (divergence)
//! and 3a (switching events and sample times):
//! - the nominal grid is `t_k = k dt`; a step never straddles a switch: when the trial step
//!   from `t_k` (modes held) carries an "on" foot's `s_i` past the stroke, or crosses the
//!   ejector start time `tau`, the switch time is located, the step is taken to it, the mode
//!   flips, and a second step completes the interval; two switches in one interval are taken in
//!   time order;
//! - q is renormalised after every step, part-steps included, never inside the stages;
//! - a run diverges when, after any step (part-steps included), a state is non-finite or
//!   |omega| > 100 rad/s;
//! - the state at a sample time within 1e-9 s of a grid time is that grid state; at a time
//!   between grid times it is one RK4 step (split at a switch inside it) from the grid state
//!   before it.
//!
//! Choices made here (docs/model.md leaves them open):
//! - Stroke-end times are located by the Illinois variant of regula falsi on the length of the
//!   trial step, safeguarded by bisection, until no double lies inside the bracket (to the last
//!   bit, so that the switch time, and the trajectory, move continuously with the parameters);
//!   the step is taken to the bracket's upper end, where the foot's displacement has just
//!   exceeded the stroke (the foot "turns off the first time s_i exceeds the stroke").
//! - A foot already past the stroke at the start of a (part-)step turns off at once (this
//!   happens only when two feet end their stroke within 1e-12 s of each other).
//! - The ejector start time is matched to within 1e-12 s: a step that would end within that
//!   of tau ends at tau.
//! - A telemetry time before release (t < 0, or t + dt_tm < 0 with a time offset) shows the
//!   carriage state.

mod lanes;
mod rk4;
mod sink;

pub use lanes::{LANES, propagate_lanes, propagate_lanes_portable};
pub use sink::SampleSink;

use rk4::{Held, LanesHeld, rk4};

use nalgebra::Vector3;

use crate::frames::{dcm_from_quaternion, euler_321_deg, wrap_deg};
use crate::model::{EquationsOfMotion, Model, RunSetup, StateVector};
use crate::table::TableState;

/// Tolerance to which the ejector start time is matched and two feet's stroke ends count as
/// one \[s\] (docs/model.md section 3a). Stroke ends themselves are located to the last bit.
pub const SWITCH_TOLERANCE_S: f64 = 1e-12;
/// A sample time this close to a grid time takes the grid state \[s\] (docs/model.md section 3a).
pub const GRID_MATCH_TOLERANCE_S: f64 = 1e-9;
/// Divergence threshold on |omega| [rad/s] (docs/model.md section 3).
pub const MAX_RATE_RAD_S: f64 = 100.0;

/// The run diverged at `t_s` (docs/model.md section 3): reported as such, never as a number.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("diverged at t = {t_s} s (non-finite state or |omega| > 100 rad/s)")]
pub struct Diverged {
    /// Time of the step after which the state failed the test \[s\].
    pub t_s: f64,
}

/// One simulated telemetry sample, as measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// Launch-frame position (x downrange, y crossrange, z down) \[m\].
    pub pos_m: [f64; 3],
    /// Euler angles (roll, pitch, yaw) \[deg\].
    pub att_deg: [f64; 3],
}

/// Mode of one ejector foot (docs/model.md section 3a).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FootMode {
    /// Before the ejector start time: not pushing yet.
    Waiting,
    /// Pushing.
    On,
    /// Stroke ended (or never started): never pushes again.
    Off,
}

/// What happened during a run, for tests and reports.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RunLog {
    /// Time each foot (forward, aft) turned on \[s\].
    pub foot_on_s: [Option<f64>; 2],
    /// Time each foot (forward, aft) turned off \[s\].
    pub foot_off_s: [Option<f64>; 2],
    /// Full and part RK4 steps taken on the main trajectory.
    pub steps: u64,
    /// How often the force evaluations left the scenario's tables (all zero without tables).
    pub tables: crate::table::TableExcursions,
    /// How often the samples found the flowfield beyond its grid (all zero without tables over
    /// position; filled by [`crate::Simulator::simulate_logged`], which reports runs).
    pub field_grid: crate::model::flowfield_grid::GridExcursions,
}

/// The integrator state between grid points.
#[derive(Clone, Copy)]
struct Cursor {
    t_s: f64,
    x: StateVector,
    modes: [FootMode; 2],
}

/// Propagates one run and records the observation at each of `times_s` (strictly increasing,
/// as telemetry times are) into `sink`.
///
/// The arithmetic uses fused multiply-adds (`f64::mul_add`: one rounding, the same bits on
/// every host). On x86-64 hosts with FMA units (Haswell and later) this dispatches, at run
/// time, to a copy of the integrator compiled for them, where each is one instruction; the
/// portable copy ([`propagate_portable`]) gives the same bits everywhere (on x86-64 hosts
/// without FMA units, slowly, through the C library's correctly rounded `fma`).
/// Compiled once, here, with the sink behind a pointer (one indirect call per sample): generic
/// over the sink, the model was compiled again into every crate that called it, two thirds of
/// `sepval-fit`'s code and most of a release build's time.
pub fn propagate<S: SampleSink>(
    model: &Model,
    run: &RunSetup,
    times_s: &[f64],
    sink: &mut S,
) -> Result<RunLog, Diverged> {
    propagate_dyn(model, run, times_s, sink)
}

/// [`propagate`] for a sink behind a pointer: the one compiled copy.
fn propagate_dyn(
    model: &Model,
    run: &RunSetup,
    times_s: &[f64],
    mut sink: &mut dyn SampleSink,
) -> Result<RunLog, Diverged> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("fma") && std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports the features `propagate_fma` is compiled for.
        return unsafe { propagate_fma(model, run, times_s, &mut sink) };
    }
    portable_dyn(model, run, times_s, sink)
}

/// [`propagate`] compiled for x86-64 hosts with AVX2 and FMA units.
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn propagate_fma<S: SampleSink>(
    model: &Model,
    run: &RunSetup,
    times_s: &[f64],
    sink: &mut S,
) -> Result<RunLog, Diverged> {
    propagate_inline(model, run, times_s, sink)
}

/// [`propagate`] for any host, without run-time dispatch: the same results bit for bit.
pub fn propagate_portable<S: SampleSink>(
    model: &Model,
    run: &RunSetup,
    times_s: &[f64],
    sink: &mut S,
) -> Result<RunLog, Diverged> {
    portable_dyn(model, run, times_s, sink)
}

/// [`propagate_portable`] for a sink behind a pointer: the one compiled copy.
fn portable_dyn(
    model: &Model,
    run: &RunSetup,
    times_s: &[f64],
    mut sink: &mut dyn SampleSink,
) -> Result<RunLog, Diverged> {
    propagate_inline(model, run, times_s, &mut sink)
}

/// The body of [`propagate`], inlined into each compiled copy (with everything it calls on
/// the hot path).
#[inline(always)]
fn propagate_inline<S: SampleSink>(
    model: &Model,
    run: &RunSetup,
    times_s: &[f64],
    sink: &mut S,
) -> Result<RunLog, Diverged> {
    let table_state = TableState::default();
    let engine = Engine::new(model, run, &table_state);
    // A run with the contract's force evaluation alone (the default event, a fit without
    // extension terms or tables) through a copy compiled without the tests for what it lacks.
    let mut log = if engine.equations.plain() {
        drive(engine.plain(), run, times_s, sink)?
    } else {
        drive(engine, run, times_s, sink)?
    };
    if model.tables.in_evaluation() {
        log.tables = table_state.excursions();
    }
    Ok(log)
}

/// The samples of [`propagate_inline`], taken by `engine`.
#[inline(always)]
fn drive<S: SampleSink, const PLAIN: bool>(
    mut engine: Engine<'_, PLAIN>,
    run: &RunSetup,
    times_s: &[f64],
    sink: &mut S,
) -> Result<RunLog, Diverged> {
    let initial = run.initial_state();
    let mut cursor = engine.start();
    let mut k: u64 = 0;
    for (index, &t_label) in times_s.iter().enumerate() {
        let t = t_label + run.time_offset_s;
        if t < -GRID_MATCH_TOLERANCE_S {
            sink.record(index, &observe(run, &initial), &initial);
            continue;
        }
        let (target_k, on_grid) = grid_target(t, engine.dt_s);
        while k < target_k {
            if cursor.modes == [FootMode::Off; 2] {
                // After the stroke ends no switch is due: plain steps, as `advance` takes them
                // then, with the state kept in registers between steps.
                let (x, t) = engine.coast(cursor.x, cursor.t_s, k, target_k)?;
                (cursor.x, cursor.t_s, k) = (x, t, target_k);
                break;
            }
            let t_next = (k + 1) as f64 * engine.dt_s;
            cursor = engine.advance(cursor, t_next, true)?;
            k += 1;
        }
        if on_grid {
            sink.record(index, &observe(run, &cursor.x), &cursor.x);
        } else {
            // One step (split at any switch inside it) from the grid state, off the main
            // trajectory.
            let off_grid = engine.advance(cursor, t, false)?;
            sink.record(index, &observe(run, &off_grid.x), &off_grid.x);
        }
    }
    Ok(engine.log)
}

/// The grid point `k` a sample at time `t` (> -1e-9 s) is taken from, and whether `t` is that
/// grid time (within 1e-9 s; otherwise `t` lies in (t_k, t_k+1) and the sample is one step off
/// the grid from t_k).
#[inline(always)]
fn grid_target(t: f64, dt_s: f64) -> (u64, bool) {
    let nearest = (t / dt_s).round().max(0.0);
    let on_grid = (t - nearest * dt_s).abs() <= GRID_MATCH_TOLERANCE_S;
    let target_k = if on_grid {
        nearest as u64
    } else {
        (t / dt_s).floor().max(0.0) as u64
    };
    (target_k, on_grid)
}

/// The observation of a state, with the measurement knobs applied (tracked point, attitude
/// bias).
#[inline]
pub fn observe(run: &RunSetup, x: &StateVector) -> Observation {
    let c_lb = dcm_from_quaternion([x[6], x[7], x[8], x[9]]);
    let r = Vector3::new(x[0], x[1], x[2]);
    let l = run.tracked_point_b_m;
    let pos = r + c_lb * l - l;
    let [roll, pitch, yaw] = euler_321_deg(&c_lb);
    let [b_roll, b_pitch, b_yaw] = run.attitude_bias_rad;
    Observation {
        pos_m: [pos.x, pos.y, pos.z],
        att_deg: [
            wrap_deg(roll + b_roll.to_degrees()),
            pitch + b_pitch.to_degrees(),
            wrap_deg(yaw + b_yaw.to_degrees()),
        ],
    }
}

/// One run's integrator (`PLAIN`: its equations are [`EquationsOfMotion::plain`]).
struct Engine<'a, const PLAIN: bool = false> {
    run: &'a RunSetup,
    equations: EquationsOfMotion<'a>,
    dt_s: f64,
    log: RunLog,
}

impl<'a> Engine<'a> {
    /// The engine of `run` (its table scratch in `table_state`).
    #[inline(always)]
    fn new(model: &'a Model, run: &'a RunSetup, table_state: &'a TableState) -> Self {
        Engine {
            run,
            equations: EquationsOfMotion::with_tables(run, model, table_state),
            dt_s: model.dt_s,
            log: RunLog::default(),
        }
    }

    /// This engine for a run whose equations are [`EquationsOfMotion::plain`].
    fn plain(self) -> Engine<'a, true> {
        debug_assert!(self.equations.plain());
        Engine {
            run: self.run,
            equations: self.equations,
            dt_s: self.dt_s,
            log: self.log,
        }
    }
}

impl<const PLAIN: bool> Engine<'_, PLAIN> {
    /// The cursor at release (t = 0): the initial state, the feet pushing at once or waiting
    /// for the ejector start time (logged).
    fn start(&mut self) -> Cursor {
        let start_mode = if self.run.ejector_start_s > 0.0 {
            FootMode::Waiting
        } else {
            FootMode::On
        };
        if start_mode == FootMode::On {
            self.log.foot_on_s = [Some(0.0); 2];
        }
        Cursor {
            t_s: 0.0,
            x: self.run.initial_state(),
            modes: [start_mode; 2],
        }
    }

    /// One classic RK4 step of length `h` from `x` at time `t` with the modes held, q
    /// renormalised (each stage at its own time: t, t + h/2, t + h/2, t + h).
    #[inline(always)]
    fn rk4(&self, x: &StateVector, t: f64, h: f64, modes: [FootMode; 2]) -> StateVector {
        rk4(
            &Held::<PLAIN> {
                equations: &self.equations,
                on: pushing(modes),
            },
            x,
            t,
            h,
        )
    }

    /// Whether a step from `c` of length `h` may not be taken whole with the modes held: a mode
    /// is due to switch at its start, or the ejector start time falls inside it (what
    /// [`Engine::advance`] checks before its trial step).
    #[inline(always)]
    fn event_at_start(&self, c: &Cursor, h: f64) -> bool {
        (0..2).any(|i| self.switch_due(c, i))
            || (c.modes.contains(&FootMode::Waiting) && self.ejector_starts_within(c.t_s, h))
    }

    /// Whether foot `i`'s mode is due to switch at the cursor's time: waiting at the ejector
    /// start time, or on and already past the stroke.
    #[inline(always)]
    fn switch_due(&self, c: &Cursor, i: usize) -> bool {
        match c.modes[i] {
            FootMode::Waiting => c.t_s >= self.run.ejector_start_s - SWITCH_TOLERANCE_S,
            FootMode::On => self.stroke_excess(&c.x, i) > 0.0,
            FootMode::Off => false,
        }
    }

    /// Whether the ejector start time falls inside a step of length `h` from `t_s` (more than
    /// 1e-12 s before its end; within that of the end it is taken at the end).
    #[inline(always)]
    fn ejector_starts_within(&self, t_s: f64, h: f64) -> bool {
        self.run.ejector_start_s - t_s < h - SWITCH_TOLERANCE_S
    }

    /// Whether a foot pushing during the step from `c` is past the stroke at its end `trial`
    /// (a stroke end inside the step, which [`Engine::advance`] locates).
    #[inline(always)]
    fn stroke_ends_in(&self, c: &Cursor, trial: &StateVector) -> bool {
        (0..2).any(|i| c.modes[i] == FootMode::On && self.stroke_excess(trial, i) > 0.0)
    }

    /// Grid steps from `t_s` = t_k to t_end (k < end), with both feet off: what
    /// [`Engine::advance`] does then (no switch is due, a full step to each grid point, the
    /// divergence test after it). Returns the state and time at t_end.
    #[inline(always)]
    fn coast(
        &mut self,
        mut x: StateVector,
        mut t_s: f64,
        k: u64,
        end: u64,
    ) -> Result<(StateVector, f64), Diverged> {
        for j in k + 1..=end {
            let t_next = j as f64 * self.dt_s;
            x = self.rk4(&x, t_s, t_next - t_s, [FootMode::Off; 2]);
            t_s = t_next;
            check_divergence(&x, t_s)?;
        }
        self.log.steps += end - k;
        Ok((x, t_s))
    }

    /// s_i - stroke of foot `i` at state `x`.
    #[inline(always)]
    fn stroke_excess(&self, x: &StateVector, i: usize) -> f64 {
        let q = [x[6], x[7], x[8], x[9]];
        let n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
        let c20 = 2.0 * (q[1] * q[3] - q[0] * q[2]) / n2;
        self.run.foot_displacement_m(i, x[2], c20) - self.run.stroke_m
    }

    /// Advances `from` to `t_target` (within one grid interval), splitting at switches.
    /// `main` says whether this is the main trajectory (whose switches are logged).
    #[inline(always)]
    fn advance(&mut self, from: Cursor, t_target: f64, main: bool) -> Result<Cursor, Diverged> {
        let mut c = from;
        loop {
            self.switch_due_modes(&mut c, main);
            let mut h = t_target - c.t_s;
            if h <= 0.0 {
                return Ok(c);
            }
            let tau = self.run.ejector_start_s;
            // The ejector start time falls inside this step: end the step there. (Within
            // 1e-12 s after the target it is taken at the target, by the next call.)
            let to_tau =
                c.modes.contains(&FootMode::Waiting) && self.ejector_starts_within(c.t_s, h);
            if to_tau {
                h = tau - c.t_s;
            }
            let trial = self.rk4(&c.x, c.t_s, h, c.modes);
            // Earliest stroke end inside the trial step.
            let mut first: Option<(usize, f64, StateVector)> = None;
            for i in 0..2 {
                if c.modes[i] == FootMode::On && self.stroke_excess(&trial, i) > 0.0 {
                    let (h_i, x_i) = self.locate_stroke_end(&c, h, &trial, i);
                    if first.as_ref().is_none_or(|(_, h_best, _)| h_i < *h_best) {
                        first = Some((i, h_i, x_i));
                    }
                }
            }
            let (t_new, x_new, switched_foot) = match first {
                Some((i, h_i, x_i)) => (c.t_s + h_i, x_i, Some(i)),
                None if to_tau => (tau, trial, None),
                None => (t_target, trial, None),
            };
            c = Cursor {
                t_s: t_new,
                x: x_new,
                modes: c.modes,
            };
            if main {
                self.log.steps += 1;
            }
            check_divergence(&c.x, c.t_s)?;
            if let Some(i) = switched_foot {
                c.modes[i] = FootMode::Off;
                if main {
                    self.log.foot_off_s[i] = Some(c.t_s);
                }
            }
            if (t_target - c.t_s).abs() <= SWITCH_TOLERANCE_S {
                // The target is reached; modes due there are settled by the next call (or by
                // the next loop of this one, for a sample taken off the grid).
                c.t_s = t_target;
                return Ok(c);
            }
        }
    }

    /// Switches the modes that are due at the cursor's time: waiting feet at the ejector start
    /// time, "on" feet already past the stroke.
    fn switch_due_modes(&mut self, c: &mut Cursor, main: bool) {
        for i in 0..2 {
            if c.modes[i] == FootMode::Waiting && self.switch_due(c, i) {
                // docs/model.md 3a: at t = tau each foot whose s_i <= stroke turns on.
                c.modes[i] = if self.stroke_excess(&c.x, i) <= 0.0 {
                    if main {
                        self.log.foot_on_s[i] = Some(c.t_s);
                    }
                    FootMode::On
                } else {
                    FootMode::Off
                };
            }
            if c.modes[i] == FootMode::On && self.switch_due(c, i) {
                c.modes[i] = FootMode::Off;
                if main {
                    self.log.foot_off_s[i] = Some(c.t_s);
                }
            }
        }
    }

    /// Locates the step length in (0, h] at which foot `i`'s displacement reaches the stroke
    /// (trial steps from `c` with the modes held) and returns it with the state there.
    #[inline(always)]
    fn locate_stroke_end(
        &self,
        c: &Cursor,
        h: f64,
        trial: &StateVector,
        i: usize,
    ) -> (f64, StateVector) {
        let g = |x: &StateVector| self.stroke_excess(x, i);
        let (mut lo, mut g_lo) = (0.0, g(&c.x));
        let (mut hi, mut g_hi, mut x_hi) = (h, g(trial), *trial);
        // Which end the last secant point replaced (Illinois: halve the other end's value
        // when the same end is kept twice).
        let mut side = 0i8;
        let mut iterations = 0;
        // To the last bit: until no double lies inside the bracket. A bracket left 1e-12 s wide
        // (before issue 36) made the switch time, and with it the trajectory, a staircase of the
        // parameters: a step of ~1e-9 deg in attitude after 1 s, larger than the change a probe
        // of 1e-6 of a weak parameter's range makes, which broke finite differences.
        while hi > lo {
            iterations += 1;
            let secant = hi - g_hi * (hi - lo) / (g_hi - g_lo);
            // Safeguard: bisect every fourth iteration or when the secant point is unusable.
            let mid = if iterations % 4 == 0 || !(secant > lo && secant < hi) {
                0.5 * (lo + hi)
            } else {
                secant
            };
            if !(mid > lo && mid < hi) {
                break;
            }
            let x_mid = self.rk4(&c.x, c.t_s, mid, c.modes);
            let g_mid = g(&x_mid);
            if g_mid > 0.0 {
                hi = mid;
                g_hi = g_mid;
                x_hi = x_mid;
                if side == 1 {
                    g_lo *= 0.5;
                }
                side = 1;
            } else {
                lo = mid;
                g_lo = g_mid;
                if side == -1 {
                    g_hi *= 0.5;
                }
                side = -1;
            }
            if iterations > 200 {
                break;
            }
        }
        (hi, x_hi)
    }
}

/// Which feet push in `modes`.
#[inline(always)]
fn pushing(modes: [FootMode; 2]) -> [bool; 2] {
    [modes[0] == FootMode::On, modes[1] == FootMode::On]
}

#[inline]
fn check_divergence(x: &StateVector, t_s: f64) -> Result<(), Diverged> {
    let rate2 = x[10] * x[10] + x[11] * x[11] + x[12] * x[12];
    if !x.iter().all(|v| v.is_finite()) || rate2 > MAX_RATE_RAD_S * MAX_RATE_RAD_S {
        return Err(Diverged { t_s });
    }
    Ok(())
}
