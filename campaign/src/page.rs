//! The campaign's derived files, written from its records after every command: CAMP/envelope.csv
//! (the current round's, the columns of `sepval envelope` and `state`), CAMP/status.json,
//! CAMP/figures/state-NN.png (each round's map of states, the releases flown by then marked
//! in the title), CAMP/figures/counts.png (the counts of states against the releases flown)
//! and CAMP/report.html (the answer first, then the map, the history of the counts per round,
//! the releases and what is left undecided).

use std::path::Path;

use sepval_core::atomic_file::write_atomically;
use sepval_envelope::row::CSV_HEADER;
use sepval_report::figures::{MapAxis, RoundCounts, state_counts_figure};
use sepval_report::html::escape_html;
use sepval_report::words::significant;

use sepval_envelope::Grid;

use crate::CampaignError;
use crate::record::{CampaignFile, STATUS_FORMAT, StatusFile, record_error, write_json};
use crate::state::{Assessed, Counts, State};

/// What the derived files are made of: the campaign's directory, its record and its grid.
pub struct View<'a> {
    /// The directory.
    pub dir: &'a Path,
    /// campaign.json.
    pub file: &'a CampaignFile,
    /// The grid.
    pub grid: &'a Grid,
}

impl View<'_> {
    /// The envelope of round `dir` (`rounds/NN`).
    pub fn round(&self, dir: &str) -> Result<Vec<Assessed>, CampaignError> {
        let path = self.dir.join(dir).join("assessment.json");
        let text = std::fs::read_to_string(&path).map_err(|e| record_error(&path, e))?;
        serde_json::from_str(&text).map_err(|e| record_error(&path, e))
    }

    /// The current round's envelope.
    pub fn current(&self) -> Result<Vec<Assessed>, CampaignError> {
        let last = self.file.rounds.last().ok_or_else(|| {
            record_error(
                self.dir,
                "holds no round: the campaign's init did not finish",
            )
        })?;
        self.round(&last.dir)
    }
}

/// Writes an envelope of the campaign as CSV: `sepval envelope`'s columns and `state`.
pub fn write_envelope_csv(path: &Path, assessed: &[Assessed]) -> Result<(), CampaignError> {
    let mut s = format!("{CSV_HEADER},state\n");
    for a in assessed {
        s.push_str(&a.row.csv_line());
        s.push(',');
        s.push_str(a.state.name());
        s.push('\n');
    }
    write_atomically(path, s.as_bytes()).map_err(|e| record_error(path, e))
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

/// Writes every derived file.
pub fn render(c: &View<'_>) -> Result<(), CampaignError> {
    let current = c.current()?;
    write_envelope_csv(&c.dir.join("envelope.csv"), &current)?;
    write_json(&c.dir.join("status.json"), &status(c.file))?;
    let figures = c.dir.join("figures");
    std::fs::create_dir_all(&figures).map_err(|e| record_error(&figures, e))?;
    for r in &c.file.rounds {
        let path = figures.join(format!("state-{:02}.png", r.round));
        let assessed = c.round(&r.dir)?;
        state_map(c, &assessed, r.round, r.releases_flown, &path)?;
    }
    let path = figures.join("counts.png");
    let rounds: Vec<RoundCounts> = c
        .file
        .rounds
        .iter()
        .map(|r| RoundCounts {
            releases_flown: r.releases_flown,
            counts: MAP_ORDER.map(|s| r.counts.of_state(s)),
        })
        .collect();
    state_counts_figure(&path, &rounds, c.grid.len()).map_err(|e| record_error(&path, e))?;
    let html = page(c, &current);
    let path = c.dir.join("report.html");
    write_atomically(&path, html.as_bytes()).map_err(|e| record_error(&path, e))
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
) -> Result<(), CampaignError> {
    let axes = c.grid.map_axes();
    let one = [c.grid.flight(0).mach];
    let (xq, xv) = axes
        .first()
        .copied()
        .unwrap_or((sepval_fit::conditions::Quantity::Mach, &one));
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
    .map_err(|e| record_error(path, e))
}

/// report.html.
fn page(c: &View<'_>, current: &[Assessed]) -> String {
    let e = escape_html;
    let mut h = String::from(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>sepval campaign</title>\
         <style>body{font-family:sans-serif;max-width:1100px;margin:2em auto}table{border-collapse:collapse}\
         td,th{border:1px solid #bbb;padding:3px 8px;text-align:right}img{max-width:100%}</style></head><body>",
    );
    h.push_str(&format!("<h1>{}</h1>", e(&headline(c.file))));
    h.push_str(&format!("<p>{}</p>", e(&c.file.words)));
    if let Some(r) = c.file.rounds.last() {
        h.push_str(&format!(
            "<img src=\"figures/state-{:02}.png\" alt=\"the map of states\">",
            r.round
        ));
    }
    h.push_str("<h2>Rounds</h2><img src=\"figures/counts.png\" alt=\"the counts of states against the releases flown\"><table><tr><th>round</th><th>releases flown</th><th>cleared</th><th>fails</th><th>undecided</th><th>settled</th></tr>");
    for r in &c.file.rounds {
        let k = &r.counts;
        h.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            r.round, r.releases_flown, k.cleared, k.fails, k.undecided, r.settled
        ));
    }
    h.push_str("</table><h2>Releases flown, in order</h2><table><tr><th>file</th><th>given</th><th>Mach</th><th>altitude [m]</th><th>alpha [deg]</th><th>check</th></tr>");
    for r in &c.file.releases {
        let k = &r.condition;
        h.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td style=\"text-align:left\">{}</td></tr>",
            e(&r.file), e(&r.given), number(k.mach), number(k.altitude_m), number(k.alpha_deg), e(&r.check)
        ));
    }
    h.push_str("</table><h2>Undecided, and why</h2>");
    if c.file.releases.is_empty() {
        h.push_str(
            "<p>No release has checked the model yet: nothing is cleared before the first \
             release, whatever the prior predicts (docs/campaign.md, \"States\").</p>",
        );
    }
    if !current.iter().any(|a| a.state == State::Undecided) {
        h.push_str("<p>None: every condition is cleared or fails.</p>");
    }
    h.push_str("<ul>");
    for a in current.iter().filter(|a| a.state == State::Undecided) {
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
        h.push_str(&format!(
            "<li>Mach {}, altitude {} m, alpha {} deg: P(fail) {:.3}, median clearance {:.1} mm (spread {:.1} mm, {:.0} % of it the factors'{rivals}), {reach}</li>",
            number(k.mach), number(k.altitude_m), number(k.alpha_deg), a.row.p_fail, a.row.clearance_p50_mm, a.spread_mm,
            share(a.factor_spread_mm)
        ));
    }
    h.push_str("</ul></body></html>\n");
    h
}

/// A number for a reader: six significant digits at most ([`significant`]).
pub fn number(v: f64) -> String {
    significant(v, 6)
}
