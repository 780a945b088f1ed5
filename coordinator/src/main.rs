//! `sepval`: post-flight validation of store-separation simulations.
//!
//! Only the command line lives here; see the `sepval_coordinator` and `sepval_common`
//! libraries for the logic.

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
use sepval_coordinator::inputs;

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
    let result = match cli.command {
        Command::Simulate(args) => simulate(args),
        Command::Effects => {
            print_effects();
            Ok(())
        }
        Command::Goals(args) => goals(args),
        Command::Scenario(args) => scenario(args),
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
