//! One condition of the envelope: its clearance distribution as DIR/envelope.csv writes it.

use serde::{Deserialize, Serialize};

use sepval_predict::ClearanceStats;

use sepval_predict::record::ConditionRecord;

/// One condition's row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Its index in the grid.
    pub index: usize,
    /// The condition.
    pub condition: ConditionRecord,
    /// The smallest clearance's 5th, 50th and 95th percentiles over the samples that ran \[mm\]
    /// (NaN when none ran).
    #[serde(with = "sepval_core::nonfinite")]
    pub clearance_p5_mm: f64,
    /// The median.
    #[serde(with = "sepval_core::nonfinite")]
    pub clearance_p50_mm: f64,
    /// The 95th percentile.
    #[serde(with = "sepval_core::nonfinite")]
    pub clearance_p95_mm: f64,
    /// The share of the samples that ran below the criterion.
    #[serde(with = "sepval_core::nonfinite")]
    pub p_below: f64,
    /// The share of all samples that fail to clear (below the criterion or diverged).
    pub p_fail: f64,
    /// Whether the condition is cleared.
    pub cleared: bool,
    /// The median time of closest approach \[s\].
    #[serde(with = "sepval_core::nonfinite")]
    pub t_closest_s: f64,
    /// The share of the samples that diverged or failed.
    pub diverged_share: f64,
    /// The store's part that comes closest most often.
    pub closest_store_part: String,
    /// The aircraft's part it comes closest to.
    pub closest_aircraft_part: String,
}

/// The header of DIR/envelope.csv.
pub const CSV_HEADER: &str = "mach,altitude_m,alpha_deg,beta_deg,gamma_deg,clearance_p5_mm,clearance_p50_mm,clearance_p95_mm,p_below,p_fail,cleared,t_closest_s,diverged_share,closest_store_part,closest_aircraft_part";

impl Row {
    /// The row of condition `index` from its prediction's clearance.
    pub fn of(index: usize, condition: ConditionRecord, c: &ClearanceStats) -> Row {
        let parts = c.closest_parts.first();
        let total = (c.samples + c.diverged).max(1) as f64;
        Row {
            index,
            condition,
            clearance_p5_mm: c.min_clearance_mm.p5,
            clearance_p50_mm: c.min_clearance_mm.p50,
            clearance_p95_mm: c.min_clearance_mm.p95,
            p_below: c.p_below,
            p_fail: c.p_fail,
            cleared: c.cleared,
            t_closest_s: c.t_closest_s.p50,
            diverged_share: c.diverged as f64 / total,
            closest_store_part: parts.map_or(String::new(), |p| p.store.clone()),
            closest_aircraft_part: parts.map_or(String::new(), |p| p.aircraft.clone()),
        }
    }

    /// The row of a condition at which every sample diverged: it fails to clear.
    pub fn all_diverged(index: usize, condition: ConditionRecord) -> Row {
        Row {
            index,
            condition,
            clearance_p5_mm: f64::NAN,
            clearance_p50_mm: f64::NAN,
            clearance_p95_mm: f64::NAN,
            p_below: f64::NAN,
            p_fail: 1.0,
            cleared: false,
            t_closest_s: f64::NAN,
            diverged_share: 1.0,
            closest_store_part: String::new(),
            closest_aircraft_part: String::new(),
        }
    }

    /// Its line of DIR/envelope.csv (numbers in the shortest form that reads back exactly;
    /// a missing number is empty).
    pub fn csv_line(&self) -> String {
        let n = |v: f64| {
            if v.is_finite() {
                format!("{v}")
            } else {
                String::new()
            }
        };
        let c = &self.condition;
        let text = sepval_report::words::csv_text;
        [
            n(c.mach),
            n(c.altitude_m),
            n(c.alpha_deg),
            n(c.beta_deg),
            n(c.gamma_deg),
            n(self.clearance_p5_mm),
            n(self.clearance_p50_mm),
            n(self.clearance_p95_mm),
            n(self.p_below),
            n(self.p_fail),
            self.cleared.to_string(),
            n(self.t_closest_s),
            n(self.diverged_share),
            text(&self.closest_store_part),
            text(&self.closest_aircraft_part),
        ]
        .join(",")
    }
}

/// DIR/envelope.csv's text: the header and the rows in grid order.
pub fn csv(rows: &[Row]) -> String {
    let mut s = String::from(CSV_HEADER);
    s.push('\n');
    for r in rows {
        s.push_str(&r.csv_line());
        s.push('\n');
    }
    s
}
