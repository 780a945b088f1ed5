//! One limit on the work of a run, applied wherever a run is set up (a scenario file, the
//! `simulate` flags, a telemetry file, a job), each checked before anything is allocated and
//! refused with the limit in the message; the bounds of plausible telemetry values; and the
//! largest input file of each kind ([`crate::input_file`] checks a file's size against its
//! limit before anything is allocated, and again while it reads).
//!
//! The limits are generous for store separation (an event lasts seconds, is sampled at a few
//! hundred hertz and integrated at a fraction of a millisecond) and small enough that one
//! simulation stays in memory and finishes in seconds: a run of [`MAX_STEPS`] steps takes about
//! 1.5 s on one core of the 2026 development machine, and [`MAX_SAMPLES`] samples of one
//! event take 224 MB (56 bytes each). The values are documented in `docs/model.md` section 6.

/// Most RK4 steps of one run (event span / integration step).
pub const MAX_STEPS: f64 = 1e7;
/// Most telemetry samples of one event, and of one job.
pub const MAX_SAMPLES: usize = 4_000_000;
/// Longest event: the latest sample time, and the simulated end time \[s\].
pub const MAX_SPAN_S: f64 = 3600.0;
/// Largest plausible position coordinate in telemetry \[m\].
pub const MAX_POSITION_M: f64 = 1e5;
/// The largest Mach number of the model's domain (docs/model.md section 1, "The model's
/// domain": the aerodynamics carry no compressibility beyond what a Mach table gives). A
/// condition beyond it is not flown (`sepval_run::domain`) and a table's Mach breakpoint
/// beyond it is refused (`sepval_common::table::Variable::domain`).
pub const MAX_MACH: f64 = 3.0;
/// Largest plausible Euler angle in telemetry (ten turns) \[deg\].
pub const MAX_ANGLE_DEG: f64 = 3600.0;

/// Largest telemetry file \[bytes\]: [`MAX_SAMPLES`] rows of 512 bytes. A row of the seven
/// columns in full precision takes at most 7 x 25 bytes (`-1.2345678901234567e-100,`) and
/// sepval writes about 120; the rest is room for extra channels, which are read and ignored.
/// The file is streamed line by line (never held whole), so this bounds the time spent on it,
/// not memory.
pub const MAX_TELEMETRY_BYTES: u64 = MAX_SAMPLES as u64 * 512;
/// Longest line of a telemetry file \[bytes\]: 64 KiB. A row of the seven columns in full
/// precision takes at most 175 bytes (sepval writes about 120) and a comment a few hundred;
/// a longer line is refused once this many bytes of it are read, so a file without a newline
/// (a gigabyte of NUL bytes) costs this much memory, not its size.
pub const MAX_TELEMETRY_LINE_BYTES: usize = 64 << 10;
/// Most values one table may hold (its grid points).
pub const MAX_TABLE_VALUES: usize = 1_000_000;
/// Largest table CSV file \[bytes\]: a table of the most grid points ([`MAX_TABLE_VALUES`]) in
/// rows of 128 bytes (three axes and two value columns in full precision take 5 x 25). The
/// file is held whole while it is read.
pub const MAX_TABLE_CSV_BYTES: u64 = MAX_TABLE_VALUES as u64 * 128;
/// Largest scenario TOML file \[bytes\]: 64 MiB, room for inline tables of about two million
/// values in full precision (a scenario written by sepval without tables is about 3 kB).
pub const MAX_SCENARIO_BYTES: u64 = 64 << 20;
/// Largest extension TOML file \[bytes\]: 1 MiB (at most 8 terms, `extension::MAX_TERMS`, of a
/// few hundred bytes each, comments included).
pub const MAX_EXTENSION_BYTES: u64 = 1 << 20;
/// Largest JSON input (a factors file; the binaries' checkpoints and results) \[bytes\]:
/// 256 MiB. A factors file is under 2 kB; a checkpoint holds a population and an archive of
/// candidates, a few MB at the study's settings.
pub const MAX_JSON_BYTES: u64 = 256 << 20;

use crate::number_text::Shown;

/// A run beyond the limits.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LimitError {
    /// Too long an event.
    #[error("an event of {} s is longer than the limit of {MAX_SPAN_S} s", Shown(*span_s))]
    Span {
        /// The span asked for \[s\].
        span_s: f64,
    },
    /// Too many integration steps.
    #[error(
        "{steps:.3e} RK4 steps ({} s at dt = {} s) exceed the limit of {MAX_STEPS:.0e} steps per run",
        Shown(*span_s),
        Shown(*dt_s)
    )]
    Steps {
        /// Steps asked for.
        steps: f64,
        /// The span \[s\].
        span_s: f64,
        /// The step \[s\].
        dt_s: f64,
    },
    /// Too many samples.
    #[error("{} samples exceed the limit of {MAX_SAMPLES} per event", Shown(*samples))]
    Samples {
        /// Samples asked for.
        samples: f64,
    },
    /// One sample: no trajectory.
    #[error(
        "one sample ({} s at {} Hz): a trajectory needs at least two (span x rate >= 1)",
        Shown(*span_s),
        Shown(*rate_hz)
    )]
    OneSample {
        /// The span \[s\].
        span_s: f64,
        /// The rate \[Hz\].
        rate_hz: f64,
    },
}

/// Checks a run that integrates from 0 to `span_s` at step `dt_s` (both finite and > 0).
pub fn check_steps(span_s: f64, dt_s: f64) -> Result<(), LimitError> {
    if span_s > MAX_SPAN_S {
        return Err(LimitError::Span { span_s });
    }
    let steps = span_s / dt_s;
    if steps > MAX_STEPS {
        return Err(LimitError::Steps {
            steps,
            span_s,
            dt_s,
        });
    }
    Ok(())
}

/// Checks telemetry sampled from 0 to `span_s` at `rate_hz` (both finite and > 0), before the
/// sample times are made.
pub fn check_sampling(span_s: f64, rate_hz: f64) -> Result<(), LimitError> {
    if span_s > MAX_SPAN_S {
        return Err(LimitError::Span { span_s });
    }
    let samples = (span_s * rate_hz).floor() + 1.0;
    if samples > MAX_SAMPLES as f64 {
        return Err(LimitError::Samples { samples });
    }
    if samples < 2.0 {
        return Err(LimitError::OneSample { span_s, rate_hz });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_refuse_with_the_limit_in_the_message() {
        check_steps(1.0, 0.0005).unwrap();
        check_sampling(1.0, 200.0).unwrap();
        check_sampling(1.0, 1.0).unwrap();
        assert_eq!(
            check_sampling(1e-300, 200.0).unwrap_err().to_string(),
            "one sample (1e-300 s at 200 Hz): a trajectory needs at least two (span x rate >= 1)"
        );
        assert_eq!(
            check_steps(1e5, 0.0005).unwrap_err().to_string(),
            "an event of 100000 s is longer than the limit of 3600 s"
        );
        assert_eq!(
            check_steps(1000.0, 1e-5).unwrap_err().to_string(),
            "1.000e8 RK4 steps (1000 s at dt = 0.00001 s) exceed the limit of 1e7 steps per run"
        );
        assert_eq!(
            check_steps(1e308, 0.0005).unwrap_err().to_string(),
            "an event of 1e308 s is longer than the limit of 3600 s"
        );
        assert_eq!(
            check_sampling(1.0, 1e9).unwrap_err().to_string(),
            "1000000001 samples exceed the limit of 4000000 per event"
        );
    }
}
