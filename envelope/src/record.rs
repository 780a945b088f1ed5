//! DIR/envelope.json: the envelope's record (format [`ENVELOPE_FORMAT`]).

use serde::{Deserialize, Serialize};

use sepval_predict::clearance::ALLOWED_PROBABILITY;
use sepval_run::conditions::Quantity;

use crate::row::Row;
use crate::summary::{Summary, summarise};
use crate::sweep::{Sweep, Swept};

/// The format of DIR/envelope.json.
pub const ENVELOPE_FORMAT: &str = "sepval-envelope/1";

/// One axis of the grid as recorded.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AxisRecord {
    /// The quantity.
    pub quantity: Quantity,
    /// Its values.
    pub values: Vec<f64>,
}

/// DIR/envelope.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnvelopeFile {
    /// [`ENVELOPE_FORMAT`].
    pub format: String,
    /// The answer in words.
    pub headline: String,
    /// Per value of the map's second axis, the runs cleared and not.
    pub summary: Vec<String>,
    /// Conditions cleared.
    pub cleared: usize,
    /// Conditions.
    pub conditions: usize,
    /// The criterion \[mm\].
    pub criterion_mm: f64,
    /// The largest share of samples failing to clear at a cleared condition.
    pub allowed_probability: f64,
    /// The axes varied.
    pub axes: Vec<AxisRecord>,
    /// One row per condition, in grid order.
    pub rows: Vec<Row>,
    /// Where it came from (recorded as its fields: `samples`, `seed`, `inputs_sha256`, `from`,
    /// `aircraft`, `store_shape`).
    #[serde(flatten)]
    pub provenance: Provenance,
    /// The releases flown (their conditions), marked on the map.
    pub flown: Vec<(f64, f64)>,
    /// Simulations run by this process (conditions resumed from not counted).
    pub evaluations: u64,
    /// Conditions taken from an interrupted sweep.
    pub resumed: usize,
    /// Wall time of this process \[s\].
    pub wall_s: f64,
}

/// Where an envelope came from, as its record says: the files and settings the caller read
/// (the binary's flags, or a campaign's record).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// Samples per condition.
    pub samples: usize,
    /// The seed.
    pub seed: u64,
    /// The SHA-256 of the sweep's inputs ([`crate::progress::inputs_digest`]).
    pub inputs_sha256: String,
    /// The fit or diagnosis predicted from.
    pub from: String,
    /// The aircraft's geometry.
    pub aircraft: String,
    /// The store's shape (`default` for the scenario's store of revolution).
    pub store_shape: String,
}

impl EnvelopeFile {
    /// The record of a finished sweep (`sweep`, its result `swept`) with the criterion
    /// `criterion_mm`, from `provenance`, in `wall_s` seconds: its summary in words, its axes,
    /// rows and the releases flown on the map's axes.
    pub fn of(
        sweep: &Sweep,
        swept: Swept,
        criterion_mm: f64,
        provenance: Provenance,
        wall_s: f64,
    ) -> (Self, Summary) {
        let summary = summarise(&sweep.grid, &swept.rows, criterion_mm);
        let file = EnvelopeFile {
            format: ENVELOPE_FORMAT.into(),
            headline: summary.headline.clone(),
            summary: summary.lines.clone(),
            cleared: summary.cleared,
            conditions: summary.total,
            criterion_mm,
            allowed_probability: ALLOWED_PROBABILITY,
            axes: sweep
                .grid
                .conditions
                .axes
                .iter()
                .map(|(q, v)| AxisRecord {
                    quantity: *q,
                    values: v.clone(),
                })
                .collect(),
            rows: swept.rows,
            provenance,
            flown: flown(sweep),
            evaluations: swept.evaluations,
            resumed: swept.resumed,
            wall_s,
        };
        (file, summary)
    }
}

/// The releases flown, on the map's axes.
fn flown(s: &Sweep) -> Vec<(f64, f64)> {
    let axes = s.grid.map_axes();
    s.fitted
        .events()
        .iter()
        .map(|e| {
            let f = &e.simulator.scenario().flight;
            (
                axes.first().map_or(f.mach, |(q, _)| q.get(f)),
                axes.get(1).map_or(0.0, |(q, _)| q.get(f)),
            )
        })
        .collect()
}

impl EnvelopeFile {
    /// What `sepval envelope` says on the terminal of the envelope written in `out`, with its
    /// `summary`: the answer, a line per row of the map, the work done, where the report is.
    pub fn terminal(&self, summary: &crate::summary::Summary, out: &std::path::Path) -> String {
        let mut s = format!("envelope:  {}\n", summary.headline);
        for l in &summary.lines {
            s.push_str(&format!("           {l}\n"));
        }
        s.push_str(&format!(
            "conditions: {} ({} resumed), {} samples each, {} simulations, {:.1} s\n",
            self.conditions, self.resumed, self.provenance.samples, self.evaluations, self.wall_s
        ));
        s.push_str(&format!(
            "report:    {}\n",
            out.join("report.html").display()
        ));
        s
    }
}
