//! The states of a campaign's envelope as a map (docs/campaign.md): each condition a cell in
//! one of three fixed colours (cleared green, undecided amber, fails red; grey for a value that
//! is none of them), the releases flown numbered in the order flown, and a legend.

use std::path::Path;

use plotters::prelude::*;

use super::FigureError;
use super::condition_map::{MapAxis, NO_VALUE_GREY, check_cells, edges};
use super::kit::{LegendMark, draw_mesh, fmt_tick, render, text, titled_with_legend};

/// A cell's state: 0 cleared, 1 undecided, 2 fails (anything else: no value, grey).
pub(super) const COLOURS: [RGBColor; 3] = [
    RGBColor(46, 160, 67),
    RGBColor(240, 173, 0),
    RGBColor(214, 39, 40),
];
/// The states' names, in the order of [`COLOURS`].
pub(super) const NAMES: [&str; 3] = ["cleared", "undecided", "fails"];

/// Draws the map of `states` (`states[iy][ix]`, one row when `y` is `None`) with the releases
/// `flown` ((x, y) in the axes' units, in the order flown) to `path`, 1200 × 900 px. A shape
/// that does not match the axes is refused before anything is written.
pub fn state_map(
    path: &Path,
    title: &str,
    x: MapAxis<'_>,
    y: Option<MapAxis<'_>>,
    states: &[Vec<u8>],
    flown: &[(f64, f64)],
) -> Result<(), FigureError> {
    check_cells(path, x, y, states)?;
    let (xe, ye) = (
        edges(x.values),
        y.map_or(vec![0.0, 1.0], |y| edges(y.values)),
    );
    let mut entries: Vec<(String, LegendMark)> = NAMES
        .iter()
        .zip(COLOURS)
        .map(|(n, c)| (n.to_string(), LegendMark::Band(c)))
        .collect();
    if !flown.is_empty() {
        entries.push(("releases flown, in order".into(), LegendMark::Ring(BLUE)));
    }
    render(path, (1200, 900), |root| {
        let main = titled_with_legend(root, title, &entries)?;
        let mut chart = ChartBuilder::on(&main)
            .margin(18)
            .x_label_area_size(55)
            .y_label_area_size(85)
            .build_cartesian_2d(xe[0]..xe[xe.len() - 1], ye[0]..ye[ye.len() - 1])?;
        draw_mesh(
            &mut chart,
            x.label,
            y.map_or("", |y| y.label),
            fmt_tick,
            fmt_tick,
        )?;
        for (iy, row) in states.iter().enumerate() {
            for (ix, &s) in row.iter().enumerate() {
                let colour = COLOURS
                    .get(usize::from(s))
                    .copied()
                    .unwrap_or(NO_VALUE_GREY);
                let rect = [(xe[ix], ye[iy]), (xe[ix + 1], ye[iy + 1])];
                chart.draw_series(std::iter::once(Rectangle::new(rect, colour.filled())))?;
                chart.draw_series(std::iter::once(Rectangle::new(rect, WHITE.stroke_width(2))))?;
            }
        }
        let centre = plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Center,
            plotters::style::text_anchor::VPos::Center,
        );
        for (k, &(fx, fy)) in flown.iter().enumerate() {
            let at = (fx, if y.is_some() { fy } else { 0.5 });
            chart.draw_series(std::iter::once(Circle::new(at, 16, WHITE.filled())))?;
            chart.draw_series(std::iter::once(Circle::new(at, 16, BLUE.stroke_width(3))))?;
            let style = text(16.0).color(&BLUE).pos(centre);
            chart.draw_series(std::iter::once(Text::new(format!("{}", k + 1), at, style)))?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::testing::check_png;

    #[test]
    fn a_state_map_is_drawn_and_a_bad_shape_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let (xs, ys) = ([0.6, 0.8, 1.0], [0.0, 5.0]);
        let x = MapAxis {
            label: "Mach [-]",
            values: &xs,
        };
        let y = MapAxis {
            label: "Alpha [deg]",
            values: &ys,
        };
        let path = dir.path().join("s.png");
        state_map(
            &path,
            "states",
            x,
            Some(y),
            &[vec![0, 1, 2], vec![0, 0, 1]],
            &[(0.8, 0.0)],
        )
        .unwrap();
        check_png(&path, (1200, 900));
        let bad = state_map(&path, "states", x, Some(y), &[vec![0, 1]], &[]).unwrap_err();
        assert!(
            bad.to_string().contains("must be 2 rows of 3 cells"),
            "{bad}"
        );
    }
}
