//! `sepval`: post-flight validation of store-separation simulations.
//!
//! The command line only: the library (`sepval_cli`) declares the flags and runs the commands;
//! this file parses the arguments, installs the signal handlers and reports errors: the whole
//! cause chain, exit status 2 (130 after SIGINT/SIGTERM); a panic is reported as a defect, with
//! its message and place, exit status 2 (`sepval_core::defect`).

use std::process::ExitCode;

use clap::Parser;
use sepval_cli::Cli;
use sepval_core::defect;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            if let Some(message) = sepval_cli::refusal(&e) {
                sepval_cli::front::err(&format!("sepval: error: {message}\n"));
                return ExitCode::from(2);
            }
            e.exit()
        }
    };
    sepval_core::cancel::install_signal_handlers();
    defect::install_hook();
    let outcome = defect::catch(|| {
        defect::inject("start");
        sepval_cli::run(cli.command)
    });
    match outcome {
        Ok(Ok(())) => ExitCode::SUCCESS,
        // A panic has unwound: the lock, temporary files and workers are gone with it.
        Err(defect) => {
            sepval_cli::front::err(&format!("sepval: {defect}\n"));
            ExitCode::from(2)
        }
        Ok(Err(e)) => {
            sepval_cli::front::err(&format!("sepval: error: {e:#}\n"));
            if sepval_core::cancel::requested() {
                ExitCode::from(130)
            } else {
                ExitCode::from(2)
            }
        }
    }
}
