//! A panic is a defect of sepval, never the user's fault: the binaries run a command inside
//! [`catch`], which turns a panic anywhere in it (its own thread, or a thread whose panic
//! reaches it) into a [`Defect`] that says so, with the panic's message and where it happened;
//! the binary prints it and exits with status 2, never aborts with a backtrace. The panic
//! unwinds first, so everything the command held is dropped on the way out as on an error:
//! the output directory's lock released (and a directory that received nothing removed),
//! temporary files deleted (no output is ever partial: files are written whole and renamed),
//! workers stopped and shared memory removed.
//!
//! [`install_hook`] replaces the standard panic message (and its backtrace hint) with a record
//! of every panic ([`catch`] reports them); with `RUST_BACKTRACE` set, the standard hook runs
//! too, for whoever debugs it.

use std::any::Any;
use std::panic::{AssertUnwindSafe, PanicHookInfo};
use std::sync::Mutex;

/// The panics recorded by the hook since the last [`catch`] began (at most [`KEPT`]).
static PANICS: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Panics kept for the report: the first is the cause, later ones its consequences.
const KEPT: usize = 4;

/// The environment variable that makes [`inject`] panic at the point it names (the tests of
/// this guard: a panic where a command would have one, with its effects on disk).
pub const INJECT_VARIABLE: &str = "SEPVAL_INJECT_PANIC";

/// A panic during a command: a defect, reported as such.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("internal error (a defect; please report it): {}", .panics.join("; then "))]
pub struct Defect {
    /// Each panic recorded, first first: "MESSAGE at FILE:LINE:COLUMN (thread NAME)".
    pub panics: Vec<String>,
}

/// Records every panic instead of printing it (the standard hook still runs when
/// `RUST_BACKTRACE` is set). Call once, at the start of a binary.
pub fn install_hook() {
    let standard = std::panic::take_hook();
    let debugging = std::env::var_os("RUST_BACKTRACE").is_some_and(|v| v != "0");
    std::panic::set_hook(Box::new(move |info| {
        record(describe(info));
        if debugging {
            standard(info);
        }
    }));
}

fn record(panic: String) {
    let mut panics = PANICS.lock().unwrap_or_else(|p| p.into_inner());
    if panics.len() < KEPT {
        panics.push(panic);
    }
}

/// "MESSAGE at FILE:LINE:COLUMN (thread NAME)".
fn describe(info: &PanicHookInfo<'_>) -> String {
    let message = payload_text(info.payload());
    let thread = std::thread::current()
        .name()
        .map_or(String::new(), |n| format!(" (thread {n})"));
    match info.location() {
        Some(l) => format!(
            "{message} at {}:{}:{}{thread}",
            l.file(),
            l.line(),
            l.column()
        ),
        None => format!("{message}{thread}"),
    }
}

fn payload_text(payload: &(dyn Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".to_string())
}

/// Runs `command`; a panic in it is returned as a [`Defect`] once it has unwound (everything
/// `command` held dropped). Without [`install_hook`], the panic's own payload is reported.
pub fn catch<T>(command: impl FnOnce() -> T) -> Result<T, Defect> {
    PANICS.lock().unwrap_or_else(|p| p.into_inner()).clear();
    std::panic::catch_unwind(AssertUnwindSafe(command)).map_err(|payload| {
        let mut panics = std::mem::take(&mut *PANICS.lock().unwrap_or_else(|p| p.into_inner()));
        if panics.is_empty() {
            panics.push(payload_text(payload.as_ref()));
        }
        Defect { panics }
    })
}

/// Panics when [`INJECT_VARIABLE`] names `point`: the tests' way to put a defect where a
/// command would meet one. Nothing happens otherwise.
#[track_caller]
pub fn inject(point: &str) {
    if std::env::var(INJECT_VARIABLE).is_ok_and(|v| v == point) {
        panic!("{INJECT_VARIABLE}={point}: a panic injected for a test");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_is_a_defect_with_its_message_and_what_it_held_is_dropped() {
        struct Held<'a>(&'a std::sync::atomic::AtomicBool);
        impl Drop for Held<'_> {
            fn drop(&mut self) {
                self.0.store(true, std::sync::atomic::Ordering::SeqCst);
            }
        }
        let dropped = std::sync::atomic::AtomicBool::new(false);
        let e = catch(|| {
            let _held = Held(&dropped);
            panic!("index {} out of bounds", 3)
        })
        .unwrap_err();
        assert!(dropped.load(std::sync::atomic::Ordering::SeqCst));
        let text = e.to_string();
        assert!(
            text.starts_with("internal error (a defect; please report it): index 3 out of bounds"),
            "{text}"
        );
        assert_eq!(catch(|| 7).unwrap(), 7);
    }
}
