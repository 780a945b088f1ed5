//! The history of a campaign (docs/campaign.md): how many conditions are cleared, undecided and
//! failing after each round, against the releases flown by then, in the state map's colours.

use std::path::Path;

use plotters::prelude::*;

use super::FigureError;
use super::kit::{LegendMark, draw_mesh, fmt_count_tick, render, titled_with_legend};
use super::state_map::{COLOURS, NAMES};

/// One round: the releases flown by then and its counts of cleared, undecided and failing
/// conditions (the state map's order).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RoundCounts {
    /// Releases flown by the round.
    pub releases_flown: usize,
    /// Conditions cleared, undecided and failing.
    pub counts: [usize; 3],
}

/// Draws the counts of every round in `rounds` (in the order run) against the releases flown,
/// a line with a marker per state, to `path`, 1000 × 650 px; the y axis runs from 0 to
/// `conditions`.
pub fn state_counts_figure(
    path: &Path,
    rounds: &[RoundCounts],
    conditions: usize,
) -> Result<(), FigureError> {
    let entries: Vec<(String, LegendMark)> = NAMES
        .iter()
        .zip(COLOURS)
        .map(|(n, c)| (n.to_string(), LegendMark::Line(c)))
        .collect();
    let most = rounds.iter().map(|r| r.releases_flown).max().unwrap_or(0);
    // From no release to the most flown, a fifth of a release beyond either end.
    let x = (-0.2, most.max(1) as f64 + 0.2);
    let y_top = conditions.max(1) as f64 * 1.05;
    render(path, (1000, 650), |root| {
        let main = titled_with_legend(root, "The envelope's states, round by round", &entries)?;
        let mut chart = ChartBuilder::on(&main)
            .margin(18)
            .x_label_area_size(55)
            .y_label_area_size(85)
            .build_cartesian_2d(x.0..x.1, 0.0..y_top)?;
        draw_mesh(
            &mut chart,
            "Releases flown",
            "Conditions",
            fmt_count_tick,
            fmt_count_tick,
        )?;
        for (state, colour) in COLOURS.iter().enumerate() {
            let points: Vec<(f64, f64)> = rounds
                .iter()
                .map(|r| (r.releases_flown as f64, r.counts[state] as f64))
                .collect();
            let style = colour.stroke_width(3);
            chart.draw_series(std::iter::once(PathElement::new(points.clone(), style)))?;
            chart.draw_series(
                points
                    .into_iter()
                    .map(|p| Circle::new(p, 6, colour.filled())),
            )?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::testing::check_png;

    #[test]
    fn the_counts_are_drawn_for_one_round_and_for_several() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("counts.png");
        let round = |releases_flown, counts| RoundCounts {
            releases_flown,
            counts,
        };
        state_counts_figure(&path, &[round(0, [0, 25, 0])], 25).unwrap();
        check_png(&path, (1000, 650));
        let rounds = [
            round(0, [10, 15, 0]),
            round(1, [18, 5, 2]),
            round(3, [22, 0, 3]),
        ];
        state_counts_figure(&path, &rounds, 25).unwrap();
        check_png(&path, (1000, 650));
        state_counts_figure(&path, &[], 0).unwrap();
        check_png(&path, (1000, 650));
    }
}
