use super::*;
use crate::figures::testing::{check_png, count_colour, dark_pixels};

/// Times 0 to 1 s at 100 Hz.
fn times_s() -> Vec<f64> {
    (0..=100).map(|i| f64::from(i) * 0.01).collect()
}

/// The smallest finite clearance at or after `free_from_s`: (its time [s], it [m]).
fn counted_min(t_s: &[f64], c_m: &[f64], free_from_s: f64) -> (f64, f64) {
    t_s.iter()
        .zip(c_m)
        .filter(|(t, c)| **t >= free_from_s && c.is_finite())
        .map(|(&t, &c)| (t, c))
        .fold(
            (f64::NAN, f64::INFINITY),
            |a, b| if b.1 < a.1 { b } else { a },
        )
}

/// A series of `c_m` over `t_s`, its minimum counted from `free_from_s`.
fn series<'a>(
    label: &'a str,
    t_s: &'a [f64],
    c_m: &'a [f64],
    free_from_s: f64,
) -> ClearanceSeries<'a> {
    let (min_t_s, min_m) = counted_min(t_s, c_m, free_from_s);
    ClearanceSeries {
        label,
        t_s,
        clearance_m: c_m,
        free_from_s,
        min_t_s,
        min_m,
    }
}

/// Where a figure of the tests is written: `dir`, or `SEPVAL_FIGURE_DIR` when it is set (for a
/// person to look at the figures:
/// `SEPVAL_FIGURE_DIR=/tmp cargo test --release -p sepval-report clearance`).
fn figure_path(dir: &tempfile::TempDir, name: &str) -> std::path::PathBuf {
    std::env::var_os("SEPVAL_FIGURE_DIR")
        .map_or_else(|| dir.path().to_path_buf(), std::path::PathBuf::from)
        .join(name)
}

/// The criterion of the examples: one inch [m].
const INCH_M: f64 = 0.0254;

#[test]
fn one_release_near_the_criterion_is_drawn_in_one_panel() {
    let dir = tempfile::tempdir().unwrap();
    let t = times_s();
    let c: Vec<f64> = t.iter().map(|&t| 0.03 + 0.17 * t).collect();
    let one = [series("release 1", &t, &c, 0.05)];
    let layout = Layout::of(&one, INCH_M).unwrap();
    assert_eq!(layout.near_mm, None);
    assert!(layout.whole_mm.0.abs() < 1e-12, "{layout:?}");
    let path = figure_path(&dir, "clearance-one.png");
    clearance_figure(&path, "Clearance of one release", &one, INCH_M).unwrap();
    check_png(&path, SIZE_PX);
    assert!(
        count_colour(&path, CRITERION_RED) > 200,
        "no criterion drawn"
    );
    assert!(count_colour(&path, HELD_GREY) > 2000, "no time held shaded");
    assert!(count_colour(&path, colour(0)) > 500, "no line drawn");
}

/// Three releases: one rising from 20 mm to 2 m over 1 s, one dipping to 10 mm (below the
/// criterion), one with a gap of missing values (`clearance-example.png`).
#[test]
fn three_releases_spanning_metres_get_a_panel_near_the_criterion() {
    let dir = tempfile::tempdir().unwrap();
    let t = times_s();
    let rising: Vec<f64> = t.iter().map(|&t| 0.02 + 1.98 * t.powf(1.5)).collect();
    let dipping: Vec<f64> = t.iter().map(|&t| 0.01 + 1.2 * (t - 0.2).powi(2)).collect();
    let mut gap: Vec<f64> = t.iter().map(|&t| 0.03 + 0.8 * t).collect();
    gap[40..50].fill(f64::NAN);
    let three = [
        series("release 1", &t, &rising, 0.06),
        series("release 2", &t, &dipping, 0.05),
        series("release 3", &t, &gap, 0.08),
    ];
    assert!((three[1].min_m - 0.01).abs() < 1e-12);
    let layout = Layout::of(&three, INCH_M).unwrap();
    let near_mm = layout.near_mm.expect("a panel near the criterion");
    assert!(near_mm.0 <= 0.0 && near_mm.1 > 1e3 * INCH_M);
    assert!(layout.whole_mm.1 >= 2000.0 && layout.whole_mm.1 > ZOOM_RATIO * near_mm.1);
    assert!((layout.held_until_s - 0.08).abs() < 1e-12);
    let path = figure_path(&dir, "clearance-example.png");
    clearance_figure(&path, "Clearance of three releases", &three, INCH_M).unwrap();
    check_png(&path, SIZE_PX);
    for i in 0..3 {
        assert!(
            count_colour(&path, colour(i)) > 300,
            "release {i} not drawn"
        );
    }
    // The lower panel has its axis labels, the minima's values and the criterion's name.
    assert!(dark_pixels(&path, 500..880) > 3000);
    assert!(
        count_colour(&path, CRITERION_RED) > 400,
        "criterion not in both panels"
    );
}

#[test]
fn inconsistent_input_is_refused_and_nothing_written() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("clearance.png");
    let t = times_s();
    let c: Vec<f64> = t.iter().map(|&t| 0.02 + t).collect();
    let good = series("good", &t, &c, 0.05);
    let short = ClearanceSeries {
        label: "short",
        clearance_m: &c[..7],
        ..good
    };
    let unheld = ClearanceSeries {
        label: "unheld",
        free_from_s: f64::NAN,
        ..good
    };
    let cases: [(&[ClearanceSeries<'_>], f64, &str); 6] = [
        (&[], INCH_M, "no release to draw"),
        (
            &[good, short],
            INCH_M,
            "\"short\" has 7 clearances for 101 times",
        ),
        (
            &[good],
            f64::NAN,
            "criterion must be finite and not negative, found NaN",
        ),
        (&[good], f64::INFINITY, "found inf m"),
        (&[good], -0.01, "found -0.01 m"),
        (
            &[unheld],
            INCH_M,
            "\"unheld\": the time from which the clearance counts",
        ),
    ];
    for (series, criterion_m, expected) in cases {
        let err = clearance_figure(&path, "x", series, criterion_m).unwrap_err();
        assert!(matches!(err, FigureError::Input { .. }), "{err:?}");
        assert!(err.to_string().contains(expected), "{err}");
        assert!(err.to_string().contains("clearance.png"), "{err}");
        assert!(!path.exists());
    }
}

#[test]
fn odd_values_draw_without_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("odd.png");
    let t = [0.0, 0.1, f64::NAN, 0.3];
    let c = [f64::NAN, -0.002, 0.5, f64::INFINITY];
    let odd = ClearanceSeries {
        label: "odd",
        t_s: &t,
        clearance_m: &c,
        free_from_s: -1.0,
        min_t_s: f64::NAN,
        min_m: f64::NAN,
    };
    let empty = ClearanceSeries {
        label: "empty",
        t_s: &[],
        clearance_m: &[],
        ..odd
    };
    let layout = Layout::of(&[odd, empty], 0.0).unwrap();
    assert!(layout.whole_mm.0 < -2.0, "{layout:?}");
    clearance_figure(&path, "odd", &[odd, empty], 0.0).unwrap();
    check_png(&path, SIZE_PX);
    // No shade (the grey of the time held appears only at the edges of antialiased text).
    assert!(count_colour(&path, HELD_GREY) < 200);
}

#[test]
fn a_criterion_above_every_clearance_stays_in_view() {
    let t = times_s();
    let c: Vec<f64> = t.iter().map(|&t| 0.002 + 0.01 * t).collect();
    let layout = Layout::of(&[series("close", &t, &c, 0.0)], INCH_M).unwrap();
    assert!(
        layout.whole_mm.1 > 25.4 && layout.whole_mm.0.abs() < 1e-12,
        "{layout:?}"
    );
    assert_eq!(layout.near_mm, None);
}

#[test]
fn lines_are_cut_where_they_leave_the_range() {
    let pieces = clipped_segments([(0.0, 0.0), (1.0, 100.0), (2.0, 0.0)], (0.0, 50.0));
    assert_eq!(
        pieces,
        vec![vec![(0.0, 0.0), (0.5, 50.0)], vec![(1.5, 50.0), (2.0, 0.0)]]
    );
    let pieces = clipped_segments(
        [
            (0.0, 10.0),
            (1.0, 20.0),
            (2.0, f64::NAN),
            (3.0, 30.0),
            (4.0, 40.0),
        ],
        (0.0, 50.0),
    );
    assert_eq!(pieces.len(), 2);
    assert!(clipped_segments([(0.0, 60.0), (1.0, 70.0)], (0.0, 50.0)).is_empty());
    let pieces = clipped_segments([(0.0, 60.0), (1.0, 70.0), (2.0, 40.0)], (0.0, 50.0));
    assert_eq!(pieces.len(), 1);
    assert!((pieces[0][0].0 - 5.0 / 3.0).abs() < 1e-12 && (pieces[0][0].1 - 50.0).abs() < 1e-12);
}

#[test]
fn clearances_are_written_with_a_precision_that_suits_them() {
    assert_eq!(fmt_mm(0.25), "0.25 mm");
    assert_eq!(fmt_mm(10.0), "10.0 mm");
    assert_eq!(fmt_mm(25.4), "25.4 mm");
    assert_eq!(fmt_mm(2000.4), "2000 mm");
}

#[test]
fn a_note_goes_below_its_dot_unless_there_is_no_room_or_another_is_there() {
    let area = [0, 0, 1000, 500];
    assert_eq!(
        place_note((100, 200), (60, 16), area, &[]),
        [112, 204, 172, 220]
    );
    // No room below: above.
    assert_eq!(
        place_note((100, 490), (60, 16), area, &[]),
        [112, 470, 172, 486]
    );
    // No room on the right: on the left.
    assert_eq!(
        place_note((980, 200), (60, 16), area, &[]),
        [908, 204, 968, 220]
    );
    // Another note in the way: below it.
    let other = [100, 200, 200, 220];
    assert_eq!(
        place_note((100, 200), (60, 16), area, &[other]),
        [112, 222, 172, 238]
    );
    // Another in the way and no room below it: above the dot, clear of it.
    let other = [100, 480, 200, 500];
    let spot = place_note((100, 482), (60, 16), area, &[other]);
    assert!(spot[3] <= other[1], "{spot:?}");
}
