//! `sepval`: post-flight validation of store-separation simulations.
//!
//! Only the command line lives here; see the `sepval_coordinator` and `sepval_common`
//! libraries for the logic.

// The doc comments here are clap's --help text, where units read `[s]`, `[m]`; rustdoc would
// take those for links.
#![allow(rustdoc::broken_intra_doc_links)]

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use sepval_common::effects::CATALOGUE;
use sepval_common::goals::goals_between;
use sepval_common::scenario::Scenario;
use sepval_common::simulation::{Simulator, sample_times};
use sepval_common::synthetic::synthetic_flight_test;
use sepval_common::telemetry::Trajectory;
use std::sync::Arc;
use std::time::Duration;

use sepval_coordinator::ipc::{IpcEvaluator, IpcOptions, Launch};

use sepval_common::evaluation::{Evaluator, InProcess, Job};
use sepval_coordinator::checkpoint::Checkpoint;
use sepval_coordinator::fit::{FitOptions, FitOutput, Method, Sigma, run_fit};
use sepval_coordinator::inputs;
use sepval_coordinator::refine::LmSettings;
use sepval_coordinator::search::ga::GaSettings;
use sepval_coordinator::search::hill::HillSettings;

#[derive(Parser)]
#[command(
    name = "sepval",
    version,
    about = "Post-flight validation of store-separation simulations",
    long_about = "sepval compares a 6DOF store-separation simulation with measured trajectories, \
                  fits the model factors that make it match, and diagnoses what it still gets wrong."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a release and write its trajectory (CSV, MODEL.md section 6).
    Simulate(SimulateArgs),
    /// List the effect catalogue: the physics the baseline model leaves out.
    Effects,
    /// Print the goals J_pos [m] and J_att [deg] of a simulated trajectory against data.
    Goals(GoalsArgs),
    /// Write a scenario file (the embedded default unless --scenario is given) as TOML.
    Scenario(ScenarioArgs),
    /// Fit the 17 factors to measured data: Anderson's genetic algorithm and hill climber.
    Fit(Box<FitArgs>),
    /// Re-evaluate a saved generation and check every goal bit for bit.
    Rerun(RerunArgs),
    /// Show what the simulation still gets wrong after a fit, name the cause from the effect
    /// catalogue, extend the model and measure the gain.
    Diagnose(Box<DiagnoseArgs>),
    /// Measure simulations per second against worker count for each transport.
    Bench(BenchArgs),
    /// Check the Pareto machinery on problems with known fronts.
    #[command(subcommand)]
    Selftest(SelftestCommand),
    /// Remove the shared-memory resources of sepval runs whose processes are all gone.
    CleanIpc,
    /// Join a zenoh run as one host's gateway: serve its chunks with local iceoryx2 workers
    /// (built with the `zenoh` feature).
    Gateway(GatewayArgs),
}

#[derive(clap::Args)]
struct GatewayArgs {
    /// The coordinator's endpoint, e.g. tcp/192.0.2.7:7447.
    #[arg(long, value_name = "ENDPOINT")]
    connect: String,
    /// The run to join (the coordinator prints it).
    #[arg(long, value_name = "RUN_ID")]
    run: String,
    /// Local iceoryx2 worker processes [default: the number of cores].
    #[arg(long)]
    workers: Option<usize>,
    /// A local worker holding a chunk longer than this [s] is killed and replaced.
    #[arg(long, default_value_t = 60.0, value_name = "S")]
    worker_timeout: f64,
    /// How long to wait for the coordinator's job setup [s].
    #[arg(long, default_value_t = 30.0, value_name = "S")]
    setup_timeout: f64,
    /// A zenoh JSON5 configuration to start from (TLS certificates, authentication).
    #[arg(long, value_name = "FILE")]
    zenoh_config: Option<PathBuf>,
}

#[derive(clap::Args)]
struct FitArgs {
    /// Measured trajectory (CSV; repeatable for several releases). Default: the embedded
    /// synthetic flight test (truth factors plus noise).
    #[arg(long, value_name = "FILE.csv")]
    data: Vec<PathBuf>,
    /// Scenario file (TOML); the embedded default when absent.
    #[arg(long, value_name = "FILE")]
    scenario: Option<PathBuf>,
    /// Searches to run [default: both; when resuming: the checkpoint's].
    #[arg(long, value_name = "ga|hill|both|ga+lm|hill+lm")]
    method: Option<String>,
    /// Seed of the genetic algorithm's generator.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Generations (evaluated populations, the initial one included) [default: 500; when
    /// resuming: the checkpoint's].
    #[arg(long)]
    generations: Option<usize>,
    /// Population size (even).
    #[arg(long, default_value_t = 100)]
    population: usize,
    /// Probability of single-point crossover.
    #[arg(long, default_value_t = 0.9)]
    p_crossover: f64,
    /// Probability of a jump mutation per bit.
    #[arg(long, default_value_t = 0.005)]
    p_jump: f64,
    /// Probability of a creep mutation per parameter.
    #[arg(long, default_value_t = 0.05)]
    p_creep: f64,
    /// Simulation budget of the hill climber.
    #[arg(long, default_value_t = 500)]
    hill_budget: usize,
    /// Simulation budget of the Levenberg-Marquardt refinement (`+lm` methods).
    #[arg(long, default_value_t = 5000)]
    lm_budget: u64,
    #[command(flatten)]
    eval: EvalArgs,
    #[command(flatten)]
    noise: NoiseArgs,
    /// The true factors (JSON), for Figure 7; the embedded truth is used with the default data.
    #[arg(long, value_name = "FILE.json")]
    truth_factors: Option<PathBuf>,
    /// Continue from a checkpoint (DIR/generations/gen-NNNN.json).
    #[arg(long, value_name = "CHECKPOINT")]
    resume: Option<PathBuf>,
    /// Skip the figures.
    #[arg(long)]
    no_figures: bool,
    /// Run directory (result.json, generations/, figures/).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

#[derive(clap::Args)]
struct DiagnoseArgs {
    /// Measured trajectory (CSV; repeatable). Default: the embedded synthetic flight test.
    #[arg(long, value_name = "FILE.csv")]
    data: Vec<PathBuf>,
    /// Scenario file (TOML); the embedded default when absent.
    #[arg(long, value_name = "FILE")]
    scenario: Option<PathBuf>,
    /// Seed of the baseline fit's genetic search.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Generations of the baseline fit's genetic search (it stops earlier when its refinement
    /// reaches the noise floor).
    #[arg(long, default_value_t = 60)]
    generations: usize,
    /// Population of the baseline fit's genetic search.
    #[arg(long, default_value_t = 100)]
    population: usize,
    /// Simulation budget of each refinement.
    #[arg(long, default_value_t = 3000)]
    lm_budget: u64,
    #[command(flatten)]
    eval: EvalArgs,
    #[command(flatten)]
    noise: NoiseArgs,
    /// Output directory (diagnosis.json, report.html, figures/, baseline/).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

#[derive(Subcommand)]
enum SelftestCommand {
    /// The genetic algorithm on ZDT1, ZDT2 or ZDT3 (30 variables): prints the hypervolume of
    /// the final front with reference point (1.1, 1.1).
    Zdt {
        /// zdt1, zdt2 or zdt3.
        #[arg(long)]
        problem: String,
        /// Evaluations (whole generations of 100).
        #[arg(long, default_value_t = 25_000)]
        evaluations: usize,
        /// Seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Bits per variable.
        #[arg(long, default_value_t = 20)]
        bits: u32,
    },
}

/// Transports `sepval bench` measures by default.
#[cfg(feature = "zenoh")]
const DEFAULT_TRANSPORTS: &str = "single,pool,ipc,uds,zenoh";
/// Transports `sepval bench` measures by default.
#[cfg(not(feature = "zenoh"))]
const DEFAULT_TRANSPORTS: &str = "single,pool,ipc,uds";

#[derive(clap::Args)]
struct BenchArgs {
    /// Worker counts, comma-separated.
    #[arg(long, default_value = "1,2,4", value_delimiter = ',')]
    workers: Vec<usize>,
    /// Simulations per measurement.
    #[arg(long, default_value_t = 2000)]
    evals: usize,
    /// Transports, comma-separated (single, pool, ipc, uds; zenoh when built with it).
    #[arg(long, default_value = DEFAULT_TRANSPORTS, value_delimiter = ',')]
    transports: Vec<String>,
    /// Measurements per transport and worker count, taken in interleaved rounds; the table
    /// reports the median.
    #[arg(long, default_value_t = 3)]
    repeat: usize,
    /// Output directory (bench.csv, bench.png).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

#[derive(clap::Args)]
struct RerunArgs {
    /// Checkpoint of the generation to re-evaluate.
    #[arg(value_name = "CHECKPOINT")]
    checkpoint: PathBuf,
    /// Data files (default: those recorded in the checkpoint).
    #[arg(long, value_name = "FILE.csv")]
    data: Vec<PathBuf>,
    /// Scenario file (default: the one recorded in the checkpoint).
    #[arg(long, value_name = "FILE")]
    scenario: Option<PathBuf>,
    #[command(flatten)]
    eval: EvalArgs,
}

/// The measurement noise that weights the goals (shared by every search command).
#[derive(clap::Args)]
struct NoiseArgs {
    /// Position noise [m] weighting J_pos (default: estimated from the data).
    #[arg(long)]
    sigma_pos_m: Option<f64>,
    /// Attitude noise [deg] weighting J_att (default: estimated from the data).
    #[arg(long)]
    sigma_att_deg: Option<f64>,
}

/// How simulations are run (shared by every search command).
#[derive(clap::Args)]
struct EvalArgs {
    /// `ipc`: worker processes over iceoryx2 shared memory; `inproc`: threads of this process;
    /// `zenoh`: workers on any host that joins --listen (built with the `zenoh` feature).
    #[arg(long, default_value = "ipc", value_name = "ipc|inproc|zenoh")]
    evaluator: String,
    /// Worker processes (ipc) [default: the number of cores]; with zenoh, the workers to wait
    /// for before the search starts [default: 1] (more may join at any time).
    #[arg(long)]
    workers: Option<usize>,
    /// zenoh: the endpoint to listen on for workers, e.g. tcp/0.0.0.0:7447 (explicit port).
    #[arg(long, value_name = "ENDPOINT")]
    listen: Option<String>,
    /// zenoh: a zenoh JSON5 configuration to start from (TLS certificates, authentication);
    /// sepval still sets peer mode, the endpoint and switches scouting off.
    #[arg(long, value_name = "FILE")]
    zenoh_config: Option<PathBuf>,
    /// Threads (inproc) [default: the number of cores].
    #[arg(long)]
    threads: Option<usize>,
    /// Do not start workers: create run RUN_ID and wait for --workers externally started
    /// `sepval-worker --run RUN_ID`.
    #[arg(long, value_name = "RUN_ID")]
    attach: Option<String>,
    /// Run id of spawned workers [default: a fresh one].
    #[arg(long, value_name = "RUN_ID")]
    run_id: Option<String>,
    /// A worker that holds a chunk longer than this [s] is killed and replaced.
    #[arg(long, default_value_t = 60.0, value_name = "S")]
    worker_timeout: f64,
    /// How long to wait for workers to join [s].
    #[arg(long, default_value_t = 60.0, value_name = "S")]
    join_timeout: f64,
    /// Announce this protocol version in the job setup (compatibility testing only).
    #[arg(long, hide = true)]
    announce_protocol: Option<u32>,
}

#[derive(clap::Args)]
struct SimulateArgs {
    /// Scenario file (TOML); the embedded default (Eglin benchmark store) when absent.
    #[arg(long, value_name = "FILE")]
    scenario: Option<PathBuf>,
    /// Factors: `truth`, `nominal`, or a JSON file mapping the 17 factor names to values.
    #[arg(long, default_value = "truth", value_name = "truth|nominal|FILE.json")]
    factors: String,
    /// Switch on a catalogue effect with its parameters in MODEL.md units and order
    /// (repeatable), e.g. `--effect roll_due_to_sideslip=-0.3`.
    #[arg(long = "effect", value_name = "ID=V1,V2,...")]
    effects: Vec<String>,
    /// Add Gaussian measurement noise (0.003 m, 0.1 deg) from this seed.
    #[arg(long, value_name = "N")]
    noise_seed: Option<u64>,
    /// Event length [s] (default: the scenario's).
    #[arg(long, value_name = "S")]
    t_end: Option<f64>,
    /// Telemetry rate [Hz] (default: the scenario's).
    #[arg(long, value_name = "HZ")]
    rate: Option<f64>,
    /// Output CSV file (written atomically).
    #[arg(long, value_name = "FILE.csv")]
    out: PathBuf,
}

#[derive(clap::Args)]
struct GoalsArgs {
    /// Measured trajectory (CSV).
    #[arg(long, value_name = "A.csv")]
    data: PathBuf,
    /// Simulated trajectory (CSV) at the same sample times.
    #[arg(long, value_name = "B.csv")]
    sim: PathBuf,
}

#[derive(clap::Args)]
struct ScenarioArgs {
    /// Scenario to rewrite (validated); the embedded default when absent.
    #[arg(long, value_name = "FILE")]
    scenario: Option<PathBuf>,
    /// Output TOML file (written atomically).
    #[arg(long, value_name = "FILE.toml")]
    out: PathBuf,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Error);
    let result = match cli.command {
        Command::Simulate(args) => simulate(args),
        Command::Effects => {
            print_effects();
            Ok(())
        }
        Command::Goals(args) => goals(args),
        Command::Scenario(args) => scenario(args),
        Command::Fit(args) => fit(*args),
        Command::Rerun(args) => rerun(args),
        Command::Diagnose(args) => diagnose(*args),
        Command::Bench(args) => bench(args),
        Command::Gateway(args) => gateway(args),
        Command::Selftest(SelftestCommand::Zdt {
            problem,
            evaluations,
            seed,
            bits,
        }) => (|| {
            use sepval_coordinator::selftest::{Zdt, run_zdt};
            if !(1..=52).contains(&bits) {
                anyhow::bail!("--bits {bits}: expected 1 to 52");
            }
            let (hv, front) = run_zdt(Zdt::parse(&problem)?, evaluations, seed, bits)?;
            println!("{hv:.6}");
            eprintln!(
                "{problem}: {} points on the final front, seed {seed}",
                front.len()
            );
            Ok(())
        })(),
        Command::CleanIpc => {
            // Explicitly asked for: any run without a live process, whatever its age.
            let cleaned = sepval_common::ipc::clean_stale_runs("", std::time::Duration::ZERO);
            println!(
                "cleaned {} stale run(s) {}",
                cleaned.len(),
                cleaned.join(" ")
            );
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sepval: error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn simulate(args: SimulateArgs) -> Result<()> {
    let scenario = inputs::scenario(args.scenario.as_deref())?;
    let factors = inputs::factors(&args.factors, &scenario.factors)?;
    let effects = inputs::effects(&args.effects)?;
    let t_end = match args.t_end {
        Some(t) => inputs::positive("--t-end", t)?,
        None => scenario.integrator.t_end_s,
    };
    let rate = match args.rate {
        Some(r) => inputs::positive("--rate", r)?,
        None => scenario.integrator.rate_hz,
    };
    let sim = Simulator::new(&scenario);
    let times = sample_times(t_end, rate);
    let mut traj = synthetic_flight_test(&sim, &factors, &effects, &times, args.noise_seed)
        .context("simulation failed")?;
    traj.comments
        .insert(0, format!("sepval simulate --factors {}", args.factors));
    traj.write(&args.out)?;
    eprintln!(
        "wrote {} ({} samples, t = 0 to {} s)",
        args.out.display(),
        traj.len(),
        traj.times_s.last().copied().unwrap_or(0.0)
    );
    Ok(())
}

fn print_effects() {
    println!("Effect catalogue (MODEL.md section 7): physics the baseline model leaves out.");
    println!("Give one to `sepval simulate` as --effect ID=V1,V2,... in the units below.\n");
    for e in CATALOGUE.iter() {
        println!("{}", e.id());
        println!("    adds: {}", e.adds());
        for p in e.params() {
            println!(
                "    {:<9} [{}]  neutral {}, fit range [{}, {}]",
                p.name, p.unit, p.neutral, p.min, p.max
            );
        }
    }
}

fn goals(args: GoalsArgs) -> Result<()> {
    let data = Trajectory::read(&args.data)?;
    let sim = Trajectory::read(&args.sim)?;
    let g = goals_between(&data, &sim).with_context(|| {
        format!(
            "cannot compare {} with {}",
            args.data.display(),
            args.sim.display()
        )
    })?;
    println!("J_pos = {:.9} m", g.j_pos_m);
    println!("J_att = {:.9} deg", g.j_att_deg);
    Ok(())
}

fn scenario(args: ScenarioArgs) -> Result<()> {
    let scenario: Scenario = inputs::scenario(args.scenario.as_deref())?;
    let text = format!(
        "# sepval scenario (SI units, angles in degrees); MODEL.md section 1 describes each field.\n{}",
        scenario.to_toml_string()
    );
    sepval_common::atomic_file::write_atomically(&args.out, text.as_bytes())?;
    eprintln!("wrote {}", args.out.display());
    Ok(())
}

fn count(flag: &str, requested: Option<usize>) -> Result<usize> {
    match requested {
        Some(0) => anyhow::bail!("{flag} 0: expected at least 1"),
        Some(n) => Ok(n),
        None => Ok(std::thread::available_parallelism().map_or(1, |n| n.get())),
    }
}

fn evaluator(args: &EvalArgs, job: Job) -> Result<Box<dyn Evaluator>> {
    let job = Arc::new(job);
    if args.evaluator != "zenoh" && (args.listen.is_some() || args.zenoh_config.is_some()) {
        anyhow::bail!("--listen and --zenoh-config are for --evaluator zenoh");
    }
    match args.evaluator.as_str() {
        "inproc" => Ok(Box::new(InProcess::new(
            job,
            count("--threads", args.threads)?,
        ))),
        "ipc" => {
            let workers = count("--workers", args.workers)?;
            let (run_id, launch) = match &args.attach {
                Some(id) => (id.clone(), Launch::Attach),
                None => (
                    args.run_id
                        .clone()
                        .unwrap_or_else(sepval_common::ipc::new_run_id),
                    Launch::Spawn {
                        executable: worker_executable()?,
                    },
                ),
            };
            let secs = |flag: &str, v: f64| -> Result<Duration> {
                inputs::positive(flag, v).map(Duration::from_secs_f64)
            };
            let options = IpcOptions {
                run_id,
                workers,
                launch,
                chunk_deadline: secs("--worker-timeout", args.worker_timeout)?,
                join_timeout: secs("--join-timeout", args.join_timeout)?,
                max_respawns: 2 * workers + 2,
                announce_protocol: args.announce_protocol,
            };
            let evaluator = IpcEvaluator::start(job, options)?;
            eprintln!(
                "sepval: run {} with {workers} worker process(es)",
                evaluator.run_id()
            );
            Ok(Box::new(evaluator))
        }
        "zenoh" => remote_evaluator(args, job),
        other => anyhow::bail!("--evaluator {other}: expected ipc, inproc or zenoh"),
    }
}

#[cfg(feature = "zenoh")]
fn remote_evaluator(args: &EvalArgs, job: Arc<Job>) -> Result<Box<dyn Evaluator>> {
    use sepval_coordinator::remote::{RemoteEvaluator, RemoteOptions};
    let listen = args
        .listen
        .clone()
        .context("--evaluator zenoh needs --listen ENDPOINT (e.g. tcp/0.0.0.0:7447)")?;
    if args.attach.is_some() {
        anyhow::bail!("--attach is for --evaluator ipc; zenoh workers always join by themselves");
    }
    let secs = |flag: &str, v: f64| -> Result<Duration> {
        inputs::positive(flag, v).map(Duration::from_secs_f64)
    };
    let options = RemoteOptions {
        run_id: args
            .run_id
            .clone()
            .unwrap_or_else(sepval_common::ipc::new_run_id),
        listen,
        min_workers: match args.workers {
            Some(0) => anyhow::bail!("--workers 0: expected at least 1"),
            Some(n) => n,
            None => 1,
        },
        join_timeout: secs("--join-timeout", args.join_timeout)?,
        chunk_deadline: secs("--worker-timeout", args.worker_timeout)?,
        zenoh_config: args.zenoh_config.clone(),
        announce_protocol: args.announce_protocol,
    };
    Ok(Box::new(RemoteEvaluator::start(job, options)?))
}

#[cfg(not(feature = "zenoh"))]
fn remote_evaluator(_: &EvalArgs, _: Arc<Job>) -> Result<Box<dyn Evaluator>> {
    anyhow::bail!(
        "--evaluator zenoh: this sepval was built without the zenoh transport; \
         rebuild with `cargo build --release --features zenoh`"
    )
}

/// The worker executable: $SEPVAL_WORKER, or `sepval-worker` beside this executable.
fn worker_executable() -> Result<PathBuf> {
    if let Some(p) = std::env::var_os("SEPVAL_WORKER") {
        return Ok(PathBuf::from(p));
    }
    let me = std::env::current_exe().context("cannot locate the sepval executable")?;
    let worker = me.with_file_name(format!("sepval-worker{}", std::env::consts::EXE_SUFFIX));
    if !worker.exists() {
        anyhow::bail!(
            "cannot find the worker executable {} (build it with `cargo build --release`, or set SEPVAL_WORKER)",
            worker.display()
        );
    }
    Ok(worker)
}

fn fit(args: FitArgs) -> Result<()> {
    let resume = match &args.resume {
        Some(p) => Some(Checkpoint::load(p)?),
        None => None,
    };
    // Inputs: the flags, or (when resuming without them) those recorded in the checkpoint.
    let (data_paths, scenario_path) = match (&resume, args.data.is_empty(), &args.scenario) {
        (Some(c), true, None) => (c.inputs.data.clone(), c.inputs.scenario.clone()),
        _ => (args.data.clone(), args.scenario.clone()),
    };
    let (job, inputs) = inputs::job(&data_paths, scenario_path.as_deref())?;
    let method = match (&args.method, &resume) {
        (Some(m), _) => Method::parse(m)?,
        (None, Some(c)) => Method::parse(&c.method)?,
        (None, None) => Method::Both,
    };
    let (ga, hill, sigma) = match &resume {
        Some(c) => {
            let path = args.resume.as_deref().expect("resume path");
            c.check_job(&job, path)?;
            let mut ga = c.settings.clone();
            if let Some(g) = args.generations {
                if g < c.state.generation {
                    anyhow::bail!(
                        "--generations {g}: the checkpoint is already at generation {}",
                        c.state.generation
                    );
                }
                ga.generations = g;
            }
            (ga, c.hill.clone(), c.sigma.clone())
        }
        None => {
            let ga = GaSettings {
                population: args.population,
                generations: args.generations.unwrap_or(500),
                p_crossover: args.p_crossover,
                p_jump: args.p_jump,
                p_creep: args.p_creep,
                seed: args.seed,
            };
            let hill = HillSettings {
                budget: args.hill_budget,
                ..HillSettings::default()
            };
            (
                ga,
                hill,
                Sigma::resolve(&job, args.noise.sigma_pos_m, args.noise.sigma_att_deg)?,
            )
        }
    };
    ga.validate()?;
    let truth = match &args.truth_factors {
        Some(p) => Some(inputs::factors(
            &p.display().to_string(),
            job.factor_table(),
        )?),
        None if data_paths.is_empty() => Some(sepval_common::factors::Factors::TRUTH),
        None => None,
    };
    let mut evaluator = evaluator(&args.eval, job)?;
    let options = FitOptions {
        method,
        ga,
        hill,
        sigma,
        truth,
        out: args.out.clone(),
        resume,
        inputs,
        progress: true,
        lm: LmSettings {
            budget: args.lm_budget,
            ..LmSettings::default()
        },
        lm_probe: LmSettings {
            budget: args.lm_budget.min(800),
            ..LmSettings::default()
        },
    };
    let output = run_fit(&options, evaluator.as_mut())?;
    let r = &output.result;
    println!(
        "fit of {} ({} samples), sigma_pos {:.4} m, sigma_att {:.4} deg ({})",
        r.events
            .iter()
            .map(|e| e.name.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        r.events.iter().map(|e| e.samples).sum::<usize>(),
        r.sigma_pos_m,
        r.sigma_att_deg,
        r.sigma_source
    );
    println!(
        "{:<6} {:>12} {:>12} {:>10} {:>12} {:>9}",
        "method", "J_pos [m]", "J_att [deg]", "weighted", "simulations", "wall [s]"
    );
    for (name, m) in &r.methods {
        println!(
            "{:<6} {:>12.6} {:>12.5} {:>10.3} {:>12} {:>9.1}",
            name,
            m.best.j_pos_m,
            m.best.j_att_deg,
            m.best.weighted,
            m.best.evaluations,
            m.best.wall_s
        );
    }
    if !args.no_figures {
        figures(&args.out, evaluator.job(), &output)?;
    }
    println!("results in {}", args.out.join("result.json").display());
    Ok(())
}

fn figures(dir: &std::path::Path, job: &Job, output: &FitOutput) -> Result<()> {
    let written = sepval_coordinator::fit::write_fit_figures(dir, job, output)?;
    println!(
        "{} figures in {}",
        written.len(),
        dir.join("figures").display()
    );
    Ok(())
}

fn rerun(args: RerunArgs) -> Result<()> {
    let checkpoint = Checkpoint::load(&args.checkpoint)?;
    let (data_paths, scenario_path) = if args.data.is_empty() && args.scenario.is_none() {
        (
            checkpoint.inputs.data.clone(),
            checkpoint.inputs.scenario.clone(),
        )
    } else {
        (args.data.clone(), args.scenario.clone())
    };
    let (job, _) = inputs::job(&data_paths, scenario_path.as_deref())?;
    let mut evaluator = evaluator(&args.eval, job)?;
    let mismatches =
        sepval_coordinator::rerun::rerun(&checkpoint, &args.checkpoint, evaluator.as_mut())?;
    let n = checkpoint.state.population.len();
    if mismatches.is_empty() {
        println!(
            "generation {}: all {n} members reproduce their goals bit for bit ({})",
            checkpoint.state.generation,
            evaluator.describe()
        );
        return Ok(());
    }
    for m in &mismatches {
        println!(
            "member {}: saved {:?}, rerun {:?}",
            m.member, m.saved, m.rerun
        );
    }
    anyhow::bail!(
        "generation {}: {} of {n} members do not reproduce their goals bit for bit",
        checkpoint.state.generation,
        mismatches.len()
    )
}

#[cfg(feature = "zenoh")]
fn gateway(args: GatewayArgs) -> Result<()> {
    use sepval_common::remote::{JoinOptions, join};
    use sepval_coordinator::remote::Gateway;
    let workers = count("--workers", args.workers)?;
    let joined = join(JoinOptions {
        endpoint: args.connect.clone(),
        run_id: args.run.clone(),
        setup_timeout: Duration::from_secs_f64(inputs::positive(
            "--setup-timeout",
            args.setup_timeout,
        )?),
        zenoh_config: args.zenoh_config.clone(),
        announce_protocol: None,
    })?;
    let local_run = sepval_common::ipc::new_run_id();
    let mut gateway = Gateway::start(
        Arc::new(joined.job().clone()),
        IpcOptions {
            run_id: local_run.clone(),
            workers,
            launch: Launch::Spawn {
                executable: worker_executable()?,
            },
            chunk_deadline: Duration::from_secs_f64(inputs::positive(
                "--worker-timeout",
                args.worker_timeout,
            )?),
            join_timeout: Duration::from_secs(60),
            max_respawns: 2 * workers + 2,
            announce_protocol: None,
        },
    )?;
    eprintln!(
        "sepval gateway: joined run {} at {} as {}, serving with {workers} local worker(s) \
         (iceoryx2 run {local_run})",
        args.run,
        args.connect,
        joined.worker_id()
    );
    let stopped = joined.serve(&mut gateway)?;
    eprintln!("sepval gateway: {stopped}");
    Ok(())
}

#[cfg(not(feature = "zenoh"))]
fn gateway(_: GatewayArgs) -> Result<()> {
    anyhow::bail!(
        "gateway: this sepval was built without the zenoh transport; rebuild with \
         `cargo build --release --features zenoh`"
    )
}

fn bench(args: BenchArgs) -> Result<()> {
    use sepval_coordinator::bench::{BenchOptions, run_bench, table, write_outputs};
    if let Some(w) = args.workers.iter().find(|w| **w == 0 || **w > 64) {
        anyhow::bail!("--workers {w}: expected 1 to 64");
    }
    let (job, _) = inputs::job(&[], None)?;
    let options = BenchOptions {
        workers: args.workers.clone(),
        evals: args.evals,
        transports: args.transports.clone(),
        worker_executable: worker_executable()?,
        repeat: args.repeat,
    };
    eprintln!(
        "benchmarking {} simulations of the default event per measurement, median of {} \
         interleaved rounds, on {} core(s)",
        args.evals,
        args.repeat,
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    let rows = run_bench(Arc::new(job), &options, &mut |r| {
        eprintln!(
            "  {:<6} {} worker(s): {:.0} simulations/s, {:.0} refused requests/s",
            r.transport,
            r.workers,
            r.evals_per_s(),
            r.evals as f64 / r.probe_wall_s
        );
    })?;
    print!("{}", table(&rows));
    write_outputs(&args.out, &rows)?;
    println!(
        "wrote {} and {}",
        args.out.join("bench.csv").display(),
        args.out.join("bench.png").display()
    );
    Ok(())
}

fn diagnose(args: DiagnoseArgs) -> Result<()> {
    use sepval_coordinator::diagnose::{DiagnoseOptions, diagnose};
    let (job, inputs) = inputs::job(&args.data, args.scenario.as_deref())?;
    let sigma = Sigma::resolve(&job, args.noise.sigma_pos_m, args.noise.sigma_att_deg)?;
    let ga = GaSettings {
        population: args.population,
        generations: args.generations,
        seed: args.seed,
        ..GaSettings::default()
    };
    ga.validate()?;
    let lm = LmSettings {
        budget: args.lm_budget,
        ..LmSettings::default()
    };
    let fit = FitOptions {
        method: Method::GaLm,
        ga,
        hill: HillSettings::default(),
        sigma,
        truth: None,
        out: args.out.join("baseline"),
        resume: None,
        inputs,
        progress: true,
        lm: lm.clone(),
        lm_probe: LmSettings {
            budget: args.lm_budget.min(800),
            ..LmSettings::default()
        },
    };
    let mut evaluator = evaluator(&args.eval, job)?;
    let options = DiagnoseOptions {
        fit,
        out: args.out.clone(),
        candidate_lm: LmSettings {
            max_iterations: 400,
            budget: 10_000,
            ..lm
        },
    };
    let d = diagnose(&options, evaluator.as_mut())?;
    println!("{}", d.verdict);
    println!(
        "causes: [{}]  explained: {}  ({} simulations, {:.1} s)",
        d.causes.join(", "),
        d.explained,
        d.evaluations,
        d.wall_s
    );
    println!(
        "report: {}  data: {}",
        args.out.join("report.html").display(),
        args.out.join("diagnosis.json").display()
    );
    Ok(())
}
