//! The unit tests of `sepval_common::table`.

#![allow(clippy::float_cmp)]

use sepval_common::table::*;

fn at(alpha_rad: f64, beta_rad: f64) -> Inputs {
    Inputs {
        alpha_rad,
        beta_rad,
        distance_m: 0.0,
        lateral_m: 0.0,
    }
}

fn axis(variable: Variable, b: &[f64]) -> Axis {
    Axis {
        variable,
        breakpoints: b.to_vec(),
    }
}

#[test]
fn bilinear_interpolation_and_edge_hold() {
    let mut p = PreparedTables::default();
    let t = Table::new(
        vec![
            axis(Variable::Mach, &[0.5, 1.0]),
            axis(Variable::Alpha, &[0.0, 10.0]),
            axis(Variable::Beta, &[-5.0, 5.0]),
        ],
        vec![0.0, 1.0, 2.0, 3.0, 10.0, 11.0, 12.0, 13.0],
        Kind::Static,
    )
    .unwrap();
    let (id, axes, values) = p.slice_mach("aero.cz", &t, 0.75);
    assert_eq!(values, vec![5.0, 6.0, 7.0, 8.0]);
    p.add_runtime(id, Target::Static(2), axes, values);
    let state = TableState::default();
    state.count_evaluation();
    let (s, _) = p.evaluate(&state, &at(5f64.to_radians(), 0.0));
    assert!((s[2] - 6.5).abs() < 1e-12, "{}", s[2]);
    // Beyond alpha: held at the alpha = 10 deg edge and recorded.
    state.count_evaluation();
    let (s, _) = p.evaluate(&state, &at(12f64.to_radians(), 5.0f64.to_radians()));
    assert!((s[2] - 8.0).abs() < 1e-12, "{}", s[2]);
    let r = p.report(&state.excursions());
    assert_eq!(r.len(), 1);
    assert_eq!(r[0].evaluations_outside, 1);
    assert_eq!(r[0].evaluations, 2);
    assert!((r[0].axes[0].worst_excursion - 2.0).abs() < 1e-9, "{r:?}");
}

#[test]
fn mach_beyond_the_table_is_held_and_counts_every_evaluation() {
    let mut p = PreparedTables::default();
    let t = Table::new(
        vec![axis(Variable::Mach, &[0.5, 0.9])],
        vec![1.0, 2.0],
        Kind::Derivative,
    )
    .unwrap();
    let (_, axes, values) = p.slice_mach("aero.cm_q_per_rad", &t, 0.95);
    assert!(axes.is_empty());
    assert_eq!(values, vec![2.0]);
    let ex = TableExcursions {
        evaluations: 40,
        ..TableExcursions::default()
    };
    let r = p.report(&ex);
    assert_eq!(r[0].evaluations_outside, 40);
    assert!((r[0].axes[0].worst_excursion - 0.05).abs() < 1e-12);
}

#[test]
fn tables_are_checked() {
    let e = Table::new(
        vec![axis(Variable::Alpha, &[0.0, 1.0])],
        vec![0.0, 1.0],
        Kind::Derivative,
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "is a table over alpha: a derivative may be tabulated over mach only"
    );
    let e = Table::new(
        vec![axis(Variable::Mach, &[0.9, 0.6])],
        vec![0.0, 1.0],
        Kind::Static,
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "axis mach breakpoints are not strictly increasing: 0.6 after 0.9"
    );
    // Breakpoints whose spacing has no finite inverse (the value between them would be NaN);
    // those too far apart for one are outside every variable's domain first.
    let e = Table::new(
        vec![axis(Variable::Mach, &[-1e308, 1e308])],
        vec![0.0, 1.0],
        Kind::Static,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("axis mach breakpoint -1e308 is outside mach's domain, 0 to 3"),
        "{e}"
    );
    let b = [0.0, 5e-324];
    let e = Table::new(vec![axis(Variable::Mach, &b)], vec![0.0, 1.0], Kind::Static)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!(
            "axis mach breakpoints {} and {} are too close together or too far apart",
            b[0], b[1]
        )),
        "{e}"
    );
    let e = Table::new(
        vec![axis(Variable::Alpha, &[0.0, 1.0])],
        vec![0.0, 1.0],
        Kind::Interference,
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "has no distance axis: an interference increment is tabulated over distance at least"
    );
}

#[test]
fn an_excursion_is_said_as_an_excess_with_its_unit() {
    let axis = |variable: &str, range: [f64; 2], worst_excursion: f64| {
        sepval_common::table::AxisExcursion {
            variable: variable.into(),
            range,
            worst_excursion,
        }
    };
    let e = sepval_common::table::TableExcursion {
        table: "flowfield".into(),
        evaluations_outside: 49,
        evaluations: 201,
        axes: vec![
            axis("x_m", [-3.0, 3.0], 2.28),
            axis("alpha_deg", [-10.0, 10.0], 1.5),
            axis("mach", [0.4, 1.6], 0.1),
        ],
        at_samples: true,
    };
    assert_eq!(
        e.to_string(),
        "left table `flowfield` in 49 of 201 samples (value held at the edge); x_m by up to \
         2.28 m beyond [-3, 3] m; alpha_deg by up to 1.5 deg beyond [-10, 10] deg; mach by up \
         to 0.1 beyond [0.4, 1.6]"
    );
}
