//! `sepval-worker`: the simulation server of a distributed fit.
//!
//! The command line only: which transport to join (`--run` over iceoryx2 shared memory,
//! `--connect` over zenoh, `--uds` over a Unix socket), then the one serve loop of
//! `sepval_transport::serve` with this process's own simulations. A worker validates every
//! request and answers a bad one with a typed failure instead of crashing; it ends cleanly when
//! its coordinator ends the run or goes away, or on SIGINT/SIGTERM. A panic is reported as a
//! defect with its message and place, exit status 2 (`sepval_core::defect`). Run `iox2 service
//! list` with the run's configuration to see its services (see docs/guide.md, "Distributed
//! evaluation").

// The doc comments here are clap's --help text, where units read `[s]`, `[m]`; rustdoc would
// take those for links.
#![allow(rustdoc::broken_intra_doc_links)]

use std::process::ExitCode;
use std::sync::Arc;
use std::time::Duration;

use anyhow::Result;
use clap::Parser;
use sepval_core::defect;
use sepval_transport::RunId;
use sepval_transport::ipc::IpcWorker;
use sepval_transport::link::Stopped;
use sepval_transport::serve::{Local, serve};
use sepval_transport::uds::UdsWorker;

#[derive(Parser)]
#[command(
    name = "sepval-worker",
    version,
    about = "Runs store-separation simulations for a sepval coordinator",
    long_about = "Runs store-separation simulations for a sepval coordinator. `sepval fit \
                  --workers N` starts workers itself; to start them yourself (as a job scheduler \
                  would), run `sepval fit --attach RUN_ID --workers N` and then N times \
                  `sepval-worker --run RUN_ID`."
)]
#[command(group(clap::ArgGroup::new("transport").required(true).args(["run", "uds"])))]
struct Cli {
    /// The run to join (the coordinator prints it).
    #[arg(long, value_name = "RUN_ID")]
    run: Option<RunId>,
    /// Serve over this Unix domain socket instead (the throughput benchmark's comparison).
    #[arg(long, value_name = "PATH")]
    uds: Option<std::path::PathBuf>,
    /// Join the run over zenoh at the coordinator's endpoint (e.g. tcp/192.0.2.7:7447) instead
    /// of shared memory: for workers on other hosts (built with the `zenoh` feature).
    #[arg(long, value_name = "ENDPOINT", requires = "run")]
    connect: Option<String>,
    /// zenoh: a zenoh JSON5 configuration to start from (TLS certificates, authentication).
    #[arg(long, value_name = "FILE", requires = "connect")]
    zenoh_config: Option<std::path::PathBuf>,
    /// How long to wait for the coordinator's job setup [s].
    #[arg(long, default_value_t = 30.0, value_name = "S", value_parser = positive_seconds)]
    setup_timeout: f64,
    /// Announce this protocol version instead of our own (compatibility testing only).
    #[arg(long, hide = true)]
    announce_protocol: Option<u32>,
}

/// A finite number of seconds > 0.
fn positive_seconds(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= 1e9 => Ok(v),
        _ => Err(format!("{text}: expected a number of seconds > 0")),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    sepval_core::cancel::install_signal_handlers();
    defect::install_hook();
    let outcome = defect::catch(|| {
        defect::inject("worker");
        serve_as(&cli)
    });
    let result = match outcome {
        Ok(result) => result,
        // A panic has unwound (the link and its shared memory dropped): a defect, said so.
        Err(defect) => {
            note(format_args!("sepval-worker: {defect}"));
            return ExitCode::from(2);
        }
    };
    match result {
        // The coordinator's own SIGTERM at the end of a run is not worth a word.
        Ok(Stopped::Signal) => ExitCode::SUCCESS,
        Ok(stopped) => {
            note(format_args!("sepval-worker: {stopped}"));
            ExitCode::SUCCESS
        }
        Err(e) => {
            note(format_args!("sepval-worker: error: {e:#}"));
            ExitCode::from(2)
        }
    }
}

/// Joins the transport the flags name and serves the run.
fn serve_as(cli: &Cli) -> Result<Stopped> {
    let setup_timeout = Duration::from_secs_f64(cli.setup_timeout);
    match (&cli.run, &cli.uds, &cli.connect) {
        (Some(run), _, Some(endpoint)) => serve_zenoh(cli, run, endpoint, setup_timeout),
        (Some(run), _, None) => (|| {
            let mut link = IpcWorker::join(run.clone(), setup_timeout, cli.announce_protocol)?;
            let mut local = Local(Arc::clone(link.job()));
            Ok(serve(&mut link, &mut local)?)
        })(),
        (None, Some(path), _) => (|| {
            let mut link = UdsWorker::join(path, setup_timeout)?;
            let mut local = Local(Arc::clone(link.job()));
            Ok(serve(&mut link, &mut local)?)
        })(),
        (None, None, _) => unreachable!("clap requires one transport"),
    }
}

/// Joins a run over zenoh and serves it.
#[cfg(feature = "zenoh")]
fn serve_zenoh(cli: &Cli, run: &RunId, endpoint: &str, setup_timeout: Duration) -> Result<Stopped> {
    use sepval_transport::zenoh::{JoinOptions, ZenohWorker};
    let mut link = ZenohWorker::join(JoinOptions {
        endpoint: endpoint.to_string(),
        run_id: run.clone(),
        setup_timeout,
        zenoh_config: cli.zenoh_config.clone(),
        announce_protocol: cli.announce_protocol,
    })?;
    note(format_args!(
        "sepval-worker: joined run {run} at {endpoint} as {}",
        link.worker_id()
    ));
    let mut local = Local(Arc::clone(link.job()));
    Ok(serve(&mut link, &mut local)?)
}

#[cfg(not(feature = "zenoh"))]
fn serve_zenoh(_: &Cli, _: &RunId, _: &str, _: Duration) -> Result<Stopped> {
    anyhow::bail!(
        "--connect: this sepval-worker was built without the zenoh transport; rebuild with \
         `cargo build --release --features zenoh`"
    )
}

/// A line on standard error; a closed stderr drops it (never a panic: the worker's exit status
/// is its answer).
fn note(text: std::fmt::Arguments<'_>) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "{text}");
}
