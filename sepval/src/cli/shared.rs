//! The groups of flags several commands share (flattened into their argument structs): the
//! inputs of a fit, the model, outliers, tables, geometry, overwriting, noise and the evaluator.

use std::path::PathBuf;

use sepval_common::telemetry::outliers::Policy;
use sepval_envelope::grid::{Axis, GridError};
use sepval_plan::conditions::{Quantity, Range};
use sepval_transport::RunId;

use super::EvaluatorKind;

/// The measured data and the model a fit runs on (fit, diagnose, rerun).
#[derive(clap::Args)]
pub struct InputArgs {
    /// Measured trajectory (CSV; repeatable for several releases). Default: the embedded
    /// synthetic flight test (truth factors plus noise).
    #[arg(long, value_name = "FILE.csv")]
    pub data: Vec<PathBuf>,
    #[command(flatten)]
    pub model: ModelArgs,
    #[command(flatten)]
    pub outliers: OutlierArgs,
}

impl InputArgs {
    /// The releases these flags fit, and `validate` held out, each read with `--outliers`.
    pub fn releases<'a>(&'a self, validate: &'a [PathBuf]) -> sepval_run::inputs::Releases<'a> {
        sepval_run::inputs::Releases {
            data: &self.data,
            validate,
            scenario: self.model.scenario.as_deref(),
            extension: self.model.extension.as_deref(),
            policy: self.outliers.policy(),
        }
    }
}

/// What is done with outliers in the telemetry a command reads (docs/model.md section 6).
#[derive(clap::Args)]
pub struct OutlierArgs {
    /// Samples far from the trend of their neighbours (docs/model.md section 6): `refuse` the
    /// file naming them, or `drop` the rows that hold one [default: refuse; rerun, and the
    /// releases a source records: what their fit did].
    #[arg(long, value_enum, value_name = "refuse|drop")]
    pub outliers: Option<OutlierArg>,
}

/// `--outliers`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum OutlierArg {
    /// Refuse a file that holds one, naming them.
    Refuse,
    /// Leave out the rows that hold one (said on stderr).
    Drop,
}

impl OutlierArgs {
    /// The policy given, else the default (refuse).
    pub fn policy(&self) -> Policy {
        self.or(Policy::Refuse)
    }

    /// The policy given, else `recorded`.
    pub fn or(&self, recorded: Policy) -> Policy {
        self.given().unwrap_or(recorded)
    }

    /// The policy given, if one is.
    pub fn given(&self) -> Option<Policy> {
        self.outliers.map(|o| match o {
            OutlierArg::Refuse => Policy::Refuse,
            OutlierArg::Drop => Policy::Drop,
        })
    }
}

/// The model a command simulates (simulate, and through [`InputArgs`] fit, diagnose, rerun).
#[derive(clap::Args)]
pub struct ModelArgs {
    /// Scenario file (TOML); the embedded default (Eglin benchmark store) when absent.
    #[arg(long, value_name = "FILE")]
    pub scenario: Option<PathBuf>,
    /// Model extension (TOML, as `diagnose` writes DIR/extension.toml): terms added to the model.
    #[arg(long, value_name = "FILE")]
    pub extension: Option<PathBuf>,
}

/// What a run that leaves a table does (simulate, fit, diagnose).
#[derive(clap::Args)]
pub struct TablesArgs {
    /// Fail (exit 2) when the run leaves one of the scenario's tables (by default the value is
    /// held at the table's edge and the excursion reported); simulate then writes nothing, fit
    /// writes result.json, which records it, diagnose stops after its baseline fit.
    #[arg(long)]
    pub strict_tables: bool,
}

/// The store and the aircraft whose clearance is assessed (docs/geometry.md).
#[derive(clap::Args)]
pub struct GeometryArgs {
    /// The aircraft's geometry in the launch frame: STL (ASCII or binary) or TOML of
    /// primitives, e.g. examples/geometry/aircraft.toml.
    #[arg(long, value_name = "FILE")]
    pub aircraft: Option<PathBuf>,
    /// The store's shape in body axes about its CG (STL or TOML) [default: the scenario's
    /// store of revolution with four fins].
    #[arg(long, value_name = "FILE", requires = "aircraft")]
    pub store_shape: Option<PathBuf>,
    /// The smallest clearance allowed [mm] (MIL-STD-1289D: 25.4); only with --aircraft (a
    /// criterion without an aircraft would be ignored, so it is refused).
    #[arg(
        long,
        default_value_t = 25.4,
        value_name = "MM",
        allow_hyphen_values = true,
        requires = "aircraft"
    )]
    pub clearance_mm: f64,
}

/// One axis of a grid as given: its text (recorded and digested as typed) and its values,
/// parsed and checked by clap ([`Axis::parse`]) before the command runs.
#[derive(Debug, Clone)]
pub struct AxisArg {
    /// `LO:HI:N` as typed.
    pub text: String,
    /// Its values.
    pub axis: Axis,
}

/// The parser of the `LO:HI:N` flag of `quantity`.
fn axis_of(quantity: Quantity) -> impl Fn(&str) -> Result<AxisArg, String> + Clone {
    move |text| {
        Axis::parse(quantity, text)
            .map(|axis| AxisArg {
                text: text.to_string(),
                axis,
            })
            .map_err(|e| match e {
                // The flag and its value are said by the parse error already.
                GridError::Syntax { message, .. } => message,
                other => other.to_string(),
            })
    }
}

/// The parser of the `LO:HI` range flag of `quantity` (`sepval plan`).
pub(super) fn range_of(quantity: Quantity) -> impl Fn(&str) -> Result<Range, String> + Clone {
    move |text| {
        let number = |s: &str| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| format!("`{s}` is not a number (expected LO:HI)"))
        };
        let Some((lo, hi)) = text.split_once(':') else {
            return Err("expected LO:HI (two numbers, e.g. 0.6:0.9)".into());
        };
        Ok(Range {
            quantity,
            lo: number(lo)?,
            hi: number(hi)?,
        })
    }
}

/// The axes of a grid of flight conditions (`sepval envelope`, `sepval campaign`), each
/// `LO:HI:N`.
#[derive(clap::Args)]
pub struct GridArgs {
    /// Mach values: LO:HI:N.
    #[arg(long, value_name = "LO:HI:N", allow_hyphen_values = true, value_parser = axis_of(Quantity::Mach))]
    pub mach: Option<AxisArg>,
    /// Altitudes [m]: LO:HI:N.
    #[arg(long, value_name = "LO:HI:N", allow_hyphen_values = true, value_parser = axis_of(Quantity::AltitudeM))]
    pub altitude_m: Option<AxisArg>,
    /// Aircraft angles of attack [deg]: LO:HI:N.
    #[arg(long, value_name = "LO:HI:N", allow_hyphen_values = true, value_parser = axis_of(Quantity::AlphaDeg))]
    pub alpha_deg: Option<AxisArg>,
    /// Aircraft sideslip angles [deg]: LO:HI:N.
    #[arg(long, value_name = "LO:HI:N", allow_hyphen_values = true, value_parser = axis_of(Quantity::BetaDeg))]
    pub beta_deg: Option<AxisArg>,
    /// Flight-path angles [deg]: LO:HI:N.
    #[arg(long, value_name = "LO:HI:N", allow_hyphen_values = true, value_parser = axis_of(Quantity::GammaDeg))]
    pub gamma_deg: Option<AxisArg>,
}

impl GridArgs {
    /// The axes given, in the order of `[flight]`.
    pub fn given(&self) -> Vec<(Quantity, &AxisArg)> {
        [
            (Quantity::Mach, &self.mach),
            (Quantity::AltitudeM, &self.altitude_m),
            (Quantity::AlphaDeg, &self.alpha_deg),
            (Quantity::BetaDeg, &self.beta_deg),
            (Quantity::GammaDeg, &self.gamma_deg),
        ]
        .into_iter()
        .filter_map(|(q, v)| v.as_ref().map(|v| (q, v)))
        .collect()
    }
}

/// Whether an earlier run in `--out` may be cleared (fit, diagnose, plan).
#[derive(clap::Args)]
pub struct OverwriteArgs {
    /// Clear --out first if it holds an earlier sepval run (it is refused otherwise).
    #[arg(long)]
    pub overwrite: bool,
}

/// The baseline fit of a command that fits its releases before it works (diagnose, update).
#[derive(clap::Args)]
pub struct BaselineArgs {
    /// Seed of the baseline fit's genetic search.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Generations of the baseline fit's genetic search (it stops earlier when its refinement
    /// reaches the noise floor).
    #[arg(long, default_value_t = 60)]
    pub generations: usize,
    /// Population of the baseline fit's genetic search.
    #[arg(long, default_value_t = 100)]
    pub population: usize,
    /// Simulation budget of the baseline fit's refinement.
    #[arg(long, default_value_t = 3000)]
    pub lm_budget: u64,
    #[command(flatten)]
    pub noise: NoiseArgs,
}

impl BaselineArgs {
    /// The baseline search the flags ask for: the study's GA, refined within the budget,
    /// weighted by the noise levels given (any not given is estimated from the releases).
    pub fn search(&self) -> sepval_fit::BaselineSearch {
        sepval_fit::BaselineSearch {
            ga: sepval_solve::ga::GaSettings {
                population: self.population,
                generations: self.generations,
                seed: self.seed,
                ..Default::default()
            },
            lm_budget: self.lm_budget,
            sigma_pos_m: self.noise.sigma_pos_m,
            sigma_att_deg: self.noise.sigma_att_deg,
        }
    }
}

/// The measurement noise that weights the goals (shared by every search command).
#[derive(clap::Args)]
pub struct NoiseArgs {
    /// Position noise [m] weighting J_pos (default: estimated from the data).
    #[arg(long)]
    pub sigma_pos_m: Option<f64>,
    /// Attitude noise [deg] weighting J_att (default: estimated from the data).
    #[arg(long)]
    pub sigma_att_deg: Option<f64>,
}

/// How simulations are run (shared by every search command).
#[derive(clap::Args)]
pub struct EvalArgs {
    /// `ipc`: worker processes over iceoryx2 shared memory; `inproc`: threads of this process;
    /// `zenoh`: workers on any host that joins --listen (built with the `zenoh` feature).
    #[arg(long, value_enum, default_value_t = EvaluatorKind::Ipc)]
    pub evaluator: EvaluatorKind,
    /// Worker processes (ipc) [default: the number of cores]; with zenoh, the workers to wait
    /// for before the search starts [default: 1] (more may join at any time).
    #[arg(long)]
    pub workers: Option<usize>,
    /// zenoh: the endpoint to listen on for workers, e.g. tcp/0.0.0.0:7447 (explicit port).
    #[arg(long, value_name = "ENDPOINT")]
    pub listen: Option<String>,
    /// zenoh: a zenoh JSON5 configuration to start from (TLS certificates, authentication);
    /// sepval still sets peer mode, the endpoint and switches scouting off.
    #[arg(long, value_name = "FILE")]
    pub zenoh_config: Option<PathBuf>,
    /// Threads (inproc) [default: the number of cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Do not start workers: create run RUN_ID and wait for --workers externally started
    /// `sepval-worker --run RUN_ID`.
    #[arg(long, value_name = "RUN_ID")]
    pub attach: Option<RunId>,
    /// Run id of spawned workers [default: a fresh one].
    #[arg(long, value_name = "RUN_ID")]
    pub run_id: Option<RunId>,
    /// A worker that holds a chunk longer than this [s] is killed and replaced.
    #[arg(long, default_value_t = 60.0, value_name = "S")]
    pub worker_timeout: f64,
    /// How long to wait for workers to join [s].
    #[arg(long, default_value_t = 60.0, value_name = "S")]
    pub join_timeout: f64,
    /// Announce this protocol version in the job setup (compatibility testing only).
    #[arg(long, hide = true)]
    pub announce_protocol: Option<u32>,
}
