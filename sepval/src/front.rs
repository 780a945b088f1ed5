//! Where a command's words and progress go: the front end that runs it. The `sepval` binary's
//! is the terminal (summaries on stdout, notes and warnings on stderr, indicatif bars); the
//! Python package installs its own, which collects the same text for the result object and
//! hands each step of progress to the caller's callback. Commands never print directly: they
//! call [`say!`](crate::say), [`note!`](crate::note), [`out`] and [`progress`], so a front end
//! changes nothing but where the text goes.
//!
//! One front end is current at a time, for the whole process (transport notices come from the
//! transports' threads): [`install`] sets one until its guard drops, and with none installed it
//! is the [`Terminal`].

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::sync::{Arc, RwLock};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use sepval_solve::run::{Progress, ProgressObserver};

/// What runs a command.
pub trait Front: Send + Sync {
    /// Text for standard output (a command's summary), newlines included.
    fn out(&self, text: &str);
    /// Text for standard error (notes, warnings, transport notices), newlines included.
    fn err(&self, text: &str);
    /// The observer of one long computation's progress (a search, a sweep).
    fn progress(&self) -> Box<dyn ProgressObserver>;
    /// The `sepval-worker` executable for `--evaluator ipc`, when this front end knows where
    /// it is (`$SEPVAL_WORKER` comes first; without either, the one beside the executable).
    fn worker(&self) -> Option<PathBuf> {
        None
    }
}

/// The terminal: stdout, stderr and progress bars (drawn only when stderr is a terminal).
pub struct Terminal;

impl Front for Terminal {
    // A closed stream (`sepval effects | head -1`, stderr closed) is nobody listening, not a
    // defect: the words are dropped and the command goes on to its end, its files complete
    // (`print!` panicked on the broken pipe, reported as an internal error).
    fn out(&self, text: &str) {
        let _ = std::io::stdout().lock().write_all(text.as_bytes());
    }

    fn err(&self, text: &str) {
        let _ = std::io::stderr().lock().write_all(text.as_bytes());
    }

    fn progress(&self) -> Box<dyn ProgressObserver> {
        Box::new(Bar::new())
    }
}

/// The front end installed, `None` for the terminal.
static CURRENT: RwLock<Option<Arc<dyn Front>>> = RwLock::new(None);

/// The current front end.
pub fn current() -> Arc<dyn Front> {
    let installed = CURRENT.read().unwrap_or_else(|e| e.into_inner()).clone();
    installed.unwrap_or_else(|| Arc::new(Terminal))
}

/// Makes `front` current until the guard returned drops (then the terminal is again).
#[must_use = "the front end is current only while the guard lives"]
pub fn install(front: Arc<dyn Front>) -> Installed {
    *CURRENT.write().unwrap_or_else(|e| e.into_inner()) = Some(front);
    Installed(())
}

/// The guard of an installed front end.
pub struct Installed(());

impl Drop for Installed {
    fn drop(&mut self) {
        *CURRENT.write().unwrap_or_else(|e| e.into_inner()) = None;
    }
}

/// Text for standard output through the current front end.
pub fn out(text: &str) {
    current().out(text);
}

/// Text for standard error through the current front end.
pub fn err(text: &str) {
    current().err(text);
}

/// A progress observer of the current front end.
pub fn progress() -> Box<dyn ProgressObserver> {
    current().progress()
}

/// `println!` through the current front end.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {
        $crate::front::out(&format!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprintln!` through the current front end.
#[macro_export]
macro_rules! note {
    ($($arg:tt)*) => {
        $crate::front::err(&format!("{}\n", format_args!($($arg)*)))
    };
}

/// A progress bar on stderr (hidden when stderr is not a terminal).
pub struct Bar {
    bar: ProgressBar,
    started: Instant,
}

impl Bar {
    /// A bar that draws only on a terminal.
    pub fn new() -> Self {
        Bar {
            bar: ProgressBar::hidden(),
            started: Instant::now(),
        }
    }
}

impl Default for Bar {
    fn default() -> Self {
        Bar::new()
    }
}

impl ProgressObserver for Bar {
    fn start(&mut self, label: &str, steps: Option<usize>) {
        self.started = Instant::now();
        self.bar = if std::io::stderr().is_terminal() {
            let bar = ProgressBar::with_draw_target(
                steps.map(|s| s as u64),
                ProgressDrawTarget::stderr(),
            );
            let template = if steps.is_some() {
                format!("{label:<7} {{pos:>4}}/{{len}} {{wide_bar}} {{msg}}")
            } else {
                format!("{label:<7} {{pos:>4}} {{spinner}} {{msg}}")
            };
            bar.set_style(ProgressStyle::with_template(&template).expect("a valid template"));
            bar
        } else {
            ProgressBar::hidden()
        };
    }

    fn progress(&mut self, p: &Progress) {
        self.bar.set_position(p.step as u64);
        let rate = p.evaluations as f64 / self.started.elapsed().as_secs_f64().max(1e-9);
        // A stage without goals (a plan's simulations) shows its rate alone.
        self.bar
            .set_message(if p.best.iter().all(|v| v.is_finite()) {
                format!(
                    "J_pos {:.4} m  J_att {:.3} deg  {rate:.0} sims/s",
                    p.best[0], p.best[1]
                )
            } else {
                format!("{rate:.0} sims/s")
            });
    }

    fn finish(&mut self) {
        self.bar.finish_and_clear();
    }
}
