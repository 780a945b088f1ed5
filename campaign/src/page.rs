//! The campaign's derived files, written from its records after every command: CAMP/envelope.csv
//! (the current round's, the columns of `sepval envelope` and `state`), CAMP/status.json,
//! CAMP/figures/state-NN.png (each round's map of states, the releases flown by then marked
//! in the title), CAMP/figures/counts.png (the counts of states against the releases flown)
//! and CAMP/report.html (the answer first, a rehearsal's comparison with its truth, then the map, the history of the counts per round,
//! the releases and what is left undecided; the template `templates/campaign.html` in
//! sepval-report's layout). They are written through [`Written::after_commit`]: each file
//! atomically, and all of them whatever a signal asks, since they derive from campaign.json,
//! already committed when they are written.

use std::path::Path;

use serde::Serialize;

use sepval_core::atomic_file::write_atomically;
use sepval_envelope::row::CSV_HEADER;
use sepval_report::figures::{FigureError, MapAxis, RoundCounts, state_counts_figure};
use sepval_report::html::{PageTemplate, render_page};
use sepval_report::words::significant;
use sepval_report::{OutputError, Written};

use sepval_envelope::Grid;

use crate::CampaignError;
use crate::record::{CampaignFile, RoundRecord, STATUS_FORMAT, StatusFile, record_error};
use crate::state::{Assessed, Counts, State};

/// What the derived files are made of: the campaign's directory, its record and its grid.
pub struct View<'a> {
    /// The directory.
    pub dir: &'a Path,
    /// campaign.json.
    pub file: &'a CampaignFile,
    /// The grid.
    pub grid: &'a Grid,
    /// A rehearsal's comparison with its truth, shown first when the page is a rehearsal's.
    pub rehearsal: Option<&'a RehearsalSection>,
}

/// A rehearsal against its truth as the page shows it (made by `Rehearsal::section`).
#[derive(Debug, Clone, Serialize)]
pub struct RehearsalSection {
    /// The verdict against the truth, in words.
    pub words: String,
    /// Each round: its counts and its false clears and false fails.
    pub rounds: Vec<RehearsalRound>,
    /// Each release flown: where, the failure probability planned, and what the truth says.
    pub flown: Vec<RehearsalRelease>,
}

/// One round of a rehearsal against its truth.
#[derive(Debug, Clone, Serialize)]
pub struct RehearsalRound {
    /// The round.
    pub round: usize,
    /// Releases flown by then.
    pub releases_flown: usize,
    /// Conditions cleared, failed and undecided.
    pub cleared: usize,
    /// Conditions that fail.
    pub fails: usize,
    /// Conditions undecided.
    pub undecided: usize,
    /// Conditions cleared that the truth fails.
    pub false_clears: usize,
    /// Conditions failed that the truth clears.
    pub false_fails: usize,
}

/// One release of a rehearsal.
#[derive(Debug, Clone, Serialize)]
pub struct RehearsalRelease {
    /// Its place in the order flown, from 1.
    pub release: usize,
    /// Its condition, in words.
    pub mach: String,
    /// Altitude \[m\].
    pub altitude_m: String,
    /// Aircraft angle of attack \[deg\].
    pub alpha_deg: String,
    /// The probability of failing there that the plan gave.
    pub p_fail_planned: String,
    /// `safe` or `UNSAFE`: what the truth does there.
    pub truth: &'static str,
    /// The plan's forecast of the conditions it settles.
    pub expected_settled: String,
    /// The conditions it settled.
    pub settled: usize,
}

impl View<'_> {
    /// The envelope of round `r`.
    pub fn round(&self, r: &RoundRecord) -> Result<Vec<Assessed>, CampaignError> {
        crate::seal::read_round(self.dir, r)
    }

    /// The current round's envelope.
    pub fn current(&self) -> Result<Vec<Assessed>, CampaignError> {
        let last = self.file.rounds.last().ok_or_else(|| {
            record_error(
                self.dir,
                "holds no round: the campaign's init did not finish",
            )
        })?;
        self.round(last)
    }
}

/// An envelope of the campaign as CSV: `sepval envelope`'s columns and `state`.
pub fn envelope_csv(assessed: &[Assessed]) -> String {
    let mut s = format!("{CSV_HEADER},state\n");
    for a in assessed {
        s.push_str(&a.row.csv_line());
        s.push(',');
        s.push_str(a.state.name());
        s.push('\n');
    }
    s
}

/// Writes an envelope of the campaign as CSV ([`envelope_csv`]) at `path`, atomically (a
/// round's, staged before it is committed).
pub fn write_envelope_csv(path: &Path, assessed: &[Assessed]) -> Result<(), CampaignError> {
    write_atomically(path, envelope_csv(assessed).as_bytes()).map_err(|e| record_error(path, e))
}

/// The status of the campaign.
pub fn status(c: &CampaignFile) -> StatusFile {
    let counts = c.rounds.last().map_or(Counts::default(), |r| r.counts);
    StatusFile {
        format: STATUS_FORMAT.into(),
        releases_flown: c.releases.len(),
        conditions: counts.conditions,
        cleared: counts.cleared,
        fails: counts.fails,
        undecided: counts.undecided,
        settled: c.settled,
    }
}

/// The answer in one sentence.
pub fn headline(c: &CampaignFile) -> String {
    let s = status(c);
    let n = s.releases_flown;
    let after = match n {
        0 => "before any release".to_string(),
        1 => "after 1 release".to_string(),
        n => format!("after {n} releases"),
    };
    format!(
        "{} {after}: cleared {} of {} conditions, {} fail, {} undecided",
        if s.settled { "settled" } else { "not settled" },
        s.cleared,
        s.conditions,
        s.fails,
        s.undecided
    )
}

/// Writes every derived file, in the order of the module documentation.
pub fn render(c: &View<'_>) -> Result<(), CampaignError> {
    let current = c.current()?;
    let mut w = Written::after_commit(c.dir);
    w.file("envelope.csv", envelope_csv(&current).as_bytes())?;
    w.json("status.json", &status(c.file))?;
    let figures = w.figures()?;
    for r in &c.file.rounds {
        let assessed = c.round(r)?;
        let path = figures.join(format!("state-{:02}.png", r.round));
        w.figure(path, |path| {
            state_map(c, &assessed, r.round, r.releases_flown, path)
        })?;
    }
    let rounds: Vec<RoundCounts> = c
        .file
        .rounds
        .iter()
        .map(|r| RoundCounts {
            releases_flown: r.releases_flown,
            counts: MAP_ORDER.map(|s| r.counts.of_state(s)),
        })
        .collect();
    w.figure(figures.join("counts.png"), |path| {
        state_counts_figure(path, &rounds, c.grid.len())
    })?;
    let html = render_page(&CAMPAIGN, &page(c, &current)).map_err(OutputError::from)?;
    w.file("report.html", html.as_bytes())?;
    Ok(())
}

/// The states in the order of `sepval_report`'s state map and counts figure, best to worst:
/// the largest index over a cell is its worst state.
const MAP_ORDER: [State; 3] = [State::Cleared, State::Undecided, State::Fails];

/// A state's index in [`MAP_ORDER`].
fn map_index(s: State) -> u8 {
    MAP_ORDER.iter().position(|&m| m == s).unwrap_or(0) as u8
}

/// A round's map of states (the worst over the axes not shown), with the releases flown by
/// then.
fn state_map(
    c: &View<'_>,
    assessed: &[Assessed],
    round: usize,
    flown: usize,
    path: &Path,
) -> Result<(), FigureError> {
    let axes = c.grid.map_axes();
    let one = [c.grid.flight(0).mach];
    let (xq, xv) = axes
        .first()
        .copied()
        .unwrap_or((sepval_run::conditions::Quantity::Mach, &one));
    let ny = axes.get(1).map_or(1, |(_, v)| v.len());
    let mut cells = vec![vec![0u8; xv.len()]; ny];
    for a in assessed {
        let (ix, iy) = c.grid.cell(a.row.index);
        cells[iy][ix] = cells[iy][ix].max(map_index(a.state));
    }
    let yq = axes.get(1).map(|(q, _)| *q);
    let releases: Vec<(f64, f64)> = c.file.releases[..flown.min(c.file.releases.len())]
        .iter()
        .map(|r| {
            let f = r.condition.flight();
            (xq.get(&f), yq.map_or(0.0, |q| q.get(&f)))
        })
        .collect();
    let y = axes.get(1).map(|(q, v)| MapAxis {
        label: q.label(),
        values: v,
    });
    sepval_report::figures::state_map(
        path,
        &format!("Round {round}: the envelope's states after {flown} release(s)"),
        MapAxis {
            label: xq.label(),
            values: xv,
        },
        y,
        &cells,
        &releases,
    )
}

/// The page's template.
const CAMPAIGN: PageTemplate = PageTemplate {
    name: "campaign.html",
    source: include_str!("../templates/campaign.html"),
};

/// What report.html shows, as the template reads it.
#[derive(Serialize)]
struct Page<'a> {
    headline: String,
    words: String,
    rehearsal: Option<&'a RehearsalSection>,
    /// The current round's map of states, relative to the page.
    map: Option<String>,
    rounds: Vec<RoundView>,
    releases: Vec<ReleaseView>,
    /// Each undecided condition and why, in words.
    undecided: Vec<String>,
}

#[derive(Serialize)]
struct RoundView {
    round: usize,
    releases_flown: usize,
    cleared: usize,
    fails: usize,
    undecided: usize,
    /// `yes` or `no`.
    settled: &'static str,
}

#[derive(Serialize)]
struct ReleaseView {
    file: String,
    given: String,
    mach: String,
    altitude_m: String,
    alpha_deg: String,
    check: String,
}

/// report.html's content.
fn page<'a>(c: &View<'a>, current: &[Assessed]) -> Page<'a> {
    Page {
        headline: headline(c.file),
        words: c.file.words.clone(),
        rehearsal: c.rehearsal,
        map: c
            .file
            .rounds
            .last()
            .map(|r| format!("figures/state-{:02}.png", r.round)),
        rounds: c
            .file
            .rounds
            .iter()
            .map(|r| RoundView {
                round: r.round,
                releases_flown: r.releases_flown,
                cleared: r.counts.cleared,
                fails: r.counts.fails,
                undecided: r.counts.undecided,
                settled: if r.settled { "yes" } else { "no" },
            })
            .collect(),
        releases: c
            .file
            .releases
            .iter()
            .map(|r| ReleaseView {
                file: r.file.clone(),
                given: r.given.clone(),
                mach: number(r.condition.mach),
                altitude_m: number(r.condition.altitude_m),
                alpha_deg: number(r.condition.alpha_deg),
                check: r.check.clone(),
            })
            .collect(),
        undecided: current
            .iter()
            .filter(|a| a.state == State::Undecided)
            .map(undecided_words)
            .collect(),
    }
}

/// Why a condition is undecided, in words: its probability of failing, its clearance and
/// spread (and the factors' and rivals' shares of it), how far it lies beyond the releases.
fn undecided_words(a: &Assessed) -> String {
    let k = &a.row.condition;
    let reach = if a.reach.is_finite() {
        format!("reach {:.2} beyond what the releases showed", a.reach)
    } else {
        "no release flown".to_string()
    };
    let share = |part: f64| 100.0 * (part / a.spread_mm).min(1.0);
    let rivals = if a.rival_spread_mm > 0.0 {
        format!(
            " (within which {:.0} % the rivals' disagreement)",
            share(a.rival_spread_mm)
        )
    } else {
        String::new()
    };
    format!(
        "Mach {}, altitude {} m, alpha {} deg: P(fail) {:.3}, median clearance {:.1} mm (spread {:.1} mm, {:.0} % of it the factors'{rivals}), {reach}",
        number(k.mach),
        number(k.altitude_m),
        number(k.alpha_deg),
        a.row.p_fail,
        a.row.clearance_p50_mm,
        a.spread_mm,
        share(a.factor_spread_mm)
    )
}

/// A number for a reader: six significant digits at most ([`significant`]).
pub fn number(v: f64) -> String {
    significant(v, 6)
}
