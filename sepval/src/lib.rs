//! The `sepval` command line as a library (`sepval_cli`): [`cli`] declares the flags, each file
//! of [`command`] turns one subcommand's flags into a validated configuration and calls the
//! libraries (`sepval_fit`, `sepval_diagnose`, `sepval_plan`, `sepval_predict`,
//! `sepval_envelope`, `sepval_transport`, `sepval_common`, ...), and [`front`] says where what a
//! command prints and its progress go. The `sepval` binary parses its arguments and calls
//! [`run`]; the Python package (`python/`) builds the same words from its keyword arguments and
//! calls [`run`] too, so both run the very same configuration code, refuse bad input with the
//! same messages and give the same results bit for bit.

// The doc comments of `cli` are clap's --help text, where units read `[s]`, `[m]`; rustdoc
// would take those for links.
#![allow(rustdoc::broken_intra_doc_links)]

#[macro_use]
pub mod front;
pub mod cli;
pub mod command;

use clap::error::{ContextKind, ContextValue, ErrorKind};

pub use cli::{Cli, Command};

/// Runs one command to its end. Errors carry their whole cause chain (print them with
/// `{:#}`); after [`sepval_core::cancel::request`] a command stops within a second with an
/// error, and `sepval_core::cancel::requested()` tells that this was why.
pub fn run(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Simulate(args) => command::simulate::run(args),
        Command::Effects => {
            command::effects::run();
            Ok(())
        }
        Command::Goals(args) => command::goals::run(args),
        Command::Scenario(args) => command::scenario::run(args),
        Command::Fit(args) => command::fit::run(*args),
        Command::Rerun(args) => command::rerun::run(args),
        Command::Diagnose(args) => command::diagnose::run(*args),
        Command::Plan(args) => command::plan::run(*args),
        Command::Predict(args) => command::predict::run(*args),
        Command::Envelope(args) => command::envelope::run(*args),
        Command::Update(args) => command::update::run(*args),
        Command::Campaign(c) => command::campaign::run(c),
        Command::Aero(args) => command::aero::run(args),
        Command::Bench(args) => command::bench::run(args),
        Command::Gateway(args) => command::gateway::run(args),
        Command::Selftest(c) => command::selftest::run(c),
        Command::CleanIpc => {
            command::clean_ipc::run();
            Ok(())
        }
    }
}

/// A flag's value outside its closed set, as every other refusal reads: `--flag value:
/// expected a, b or c`; `None` for clap's other errors (help, usage), which clap renders.
pub fn refusal(e: &clap::Error) -> Option<String> {
    let text = |kind| match e.get(kind) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        _ => None,
    };
    let flag = text(ContextKind::InvalidArg)?;
    let flag = flag.split([' ', '=']).next().unwrap_or(&flag).to_string();
    let value = text(ContextKind::InvalidValue)?;
    if e.kind() == ErrorKind::ValueValidation {
        // A typed value that refused itself (a run id): its own message says why.
        let reason = std::error::Error::source(e)?.to_string();
        let value = if value.is_empty() {
            "\"\"".to_string()
        } else {
            value
        };
        return Some(format!("{flag} {value}: {reason}"));
    }
    if e.kind() != ErrorKind::InvalidValue {
        return None;
    }
    let valid = match e.get(ContextKind::ValidValue) {
        Some(ContextValue::Strings(v)) if !v.is_empty() => v.clone(),
        _ => return None,
    };
    let expected = match valid.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => return None,
    };
    Some(format!("{flag} {value}: expected {expected}"))
}
