//! `sepval bench`: simulations per second against worker count, per transport.

use std::sync::Arc;

use std::path::PathBuf;

use anyhow::Result;
use sepval_report::figures::throughput_figure;
use sepval_run::out_dir::Request;
use sepval_transport::bench::{BenchOptions, Transport, run_bench, series, table, write_csv};

use super::{tell, worker_executable};
use crate::cli::{BenchArgs, TransportArg};

/// Runs `sepval bench`.
pub fn run(args: BenchArgs) -> Result<()> {
    let transports: Vec<Transport> = args
        .transports
        .iter()
        .map(|t| match t {
            TransportArg::Scalar => Transport::Scalar,
            TransportArg::Single => Transport::Single,
            TransportArg::Pool => Transport::Pool,
            TransportArg::Ipc => Transport::Ipc,
            TransportArg::Uds => Transport::Uds,
            TransportArg::Zenoh => Transport::Zenoh,
        })
        .collect();
    let options = BenchOptions {
        workers: args.workers.clone(),
        evals: args.evals,
        transports,
        worker_executable: PathBuf::new(),
        repeat: args.repeat,
    };
    options.check()?;
    let options = BenchOptions {
        worker_executable: worker_executable()?,
        ..options
    };
    // A run directory as every command's: refused before anything runs when it holds what
    // an earlier bench did not write (before 2026-11-29 bench.csv and bench.png were written
    // into any directory, over a file of that name).
    let run_dir = super::claim_out(
        &args.out,
        Request {
            command: "bench",
            claim: super::fresh_or_overwrite(&args.overwrite),
            inputs: &[],
            resume: None,
        },
    )?;
    let (job, _) = sepval_run::inputs::job(&[], None, None, Default::default(), &mut tell())?;
    note!(
        "benchmarking {} simulations of the default event per measurement, median of {} \
         interleaved rounds, on {} core(s)",
        args.evals,
        args.repeat,
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    let rows = run_bench(Arc::new(job), &options, &mut |r| {
        note!(
            "  {:<6} {} worker(s): {:.0} simulations/s, {:.0} refused requests/s",
            r.transport,
            r.workers,
            r.evals_per_s(),
            r.evals as f64 / r.probe_wall_s
        );
    })?;
    crate::front::out(&table(&rows));
    run_dir.prepare()?;
    write_csv(&args.out, &rows)?;
    let data = series(&rows);
    let lines: Vec<(&str, &[(usize, f64)])> = data
        .iter()
        .map(|(n, v)| (n.as_str(), v.as_slice()))
        .collect();
    throughput_figure(&args.out.join("bench.png"), &lines)?;
    say!(
        "wrote {} and {}",
        args.out.join("bench.csv").display(),
        args.out.join("bench.png").display()
    );
    run_dir.commit();
    Ok(())
}
