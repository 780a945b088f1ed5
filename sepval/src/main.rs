//! `sepval`: post-flight validation of store-separation simulations.
//!
//! The command line only: [`cli`] declares the flags, each file of [`command`] turns one
//! subcommand's flags into a validated configuration and calls the libraries
//! (`sepval_fit`, `sepval_diagnose`, `sepval_plan`, `sepval_transport`, `sepval_common`, ...), and this file dispatches and
//! reports errors: the whole cause chain, exit status 2 (130 after SIGINT/SIGTERM).

// The doc comments here are clap's --help text, where units read `[s]`, `[m]`; rustdoc would
// take those for links.
#![allow(rustdoc::broken_intra_doc_links)]

mod cli;
mod command;

use std::process::ExitCode;

use clap::Parser;
use clap::error::{ContextKind, ContextValue, ErrorKind};

use cli::{Cli, Command};

/// A flag's value outside its closed set, as every other refusal reads: `--flag value:
/// expected a, b or c`.
fn invalid_value(e: &clap::Error) -> Option<String> {
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

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            if let Some(message) = invalid_value(&e) {
                eprintln!("sepval: error: {message}");
                return ExitCode::from(2);
            }
            e.exit()
        }
    };
    sepval_common::cancel::install_signal_handlers();
    let result = match cli.command {
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
        Command::Bench(args) => command::bench::run(args),
        Command::Gateway(args) => command::gateway::run(args),
        Command::Selftest(c) => command::selftest::run(c),
        Command::CleanIpc => {
            command::clean_ipc::run();
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sepval: error: {e:#}");
            if sepval_common::cancel::requested() {
                ExitCode::from(130)
            } else {
                ExitCode::from(2)
            }
        }
    }
}
