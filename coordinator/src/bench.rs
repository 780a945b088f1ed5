//! `sepval bench`: simulations per second against worker count, per transport.
//!
//! Transports: `single` (one thread, in-process), `pool` (in-process thread pool), `ipc`
//! (iceoryx2 worker processes), `uds` (the same requests as postcard frames over Unix domain
//! sockets) and, when built with the `zenoh` feature, `zenoh` (workers joining over TCP on the
//! loopback interface). Each measurement is one batch of `evals` distinct candidates after a warm-up batch;
//! starting the workers is not timed. The transport overhead per evaluation is the wall time
//! beyond ideal scaling of the single-thread rate: (wall x workers - evals x t_single) / evals.

use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use rand::RngExt;
use sepval_common::atomic_file::write_atomically;
use sepval_common::evaluation::{Candidate, Evaluator, InProcess, Job};
use sepval_common::factors::Factors;

use crate::ipc::{IpcEvaluator, IpcOptions, Launch};
use crate::uds::UdsEvaluator;

/// One measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchRow {
    /// Transport name.
    pub transport: String,
    /// Workers (threads for `pool`).
    pub workers: usize,
    /// Evaluations timed.
    pub evals: usize,
    /// Wall time [s].
    pub wall_s: f64,
}

impl BenchRow {
    /// Simulations per second.
    pub fn evals_per_s(&self) -> f64 {
        self.evals as f64 / self.wall_s
    }
}

/// Benchmark settings.
pub struct BenchOptions {
    /// Worker counts.
    pub workers: Vec<usize>,
    /// Evaluations per measurement.
    pub evals: usize,
    /// Transports to measure.
    pub transports: Vec<String>,
    /// The worker executable.
    pub worker_executable: std::path::PathBuf,
}

/// `n` distinct candidates around the truth (seeded, within bounds).
pub fn candidates(job: &Job, n: usize) -> Vec<Candidate> {
    let table = job.factor_table();
    let mut rng = crate::rng::seeded(7);
    (0..n)
        .map(|_| {
            let mut f = Factors::TRUTH;
            for (v, s) in f.0.iter_mut().zip(table.0.iter()) {
                let u: f64 = rng.random::<f64>() - 0.5;
                *v = (*v + 0.1 * u * s.range()).clamp(s.min, s.max);
            }
            Candidate::baseline(f)
        })
        .collect()
}

fn time(evaluator: &mut dyn Evaluator, batch: &[Candidate], warm: &[Candidate]) -> Result<f64> {
    evaluator.evaluate(warm, false)?;
    let t0 = Instant::now();
    let out = evaluator.evaluate(batch, false)?;
    let wall = t0.elapsed().as_secs_f64();
    if out.len() != batch.len() {
        bail!(
            "{} returned {} of {} results",
            evaluator.describe(),
            out.len(),
            batch.len()
        );
    }
    Ok(wall)
}

/// Runs the benchmark; `progress` hears each finished row.
pub fn run_bench(
    job: Arc<Job>,
    options: &BenchOptions,
    progress: &mut dyn FnMut(&BenchRow),
) -> Result<Vec<BenchRow>> {
    if options.evals == 0 {
        bail!("--evals 0: expected at least 1");
    }
    let batch = candidates(&job, options.evals);
    let warm = candidates(&job, 8.min(options.evals));
    let mut rows = Vec::new();
    let mut push = |row: BenchRow, rows: &mut Vec<BenchRow>| {
        progress(&row);
        rows.push(row);
    };
    for t in &options.transports {
        let counts: Vec<usize> = if t == "single" {
            vec![1]
        } else {
            options.workers.clone()
        };
        for &w in &counts {
            let mut evaluator: Box<dyn Evaluator> = match t.as_str() {
                "single" => Box::new(InProcess::new(Arc::clone(&job), 1)),
                "pool" => Box::new(InProcess::new(Arc::clone(&job), w)),
                "ipc" => Box::new(IpcEvaluator::start(
                    Arc::clone(&job),
                    IpcOptions {
                        run_id: sepval_common::ipc::new_run_id(),
                        workers: w,
                        launch: Launch::Spawn {
                            executable: options.worker_executable.clone(),
                        },
                        chunk_deadline: Duration::from_secs(120),
                        join_timeout: Duration::from_secs(60),
                        max_respawns: 0,
                        announce_protocol: None,
                    },
                )?),
                "uds" => Box::new(UdsEvaluator::start(
                    Arc::clone(&job),
                    w,
                    &options.worker_executable,
                    Duration::from_secs(120),
                )?),
                #[cfg(feature = "zenoh")]
                "zenoh" => Box::new(LoopbackZenoh::start(
                    Arc::clone(&job),
                    w,
                    &options.worker_executable,
                )?),
                #[cfg(not(feature = "zenoh"))]
                "zenoh" => bail!(
                    "transport zenoh: this sepval was built without the zenoh feature \
                     (cargo build --release --features zenoh)"
                ),
                other => bail!("transport {other}: expected single, pool, ipc, uds or zenoh"),
            };
            let wall = time(evaluator.as_mut(), &batch, &warm)
                .with_context(|| format!("benchmarking {t} with {w} worker(s)"))?;
            push(
                BenchRow {
                    transport: t.clone(),
                    workers: w,
                    evals: options.evals,
                    wall_s: wall,
                },
                &mut rows,
            );
        }
    }
    Ok(rows)
}

/// Seconds per evaluation of the `single` row, if measured.
pub fn single_seconds(rows: &[BenchRow]) -> Option<f64> {
    rows.iter()
        .find(|r| r.transport == "single")
        .map(|r| r.wall_s / r.evals as f64)
}

/// Transport overhead per evaluation [us] of a row, against ideal scaling of `single`.
pub fn overhead_us(row: &BenchRow, t_single: f64) -> f64 {
    (row.wall_s * row.workers as f64 - row.evals as f64 * t_single) / row.evals as f64 * 1e6
}

/// The table printed by `sepval bench`.
pub fn table(rows: &[BenchRow]) -> String {
    let t1 = single_seconds(rows);
    let mut s = format!(
        "{:<7} {:>7} {:>6} {:>9} {:>10} {:>8} {:>10} {:>12}\n",
        "transp.",
        "workers",
        "evals",
        "wall [s]",
        "evals/s",
        "speedup",
        "efficiency",
        "overhead [us]"
    );
    for r in rows {
        let (speedup, eff, over) = match t1 {
            Some(t) => {
                let sp = r.evals as f64 * t / r.wall_s;
                (
                    format!("{sp:.2}"),
                    format!("{:.0} %", 100.0 * sp / r.workers as f64),
                    format!("{:.1}", overhead_us(r, t)),
                )
            }
            None => ("-".into(), "-".into(), "-".into()),
        };
        s.push_str(&format!(
            "{:<7} {:>7} {:>6} {:>9.3} {:>10.0} {:>8} {:>10} {:>12}\n",
            r.transport,
            r.workers,
            r.evals,
            r.wall_s,
            r.evals_per_s(),
            speedup,
            eff,
            over
        ));
    }
    s
}

/// Writes DIR/bench.csv and DIR/bench.png.
pub fn write_outputs(dir: &Path, rows: &[BenchRow]) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut csv = String::from("transport,workers,evals,wall_s,evals_per_s\n");
    for r in rows {
        csv.push_str(&format!(
            "{},{},{},{},{}\n",
            r.transport,
            r.workers,
            r.evals,
            r.wall_s,
            r.evals_per_s()
        ));
    }
    write_atomically(&dir.join("bench.csv"), csv.as_bytes())?;
    let mut names: Vec<String> = Vec::new();
    for r in rows {
        if !names.contains(&r.transport) {
            names.push(r.transport.clone());
        }
    }
    let data: Vec<(String, Vec<(usize, f64)>)> = names
        .iter()
        .map(|n| {
            (
                n.clone(),
                rows.iter()
                    .filter(|r| &r.transport == n)
                    .map(|r| (r.workers, r.evals_per_s()))
                    .collect(),
            )
        })
        .collect();
    let series: Vec<(&str, &[(usize, f64)])> = data
        .iter()
        .map(|(n, v)| (n.as_str(), v.as_slice()))
        .collect();
    crate::figures::throughput_figure(&dir.join("bench.png"), &series)?;
    Ok(())
}

/// The zenoh transport on one host: a coordinator listening on a free loopback port and `w`
/// `sepval-worker --connect` processes (killed when dropped).
#[cfg(feature = "zenoh")]
struct LoopbackZenoh {
    evaluator: Option<crate::remote::RemoteEvaluator>,
    children: Vec<std::process::Child>,
}

#[cfg(feature = "zenoh")]
impl LoopbackZenoh {
    fn start(job: Arc<Job>, workers: usize, executable: &Path) -> Result<Self> {
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .context("finding a free loopback port")?
            .port();
        let endpoint = format!("tcp/127.0.0.1:{port}");
        let run_id = sepval_common::ipc::new_run_id();
        let mut me = LoopbackZenoh {
            evaluator: None,
            children: Vec::new(),
        };
        for _ in 0..workers {
            me.children.push(
                std::process::Command::new(executable)
                    .args(["--connect", &endpoint, "--run", &run_id])
                    .stdin(std::process::Stdio::null())
                    .stderr(std::process::Stdio::null())
                    .spawn()
                    .with_context(|| format!("cannot start {}", executable.display()))?,
            );
        }
        me.evaluator = Some(crate::remote::RemoteEvaluator::start(
            job,
            crate::remote::RemoteOptions {
                run_id,
                listen: endpoint,
                min_workers: workers,
                join_timeout: Duration::from_secs(60),
                chunk_deadline: Duration::from_secs(120),
                zenoh_config: None,
                announce_protocol: None,
            },
        )?);
        Ok(me)
    }
}

#[cfg(feature = "zenoh")]
impl Evaluator for LoopbackZenoh {
    fn evaluate(
        &mut self,
        batch: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<sepval_common::evaluation::Evaluation>, sepval_common::evaluation::EvalError>
    {
        self.evaluator
            .as_mut()
            .expect("started")
            .evaluate(batch, with_samples)
    }

    fn job(&self) -> &Job {
        self.evaluator.as_ref().expect("started").job()
    }

    fn describe(&self) -> String {
        self.evaluator.as_ref().expect("started").describe()
    }
}

#[cfg(feature = "zenoh")]
impl Drop for LoopbackZenoh {
    fn drop(&mut self) {
        // The coordinator tells its workers to quit; reap them, killing any that linger.
        self.evaluator = None;
        let until = Instant::now() + Duration::from_secs(5);
        for c in self.children.iter_mut() {
            while matches!(c.try_wait(), Ok(None)) && Instant::now() < until {
                std::thread::sleep(Duration::from_millis(5));
            }
            if matches!(c.try_wait(), Ok(None)) {
                let _ = c.kill();
            }
            let _ = c.wait();
        }
    }
}
