//! The flowfield's shape given as a table over depth (docs/model.md section 3b, "The shape as a
//! table"): it agrees with the independent reference implementation
//! (`scripts/reference_model.py`), a table of the analytic shape flies the analytic release to
//! its interpolation's error, the lanes keep the scalar runs' bits, and a table that is not one
//! is refused naming the field.

use sepval_common::scenario::Scenario;
use sepval_common::{Factors, Simulator};

use crate::flowfield::{
    assert_flies, conformance_scenario, example_with, largest_difference,
    loads_at_the_reference_test_state, refusal,
};

/// [`EXAMPLE`] with its shape as a table over depth (the analytic g at the depths given) in
/// place of `half_depth_m` and `reversal_m`.
fn example_with_shape_table(depth_m: &[f64]) -> String {
    let g: Vec<f64> = depth_m
        .iter()
        .map(|&z| (1.0 - z / 2.0) / (1.0 + z / 0.8))
        .collect();
    example_with_shape(depth_m, &g)
}

/// [`EXAMPLE`] with the shape table `depth_m`, `g` in place of `half_depth_m` and `reversal_m`.
fn example_with_shape(depth_m: &[f64], g: &[f64]) -> String {
    let list = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:?}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let table = format!(
        "shape = {{ depth_m = [{}], g = [{}] }}",
        list(depth_m),
        list(g)
    );
    let text = example_with("half_depth_m = 0.8", &table);
    let reversal = text.lines().find(|l| l.starts_with("reversal_m")).unwrap();
    text.replacen(reversal, "", 1)
}

/// docs/model.md section 3b's shape-table case, from `scripts/reference_model.py --json`
/// (`shape_table_case`): the conformance field with g a table over depth. Its trajectory (t, x,
/// y, z [m], roll, pitch, yaw [deg], truth factors, noise-free) and its increments at the
/// reference's test state (dCX ... dCn).
const SHAPE_TABLE: ([f64; 5], [f64; 5]) = ([0.0, 0.3, 0.9, 1.6, 2.5], [1.0, 0.62, 0.2, -0.07, 0.0]);
const SHAPE_TABLE_ROWS: [[f64; 7]; 5] = [
    [
        0.05,
        -0.0056594553956929704,
        0.0006944083363521602,
        0.08720352606221679,
        0.058859770967716094,
        1.6829778554559471,
        -0.0017700928874638498,
    ],
    [
        0.1,
        -0.023135392187252156,
        0.0025951604180151876,
        0.27632497223319286,
        0.2485577270831644,
        4.947151155555662,
        0.003627628210339526,
    ],
    [
        0.25,
        -0.15923229895188312,
        0.012067105748484337,
        0.9337498961128852,
        1.8784179965709853,
        13.79056606837605,
        0.25682323224174997,
    ],
    [
        0.5,
        -0.7682549775798978,
        0.031450422438071245,
        2.192482066470953,
        8.836811498625439,
        26.662796123277744,
        2.282707738773999,
    ],
    [
        1.0,
        -4.462230091869594,
        0.23661799846027187,
        4.589613638528306,
        36.53118263260081,
        49.24093986611077,
        14.513934175075823,
    ],
];
const SHAPE_TABLE_INCREMENTS: [f64; 6] = [
    0.1003314632793472,
    0.09410001884360576,
    -0.0723222130041506,
    -0.00819589897448718,
    -0.034646453144673794,
    -0.012426103759559827,
];

#[test]
fn a_shape_table_agrees_with_the_independent_implementation() {
    let text = example_with_shape(&SHAPE_TABLE.0, &SHAPE_TABLE.1);
    let scenario = Scenario::from_toml_str(&text, "shape table").unwrap();
    assert_flies(&scenario, &SHAPE_TABLE_ROWS);
    let got = loads_at_the_reference_test_state(&scenario);
    for (name, (g, e)) in ["dCX", "dCY", "dCZ", "dCl", "dCm", "dCn"]
        .iter()
        .zip(got.iter().zip(SHAPE_TABLE_INCREMENTS))
    {
        assert!((g - e).abs() < 1e-13, "{name}: {g} vs the reference's {e}");
    }
}

#[test]
fn lanes_equal_scalar_runs_bit_for_bit_with_a_shape_table() {
    // A field whose shape is a table goes one run at a time through the lanes (its lookups are
    // scalar): every catalogue effect, interference_decay scaling the table's depths.
    let depths: Vec<f64> = (0..12)
        .map(|k| 0.25 * k as f64 * (1.0 + k as f64 / 4.0))
        .collect();
    let scenario = Scenario::from_toml_str(&example_with_shape_table(&depths), "table").unwrap();
    let sim = Simulator::new(&scenario);
    crate::lanes::check_lanes_against_scalar(&sim, &sim.default_times());
}

#[test]
fn a_shape_table_of_the_analytic_shape_flies_the_analytic_release() {
    let depths: Vec<f64> = (0..32).map(|k| 6.0 * (k as f64 / 31.0).powi(2)).collect();
    let table = Scenario::from_toml_str(&example_with_shape_table(&depths), "table").unwrap();
    let (pos_m, att_deg) = largest_difference(&conformance_scenario(), &table, &Factors::TRUTH);
    // The linear interpolation's error on the field, a fraction of a percent near the store.
    assert!(pos_m < 2e-3 && att_deg < 0.05, "{pos_m} m, {att_deg} deg");
    assert!(pos_m > 0.0, "the table is a different path");
}

#[test]
fn a_shape_table_that_is_not_one_is_refused_naming_the_field() {
    let table = example_with_shape_table(&[0.0, 1.0, 2.0]);
    let cases = [
        (
            table.replace("depth_m = [0.0, 1.0, 2.0]", "depth_m = [0.0, 1.0]"),
            "flowfield.shape.g",
            "one per depth",
        ),
        (
            table.replace("depth_m = [0.0, 1.0, 2.0]", "depth_m = [0.1, 1.0, 2.0]"),
            "flowfield.shape.depth_m",
            "expected 0",
        ),
        (
            table.replace("depth_m = [0.0, 1.0, 2.0]", "depth_m = [0.0, 2.0, 1.0]"),
            "flowfield.shape.depth_m",
            "above the depth before it",
        ),
        (
            table.replace("g = [1.0,", "g = [0.9,"),
            "flowfield.shape.g",
            "expected 1",
        ),
        (
            table
                .replace("g = [1.0,", "g = [1.0, nan,")
                .replace("depth_m = [0.0,", "depth_m = [0.0, 0.5,"),
            "flowfield.shape.g",
            "finite",
        ),
        (
            example_with_shape_table(&[0.0]),
            "flowfield.shape.depth_m",
            "expected 2 to 32",
        ),
        (
            table.replace("shape = {", "half_depth_m = 0.8\nshape = {"),
            "flowfield.shape",
            "not both",
        ),
        (
            table.replace("shape = {", "reversal_m = 2.0\nshape = {"),
            "flowfield.reversal_m",
            "shape table",
        ),
        (
            example_with("half_depth_m = 0.8", ""),
            "flowfield.half_depth_m",
            "is missing",
        ),
        (
            table.clone()
                + "\n[[correction]]\nfield = \"flowfield.half_depth_m\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n",
            "correction[0]",
            "shape is a table",
        ),
    ];
    for (text, field, reason) in cases {
        let message = refusal(&text);
        assert!(
            message.contains(field) && message.contains(reason),
            "expected `{field}` ... `{reason}`, got: {message}"
        );
    }
}
