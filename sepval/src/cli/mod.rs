//! The command line: clap types only, one `ValueEnum` per closed set of values. Raw flags
//! become a validated configuration in `command/` before anything runs.

use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};

mod campaign;
mod shared;
pub use campaign::{
    CampaignAddArgs, CampaignCommand, CampaignInitArgs, CampaignNextArgs, CampaignRehearseArgs,
    CampaignStatusArgs,
};
use sepval_plan::conditions::{Quantity, Range};
use sepval_transport::RunId;
pub use shared::{
    AxisArg, BaselineArgs, EvalArgs, GeometryArgs, GridArgs, InputArgs, ModelArgs, NoiseArgs,
    OutlierArg, OutlierArgs, OverwriteArgs, TablesArgs,
};

#[derive(Parser)]
#[command(
    name = "sepval",
    version,
    about = "Post-flight validation of store-separation simulations",
    long_about = "sepval compares a 6DOF store-separation simulation with measured trajectories, \
                  fits the model factors that make it match, diagnoses what it still gets wrong, \
                  plans the next release, predicts releases not flown with bands that hold, and \
                  maps where the store clears the aircraft."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Simulate a release and write its trajectory (CSV, docs/model.md section 6).
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
    /// Plan the next release: the flight condition that would best tell a diagnosis's answer
    /// from its rivals, or (with no rivals) most shrink the uncertainty of its parameters.
    Plan(Box<PlanArgs>),
    /// Predict a release not flown, with bands from the factors, the model's form and the
    /// measurement; with --data, check a flown release against them.
    Predict(Box<PredictArgs>),
    /// Map the separation envelope: the store's clearance to the aircraft predicted over a grid
    /// of flight conditions, and where it holds with confidence.
    Envelope(Box<EnvelopeArgs>),
    /// Update the store's aerodynamic data from its releases: corrections as tables in the
    /// scenario's own form, kept only as far as they predict a release they were not fitted to.
    Update(Box<UpdateArgs>),
    /// Run a test program as one record: the envelope before any release, the next release to
    /// fly, each release flown added, until the envelope is settled (docs/campaign.md).
    #[command(subcommand)]
    Campaign(CampaignCommand),
    /// Estimate a store's freestream aerodynamics from its shape (docs/aero.md).
    Aero(AeroArgs),
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
pub struct GatewayArgs {
    /// The coordinator's endpoint, e.g. tcp/192.0.2.7:7447.
    #[arg(long, value_name = "ENDPOINT")]
    pub connect: String,
    /// The run to join (the coordinator prints it).
    #[arg(long, value_name = "RUN_ID")]
    pub run: RunId,
    /// Local iceoryx2 worker processes [default: the number of cores].
    #[arg(long)]
    pub workers: Option<usize>,
    /// A local worker holding a chunk longer than this [s] is killed and replaced.
    #[arg(long, default_value_t = 60.0, value_name = "S")]
    pub worker_timeout: f64,
    /// How long to wait for the coordinator's job setup [s].
    #[arg(long, default_value_t = 30.0, value_name = "S")]
    pub setup_timeout: f64,
    /// A zenoh JSON5 configuration to start from (TLS certificates, authentication).
    #[arg(long, value_name = "FILE")]
    pub zenoh_config: Option<PathBuf>,
}

#[derive(clap::Args)]
pub struct FitArgs {
    #[command(flatten)]
    pub inputs: InputArgs,
    /// Searches to run [default: both; when resuming: the checkpoint's].
    #[arg(long, value_enum)]
    pub method: Option<MethodArg>,
    /// Seed of the genetic algorithm's generator.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Generations (evaluated populations, the initial one included) [default: 500; when
    /// resuming: the checkpoint's].
    #[arg(long)]
    pub generations: Option<usize>,
    /// Population size (even).
    #[arg(long, default_value_t = 100)]
    pub population: usize,
    /// Probability of single-point crossover.
    #[arg(long, default_value_t = 0.9)]
    pub p_crossover: f64,
    /// Probability of a jump mutation per bit.
    #[arg(long, default_value_t = 0.005)]
    pub p_jump: f64,
    /// Probability of a creep mutation per parameter.
    #[arg(long, default_value_t = 0.05)]
    pub p_creep: f64,
    /// Simulation budget of the hill climber.
    #[arg(long, default_value_t = 500)]
    pub hill_budget: usize,
    /// Simulation budget of the Levenberg-Marquardt refinement (`+lm` methods).
    #[arg(long, default_value_t = 5000)]
    pub lm_budget: u64,
    #[command(flatten)]
    pub eval: EvalArgs,
    #[command(flatten)]
    pub geometry: GeometryArgs,
    #[command(flatten)]
    pub noise: NoiseArgs,
    /// The true factors (JSON), for Figure 7; the embedded truth is used with the default data.
    #[arg(long, value_name = "FILE.json")]
    pub truth_factors: Option<PathBuf>,
    /// Continue from a checkpoint (DIR/generations/gen-NNNN.json).
    #[arg(long, value_name = "CHECKPOINT")]
    pub resume: Option<PathBuf>,
    /// Skip the figures.
    #[arg(long)]
    pub no_figures: bool,
    #[command(flatten)]
    pub tables: TablesArgs,
    #[command(flatten)]
    pub overwrite: OverwriteArgs,
    /// Run directory (result.json, generations/, figures/).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

#[derive(clap::Args)]
pub struct DiagnoseArgs {
    #[command(flatten)]
    pub inputs: InputArgs,
    /// A release not used for fitting (CSV; repeatable): the baseline and the answer predict it
    /// and their errors are reported, the honest measure of an extension.
    #[arg(long, value_name = "FILE.csv")]
    pub validate: Vec<PathBuf>,
    #[command(flatten)]
    pub baseline: BaselineArgs,
    #[command(flatten)]
    pub eval: EvalArgs,
    #[command(flatten)]
    pub geometry: GeometryArgs,
    #[command(flatten)]
    pub tables: TablesArgs,
    /// An earlier diagnosis of the first of these releases (its --out directory): every
    /// explanation it left open (its answer, rivals and classes not told apart) is refitted on
    /// every release and competes for the answer; the report says what became of each.
    #[arg(long, value_name = "DIAG")]
    pub after: Option<PathBuf>,
    /// The plan made from the --after diagnosis (the --out directory of `sepval plan`): its
    /// predicted separations are set against the diagnosis's, and disagreements listed.
    #[arg(long, value_name = "PLANDIR", requires = "after")]
    pub plan: Option<PathBuf>,
    /// Output directory (diagnosis.json, report.html, figures/, baseline/).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    #[command(flatten)]
    pub overwrite: OverwriteArgs,
}

#[derive(clap::Args)]
pub struct PlanArgs {
    /// The output directory of `sepval diagnose` to plan from (its diagnosis.json).
    #[arg(long, value_name = "DIR")]
    pub from: PathBuf,
    /// Range of the candidate conditions' Mach number [default: the first release's].
    #[arg(long, value_name = "LO:HI", allow_hyphen_values = true, value_parser = shared::range_of(Quantity::Mach))]
    pub mach: Option<Range>,
    /// Range of the candidate conditions' altitude [m] [default: the first release's].
    #[arg(long, value_name = "LO:HI", allow_hyphen_values = true, value_parser = shared::range_of(Quantity::AltitudeM))]
    pub altitude_m: Option<Range>,
    /// Range of the candidate conditions' aircraft angle of attack [deg] [default: the first release's].
    #[arg(long, value_name = "LO:HI", allow_hyphen_values = true, value_parser = shared::range_of(Quantity::AlphaDeg))]
    pub alpha_deg: Option<Range>,
    /// Range of the candidate conditions' aircraft sideslip [deg] [default: the first release's].
    #[arg(long, value_name = "LO:HI", allow_hyphen_values = true, value_parser = shared::range_of(Quantity::BetaDeg))]
    pub beta_deg: Option<Range>,
    /// Range of the candidate conditions' flight-path angle [deg] [default: the first release's].
    #[arg(long, value_name = "LO:HI", allow_hyphen_values = true, value_parser = shared::range_of(Quantity::GammaDeg))]
    pub gamma_deg: Option<Range>,
    /// Points per axis given with LO < HI (the grid has points^axes conditions).
    #[arg(long, default_value_t = sepval_plan::DEFAULT_POINTS, value_name = "N")]
    pub points: usize,
    #[command(flatten)]
    pub eval: EvalArgs,
    /// Output directory (plan.json, plan.html, figures/).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    #[command(flatten)]
    pub overwrite: OverwriteArgs,
}

#[derive(clap::Args)]
pub struct PredictArgs {
    /// The output directory of `sepval fit` (with --method ga+lm or hill+lm) or of `sepval
    /// diagnose` to predict from (its result.json or diagnosis.json).
    #[arg(long, value_name = "DIR")]
    pub from: PathBuf,
    /// The release to predict: a scenario of the store fitted with the flight condition to
    /// predict in [flight] (Mach, altitude, alpha, beta, gamma).
    #[arg(long, value_name = "COND.toml")]
    pub scenario: PathBuf,
    /// Model extension (TOML) the source was fitted with [default: the one its inputs record].
    #[arg(long, value_name = "FILE")]
    pub extension: Option<PathBuf>,
    /// Samples drawn.
    #[arg(long, default_value_t = 1000, value_name = "N")]
    pub samples: usize,
    /// Level of the bands, in (0, 1).
    #[arg(long, default_value_t = 0.95, allow_hyphen_values = true)]
    pub level: f64,
    /// Seed of every draw.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Include the measurement noise of the source in the bands (to compare with telemetry
    /// rather than the truth; always with --data).
    #[arg(long)]
    pub with_noise: bool,
    /// A release flown at the condition (CSV): the post-flight check against the bands.
    #[arg(long, value_name = "FLOWN.csv")]
    pub data: Option<PathBuf>,
    /// A release held out of the fit (CSV; repeatable): calibrates the model-form discrepancy.
    #[arg(long, value_name = "FILE.csv")]
    pub validate: Vec<PathBuf>,
    #[command(flatten)]
    pub outliers: OutlierArgs,
    #[command(flatten)]
    pub geometry: GeometryArgs,
    #[command(flatten)]
    pub eval: EvalArgs,
    /// Output directory (prediction.json, bands.csv, report.html, figures/).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    #[command(flatten)]
    pub overwrite: OverwriteArgs,
}

#[derive(Subcommand)]
pub enum SelftestCommand {
    /// The genetic algorithm on ZDT1, ZDT2 or ZDT3 (30 variables): prints the hypervolume of
    /// the final front with reference point (1.1, 1.1).
    Zdt {
        /// The test problem.
        #[arg(long, value_enum)]
        problem: ZdtArg,
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
pub const DEFAULT_TRANSPORTS: &str = "scalar,single,pool,ipc,uds,zenoh";
/// Transports `sepval bench` measures by default.
#[cfg(not(feature = "zenoh"))]
pub const DEFAULT_TRANSPORTS: &str = "scalar,single,pool,ipc,uds";

#[derive(clap::Args)]
pub struct BenchArgs {
    /// Worker counts, comma-separated.
    #[arg(long, default_value = "1,2,4", value_delimiter = ',')]
    pub workers: Vec<usize>,
    /// Simulations per measurement.
    #[arg(long, default_value_t = 2000)]
    pub evals: usize,
    /// Transports, comma-separated (zenoh when built with it).
    #[arg(long, value_enum, default_value = DEFAULT_TRANSPORTS, value_delimiter = ',')]
    pub transports: Vec<TransportArg>,
    /// Measurements per transport and worker count, taken in interleaved rounds; the table
    /// reports the median.
    #[arg(long, default_value_t = 3)]
    pub repeat: usize,
    /// Output directory (bench.csv, bench.png).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    #[command(flatten)]
    pub overwrite: OverwriteArgs,
}

/// The inputs' defaults are the checkpoint's record, each input on its own: the shared help
/// says what they are for a fresh fit, so rerun says its own.
#[derive(clap::Args)]
#[command(
    mut_arg("data", |a| a.help("Data files (default: those recorded in the checkpoint)")),
    mut_arg("scenario", |a| a.help("Scenario file (default: the one recorded in the checkpoint)")),
    mut_arg("extension", |a| a.help(
        "Model extension (TOML, as `diagnose` writes DIR/extension.toml): terms added to the \
         model (default: the one recorded in the checkpoint)"
    )),
)]
pub struct RerunArgs {
    /// Checkpoint of the generation to re-evaluate.
    #[arg(value_name = "CHECKPOINT")]
    pub checkpoint: PathBuf,
    #[command(flatten)]
    pub inputs: InputArgs,
    #[command(flatten)]
    pub eval: EvalArgs,
}

#[derive(clap::Args)]
pub struct EnvelopeArgs {
    /// The output directory of `sepval fit` (with --method ga+lm or hill+lm) or of `sepval
    /// diagnose` to predict from.
    #[arg(long, value_name = "DIR")]
    pub from: PathBuf,
    #[command(flatten)]
    pub grid: GridArgs,
    /// Model extension (TOML) the source was fitted with [default: the one its inputs record].
    #[arg(long, value_name = "FILE")]
    pub extension: Option<PathBuf>,
    /// Samples per condition.
    #[arg(long, default_value_t = 1000, value_name = "N")]
    pub samples: usize,
    /// Seed of every draw (the same samples at every condition).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// A release held out of the fit (CSV; repeatable): calibrates the model-form discrepancy.
    #[arg(long, value_name = "FILE.csv")]
    pub validate: Vec<PathBuf>,
    #[command(flatten)]
    pub outliers: OutlierArgs,
    #[command(flatten)]
    pub geometry: GeometryArgs,
    #[command(flatten)]
    pub eval: EvalArgs,
    /// Output directory (envelope.csv, envelope.json, report.html, figures/).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Go on with the interrupted sweep in --out (same inputs) instead of starting anew.
    #[arg(long, conflicts_with = "overwrite")]
    pub resume: bool,
    #[command(flatten)]
    pub overwrite: OverwriteArgs,
}

#[derive(clap::Args)]
pub struct UpdateArgs {
    #[command(flatten)]
    pub inputs: InputArgs,
    /// A release never fitted (CSV; repeatable): the store as given, the factors alone and the
    /// updated store predict it.
    #[arg(long, value_name = "FILE.csv")]
    pub validate: Vec<PathBuf>,
    /// The factors fitted with the corrections, comma-separated [default: all 17]; the others
    /// stay at the baseline fit's values.
    #[arg(long, value_name = "NAME,...", value_parser = factor_names)]
    pub free: Option<FactorNames>,
    #[command(flatten)]
    pub baseline: BaselineArgs,
    #[command(flatten)]
    pub eval: EvalArgs,
    /// Also write the updated store as a DAVE-ML 2.0 model, DIR/store.dml: its tables, each
    /// correction's standard deviation as an uncertainty (normalPDF), and checkData
    /// (docs/daveml.md).
    #[arg(long)]
    pub daveml: bool,
    /// Output directory (update.json, scenario.toml, tables/, factors.json, report.html,
    /// figures/, baseline/).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    #[command(flatten)]
    pub overwrite: OverwriteArgs,
}

#[derive(clap::Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Factors: `truth`, `nominal`, or a JSON file mapping the 17 factor names to values.
    #[arg(long, default_value = "truth", value_name = "truth|nominal|FILE.json")]
    pub factors: String,
    /// Switch on a catalogue effect with its parameters in docs/model.md units and order
    /// (repeatable), e.g. `--effect roll_due_to_sideslip=-0.3`.
    #[arg(long = "effect", value_name = "ID=V1,V2,...")]
    pub effects: Vec<String>,
    /// Add Gaussian measurement noise (0.003 m, 0.1 deg) from this seed.
    #[arg(long, value_name = "N")]
    pub noise_seed: Option<u64>,
    /// Event length [s] (default: the scenario's).
    #[arg(long, value_name = "S")]
    pub t_end: Option<f64>,
    /// Telemetry rate [Hz] (default: the scenario's).
    #[arg(long, value_name = "HZ")]
    pub rate: Option<f64>,
    #[command(flatten)]
    pub tables: TablesArgs,
    #[command(flatten)]
    pub geometry: GeometryArgs,
    /// Output CSV file (written atomically).
    #[arg(long, value_name = "FILE.csv")]
    pub out: PathBuf,
}

#[derive(clap::Args)]
pub struct GoalsArgs {
    /// Measured trajectory (CSV).
    #[arg(long, value_name = "A.csv")]
    pub data: PathBuf,
    /// Simulated trajectory (CSV) at the same sample times.
    #[arg(long, value_name = "B.csv")]
    pub sim: PathBuf,
    #[command(flatten)]
    pub outliers: OutlierArgs,
}

#[derive(clap::Args)]
pub struct AeroArgs {
    /// The store's shape: a store TOML (docs/geometry.md: body of revolution, nose, fins).
    #[arg(long, value_name = "SHAPE.toml")]
    pub store_shape: PathBuf,
    /// Mach numbers LO:HI:N (N points from LO to HI), within 0.05 to 2.
    #[arg(long, value_name = "LO:HI:N", default_value = sepval_aero::grid::DEFAULT_MACH)]
    pub mach: String,
    /// Angles of attack and of sideslip LO:HI:N [deg], within -30 to 30.
    #[arg(long, value_name = "LO:HI:N", default_value = sepval_aero::grid::DEFAULT_ALPHA_DEG)]
    pub alpha_deg: String,
    /// Altitude of the condition (ISA) [m], for the Reynolds number of the skin friction.
    #[arg(long, value_name = "M", default_value_t = sepval_aero::DEFAULT_ALTITUDE_M)]
    pub altitude_m: f64,
    /// A new output directory: aero.toml, store.dml and summary.txt.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

#[derive(clap::Args)]
pub struct ScenarioArgs {
    /// Scenario to rewrite (validated); the embedded default when absent.
    #[arg(long, value_name = "FILE")]
    pub scenario: Option<PathBuf>,
    /// Write the scenario's aerodynamics as tables (docs/model.md section 1): --out is then a
    /// directory that receives scenario.toml and tables/*.csv, a starting point for your own
    /// tabulated data that simulates as the constant form to rounding.
    #[arg(long)]
    pub tables: bool,
    /// With --tables, the interference increments too, as tables over distance sampled from
    /// their exponential decay (linear between breakpoints: within about 1e-4 m and 0.01 deg of
    /// the exponential form's trajectory, not to rounding).
    #[arg(long, requires = "tables")]
    pub interference_tables: bool,
    /// Read the store's aerodynamics from a DAVE-ML model (docs/daveml.md) into the scenario
    /// (the embedded default unless --scenario is given): --out is then a new directory that
    /// receives scenario.toml and tables/*.csv; the file's checkData must pass first.
    #[arg(long, value_name = "FILE.dml", conflicts_with_all = ["tables", "to_daveml"])]
    pub from_daveml: Option<PathBuf>,
    /// With --from-daveml, which DAVE-ML variable is which sepval input or field, added to the
    /// default map (docs/daveml.md).
    #[arg(long, value_name = "MAP.toml", requires = "from_daveml")]
    pub map: Option<PathBuf>,
    /// The store's [aero] estimated from its shape (a store TOML, docs/aero.md) in place of the
    /// scenario's (the embedded default unless --scenario is given), with the shape's diameter
    /// and the static offsets' ranges widened to three of the estimate's sigmas where they are
    /// narrower; the mass properties and the rest stay the scenario's. --out is the TOML file.
    #[arg(long, value_name = "SHAPE.toml", conflicts_with_all = ["tables", "to_daveml", "from_daveml"])]
    pub from_shape: Option<PathBuf>,
    /// Write the scenario's aerodynamic and interference fields as a DAVE-ML 2.0 model to
    /// --out FILE.dml, with checkData computed by sepval (docs/daveml.md).
    #[arg(long, conflicts_with = "tables")]
    pub to_daveml: bool,
    /// Output TOML file (written atomically); with --tables or --from-daveml, an output
    /// directory; with --to-daveml, the DAVE-ML file.
    #[arg(long, value_name = "FILE.toml|DIR|FILE.dml")]
    pub out: PathBuf,
}

/// `--method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// The study's genetic algorithm.
    Ga,
    /// The study's hill climber.
    Hill,
    /// Both, as in the study's comparison.
    Both,
    /// The genetic algorithm, then refinement to the noise floor.
    #[value(name = "ga+lm")]
    GaLm,
    /// The hill climber, then refinement to the noise floor.
    #[value(name = "hill+lm")]
    HillLm,
}

/// `--evaluator`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum EvaluatorKind {
    /// Worker processes over iceoryx2 shared memory.
    Ipc,
    /// Threads of this process.
    Inproc,
    /// Workers on any host that joins --listen (built with the `zenoh` feature).
    Zenoh,
}

/// `--transports`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum TransportArg {
    /// One thread of this process, one candidate at a time through the scalar propagator (the
    /// reference for the lane propagator's gain).
    Scalar,
    /// One thread of this process.
    Single,
    /// A thread pool of this process.
    Pool,
    /// iceoryx2 worker processes.
    Ipc,
    /// Unix-socket worker processes.
    Uds,
    /// zenoh worker processes over loopback TCP.
    Zenoh,
}

/// `selftest zdt --problem`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ZdtArg {
    /// Convex front.
    Zdt1,
    /// Non-convex front.
    Zdt2,
    /// Disconnected front.
    Zdt3,
}

/// The names of `--free NAME,...`, none of them empty (`update` checks them against the 17
/// factors).
#[derive(Debug, Clone)]
pub struct FactorNames(pub Vec<String>);

/// `--free`'s list, refused at parse time when a name is empty (`--free ""`, `--free ,`,
/// `--free cmoff,`): an empty list would leave the update nothing to fit.
fn factor_names(text: &str) -> Result<FactorNames, String> {
    let names: Vec<String> = text.split(',').map(|n| n.trim().to_string()).collect();
    if names.iter().any(String::is_empty) {
        return Err(
            "an empty factor name: expected names separated by commas, e.g. cmoff,cnoff".into(),
        );
    }
    Ok(FactorNames(names))
}
