//! What a campaign refuses, and why: each refusal names the release, the flag or the record it
//! is about, and what it expected.

use std::path::PathBuf;

use sepval_common::simulation::SimError;
use sepval_fit::sigma::SigmaError;
use sepval_predict::releases::GeometryError;

use crate::CampaignError;
use crate::page::number;

/// A release, a flag or a step of a campaign refused.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Refusal {
    /// `campaign init` without `--aircraft`.
    #[error(
        "--aircraft FILE is required: the aircraft's geometry (e.g. examples/geometry/aircraft.toml)"
    )]
    NoAircraft,
    /// `campaign init` without an axis.
    #[error(
        "give at least one axis: --mach, --altitude-m, --alpha-deg, --beta-deg or --gamma-deg, each LO:HI:N"
    )]
    NoAxis,
    /// An axis flag that names no axis.
    #[error("{flag}: not an axis")]
    NotAnAxis {
        /// The flag.
        flag: String,
    },
    /// A `--preflight` trajectory that cannot be read as a release of the campaign.
    #[error("--preflight {}: {reason}", path.display())]
    Preflight {
        /// The file.
        path: PathBuf,
        /// Why (its own message, with the file's place).
        reason: Box<CampaignError>,
    },
    /// A `--preflight` trajectory given twice.
    #[error("--preflight {} is the same trajectory as {}: give each once", path.display(), other.display())]
    PreflightTwice {
        /// The file given again.
        path: PathBuf,
        /// The one given before it.
        other: PathBuf,
    },
    /// The noise of the pre-flight trajectories.
    #[error("the noise of the pre-flight trajectories: {reason}")]
    PreflightNoise {
        /// Why it cannot be estimated.
        reason: SigmaError,
    },
    /// A pre-flight fit without a refined optimum.
    #[error(
        "the fit of the pre-flight trajectories found no refined optimum (its Levenberg-Marquardt refinement did not finish): their information cannot be weighed"
    )]
    PreflightNotRefined,
    /// A pre-flight fit whose Jacobian does not fit its residuals and factors.
    #[error(
        "the pre-flight fit's Jacobian is {rows} x {columns} for {residuals} residuals and {factors} factors"
    )]
    JacobianShape {
        /// Its rows.
        rows: usize,
        /// Its columns.
        columns: usize,
        /// The residuals.
        residuals: usize,
        /// The factors.
        factors: usize,
    },
    /// A pre-flight fit's Jacobian with numbers that are not finite.
    #[error(
        "the pre-flight fit's Jacobian holds numbers that are not finite: its information cannot be weighed"
    )]
    JacobianNotFinite,
    /// A pre-flight posterior whose precision is not positive definite.
    #[error(
        "the pre-flight posterior's precision is not positive definite: its information cannot be weighed"
    )]
    PrecisionNotPositive,
    /// The noise of the releases flown.
    #[error("the noise of the releases: {reason}")]
    ReleasesNoise {
        /// Why it cannot be estimated.
        reason: SigmaError,
    },
    /// A file or directory in the campaign's place for its next round or a release's copy.
    #[error(
        "{} is there already, and the campaign's record (campaign.json) does not name it: the campaign would put its {} there; move it out of the campaign directory",
        path.display(),
        if *round { "next round" } else { "copy of the release" }
    )]
    Occupied {
        /// What is there.
        path: PathBuf,
        /// Whether the place is a round's (else a release's copy).
        round: bool,
    },
    /// A release the campaign holds already.
    #[error(
        "{name} is already in the campaign as {file} (given as {given}): each release is added once"
    )]
    AlreadyIn {
        /// The release given.
        name: String,
        /// Its copy in the campaign.
        file: String,
        /// How it was given then.
        given: String,
    },
    /// A release given twice in one addition.
    #[error("{name} is the same release as {other}: give each release once")]
    GivenTwice {
        /// The release given again.
        name: String,
        /// The one given before it.
        other: String,
    },
    /// A release that shares half or more of its samples with another.
    #[error(
        "{name} shares {shared} of its {samples} samples (time and value, bit for bit) with {other}, {}: the same flight, wholly or in part, would count twice as evidence; each release is added once",
        if *flown { "flown already" } else { "given beside it" }
    )]
    SameFlight {
        /// The release given.
        name: String,
        /// The other release.
        other: String,
        /// Whether the other is flown already (else given beside it).
        flown: bool,
        /// The samples shared.
        shared: usize,
        /// The release's samples.
        samples: usize,
    },
    /// A release without the metadata lines that state its condition.
    #[error(
        "{name} does not state its condition: no `# {}` line; a campaign release names its Mach, altitude and every axis of the grid in its metadata (e.g. `# mach = 0.8`), so that it is recorded where it was flown, not at the scenario's condition",
        missing.join(" = ...`, `# ")
    )]
    Unstated {
        /// The release.
        name: String,
        /// The metadata keys missing.
        missing: Vec<String>,
    },
    /// A release made with another scenario, without `--other-scenario`.
    #[error(
        "{name} was made with another scenario than the campaign's at its condition (its `# scenario_sha256` {recorded}, the campaign's {ours}): a campaign's releases are of its store and scenario; give --other-scenario if this is another simulation (or a flight) of the same store"
    )]
    OtherScenario {
        /// The release.
        name: String,
        /// Its `scenario_sha256`.
        recorded: String,
        /// The campaign's at its condition.
        ours: String,
    },
    /// A rehearsal's truth that cannot be simulated at a release.
    #[error("the truth at release {number}: {reason}")]
    TruthAtRelease {
        /// The release's number.
        number: usize,
        /// Why.
        reason: SimError,
    },
    /// A rehearsal's truth that cannot be traced against the aircraft at a condition.
    #[error(
        "{at} cannot be traced against the aircraft ({reason}): a rehearsal's truth must be traced at every condition of its grid (check --truth-factors, --truth-effect and the grid)"
    )]
    TruthUntraced {
        /// The condition.
        at: TruthAt,
        /// Why.
        reason: GeometryError,
    },
    /// A rehearsal's truth that cannot be simulated at a condition.
    #[error(
        "{at} cannot be simulated ({reason}): a rehearsal's truth must be traced at every condition of its grid (check --truth-factors, --truth-effect and the grid)"
    )]
    TruthUnsimulated {
        /// The condition.
        at: TruthAt,
        /// Why.
        reason: SimError,
    },
    /// A rehearsal's truth that flies at no condition of its grid.
    #[error(
        "{}, nor at any other of the grid's {conditions} conditions: a rehearsal's truth must fly somewhere in its grid (check --truth-factors, --truth-effect and the grid)",
        first.as_ref().map(|(at, d)| format!("{at} does not fly ({d})")).unwrap_or_default()
    )]
    TruthNeverFlies {
        /// The first condition where it does not fly, and how it diverged there.
        first: Option<(TruthAt, sepval_common::propagator::Diverged)>,
        /// The grid's conditions.
        conditions: usize,
    },
}

/// A condition of a rehearsal's grid, as a refusal names it.
#[derive(Debug, Clone, PartialEq)]
pub struct TruthAt {
    /// Mach.
    pub mach: f64,
    /// Altitude \[m\].
    pub altitude_m: f64,
    /// Angle of attack \[deg\].
    pub alpha_deg: f64,
    /// Its number in the grid (from 1).
    pub condition: usize,
}

impl std::fmt::Display for TruthAt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the truth at Mach {}, altitude {} m, alpha {} deg (condition {} of the grid)",
            number(self.mach),
            number(self.altitude_m),
            number(self.alpha_deg),
            self.condition
        )
    }
}
