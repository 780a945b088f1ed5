//! `sepval bench`: simulations per second against worker count, per transport.
//!
//! Transports: `single` (one thread, in-process), `pool` (in-process thread pool), `ipc`
//! (iceoryx2 worker processes), `uds` (the same requests as postcard frames over Unix domain
//! sockets) and, when built with the `zenoh` feature, `zenoh` (workers joining over TCP on the
//! loopback interface). Each measurement is one batch of `evals` distinct candidates after a warm-up batch;
//! starting the workers is not timed. Measurements are repeated in interleaved rounds and the
//! median is reported, so that a slow spell of a shared machine hits every transport alike. The
//! transport overhead per evaluation is measured directly: the same number of requests that the
//! job refuses before simulating (a factor out of bounds) cross the transport in full, and the
//! worker time they take beyond the same refusals in one thread is the transport's cost.

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
    /// Wall time \[s\] (the median of the repeats).
    pub wall_s: f64,
    /// Wall time \[s\] of as many requests refused without simulating (the median of the
    /// repeats): what the transport alone costs.
    pub probe_wall_s: f64,
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
    /// Measurements per (transport, worker count), interleaved; the median is reported.
    pub repeat: usize,
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

/// `n` requests that every transport carries in full but that the job refuses before
/// simulating (the first factor just above its upper bound): timing them measures the
/// transport, not the model.
pub fn probes(job: &Job, n: usize) -> Vec<Candidate> {
    let bound = job.factor_table().0[0];
    let mut f = Factors::TRUTH;
    f.0[0] = bound.max + bound.range().max(1.0);
    vec![Candidate::baseline(f); n]
}

fn time(evaluator: &mut dyn Evaluator, batch: &[Candidate]) -> Result<f64> {
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

fn start(
    job: &Arc<Job>,
    transport: &str,
    workers: usize,
    options: &BenchOptions,
) -> Result<Box<dyn Evaluator>> {
    Ok(match transport {
        "single" => Box::new(InProcess::new(Arc::clone(job), 1)),
        "pool" => Box::new(InProcess::new(Arc::clone(job), workers)),
        "ipc" => Box::new(IpcEvaluator::start(
            Arc::clone(job),
            IpcOptions {
                run_id: sepval_common::ipc::new_run_id(),
                workers,
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
            Arc::clone(job),
            workers,
            &options.worker_executable,
            Duration::from_secs(120),
        )?),
        #[cfg(feature = "zenoh")]
        "zenoh" => Box::new(LoopbackZenoh::start(
            Arc::clone(job),
            workers,
            &options.worker_executable,
        )?),
        #[cfg(not(feature = "zenoh"))]
        "zenoh" => bail!(
            "transport zenoh: this sepval was built without the zenoh feature \
             (cargo build --release --features zenoh)"
        ),
        other => bail!("transport {other}: expected single, pool, ipc, uds or zenoh"),
    })
}

fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Runs the benchmark: `repeat` rounds, each measuring every (transport, worker count) once in
/// turn (so a slow spell of the machine hits every transport alike), each measurement with
/// freshly started workers, a warm-up batch, the timed batch and the timed probes; rows report
/// medians. `progress` hears each finished row.
pub fn run_bench(
    job: Arc<Job>,
    options: &BenchOptions,
    progress: &mut dyn FnMut(&BenchRow),
) -> Result<Vec<BenchRow>> {
    if options.evals == 0 {
        bail!("--evals 0: expected at least 1");
    }
    if options.repeat == 0 {
        bail!("--repeat 0: expected at least 1");
    }
    let batch = candidates(&job, options.evals);
    let warm = candidates(&job, 8.min(options.evals));
    let probe = probes(&job, options.evals);
    let cells: Vec<(String, usize)> = options
        .transports
        .iter()
        .flat_map(|t| {
            let counts = if t == "single" {
                vec![1]
            } else {
                options.workers.clone()
            };
            counts.into_iter().map(move |w| (t.clone(), w))
        })
        .collect();
    let mut walls: Vec<(Vec<f64>, Vec<f64>)> = vec![(Vec::new(), Vec::new()); cells.len()];
    let mut rows = Vec::new();
    for round in 0..options.repeat {
        for ((t, w), (wall, probe_wall)) in cells.iter().zip(walls.iter_mut()) {
            let mut evaluator = start(&job, t, *w, options)?;
            let what = || format!("benchmarking {t} with {w} worker(s)");
            evaluator.evaluate(&warm, false).with_context(what)?;
            wall.push(time(evaluator.as_mut(), &batch).with_context(what)?);
            probe_wall.push(time(evaluator.as_mut(), &probe).with_context(what)?);
            if round + 1 == options.repeat {
                let row = BenchRow {
                    transport: t.clone(),
                    workers: *w,
                    evals: options.evals,
                    wall_s: median(wall),
                    probe_wall_s: median(probe_wall),
                };
                progress(&row);
                rows.push(row);
            }
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

/// Transport overhead per evaluation \[us\]: the worker time a refused request costs through
/// this transport (probe wall x workers / evals) beyond what it costs in one thread (the
/// `single` row's probes).
pub fn overhead_us(row: &BenchRow, rows: &[BenchRow]) -> Option<f64> {
    let single = rows.iter().find(|r| r.transport == "single")?;
    let per = |r: &BenchRow| r.probe_wall_s * r.workers as f64 / r.evals as f64;
    Some((per(row) - per(single)) * 1e6)
}

/// The table printed by `sepval bench`.
pub fn table(rows: &[BenchRow]) -> String {
    let t1 = single_seconds(rows);
    let mut s = format!(
        "{:<7} {:>7} {:>6} {:>9} {:>10} {:>8} {:>10} {:>14}\n",
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
        let (speedup, eff) = match t1 {
            Some(t) => {
                let sp = r.evals as f64 * t / r.wall_s;
                (
                    format!("{sp:.2}"),
                    format!("{:.0} %", 100.0 * sp / r.workers as f64),
                )
            }
            None => ("-".into(), "-".into()),
        };
        let over = overhead_us(r, rows).map_or("-".into(), |o| format!("{o:.2}"));
        s.push_str(&format!(
            "{:<7} {:>7} {:>6} {:>9.3} {:>10.0} {:>8} {:>10} {:>14}\n",
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
