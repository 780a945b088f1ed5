//! Where a long computation's wall time goes, stage by stage: when its environment variable is
//! set (to anything), each stage's wall time since the previous stage ended is printed on
//! stderr as `LABEL timing: STAGE S s`. For finding what to make faster; nothing of it reaches
//! any output, and without the variable it costs one lookup per stage.

use std::sync::Mutex;
use std::time::Instant;

/// A clock of stages, switched on by an environment variable (a `static` of each computation).
pub struct StageClock {
    var: &'static str,
    label: &'static str,
    /// When the previous stage ended (`None` before the first).
    last: Mutex<Option<Instant>>,
}

impl StageClock {
    /// A clock printing `label timing: ...` when `var` is set.
    pub const fn new(var: &'static str, label: &'static str) -> StageClock {
        StageClock {
            var,
            label,
            last: Mutex::new(None),
        }
    }

    /// The environment variable that switches it on.
    pub fn var(&self) -> &'static str {
        self.var
    }

    /// Starts the clock (the computation begins).
    pub fn start(&self) {
        if std::env::var_os(self.var).is_some() {
            *self.last.lock().unwrap_or_else(|e| e.into_inner()) = Some(Instant::now());
        }
    }

    /// Prints the wall time of `stage`, which ends now, when the clock is on.
    pub fn lap(&self, stage: &str) {
        if std::env::var_os(self.var).is_none() {
            return;
        }
        let now = Instant::now();
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(before) = last.replace(now) {
            eprintln!(
                "{} timing: {stage} {:.2} s",
                self.label,
                now.duration_since(before).as_secs_f64()
            );
        }
    }
}
