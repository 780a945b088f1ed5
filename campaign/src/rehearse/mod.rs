//! `sepval campaign rehearse`: a virtual test program, for sizing one before it is flown
//! (docs/campaign.md, "Rehearsal"). The campaign begun with `init` is run against a stated
//! truth (a scenario with its factors, effects and extension): `next` plans one release, the
//! truth flies it through sepval's own simulator with the instrument's noise (seed
//! `noise_seed + k` for the k-th release), `add` records it, until the envelope is settled or
//! `max_releases` were flown. Each round's envelope is compared with the truth's, computed at
//! every grid condition from the truth without noise: a condition the campaign clears where the
//! truth fails is a false clear, one it fails where the truth clears a false fail, and every
//! release planned is checked to have been truly safe.

mod check;
mod fly;

use serde::{Deserialize, Serialize};

use sepval_common::effects::EffectSet;
use sepval_common::propagator::Diverged;
use sepval_common::scenario::Scenario;
use sepval_common::simulation::{SimError, Simulator, sample_times};
use sepval_common::synthetic::synthetic_flight_test;
use sepval_core::cancel;
use sepval_core::factors::Factors;

use sepval_envelope::Grid;
use sepval_predict::ClearanceSettings;
use sepval_predict::record::ConditionRecord;
use sepval_predict::releases;
use sepval_solve::run::ProgressObserver;

use crate::CampaignError;
use crate::assess::StartEvaluator;
use crate::page::{self, RehearsalRelease, RehearsalRound, RehearsalSection};
use crate::program::Campaign;
use crate::record::{record_error, write_json};
use crate::refusal::{Refusal, TruthAt};
use crate::state::{Counts, State};
use check::check_settled;
pub use check::{CHECK_DIR, CandidateFlown};
use fly::{Candidate, Flew, Release, fly};

/// The format of CAMP/rehearsal.json.
pub const REHEARSAL_FORMAT: &str = "sepval-campaign-rehearsal/1";

/// The truth a rehearsal flies.
pub struct Truth {
    /// The store and its model (flown at each condition of the grid).
    pub scenario: Scenario,
    /// Its factors.
    pub factors: Factors,
    /// Its effects.
    pub effects: EffectSet,
    /// The noise seed of the first release.
    pub noise_seed: u64,
}

/// Why the truth a rehearsal flies cannot be read, naming its flag.
#[derive(Debug, thiserror::Error)]
pub enum TruthInputError {
    /// `--truth-scenario` (with `--truth-extension`).
    #[error("--truth-scenario")]
    Scenario(#[source] sepval_run::inputs::InputError),
    /// `--truth-factors`.
    #[error("--truth-factors")]
    Factors(#[source] sepval_run::inputs::InputError),
    /// `--truth-effect` (its message names the flag).
    #[error(transparent)]
    Effects(sepval_run::inputs::InputError),
}

impl Truth {
    /// The truth its flags name: the scenario (the embedded default without one) with its
    /// extension, the factors (`truth`, `nominal` or a JSON file), the effects, and the noise
    /// seed of the first release.
    pub fn read(
        scenario: Option<&std::path::Path>,
        extension: Option<&std::path::Path>,
        factors: &str,
        effects: &[String],
        noise_seed: u64,
    ) -> Result<Truth, TruthInputError> {
        use sepval_run::inputs;
        let scenario = inputs::scenario(scenario, extension).map_err(TruthInputError::Scenario)?;
        let factors =
            inputs::factors(factors, &scenario.factors).map_err(TruthInputError::Factors)?;
        let effects =
            inputs::effects_of("--truth-effect", effects).map_err(TruthInputError::Effects)?;
        Ok(Truth {
            scenario,
            factors,
            effects,
            noise_seed,
        })
    }
}

/// The truth at one condition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthCondition {
    /// The condition.
    pub condition: ConditionRecord,
    /// Its smallest clearance without noise \[mm\] (`"nan"`: it diverged, the store tumbles).
    #[serde(with = "sepval_core::nonfinite")]
    pub min_clearance_mm: f64,
    /// Whether it fails to clear (below the criterion, or diverged).
    pub fails: bool,
}

/// One round against the truth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RoundAgainstTruth {
    /// The round.
    pub round: usize,
    /// Releases flown by then.
    pub releases_flown: usize,
    /// Its counts.
    pub counts: Counts,
    /// Conditions cleared that the truth fails.
    pub false_clears: usize,
    /// Conditions failed that the truth clears.
    pub false_fails: usize,
}

/// One release flown in the rehearsal.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FlownRelease {
    /// Its condition.
    pub condition: ConditionRecord,
    /// The planned probability of failing there.
    pub p_fail_planned: f64,
    /// Whether the truth clears there.
    pub truly_safe: bool,
    /// The plan's forecast: how many of the undecided conditions it would settle
    /// (`expected_settled` of next.json).
    pub expected_settled: f64,
    /// How many it settled: undecided in the round before it, cleared or failing after.
    pub settled: usize,
    /// How many conditions decided before it were undecided after.
    pub unsettled: usize,
}

/// CAMP/rehearsal.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Rehearsal {
    /// [`REHEARSAL_FORMAT`].
    pub format: String,
    /// The truth at every grid condition.
    pub truth: Vec<TruthCondition>,
    /// The releases flown, in order.
    pub flown: Vec<FlownRelease>,
    /// Every round against the truth.
    pub rounds: Vec<RoundAgainstTruth>,
    /// Whether the campaign settled within the releases allowed.
    pub settled: bool,
    /// The claim "settled" checked (each a [`CandidateFlown`]): each condition safe to fly when
    /// it was made, flown in turn (empty: not asked for, not settled, or nothing was undecided).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub settled_check: Vec<CandidateFlown>,
    /// In words.
    pub words: String,
}

/// The plan's forecasts held against what the releases then did: the sums over the releases
/// flown of `expected_settled` and of the conditions settled (docs/campaign.md, "Forecasts").
pub fn forecast_totals(flown: &[FlownRelease]) -> (f64, usize) {
    (
        // Summed from +0.0 (an empty f64 sum is -0.0, said "-0.0").
        flown.iter().fold(0.0, |t, f| t + f.expected_settled),
        flown.iter().map(|f| f.settled).sum(),
    )
}

impl Rehearsal {
    /// What `sepval campaign rehearse` says of it on the terminal: each release flown, each
    /// round against the truth, and the verdict.
    pub fn lines(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (k, f) in self.flown.iter().enumerate() {
            out.push(format!(
                "release {}: {} (P(fail) planned {:.3}; truly {}; expected to settle {:.1}, settled {})",
                k + 1,
                at(&f.condition),
                f.p_fail_planned,
                if f.truly_safe { "safe" } else { "UNSAFE" },
                f.expected_settled,
                f.settled
            ));
        }
        for round in &self.rounds {
            out.push(format!(
                "round {}:   cleared {}, fails {}, undecided {}; false clears {}, false fails {}",
                round.round,
                round.counts.cleared,
                round.counts.fails,
                round.counts.undecided,
                round.false_clears,
                round.false_fails
            ));
        }
        for f in &self.settled_check {
            out.push(format!(
                "settled check: {} (P(fail) {:.3}; truly {}) would settle {}, unsettle {}",
                at(&f.condition),
                f.p_fail,
                if f.truly_safe { "safe" } else { "UNSAFE" },
                f.settled,
                f.unsettled
            ));
        }
        out.push(format!("rehearsal: {}", self.words));
        out
    }

    /// What the campaign's page shows of it.
    pub fn section(&self) -> RehearsalSection {
        RehearsalSection {
            words: self.words.clone(),
            rounds: self
                .rounds
                .iter()
                .map(|r| RehearsalRound {
                    round: r.round,
                    releases_flown: r.releases_flown,
                    cleared: r.counts.cleared,
                    fails: r.counts.fails,
                    undecided: r.counts.undecided,
                    false_clears: r.false_clears,
                    false_fails: r.false_fails,
                })
                .collect(),
            flown: self
                .flown
                .iter()
                .enumerate()
                .map(|(k, f)| RehearsalRelease {
                    release: k + 1,
                    mach: crate::page::number(f.condition.mach),
                    altitude_m: crate::page::number(f.condition.altitude_m),
                    alpha_deg: crate::page::number(f.condition.alpha_deg),
                    p_fail_planned: format!("{:.3}", f.p_fail_planned),
                    truth: if f.truly_safe { "safe" } else { "UNSAFE" },
                    expected_settled: format!("{:.1}", f.expected_settled),
                    settled: f.settled,
                })
                .collect(),
        }
    }
}

/// The truth at every condition of `grid` with `clearance`, computed before the campaign
/// begins. Where the truth's simulation diverges the store tumbles: that condition fails
/// (its smallest clearance `"nan"`), as a store that tumbles off its rack fails in flight. A
/// truth that flies none of the grid's conditions, or whose trajectory cannot be traced
/// against the aircraft, is refused before anything is written, naming the condition (before
/// 2026-12-01 it was found after the whole `init` and left a round-0 campaign behind).
pub fn truth_envelope(
    grid: &Grid,
    clearance: &ClearanceSettings,
    truth: &Truth,
) -> Result<Vec<TruthCondition>, CampaignError> {
    let base = &truth.scenario;
    let times = sample_times(base.integrator.t_end_s, base.integrator.rate_hz);
    let criterion_m = clearance.criterion_m;
    let mut first_tumble: Option<(TruthAt, Diverged)> = None;
    let envelope = (0..grid.len())
        .map(|k| {
            cancel::check()?;
            let s = grid.scenario(base, k);
            let f = &s.flight;
            let at = TruthAt {
                mach: f.mach,
                altitude_m: f.altitude_m,
                alpha_deg: f.alpha_deg,
                condition: k + 1,
            };
            let min_m = match synthetic_flight_test(
                &Simulator::new(&s),
                &truth.factors,
                &truth.effects,
                &times,
                None,
            ) {
                Ok(flown) => {
                    releases::trace(clearance, &flown)
                        .map_err(|reason| Refusal::TruthUntraced {
                            at: at.clone(),
                            reason,
                        })?
                        .min
                        .distance_m
                }
                Err(SimError::Diverged(d)) => {
                    first_tumble.get_or_insert((at, d));
                    f64::NAN
                }
                Err(reason) => return Err(Refusal::TruthUnsimulated { at, reason }.into()),
            };
            Ok(TruthCondition {
                condition: ConditionRecord::of(&s.flight),
                min_clearance_mm: 1e3 * min_m,
                fails: min_m.is_nan() || min_m < criterion_m,
            })
        })
        .collect::<Result<Vec<_>, CampaignError>>()?;
    if envelope.iter().all(|t| t.min_clearance_mm.is_nan()) {
        return Err(Refusal::TruthNeverFlies {
            first: first_tumble,
            conditions: envelope.len(),
        }
        .into());
    }
    Ok(envelope)
}

/// The current round against the truth.
fn against(c: &Campaign, truth: &[TruthCondition]) -> Result<RoundAgainstTruth, CampaignError> {
    let current = c.current()?;
    let count = |state: State, truth_fails: bool| {
        current
            .iter()
            .zip(truth)
            .filter(|(a, t)| a.state == state && t.fails == truth_fails)
            .count()
    };
    Ok(RoundAgainstTruth {
        round: c.file.rounds.len() - 1,
        releases_flown: c.file.releases.len(),
        counts: Counts::of(&current),
        false_clears: count(State::Cleared, true),
        false_fails: count(State::Fails, false),
    })
}

/// How long a rehearsal runs and what it checks at the end.
#[derive(Debug, Clone, Copy)]
pub struct Schedule {
    /// The most releases to fly.
    pub max_releases: usize,
    /// Whether a campaign that settles with conditions undecided has the claim checked by
    /// flying each safe candidate in turn (each a [`CandidateFlown`]).
    pub check_settled: bool,
}

/// Runs the rehearsal on the campaign `c` (begun with `init`) against `truth`, whose envelope
/// over the campaign's grid is `truth_at` ([`truth_envelope`]); writes CAMP/rehearsal.json
/// after every round.
pub fn rehearse(
    c: &mut Campaign,
    truth: &Truth,
    truth_at: Vec<TruthCondition>,
    schedule: Schedule,
    start: &mut StartEvaluator<'_>,
    observer: &mut dyn ProgressObserver,
) -> Result<Rehearsal, CampaignError> {
    let mut r = Rehearsal {
        format: REHEARSAL_FORMAT.into(),
        truth: truth_at,
        flown: Vec::new(),
        rounds: Vec::new(),
        settled: c.file.settled,
        settled_check: Vec::new(),
        words: String::new(),
    };
    r.rounds.push(against(c, &r.truth)?);
    let flown_dir = c.dir.join("rehearsal");
    std::fs::create_dir_all(&flown_dir).map_err(|e| record_error(&flown_dir, e))?;
    let mut tumbled: Option<String> = None;
    for k in 0..schedule.max_releases {
        if c.file.settled {
            break;
        }
        let next = c.next(1)?;
        let Some(p) = next.releases.first() else {
            break;
        };
        let release = Release {
            truth,
            at: Candidate {
                index: p.index,
                p_fail: p.p_fail,
                expected_settled: p.expected_settled,
            },
            number: k + 1,
            dir: &flown_dir,
        };
        match fly(c, &release, r.truth[p.index].fails, start, observer)? {
            Flew::Added(f) => r.flown.push(f),
            Flew::Tumbled(f, why) => {
                // The campaign flew where the store tumbles: an unsafe release, and the last.
                r.flown.push(f);
                tumbled = Some(why);
                break;
            }
        }
        r.rounds.push(against(c, &r.truth)?);
        r.settled = c.file.settled;
        write_json(&c.dir.join("rehearsal.json"), &r)?;
    }
    if schedule.check_settled && r.settled && tumbled.is_none() {
        r.settled_check = check_settled(c, truth, &r.truth, r.flown.len() + 1, start, observer)?;
    }
    r.words = verdict(&r, tumbled);
    write_json(&c.dir.join("rehearsal.json"), &r)?;
    // The page again, now with the comparison with the truth first.
    let section = r.section();
    let view = page::View {
        rehearsal: Some(&section),
        ..c.view()
    };
    page::render(&view)?;
    Ok(r)
}

/// The rehearsal's verdict in words.
fn verdict(r: &Rehearsal, tumbled: Option<String>) -> String {
    let last = r.rounds.last().expect("round 0 is there");
    let (expected, settled) = forecast_totals(&r.flown);
    let mut words = format!(
        "{} after {} release(s): cleared {}, fails {}, undecided {}; against the truth {} false clear(s), {} false fail(s); {} of the {} releases flown truly safe; the plan expected them to settle {expected:.1} condition(s), they settled {settled}",
        if r.settled { "settled" } else { "not settled" },
        last.releases_flown,
        last.counts.cleared,
        last.counts.fails,
        last.counts.undecided,
        last.false_clears,
        last.false_fails,
        r.flown.iter().filter(|f| f.truly_safe).count(),
        r.flown.len()
    );
    if let Some(t) = tumbled {
        words = format!("{words}; {t}");
    }
    if !r.settled_check.is_empty() {
        words = format!("{words}; {}", check_words(&r.settled_check));
    }
    let tumbles = r
        .truth
        .iter()
        .filter(|t| t.min_clearance_mm.is_nan())
        .count();
    if tumbles > 0 {
        words = format!(
            "{words}; the truth tumbles (its simulation diverges) at {tumbles} of the grid's {} conditions, counted as failing",
            r.truth.len()
        );
    }
    words
}

/// A condition in words: its Mach, altitude and alpha.
fn at(c: &ConditionRecord) -> String {
    format!(
        "Mach {}, altitude {} m, alpha {} deg",
        page::number(c.mach),
        page::number(c.altitude_m),
        page::number(c.alpha_deg)
    )
}

/// The settled check in words.
fn check_words(check: &[CandidateFlown]) -> String {
    let n = check.len();
    let settling: Vec<&CandidateFlown> = check.iter().filter(|f| f.settled > 0).collect();
    let unsafe_ = check.iter().filter(|f| !f.truly_safe).count();
    let mut words = if settling.is_empty() {
        format!(
            "\"settled\" checked by flying each of the {n} condition(s) then safe to fly in turn: none settles a condition"
        )
    } else {
        let most = settling.iter().map(|f| f.settled).max().unwrap_or(0);
        format!(
            "\"settled\" checked by flying each of the {n} condition(s) then safe to fly in turn: WRONG, {} of them would settle conditions (up to {most})",
            settling.len()
        )
    };
    if unsafe_ > 0 {
        words = format!("{words}; {unsafe_} of those candidates truly fail");
    }
    words
}
