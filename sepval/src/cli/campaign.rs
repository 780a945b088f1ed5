//! `sepval campaign`'s subcommands and flags (docs/campaign.md).

use std::path::PathBuf;

use clap::Subcommand;

use super::{EvalArgs, GeometryArgs, GridArgs, OutlierArgs};

#[derive(Subcommand)]
pub enum CampaignCommand {
    /// Begin a campaign: the grid, the criterion and the envelope predicted from the prior.
    Init(Box<CampaignInitArgs>),
    /// The next release(s) to fly: safe to fly, ranked by what they are expected to settle.
    Next(CampaignNextArgs),
    /// Record flown releases: each checked against its prediction, every release diagnosed
    /// again, the envelope predicted again.
    Add(CampaignAddArgs),
    /// The campaign's state in a few lines.
    Status(CampaignStatusArgs),
    /// A virtual test program for sizing one: init, then plan, fly the planned release with a
    /// stated truth (sepval's simulator, with noise) and add it, until settled.
    Rehearse(Box<CampaignRehearseArgs>),
}

#[derive(clap::Args)]
pub struct CampaignRehearseArgs {
    #[command(flatten)]
    pub init: CampaignInitArgs,
    /// The truth's scenario (TOML) [default: the embedded default].
    #[arg(long, value_name = "FILE")]
    pub truth_scenario: Option<PathBuf>,
    /// A model extension of the truth (TOML).
    #[arg(long, value_name = "FILE")]
    pub truth_extension: Option<PathBuf>,
    /// An effect of the truth, ID=V (repeatable; `sepval effects` lists them).
    #[arg(long, value_name = "ID=V")]
    pub truth_effect: Vec<String>,
    /// The truth's factors: `truth`, `nominal` or a JSON file.
    #[arg(long, default_value = "truth", value_name = "truth|nominal|FILE")]
    pub truth_factors: String,
    /// The noise seed of the first release flown (the k-th: this plus k - 1).
    #[arg(long, default_value_t = 1)]
    pub noise_seed: u64,
    /// The most releases to fly.
    #[arg(long, default_value_t = 6, value_name = "MAX")]
    pub releases: usize,
    /// When the campaign settles with conditions undecided, check the claim: fly each
    /// condition then safe to fly in turn, each on a copy of the campaign, and count what it
    /// settles (one `add` a candidate).
    #[arg(long)]
    pub check_settled: bool,
}

#[derive(clap::Args)]
pub struct CampaignInitArgs {
    /// The store's scenario (TOML) [default: the embedded default].
    #[arg(long, value_name = "FILE")]
    pub scenario: Option<PathBuf>,
    #[command(flatten)]
    pub grid: GridArgs,
    /// The largest probability of failing to clear at which a condition is cleared (and of
    /// clearing at which it fails).
    #[arg(long, default_value_t = 0.05, value_name = "P")]
    pub allowed: f64,
    /// The largest probability of failing to clear at which a release may be flown.
    #[arg(long, default_value_t = 0.01, value_name = "P")]
    pub fly_risk: f64,
    /// The factors before any release (JSON, format sepval-prior/1) [default: each factor's
    /// nominal value, a sixth of the study's range as its standard deviation].
    #[arg(long, value_name = "FILE")]
    pub prior: Option<PathBuf>,
    /// The store's data with uncertainty (DAVE-ML 2.0, a `normalPDF` on its tables, as
    /// `sepval update --daveml` writes it): each uncertain table sets the factor that moves it.
    #[arg(long, value_name = "FILE.xml")]
    pub prior_daveml: Option<PathBuf>,
    /// The store's shape (a store TOML, docs/aero.md): its estimated aerodynamics' stated
    /// uncertainty sets the offsets' spread (caoff, cyoff, czoff, cmoff, cnoff); give the
    /// scenario `sepval scenario --from-shape` made of it (docs/campaign.md).
    #[arg(long, value_name = "SHAPE.toml")]
    pub prior_from_shape: Option<PathBuf>,
    /// A pre-flight trajectory (a captive-trajectory test or a CFD release: CSV stating its
    /// condition as a release does; repeatable), fitted into the prior with the allowance below.
    #[arg(long, value_name = "FILE.csv")]
    pub preflight: Vec<PathBuf>,
    /// The model-form allowance of pre-flight positions, added in quadrature to their noise
    /// (they are not flight).
    #[arg(long, default_value_t = 0.01, value_name = "M")]
    pub preflight_allowance_m: f64,
    /// The model-form allowance of pre-flight attitudes.
    #[arg(long, default_value_t = 1.0, value_name = "DEG")]
    pub preflight_allowance_deg: f64,
    /// Samples per condition.
    #[arg(long, default_value_t = 1000, value_name = "N")]
    pub samples: usize,
    /// Seed of every draw and of each round's fit.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Generations of the genetic search of each round's baseline fit (then
    /// Levenberg-Marquardt, then the diagnosis).
    #[arg(long, default_value_t = 20)]
    pub generations: usize,
    #[command(flatten)]
    pub geometry: GeometryArgs,
    #[command(flatten)]
    pub eval: EvalArgs,
    /// The campaign's directory (new or empty).
    #[arg(long, value_name = "CAMP")]
    pub out: PathBuf,
}

#[derive(clap::Args)]
pub struct CampaignNextArgs {
    /// The campaign's directory.
    #[arg(value_name = "CAMP")]
    pub campaign: PathBuf,
    /// Releases to plan together (complementary, not neighbours).
    #[arg(long, default_value_t = 1, value_name = "K")]
    pub count: usize,
}

#[derive(clap::Args)]
pub struct CampaignAddArgs {
    /// The campaign's directory.
    #[arg(value_name = "CAMP")]
    pub campaign: PathBuf,
    /// A release flown (CSV with its condition in its metadata; repeatable).
    #[arg(long, value_name = "FILE.csv", required = true)]
    pub data: Vec<PathBuf>,
    /// Accept a release whose `# scenario_sha256` names another scenario than the campaign's
    /// (another simulation, or a flight, of the same store); it is recorded with a note.
    #[arg(long)]
    pub other_scenario: bool,
    #[command(flatten)]
    pub outliers: OutlierArgs,
    #[command(flatten)]
    pub eval: EvalArgs,
}

#[derive(clap::Args)]
pub struct CampaignStatusArgs {
    /// The campaign's directory.
    #[arg(value_name = "CAMP")]
    pub campaign: PathBuf,
}
