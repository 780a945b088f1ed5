//! The campaign's commands over its directory (docs/campaign.md): `init` (the envelope under
//! the prior, round 0), `add` (releases flown: each checked against its prediction, the model
//! fitted again to every release, the envelope predicted again), `next` (the plan written to
//! next.json) and `status`.
//!
//! Every change is staged and committed whole: `add` writes the releases' copies and the new
//! round under `CAMP/.staging/`, renames the round into `rounds/NN` and writes campaign.json
//! last (the commit). A command interrupted before that commit leaves campaign.json as it was;
//! whatever it left (a staging directory, a round or a release copy that campaign.json does not
//! name and that it recorded creating, `journal.rs`) is removed by the next command that
//! opens the campaign, and nothing else is. The derived files
//! (envelope.csv, status.json, report.html, figures/) are written after the commit from the
//! records, and again by every command, so that they always follow campaign.json.

use std::path::{Path, PathBuf};
use std::time::Instant;

use sepval_common::evaluation::{Event, Job};
use sepval_common::scenario::{Scenario, hex_sha256};
use sepval_common::simulation::Simulator;
use sepval_common::telemetry::Trajectory;
use sepval_envelope::grid::{Axis, Grid};
use sepval_predict::ClearanceSettings;
use sepval_predict::ensemble::Ensemble;
use sepval_predict::record::ConditionRecord;
use sepval_run::conditions::Quantity;
use sepval_run::inputs;
use sepval_run::out_dir::DirLock;
use sepval_solve::run::ProgressObserver;

use crate::assess::{AssessSettings, Fitted, Model, StartEvaluator, assess};
use crate::begin::Narrowing;
use crate::next::{Criteria, Plan, plan};
use crate::record::record_error;
use crate::record::{
    ASSESSMENT_FORMAT, AssessmentFile, CAMPAIGN_FORMAT, CampaignFile, InputRecord, NEXT_FORMAT,
    NextFile, RoundRecord, SettingsRecord, check_recorded,
};
use crate::seal::{read_sealed, write_sealed};
use crate::state::{Assessed, Counts};
use crate::{CampaignError, journal, page};

pub(crate) use crate::journal::STAGING;

/// What every command of a campaign works with: its record read and its inputs loaded.
pub struct Campaign {
    /// The directory.
    pub dir: PathBuf,
    /// campaign.json.
    pub file: CampaignFile,
    /// The scenario.
    pub scenario: Scenario,
    /// The grid.
    pub grid: Grid,
    /// The clearance.
    pub clearance: ClearanceSettings,
    /// How the commands run: threads of this process.
    pub threads: usize,
    _lock: DirLock,
}

/// The scenario and the clearance a campaign's settings name, read as `init` read them (the
/// embedded default scenario when the settings name none).
fn load(s: &SettingsRecord) -> Result<(Scenario, ClearanceSettings), CampaignError> {
    let scenario = inputs::scenario(s.scenario.as_ref().map(|r| Path::new(&r.path)), None)
        .map_err(|e| CampaignError::Inputs(Box::new(e)))?;
    let aircraft = Path::new(&s.aircraft.path);
    let store_shape = s.store_shape.as_ref().map(|r| Path::new(&r.path));
    let clearance = ClearanceSettings::read(aircraft, store_shape, s.clearance_mm, &scenario)
        .map_err(|e| CampaignError::Clearance(Box::new(e)))?;
    Ok((scenario, clearance))
}

/// The inputs of `init`, loaded and checked by the caller.
pub struct Init {
    /// The settings.
    pub settings: SettingsRecord,
    /// The scenario.
    pub scenario: Scenario,
    /// The grid of the settings' axes.
    pub grid: Grid,
    /// The clearance.
    pub clearance: ClearanceSettings,
    /// Threads of this process.
    pub threads: usize,
    /// Pre-flight trajectories to take into the prior ([`crate::preflight`]).
    pub preflight: Option<crate::preflight::Preflight>,
}

/// The file of `path` as the campaign records it.
pub fn input_record(path: &Path) -> Result<InputRecord, CampaignError> {
    let bytes = std::fs::read(path).map_err(|e| record_error(path, e))?;
    let absolute = std::fs::canonicalize(path).map_err(|e| record_error(path, e))?;
    Ok(InputRecord {
        path: absolute.display().to_string(),
        sha256: hex_sha256(&bytes),
    })
}

/// The grid of the settings' axes about `scenario`.
pub fn grid_of(settings: &SettingsRecord, scenario: &Scenario) -> Result<Grid, CampaignError> {
    let quantities = [
        Quantity::Mach,
        Quantity::AltitudeM,
        Quantity::AlphaDeg,
        Quantity::BetaDeg,
        Quantity::GammaDeg,
    ];
    let axes: Vec<Axis> = settings
        .axes
        .iter()
        .map(|(flag, text)| {
            let q = quantities
                .iter()
                .find(|q| q.flag() == flag)
                .ok_or_else(|| crate::Refusal::NotAnAxis {
                    flag: flag.to_string(),
                })?;
            Ok::<_, CampaignError>(Axis::parse(*q, text)?)
        })
        .collect::<Result<_, _>>()?;
    Ok(Grid::of(scenario, &axes)?)
}

/// What `init` makes in the campaign's directory besides its lock: all that a failed `init`
/// removes ([`Unmade`]).
const INIT_MAKES: [&str; 9] = [
    "campaign.json",
    crate::preflight::FIT_DIR,
    "status.json",
    "envelope.csv",
    "report.html",
    "next.json",
    "figures",
    "rounds",
    STAGING,
];

/// Removes what a failed (or interrupted, or panicking) `init` made, when dropped armed: the
/// directory when `init` created it, else the entries of [`INIT_MAKES`] in it (it was empty).
/// Before 2026-12-01 a disk filling during `init` left campaign.json, status.json, envelope.csv
/// and rounds/ without the report, which `status` took for a campaign.
struct Unmade {
    dir: PathBuf,
    created: bool,
    armed: bool,
}

impl Drop for Unmade {
    fn drop(&mut self) {
        if !self.armed {
            return;
        }
        if self.created {
            let _ = std::fs::remove_dir_all(&self.dir);
            return;
        }
        for name in INIT_MAKES {
            let p = self.dir.join(name);
            let _ = match std::fs::symlink_metadata(&p) {
                Ok(m) if m.is_dir() => std::fs::remove_dir_all(&p),
                Ok(_) => std::fs::remove_file(&p),
                Err(_) => Ok(()),
            };
        }
    }
}

/// Refuses `dir` unless it is absent or empty; says so when it holds what an interrupted
/// `init` left (no campaign.json).
fn refuse_taken(dir: &Path) -> Result<(), CampaignError> {
    if !dir.exists() {
        return Ok(());
    }
    let names: Vec<String> = std::fs::read_dir(dir)
        .map_err(|e| record_error(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect();
    if names.is_empty() {
        return Ok(());
    }
    let left = !names.iter().any(|n| n == "campaign.json")
        && names
            .iter()
            .all(|n| INIT_MAKES.contains(&n.as_str()) || n == ".sepval-lock");
    Err(record_error(
        dir,
        if left {
            "holds what an interrupted `campaign init` left (no campaign.json): no campaign began there; remove the directory and begin again"
        } else {
            "not empty: a campaign begins in a new or empty directory (give another --out)"
        },
    ))
}

/// Starts a campaign in `dir` (absent or empty): round 0, the envelope under the prior. On an
/// error, a signal or a panic, what it made is removed (`Unmade`).
pub fn init(
    dir: &Path,
    init: Init,
    start: &mut StartEvaluator<'_>,
    observer: &mut dyn ProgressObserver,
) -> Result<Campaign, CampaignError> {
    refuse_taken(dir)?;
    let created = !dir.exists();
    std::fs::create_dir_all(dir).map_err(|e| record_error(dir, e))?;
    let mut unmade = Unmade {
        dir: dir.to_path_buf(),
        created,
        armed: true,
    };
    let (lock, _) = DirLock::take(dir)?;
    let mut init = init;
    if let Some(p) = init.preflight.take() {
        let s = &init.settings;
        let ga = sepval_solve::ga::GaSettings {
            generations: s.generations,
            seed: s.seed,
            ..Default::default()
        };
        let scenario = s.scenario.as_ref().map(|r| Path::new(&r.path));
        let fit = dir.join(crate::preflight::FIT_DIR);
        let at = (&init.scenario.factors, scenario, ga);
        let prior = crate::preflight::posterior(&s.prior, &p, at, &fit, start, observer)?;
        init.settings.prior = prior;
    }
    let file = CampaignFile {
        format: CAMPAIGN_FORMAT.into(),
        grid: init
            .grid
            .conditions
            .list
            .iter()
            .map(|c| ConditionRecord::of(&c.flight))
            .collect(),
        settings: init.settings,
        releases: Vec::new(),
        rounds: Vec::new(),
        settled: false,
        words: String::new(),
        version: env!("CARGO_PKG_VERSION").into(),
    };
    let mut c = Campaign {
        dir: dir.to_path_buf(),
        file,
        scenario: init.scenario,
        grid: init.grid,
        clearance: init.clearance,
        threads: init.threads,
        _lock: lock,
    };
    let model = c.model()?;
    c.round(&model, start, observer)?;
    unmade.armed = false;
    Ok(c)
}

impl Campaign {
    /// Opens the campaign in `dir`: its record read, its inputs (the scenario and the geometry
    /// of its settings) read and checked unchanged, what an interrupted command left removed,
    /// the directory locked.
    pub fn open(dir: &Path, threads: usize) -> Result<Campaign, CampaignError> {
        let path = dir.join("campaign.json");
        if !path.is_file() {
            return Err(record_error(
                dir,
                "holds no campaign (no campaign.json): begin one with `sepval campaign init`",
            ));
        }
        let (lock, _) = DirLock::take(dir)?;
        let file: CampaignFile = read_sealed(&path, CAMPAIGN_FORMAT)?;
        let inputs = [
            Some(&file.settings.aircraft),
            file.settings.scenario.as_ref(),
            file.settings.store_shape.as_ref(),
        ];
        for r in inputs.into_iter().flatten() {
            let now = input_record(Path::new(&r.path))?;
            if now.sha256 != r.sha256 {
                return Err(record_error(
                    Path::new(&r.path),
                    "changed since the campaign began (its SHA-256 differs): a campaign's scenario and geometry stay as they were; begin a new campaign for new ones",
                ));
            }
        }
        let (scenario, clearance) = load(&file.settings)?;
        let grid = grid_of(&file.settings, &scenario)?;
        let c = Campaign {
            dir: dir.to_path_buf(),
            file,
            scenario,
            grid,
            clearance,
            threads,
            _lock: lock,
        };
        c.tidy()?;
        Ok(c)
    }

    /// What releases added to the campaign are read against.
    pub fn against(&self) -> crate::release::Against<'_> {
        crate::release::Against {
            scenario: &self.scenario,
            axes: &self.file.settings.axes,
            grid: &self.grid,
        }
    }

    /// Removes what an interrupted command left: the staging directory, and the rounds and
    /// release copies it recorded creating that campaign.json does not name ([`journal`]);
    /// nothing else in the directory.
    pub(crate) fn tidy(&self) -> Result<(), CampaignError> {
        let named = |rel: &str| {
            self.file.rounds.iter().any(|r| r.dir == rel)
                || self.file.releases.iter().any(|r| r.file == rel)
        };
        journal::undo(&self.dir, &named)
    }

    /// What the derived files are made of.
    pub fn view(&self) -> page::View<'_> {
        page::View {
            dir: &self.dir,
            file: &self.file,
            grid: &self.grid,
            rehearsal: None,
        }
    }

    /// The assessment settings.
    pub(crate) fn assess_settings(&self) -> AssessSettings {
        let s = &self.file.settings;
        AssessSettings {
            samples: s.samples,
            seed: s.seed,
            threads: self.threads,
            allowed: s.allowed,
            clearance: self.clearance.clone(),
        }
    }

    /// The planning's criteria.
    pub fn criteria(&self) -> Criteria {
        let s = &self.file.settings;
        Criteria {
            criterion_mm: s.clearance_mm,
            allowed: s.allowed,
            fly_risk: s.fly_risk,
        }
    }

    /// The releases flown as a job (their copies in the campaign).
    pub(crate) fn job(&self) -> Result<Option<Job>, CampaignError> {
        if self.file.releases.is_empty() {
            return Ok(None);
        }
        let mut events = Vec::new();
        for r in &self.file.releases {
            let path = self.dir.join(&r.file);
            let bytes = check_recorded(&path, &r.copy_sha256)?;
            let text = String::from_utf8(bytes).map_err(|e| record_error(&path, e))?;
            let data = Trajectory::parse(&text, &path.display().to_string())
                .map_err(|e| record_error(&path, e))?;
            let mut s = self.scenario.clone();
            s.flight = r.condition.flight();
            events.push(Event {
                name: r.file.clone(),
                simulator: Simulator::new(&s),
                data,
            });
        }
        Ok(Some(Job::new(events)?))
    }

    /// What the current round believes: the prior, or the diagnosis in the last round's
    /// directory.
    pub fn model(&self) -> Result<Model, CampaignError> {
        self.model_of(self.job()?)
    }

    /// [`Campaign::model`] of `flown`, the releases flown as [`Campaign::job`] reads them.
    pub(crate) fn model_of(&self, flown: Option<Job>) -> Result<Model, CampaignError> {
        let table = &self.scenario.factors;
        match (flown, self.file.rounds.last()) {
            (Some(job), Some(last)) if last.releases_flown > 0 => {
                fitted_model(&self.dir.join(&last.dir).join("diagnosis"), job)
            }
            _ => {
                let (space, distribution) = self.file.settings.prior.distribution(table);
                Ok(Model {
                    space,
                    distribution,
                    fitted: None,
                })
            }
        }
    }

    /// The current round's envelope.
    pub fn current(&self) -> Result<Vec<Assessed>, CampaignError> {
        let last = self.file.rounds.last().ok_or_else(|| {
            record_error(
                &self.dir,
                "holds no round: the campaign's init did not finish",
            )
        })?;
        crate::seal::read_round(&self.dir, last)
    }

    /// The plan of `count` releases from the current round, and the round's narrowing when
    /// nothing is safe to fly under the prior (its words in the plan's).
    pub fn plan(&self, count: usize) -> Result<(Plan, Option<Narrowing>), CampaignError> {
        let flown: Vec<_> = self
            .file
            .releases
            .iter()
            .map(|r| r.condition.flight())
            .collect();
        let last = self.file.rounds.last().ok_or_else(|| {
            record_error(
                &self.dir,
                "holds no round: the campaign's init did not finish",
            )
        })?;
        let file = crate::seal::read_round_file(&self.dir, last)?;
        let mut p = plan(&self.grid, &file.conditions, &flown, self.criteria(), count);
        let narrowing = file
            .narrowing
            .filter(|n| p.least_risky.as_ref().is_some_and(|l| l.index == n.index));
        if let (Some(n), Some(l)) = (&narrowing, p.least_risky.as_mut()) {
            let words = n.words();
            l.why = format!("{}; {words}", l.why);
            let f = self.grid.flight(l.index);
            p.words = format!(
                "{}; at the least risky (Mach {}, altitude {} m, alpha {} deg, P(fail) {:.3}) {words}",
                p.words,
                page::number(f.mach),
                page::number(f.altitude_m),
                page::number(f.alpha_deg),
                l.p_fail
            );
        }
        Ok((p, narrowing))
    }

    /// What `sepval campaign status` says: the answer, in words, and the releases next.json
    /// plans, if any.
    pub fn status_lines(&self) -> Result<String, CampaignError> {
        let mut s = format!("{}\n{}\n", page::headline(&self.file), self.file.words);
        let next = self.dir.join("next.json");
        if next.is_file() {
            let n: NextFile = read_sealed(&next, NEXT_FORMAT)?;
            for r in &n.releases {
                s.push_str(&format!(
                    "next:      Mach {}, altitude {} m, alpha {} deg: {}\n",
                    page::number(r.mach),
                    page::number(r.altitude_m),
                    page::number(r.alpha_deg),
                    r.why
                ));
            }
        }
        Ok(s)
    }

    /// Plans `count` releases and writes next.json.
    pub fn next(&self, count: usize) -> Result<NextFile, CampaignError> {
        let (p, narrowing) = self.plan(count)?;
        let next = NextFile {
            format: NEXT_FORMAT.into(),
            round: self.file.rounds.len() - 1,
            releases: p.releases,
            least_risky: p.least_risky,
            settled: p.settled,
            words: p.words,
            narrowing,
        };
        write_sealed(&self.dir.join("next.json"), &next)?;
        page::render(&self.view())?;
        Ok(next)
    }

    /// Under the prior (`model` unfitted) with no condition of `assessed` safe to fly: what
    /// would make the least risky safe to fly ([`crate::begin`]).
    fn narrowing(
        &self,
        model: &Model,
        assessed: &[Assessed],
        start: &mut StartEvaluator<'_>,
    ) -> Result<Option<Narrowing>, CampaignError> {
        let fly_risk = self.file.settings.fly_risk;
        let least = (0..assessed.len())
            .min_by(|&a, &b| assessed[a].row.p_fail.total_cmp(&assessed[b].row.p_fail));
        let Some(k) =
            least.filter(|&k| model.fitted.is_none() && assessed[k].row.p_fail > fly_risk)
        else {
            return Ok(None);
        };
        let p_fail = assessed[k].row.p_fail;
        let at = (&self.grid, &self.scenario);
        let settings = self.assess_settings();
        crate::begin::narrowing(model, at, k, &settings, (p_fail, fly_risk), start).map(Some)
    }

    /// A new round from `model`: the envelope assessed and staged, then committed.
    pub(crate) fn round(
        &mut self,
        model: &Model,
        start: &mut StartEvaluator<'_>,
        observer: &mut dyn ProgressObserver,
    ) -> Result<(), CampaignError> {
        let t0 = Instant::now();
        let n = self.file.rounds.len();
        let dir = format!("rounds/{n:02}");
        journal::claim(&self.dir, &dir)?;
        let staged = self.dir.join(STAGING).join("round");
        std::fs::create_dir_all(&staged).map_err(|e| record_error(&staged, e))?;
        let assessed = assess(
            model,
            &self.grid,
            &self.scenario,
            &self.assess_settings(),
            start,
            observer,
        )?;
        let narrowing = self.narrowing(model, &assessed, start)?;
        let file = AssessmentFile {
            format: ASSESSMENT_FORMAT.into(),
            conditions: assessed,
            narrowing,
        };
        let assessment = staged.join("assessment.json");
        let assessment_sha256 = write_sealed(&assessment, &file)?;
        let assessed = file.conditions;
        page::write_envelope_csv(&staged.join("envelope.csv"), &assessed)?;
        // The diagnosis of an add's model was staged beside the round.
        let diagnosis = self.dir.join(STAGING).join("diagnosis");
        if diagnosis.is_dir() {
            std::fs::rename(&diagnosis, staged.join("diagnosis"))
                .map_err(|e| record_error(&diagnosis, e))?;
        }
        sepval_core::cancel::check()?;
        let target = self.dir.join(&dir);
        std::fs::create_dir_all(self.dir.join("rounds")).map_err(|e| record_error(&target, e))?;
        journal::record(&self.dir, &dir)?;
        std::fs::rename(&staged, &target).map_err(|e| record_error(&target, e))?;
        let counts = Counts::of(&assessed);
        self.file.rounds.push(RoundRecord {
            round: n,
            releases_flown: self.file.releases.len(),
            counts,
            settled: false,
            dir,
            assessment_sha256,
            evaluations: (self.grid.len() * self.file.settings.samples) as u64,
            wall_s: t0.elapsed().as_secs_f64(),
        });
        let (p, _) = self.plan(1)?;
        let last = self.file.rounds.last_mut().expect("pushed above");
        last.settled = p.settled;
        self.file.settled = p.settled;
        self.file.words = p.words;
        write_sealed(&self.dir.join("campaign.json"), &self.file)?;
        // A test's stand-in for a disk that fills after the commit.
        sepval_core::defect::inject("campaign-committed");
        let _ = std::fs::remove_dir_all(self.dir.join(STAGING));
        let _ = std::fs::remove_file(self.dir.join("next.json"));
        page::render(&self.view())
    }
}

/// The model of the diagnosis (or fit) written in `dir` of the releases of `job`: its answer's
/// distribution and its rivals with their weights.
pub(crate) fn fitted_model(dir: &Path, job: Job) -> Result<Model, CampaignError> {
    let source =
        sepval_predict::read_source(dir).map_err(|e| CampaignError::Source(Box::new(e.into())))?;
    let ensemble = Ensemble::of(&source, job.factor_table())
        .map_err(|e| CampaignError::Source(Box::new(e.into())))?;
    let answer = ensemble.answer();
    let distribution = sepval_predict::sampling::ParameterDistribution::of(
        &answer.space,
        &answer.x,
        &source.identifiability,
    );
    Ok(Model {
        space: answer.space.clone(),
        distribution,
        fitted: Some(Fitted {
            source,
            ensemble,
            job,
        }),
    })
}
