//! One command of the `sepval` command line run for Python: its words parsed by the CLI's own
//! parser, the command run by the CLI's own code on a thread of its own while the calling
//! thread, the GIL released, waits for what it says; Ctrl-C (`KeyboardInterrupt`) and an
//! exception raised by the progress callback raise sepval's one cancellation flag, the command
//! stops within a second, and the flag is withdrawn before the call returns.
//!
//! What the command prints (its summary, its notes and warnings) is collected, not printed: the
//! package shows it as the result's `summary` and `log`, and warnings as Python warnings. Each
//! step of progress is handed to the callback on the calling thread while the command waits for
//! it, so a callback sees the search as it is at that step, and one that raises stops it there.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::sync::{Arc, LazyLock};
use std::time::Duration;

use clap::Parser;
use crossbeam::channel::{self, Receiver, RecvTimeoutError, Sender};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sepval_cli::front::{self, Front};
use sepval_core::cancel;
use sepval_solve::run::{Progress, ProgressObserver};

use crate::SepvalError;

/// How often the waiting thread looks for Ctrl-C.
const POLL: Duration = Duration::from_millis(50);

/// One command at a time in this process: the cancellation flag and the front end are
/// process-wide. The token is taken from the channel and given back.
static TOKEN: LazyLock<(Sender<()>, Receiver<()>)> = LazyLock::new(|| {
    let (tx, rx) = channel::bounded(1);
    tx.send(()).expect("an empty channel of one");
    (tx, rx)
});

/// What the command said: its standard output and its lines of standard error.
pub struct Said {
    /// The summary (stdout).
    pub out: String,
    /// Notes, warnings and notices (stderr), one per entry.
    pub err: Vec<String>,
}

/// A message from the command's thread to the waiting one.
enum Message {
    Out(String),
    Err(String),
    Step(Step, Sender<()>),
    Done(Result<(), String>),
}

/// One event of progress, as the callback receives it (a dict).
enum Step {
    Start { stage: String, steps: Option<usize> },
    Progress { stage: String, p: Progress },
    Finish { stage: String },
}

/// The Python package's front end: everything goes to the waiting thread.
struct Relay {
    tx: Sender<Message>,
    worker: Option<PathBuf>,
}

impl Front for Relay {
    fn out(&self, text: &str) {
        let _ = self.tx.send(Message::Out(text.to_string()));
    }

    fn err(&self, text: &str) {
        let _ = self.tx.send(Message::Err(text.to_string()));
    }

    fn progress(&self) -> Box<dyn ProgressObserver> {
        Box::new(Steps {
            tx: self.tx.clone(),
            stage: String::new(),
        })
    }

    fn worker(&self) -> Option<PathBuf> {
        self.worker.clone()
    }
}

/// A progress observer that hands each event over and waits until it was heard.
struct Steps {
    tx: Sender<Message>,
    stage: String,
}

impl Steps {
    fn send(&self, step: Step) {
        let (ack, heard) = channel::bounded(1);
        if self.tx.send(Message::Step(step, ack)).is_ok() {
            // Given back once the callback returned (or dropped if nobody listens).
            let _ = heard.recv();
        }
    }
}

impl ProgressObserver for Steps {
    fn start(&mut self, label: &str, steps: Option<usize>) {
        self.stage = label.to_string();
        self.send(Step::Start {
            stage: self.stage.clone(),
            steps,
        });
    }

    fn progress(&mut self, p: &Progress) {
        self.send(Step::Progress {
            stage: self.stage.clone(),
            p: p.clone(),
        });
    }

    fn finish(&mut self) {
        self.send(Step::Finish {
            stage: self.stage.clone(),
        });
    }
}

impl Step {
    /// The event as a plain dict: `event` (`start`, `step`, `finish`), `stage` and, for a
    /// step, `step`, `steps`, `evaluations`, `j_pos_m`, `j_att_deg` (None without goals).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        match self {
            Step::Start { stage, steps } => {
                d.set_item("event", "start")?;
                d.set_item("stage", stage)?;
                d.set_item("steps", steps)?;
            }
            Step::Progress { stage, p } => {
                let finite = |v: f64| v.is_finite().then_some(v);
                d.set_item("event", "step")?;
                d.set_item("stage", stage)?;
                d.set_item("step", p.step)?;
                d.set_item("steps", p.steps)?;
                d.set_item("evaluations", p.evaluations)?;
                d.set_item("j_pos_m", finite(p.best[0]))?;
                d.set_item("j_att_deg", finite(p.best[1]))?;
            }
            Step::Finish { stage } => {
                d.set_item("event", "finish")?;
                d.set_item("stage", stage)?;
            }
        }
        Ok(d)
    }
}

/// Runs the command of `words` (as after `sepval` on a command line) to its end. `progress`
/// hears each step; `worker` is the `sepval-worker` executable for `--evaluator ipc`.
pub fn run(
    py: Python<'_>,
    words: Vec<String>,
    progress: Option<Py<PyAny>>,
    worker: Option<PathBuf>,
) -> PyResult<Said> {
    let cli = parse(words)?;
    if CALLING.get() {
        return Err(SepvalError::new_err(
            "a sepval command is already running on this thread (a progress callback cannot \
             start another)",
        ));
    }
    let _turn = wait_for(py)?;
    run_alone(py, cli, progress, worker)
}

thread_local! {
    /// Whether this thread is in a call (its progress callback runs here too).
    static CALLING: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// The token of the one command running, taken by this thread (CALLING), given back when
/// dropped (also on a panic).
struct Turn;

impl Turn {
    fn taken() -> Turn {
        CALLING.set(true);
        Turn
    }
}

impl Drop for Turn {
    fn drop(&mut self) {
        CALLING.set(false);
        let _ = TOKEN.0.send(());
    }
}

/// The command's words through the CLI's own parser: its refusals read as the CLI's.
fn parse(words: Vec<String>) -> PyResult<sepval_cli::Cli> {
    let argv = std::iter::once("sepval".to_string()).chain(words);
    sepval_cli::Cli::try_parse_from(argv).map_err(|e| {
        let message = sepval_cli::refusal(&e).unwrap_or_else(|| e.to_string());
        SepvalError::new_err(message.trim_end().to_string())
    })
}

/// Takes the token, looking for Ctrl-C while another thread's command runs.
fn wait_for(py: Python<'_>) -> PyResult<Turn> {
    loop {
        match py.detach(|| TOKEN.1.recv_timeout(POLL)) {
            Ok(()) => return Ok(Turn::taken()),
            Err(RecvTimeoutError::Timeout) => py.check_signals()?,
            Err(RecvTimeoutError::Disconnected) => {
                return Err(SepvalError::new_err("sepval's command token is gone"));
            }
        }
    }
}

/// Runs the command on its thread, the only one in this process.
fn run_alone(
    py: Python<'_>,
    cli: sepval_cli::Cli,
    progress: Option<Py<PyAny>>,
    worker: Option<PathBuf>,
) -> PyResult<Said> {
    cancel::reset();
    let (tx, rx) = channel::unbounded();
    let installed = front::install(Arc::new(Relay {
        tx: tx.clone(),
        worker,
    }));
    let thread = std::thread::Builder::new()
        .name("sepval".into())
        .spawn(move || {
            let outcome = catch_unwind(AssertUnwindSafe(|| sepval_cli::run(cli.command)));
            let done = match outcome {
                Ok(Ok(())) => Ok(()),
                Ok(Err(e)) => Err(format!("{e:#}")),
                Err(_) => Err("internal error: the command panicked".to_string()),
            };
            let _ = tx.send(Message::Done(done));
        })
        .map_err(|e| SepvalError::new_err(format!("cannot start the command's thread: {e}")))?;
    let (said, done, raised) = listen(py, &rx, progress.as_ref());
    let _ = thread.join();
    drop(installed);
    cancel::reset();
    if let Some(e) = raised {
        return Err(e);
    }
    match done {
        Ok(()) => Ok(said),
        Err(message) => Err(SepvalError::new_err(message)),
    }
}

/// Collects what the command says until it is done; the first exception raised while it ran
/// (Ctrl-C, or the callback's) has stopped it and is returned to be raised.
fn listen(
    py: Python<'_>,
    rx: &Receiver<Message>,
    progress: Option<&Py<PyAny>>,
) -> (Said, Result<(), String>, Option<PyErr>) {
    let mut said = Said {
        out: String::new(),
        err: Vec::new(),
    };
    let mut raised: Option<PyErr> = None;
    let stop = |e: PyErr, raised: &mut Option<PyErr>| {
        if raised.is_none() {
            cancel::request();
            *raised = Some(e);
        }
    };
    loop {
        match py.detach(|| rx.recv_timeout(POLL)) {
            Ok(Message::Out(text)) => said.out.push_str(&text),
            Ok(Message::Err(text)) => said.err.push(text.trim_end().to_string()),
            Ok(Message::Step(step, heard)) => {
                if let (Some(callback), None) = (progress, &raised) {
                    let called = step
                        .to_dict(py)
                        .and_then(|d| callback.call1(py, (d,)).map(drop));
                    if let Err(e) = called {
                        stop(e, &mut raised);
                    }
                }
                let _ = heard.send(());
            }
            Ok(Message::Done(done)) => return (said, done, raised),
            Err(RecvTimeoutError::Timeout) => {
                if let Err(e) = py.check_signals() {
                    stop(e, &mut raised);
                }
            }
            Err(RecvTimeoutError::Disconnected) => {
                let lost = Err("internal error: the command's thread ended without an answer");
                return (said, lost.map_err(str::to_string), raised);
            }
        }
    }
}
