//! The envelope map's tests: contours on one row or column, the figure drawn, bad input
//! refused, releases off the map counted, cell values formatted.

use super::*;
use crate::figures::testing::{check_png, count_colour};

/// A probability rising away from (0.8, 6000): a 10 x 10 grid of Mach by altitude [m].
fn probability_grid() -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
    let mach: Vec<f64> = (0..10).map(|i| 0.5 + 0.05 * f64::from(i)).collect();
    let alt_m: Vec<f64> = (0..10).map(|i| 1000.0 * f64::from(i)).collect();
    let cells = alt_m
        .iter()
        .map(|&h| {
            mach.iter()
                .map(|&m| {
                    let d = ((m - 0.8) / 0.2).hypot((h - 6000.0) / 5000.0);
                    1.0 / (1.0 + (-(d - 1.0) * 6.0).exp())
                })
                .collect()
        })
        .collect();
    (mach, alt_m, cells)
}

fn probability_map<'a>(
    axes: (&'a [f64], &'a [f64]),
    cells: &'a [Vec<f64>],
    criterion: f64,
    flown: &'a [(f64, f64)],
) -> EnvelopeMap<'a> {
    EnvelopeMap {
        title: "Probability of clearance below 25.4 mm",
        x: MapAxis {
            label: "Mach [-]",
            values: axes.0,
        },
        y: Some(MapAxis {
            label: "Altitude [m]",
            values: axes.1,
        }),
        cells,
        value_label: "P(clearance < 25.4 mm) [-]",
        safety: Safety::LowIsSafe,
        criterion,
        criterion_label: "allowed probability 0.05",
        flown,
    }
}

#[test]
fn a_ten_by_ten_map_draws_its_contour_and_the_releases_flown() {
    let dir = tempfile::tempdir().unwrap();
    let (mach, alt_m, cells) = probability_grid();
    let flown = [(0.8, 6000.0), (0.6, 2000.0), (0.9, 8500.0), (1.5, 3000.0)];
    let path = dir.path().join("envelope.png");
    envelope_map(
        &path,
        &probability_map((&mach, &alt_m), &cells, 0.05, &flown),
    )
    .unwrap();
    check_png(&path, (1200, 900));
    // Three rings of about 300 blue pixels each (the fourth is off the map), and the
    // legend's: not four on the map.
    let blue = count_colour(&path, FLOWN_BLUE);
    assert!((1000..1500).contains(&blue), "{blue} blue pixels");
    // The contour's black line: a criterion no cell reaches draws none.
    let with_contour = count_colour(&path, BLACK);
    let none = dir.path().join("none.png");
    envelope_map(&none, &probability_map((&mach, &alt_m), &cells, 1e-6, &[])).unwrap();
    let without = count_colour(&none, BLACK);
    assert!(with_contour > without + 2000, "{with_contour} vs {without}");
}

#[test]
fn a_one_axis_map_with_a_cell_without_value_draws_one_row() {
    let dir = tempfile::tempdir().unwrap();
    let mach: Vec<f64> = (0..10).map(|i| 0.5 + 0.05 * f64::from(i)).collect();
    let mut row: Vec<f64> = mach.iter().map(|m| 60.0 - 50.0 * m).collect();
    row[8] = f64::NAN;
    let cells = [row];
    let map = EnvelopeMap {
        title: "5th-percentile clearance",
        x: MapAxis {
            label: "Mach [-]",
            values: &mach,
        },
        y: None,
        cells: &cells,
        value_label: "clearance, 5th percentile [mm]",
        safety: Safety::HighIsSafe,
        criterion: 25.4,
        criterion_label: "criterion 25.4 mm",
        flown: &[(0.6, 123.0)],
    };
    let path = dir.path().join("row.png");
    envelope_map(&path, &map).unwrap();
    check_png(&path, (1200, 900));
    // The cell without a value is grey (about 90 x 700 px), and the legend's box.
    assert!(count_colour(&path, NO_VALUE_GREY) > 30_000);
    assert!(count_colour(&path, FLOWN_BLUE) > 200);
    // The crossing at Mach 0.692 is a vertical line across the row (3 px by about 700).
    let black = count_colour(&path, BLACK);
    assert!(black > 2000, "{black} black pixels");
    // With the cell without a value where it crosses, the line is not drawn.
    let mut holed = cells.clone();
    holed[0][4] = f64::NAN;
    let checked = check(&EnvelopeMap {
        cells: &holed,
        ..map
    })
    .unwrap();
    assert_eq!(
        not_drawn(&checked, 25.4, Safety::HighIsSafe),
        " (crossed only beside cells without a value)"
    );
    envelope_map(
        &path,
        &EnvelopeMap {
            cells: &holed,
            ..map
        },
    )
    .unwrap();
    assert!(count_colour(&path, BLACK) < black - 2000);
    let unsafe_row = [vec![1.0; 10]];
    let all_unsafe = check(&EnvelopeMap {
        cells: &unsafe_row,
        ..map
    })
    .unwrap();
    assert_eq!(
        not_drawn(&all_unsafe, 25.4, Safety::HighIsSafe),
        " (not crossed: every value on the unsafe side)"
    );
}

#[test]
fn a_single_row_or_column_crosses_as_straight_lines() {
    let (mach, alt_m, cells) = probability_grid();
    let column: Vec<Vec<f64>> = cells.iter().map(|r| vec![r[6]]).collect();
    let map = probability_map((&mach[6..7], &alt_m), &column, 0.05, &[]);
    let checked = check(&map).unwrap();
    let extent = Extent {
        x: (0.75, 0.85),
        y: (-500.0, 9500.0),
    };
    // Mach 0.8 crosses 0.05 twice along the altitude: two horizontal lines across the map.
    let lines = contour(&map, &checked, &extent).unwrap();
    assert_eq!(lines.len(), 2, "{lines:?}");
    for [p, q] in &lines {
        assert!(
            (p.1 - q.1).abs() < 1e-9 && (3000.0..9000.0).contains(&p.1),
            "{p:?}"
        );
        assert!((p.0 - 0.75).abs() < 1e-12 && (q.0 - 0.85).abs() < 1e-12);
    }
    // One altitude given as a y axis of one value: vertical lines, as without y.
    let map = probability_map((&mach, &alt_m[6..7]), &cells[6..7], 0.05, &[]);
    let checked = check(&map).unwrap();
    let lines = contour(&map, &checked, &extent).unwrap();
    assert_eq!(lines.len(), 2, "{lines:?}");
    assert!(lines.iter().all(|[p, q]| (p.0 - q.0).abs() < 1e-12));
}

#[test]
fn inconsistent_input_is_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.png");
    let (mach, alt_m, cells) = probability_grid();
    let refused = |map: EnvelopeMap<'_>| {
        let e = envelope_map(&path, &map).unwrap_err();
        assert!(matches!(e, FigureError::Input { .. }), "{e:?}");
        assert!(!path.exists());
        e.to_string()
    };
    let e = refused(probability_map((&mach, &alt_m), &cells[1..], 0.05, &[]));
    assert!(e.ends_with("envelope map: the grid must be 10 rows of 10 cells: found 9 rows"));
    let short: Vec<Vec<f64>> = cells.iter().map(|r| r[1..].to_vec()).collect();
    let e = refused(probability_map((&mach, &alt_m), &short, 0.05, &[]));
    assert!(e.ends_with("row 0 has 9 cells"), "{e}");
    let mut back = mach.clone();
    back.swap(2, 3);
    let e = refused(probability_map((&back, &alt_m), &cells, 0.05, &[]));
    assert!(
        e.contains("x axis must be finite and strictly increasing: value 3"),
        "{e}"
    );
    let mut holed = alt_m.clone();
    holed[5] = f64::NAN;
    let e = refused(probability_map((&mach, &holed), &cells, 0.05, &[]));
    assert!(e.contains("y axis"), "{e}");
    let e = refused(probability_map((&mach, &alt_m), &cells, f64::NAN, &[]));
    assert!(
        e.ends_with("the criterion must be finite, found NaN"),
        "{e}"
    );
    let e = refused(probability_map((&[], &alt_m), &cells, 0.05, &[]));
    assert!(e.ends_with("the x axis has no values"), "{e}");
}

#[test]
fn releases_off_the_map_are_counted_in_the_legend() {
    let (mach, alt_m, cells) = probability_grid();
    let flown = [(0.7, 3000.0), (0.7, 1e6), (f64::NAN, 0.0)];
    let map = probability_map((&mach, &alt_m), &cells, 2.0, &flown);
    let checked = check(&map).unwrap();
    let extent = Extent {
        x: (0.475, 0.975),
        y: (-500.0, 9500.0),
    };
    let drawn = Flown::within(&flown, &extent, true);
    assert_eq!(drawn.points, vec![(0.7, 3000.0)]);
    let labels: Vec<String> = legend(&map, &checked, &[], &drawn)
        .into_iter()
        .map(|(l, _)| l)
        .collect();
    assert_eq!(
        labels,
        [
            "allowed probability 0.05 (not crossed: every value on the safe side)",
            "releases flown (2 outside the map, not shown)"
        ]
    );
    // On one axis the y is ignored and the point sits mid-row.
    let drawn = Flown::within(&flown[1..2], &extent, false);
    assert_eq!(drawn.points, vec![(0.7, 4500.0)]);
}

#[test]
fn cell_values_have_three_significant_digits() {
    assert_eq!(fmt_cell(0.05234), "0.0523");
    assert_eq!(fmt_cell(0.05), "0.05");
    assert_eq!(fmt_cell(25.44), "25.4");
    assert_eq!(fmt_cell(131.2), "131");
    assert_eq!(fmt_cell(1.0), "1");
    assert_eq!(fmt_cell(0.0), "0");
    assert_eq!(fmt_cell(-0.0004), "-0.0004");
    assert_eq!(fmt_cell(2.5e6), "2.5e6");
}
