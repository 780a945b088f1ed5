//! `sepval bench`: simulations per second against worker count, per transport.
//!
//! Transports: `scalar` (one thread, in-process, one candidate at a time through the scalar
//! propagator: the reference for the lane propagator), `single` (one thread, in-process, four
//! candidates at a time through the lane propagator, as every other transport runs them), `pool` (in-process thread pool), `ipc`
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

use crate::dispatch::DispatchOptions;
use crate::ipc::{IpcOptions, Launch};
use crate::link::quiet;
use crate::spec::EvaluatorSpec;
use crate::{RunId, TransportError};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sepval_common::evaluation::{Candidate, EvalError, Evaluator, Job};
use sepval_core::atomic_file::{WriteError, write_atomically};
use sepval_core::factors::Factors;

/// A transport `sepval bench` can measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transport {
    /// One thread of this process, one candidate at a time (the scalar propagator).
    Scalar,
    /// One thread of this process.
    Single,
    /// A thread pool in this process.
    Pool,
    /// iceoryx2 worker processes.
    Ipc,
    /// Unix-socket worker processes.
    Uds,
    /// zenoh worker processes over loopback TCP (feature `zenoh`).
    Zenoh,
}

impl Transport {
    /// Its name in tables and files.
    pub fn name(self) -> &'static str {
        match self {
            Transport::Scalar => "scalar",
            Transport::Single => "single",
            Transport::Pool => "pool",
            Transport::Ipc => "ipc",
            Transport::Uds => "uds",
            Transport::Zenoh => "zenoh",
        }
    }
}

/// Errors of a benchmark.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BenchError {
    /// A worker count outside 1 to [`MAX_WORKERS`](crate::ipc::MAX_WORKERS).
    #[error("--workers {workers}: expected 1 to {}", crate::ipc::MAX_WORKERS)]
    Workers {
        /// The count given.
        workers: usize,
    },
    /// A flag's count of 0 where at least one is needed.
    #[error("{flag} 0: expected at least 1")]
    ZeroFlag {
        /// The flag (`--evals`, `--repeat`).
        flag: &'static str,
    },
    /// zenoh asked of a build without it.
    #[error(
        "--transports zenoh: this sepval was built without the zenoh feature (cargo build --release --features zenoh)"
    )]
    NoZenoh,
    /// A count of 0 where at least one is needed.
    #[error("{setting} 0: expected at least 1")]
    Zero {
        /// The setting ("evaluations", "repeat").
        setting: &'static str,
    },
    /// A transport that could not be started.
    #[error("starting {transport} with {workers} worker(s)")]
    Start {
        /// The transport.
        transport: &'static str,
        /// Workers.
        workers: usize,
        /// Why.
        #[source]
        source: TransportError,
    },
    /// A measurement that failed.
    #[error("benchmarking {transport} with {workers} worker(s)")]
    Measure {
        /// The transport.
        transport: &'static str,
        /// Workers.
        workers: usize,
        /// Why.
        #[source]
        source: EvalError,
    },
    /// An output that cannot be written.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// The output directory.
    #[error("cannot create {path}")]
    Dir {
        /// The directory.
        path: std::path::PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
}

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
    pub transports: Vec<Transport>,
    /// The worker executable.
    pub worker_executable: std::path::PathBuf,
    /// Measurements per (transport, worker count), interleaved; the median is reported.
    pub repeat: usize,
}

impl BenchOptions {
    /// Refuses what the flags gave that cannot be measured, naming the flag: a worker count
    /// outside 1 to [`MAX_WORKERS`](crate::ipc::MAX_WORKERS), no evaluation or round, zenoh
    /// in a build without it.
    pub fn check(&self) -> Result<(), BenchError> {
        let max = crate::ipc::MAX_WORKERS;
        if let Some(&workers) = self.workers.iter().find(|w| **w == 0 || **w > max) {
            return Err(BenchError::Workers { workers });
        }
        if self.evals == 0 {
            return Err(BenchError::ZeroFlag { flag: "--evals" });
        }
        if self.repeat == 0 {
            return Err(BenchError::ZeroFlag { flag: "--repeat" });
        }
        if cfg!(not(feature = "zenoh")) && self.transports.contains(&Transport::Zenoh) {
            return Err(BenchError::NoZenoh);
        }
        Ok(())
    }
}

/// `n` distinct candidates around the truth (seeded, within bounds).
pub fn candidates(job: &Job, n: usize) -> Vec<Candidate> {
    let table = job.factor_table();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
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

fn time(evaluator: &mut dyn Evaluator, batch: &[Candidate]) -> Result<f64, EvalError> {
    let t0 = Instant::now();
    let out = evaluator.evaluate(batch, false)?;
    let wall = t0.elapsed().as_secs_f64();
    assert_eq!(
        out.len(),
        batch.len(),
        "an evaluator returns one result per candidate"
    );
    Ok(wall)
}

fn dispatch(workers: usize) -> DispatchOptions {
    DispatchOptions {
        min_workers: workers,
        join_timeout: Duration::from_secs(60),
        chunk_deadline: Duration::from_secs(120),
    }
}

fn start(
    job: &Arc<Job>,
    transport: Transport,
    workers: usize,
    options: &BenchOptions,
) -> Result<Box<dyn Evaluator>, TransportError> {
    let spec = match transport {
        Transport::Scalar => return Ok(Box::new(OneAtATime(Arc::clone(job)))),
        Transport::Single => EvaluatorSpec::InProcess { threads: 1 },
        Transport::Pool => EvaluatorSpec::InProcess { threads: workers },
        Transport::Ipc => EvaluatorSpec::Ipc {
            link: IpcOptions {
                run_id: RunId::fresh(),
                workers,
                launch: Launch::Spawn {
                    executable: options.worker_executable.clone(),
                },
                max_respawns: 0,
                join_timeout: Duration::from_secs(60),
                announce_protocol: None,
            },
            dispatch: dispatch(workers),
        },
        Transport::Uds => EvaluatorSpec::Uds {
            workers,
            executable: options.worker_executable.clone(),
            dispatch: dispatch(workers),
        },
        #[cfg(feature = "zenoh")]
        Transport::Zenoh => {
            return Ok(Box::new(LoopbackZenoh::start(
                Arc::clone(job),
                workers,
                &options.worker_executable,
            )?));
        }
        #[cfg(not(feature = "zenoh"))]
        Transport::Zenoh => {
            return Err(TransportError::NotBuilt { transport: "zenoh" });
        }
    };
    spec.start(Arc::clone(job), quiet())
}

/// The `scalar` row's evaluator: one candidate after the other in this thread, each a batch of
/// one (which [`Job::evaluate_batch`] runs through the scalar propagator).
struct OneAtATime(Arc<Job>);

impl Evaluator for OneAtATime {
    fn evaluate(
        &mut self,
        batch: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<sepval_common::evaluation::Evaluation>, EvalError> {
        let job = &self.0;
        Ok(batch
            .iter()
            .map(|c| {
                if with_samples {
                    job.evaluate_with_samples(c)
                } else {
                    job.evaluate(c)
                }
            })
            .collect())
    }

    fn job(&self) -> &Arc<Job> {
        &self.0
    }

    fn describe(&self) -> String {
        "inproc, 1 thread, one candidate at a time (scalar)".into()
    }
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
) -> Result<Vec<BenchRow>, BenchError> {
    if options.evals == 0 {
        return Err(BenchError::Zero {
            setting: "evaluations",
        });
    }
    if options.repeat == 0 {
        return Err(BenchError::Zero { setting: "repeat" });
    }
    let batch = candidates(&job, options.evals);
    let warm = candidates(&job, 8.min(options.evals));
    let probe = probes(&job, options.evals);
    let cells: Vec<(Transport, usize)> = options
        .transports
        .iter()
        .flat_map(|&t| {
            let counts = if matches!(t, Transport::Single | Transport::Scalar) {
                vec![1]
            } else {
                options.workers.clone()
            };
            counts.into_iter().map(move |w| (t, w))
        })
        .collect();
    let mut walls: Vec<(Vec<f64>, Vec<f64>)> = vec![(Vec::new(), Vec::new()); cells.len()];
    let mut rows = Vec::new();
    for round in 0..options.repeat {
        for ((t, w), (wall, probe_wall)) in cells.iter().zip(walls.iter_mut()) {
            let (transport, workers) = (t.name(), *w);
            let mut evaluator =
                start(&job, *t, workers, options).map_err(|source| BenchError::Start {
                    transport,
                    workers,
                    source,
                })?;
            let measure = |source| BenchError::Measure {
                transport,
                workers,
                source,
            };
            evaluator.evaluate(&warm, false).map_err(measure)?;
            wall.push(time(evaluator.as_mut(), &batch).map_err(measure)?);
            probe_wall.push(time(evaluator.as_mut(), &probe).map_err(measure)?);
            if round + 1 == options.repeat {
                let row = BenchRow {
                    transport: transport.to_string(),
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

/// Writes DIR/bench.csv (the figure, DIR/bench.png, is drawn from [`series`] by the caller).
pub fn write_csv(dir: &Path, rows: &[BenchRow]) -> Result<(), BenchError> {
    std::fs::create_dir_all(dir).map_err(|source| BenchError::Dir {
        path: dir.to_path_buf(),
        source,
    })?;
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
    Ok(())
}

/// Simulations per second against worker count, one series per transport in the order the
/// rows first name them.
pub fn series(rows: &[BenchRow]) -> Vec<(String, Vec<(usize, f64)>)> {
    let mut names: Vec<String> = Vec::new();
    for r in rows {
        if !names.contains(&r.transport) {
            names.push(r.transport.clone());
        }
    }
    names
        .into_iter()
        .map(|n| {
            let points = rows
                .iter()
                .filter(|r| r.transport == n)
                .map(|r| (r.workers, r.evals_per_s()))
                .collect();
            (n, points)
        })
        .collect()
}

/// The zenoh transport on one host: a coordinator listening on a free loopback port and `w`
/// `sepval-worker --connect` processes (killed when dropped).
#[cfg(feature = "zenoh")]
struct LoopbackZenoh {
    evaluator: Option<Box<dyn Evaluator>>,
    children: Vec<std::process::Child>,
}

#[cfg(feature = "zenoh")]
impl LoopbackZenoh {
    fn start(job: Arc<Job>, workers: usize, executable: &Path) -> Result<Self, TransportError> {
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .map_err(crate::io("finding a free loopback port"))?
            .port();
        let endpoint = format!("tcp/127.0.0.1:{port}");
        let run_id = RunId::fresh();
        let mut me = LoopbackZenoh {
            evaluator: None,
            children: Vec::new(),
        };
        for _ in 0..workers {
            me.children.push(
                std::process::Command::new(executable)
                    .args(["--connect", &endpoint, "--run", run_id.as_str()])
                    .stdin(std::process::Stdio::null())
                    .stderr(std::process::Stdio::null())
                    .spawn()
                    .map_err(crate::io(format!("cannot start {}", executable.display())))?,
            );
        }
        let spec = EvaluatorSpec::Zenoh {
            link: crate::zenoh::ZenohOptions {
                run_id,
                listen: endpoint,
                workers,
                join_timeout: Duration::from_secs(60),
                zenoh_config: None,
                announce_protocol: None,
            },
            dispatch: dispatch(workers),
        };
        me.evaluator = Some(spec.start(job, quiet())?);
        Ok(me)
    }
}

#[cfg(feature = "zenoh")]
impl Evaluator for LoopbackZenoh {
    fn evaluate(
        &mut self,
        batch: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<sepval_common::evaluation::Evaluation>, EvalError> {
        self.evaluator
            .as_mut()
            .expect("started")
            .evaluate(batch, with_samples)
    }

    fn job(&self) -> &Arc<Job> {
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
