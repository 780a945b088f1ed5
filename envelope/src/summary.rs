//! The envelope in words, answer first: how many conditions are cleared, and per value of the
//! map's second axis the runs of the first that are cleared and not ("at altitude 3000 m:
//! cleared Mach 0.60-0.85; not cleared Mach 0.90-0.95"). With more than two axes varied a
//! cell is cleared only when every condition it covers is.

use sepval_run::conditions::Quantity;

use crate::grid::Grid;
use crate::row::Row;

/// The envelope in words.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// One sentence: the count and the rule.
    pub headline: String,
    /// One line per value of the map's second axis (one line with a single axis or none).
    pub lines: Vec<String>,
    /// Conditions cleared.
    pub cleared: usize,
    /// Conditions.
    pub total: usize,
}

/// How a quantity is written: its word, decimals and unit.
fn words(q: Quantity) -> (&'static str, usize, &'static str) {
    match q {
        Quantity::Mach => ("Mach", 2, ""),
        Quantity::AltitudeM => ("altitude", 0, " m"),
        Quantity::AlphaDeg => ("alpha", 1, " deg"),
        Quantity::BetaDeg => ("beta", 1, " deg"),
        Quantity::GammaDeg => ("flight-path angle", 1, " deg"),
    }
}

/// `v` as the quantity is written in words ("altitude 3000 m").
pub fn value(q: Quantity, v: f64) -> String {
    let (word, d, unit) = words(q);
    format!("{word} {v:.d$}{unit}")
}

/// A range of the quantity in words ("Mach 0.60-0.85").
fn span(q: Quantity, lo: f64, hi: f64) -> String {
    let (word, d, unit) = words(q);
    format!("{word} {lo:.d$}-{hi:.d$}{unit}")
}

/// The summary of `rows` (one per condition of `grid`, in grid order).
pub fn summarise(grid: &Grid, rows: &[Row], criterion_mm: f64) -> Summary {
    let total = rows.len();
    let cleared = rows.iter().filter(|r| r.cleared).count();
    let headline = format!(
        "Cleared at {cleared} of {total} conditions: a condition is cleared when at most 5 % of its samples come within {criterion_mm} mm of the aircraft or diverge."
    );
    let axes = grid.map_axes();
    let Some(&(xq, xv)) = axes.first() else {
        let word = if cleared == total {
            "cleared"
        } else {
            "not cleared"
        };
        return Summary {
            headline,
            lines: vec![format!("The one condition swept is {word}.")],
            cleared,
            total,
        };
    };
    if cleared == total || cleared == 0 {
        // One verdict over the whole grid: one line.
        let word = if cleared == total {
            "cleared"
        } else {
            "not cleared"
        };
        let ranges: Vec<String> = axes
            .iter()
            .map(|(q, v)| match v {
                [one] => value(*q, *one),
                _ => span(*q, v[0], v[v.len() - 1]),
            })
            .collect();
        return Summary {
            headline,
            lines: vec![format!("{word} everywhere swept: {}", ranges.join(", "))],
            cleared,
            total,
        };
    }
    let ny = axes.get(1).map_or(1, |(_, v)| v.len());
    let mut ok = vec![vec![true; xv.len()]; ny];
    for r in rows {
        let (ix, iy) = grid.cell(r.index);
        ok[iy][ix] &= r.cleared;
    }
    let lines = (0..ny)
        .map(|iy| {
            let mut parts = Vec::new();
            let mut i = 0;
            while i < xv.len() {
                let mut j = i;
                while j + 1 < xv.len() && ok[iy][j + 1] == ok[iy][i] {
                    j += 1;
                }
                let word = if ok[iy][i] { "cleared" } else { "not cleared" };
                let range = if i == j {
                    value(xq, xv[i])
                } else {
                    span(xq, xv[i], xv[j])
                };
                parts.push(format!("{word} {range}"));
                i = j + 1;
            }
            let at = axes.get(1).map_or(String::new(), |(yq, yv)| {
                format!("at {}: ", value(*yq, yv[iy]))
            });
            format!("{at}{}", parts.join("; "))
        })
        .collect();
    Summary {
        headline,
        lines,
        cleared,
        total,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::Axis;
    use sepval_common::scenario::Scenario;
    use sepval_predict::record::ConditionRecord;

    #[test]
    fn the_summary_names_the_runs_cleared_and_not_per_altitude() {
        let s = Scenario::embedded_default();
        let axes = [
            Axis::parse(Quantity::Mach, "0.6:0.9:4").unwrap(),
            Axis::parse(Quantity::AltitudeM, "1000:5000:2").unwrap(),
        ];
        let g = Grid::of(&s, &axes).unwrap();
        let rows: Vec<Row> = (0..g.len())
            .map(|k| {
                let f = g.flight(k);
                let mut r = Row::all_diverged(k, ConditionRecord::of(f));
                r.cleared = f.mach < 0.85;
                r
            })
            .collect();
        let sum = summarise(&g, &rows, 25.4);
        assert_eq!((sum.cleared, sum.total), (6, 8));
        assert_eq!(
            sum.lines,
            vec![
                "at altitude 1000 m: cleared Mach 0.60-0.80; not cleared Mach 0.90",
                "at altitude 5000 m: cleared Mach 0.60-0.80; not cleared Mach 0.90",
            ]
        );
        assert!(sum.headline.starts_with("Cleared at 6 of 8 conditions"));
        let all: Vec<Row> = rows
            .into_iter()
            .map(|r| Row { cleared: true, ..r })
            .collect();
        assert_eq!(
            summarise(&g, &all, 25.4).lines,
            vec!["cleared everywhere swept: Mach 0.60-0.90, altitude 1000-5000 m"]
        );
    }
}
