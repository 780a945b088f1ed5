//! The flowfield given as tables over position (docs/model.md section 3b, "The field as a table
//! over position"): the guide's surveyed field agrees with the independent reference
//! implementation (`scripts/reference_model.py`), the lanes keep the scalar runs' bits, a survey
//! of the analytic field flies the analytic release to its interpolation's error, the tables
//! scale with the aircraft's lift and Mach, and a field of tables that is not one is refused
//! naming the field.

use std::path::{Path, PathBuf};

use sepval_common::scenario::Scenario;
use sepval_common::{EffectSet, Factors, Simulator};

use crate::flowfield::{
    EXAMPLE, assert_flies, conformance_scenario, largest_difference,
    loads_at_the_reference_test_state,
};

fn example_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/flowfield-store")
}

/// The guide's surveyed field, `examples/flowfield-store/grid.toml` (its tables in
/// `field-grid.csv`).
fn grid_scenario() -> Scenario {
    Scenario::load(&example_dir().join("grid.toml")).unwrap()
}

/// `grid.toml`'s text with `from` (which it holds) replaced by `to`, loaded beside its CSV;
/// the error's text if it is refused.
fn grid_with(from: &str, to: &str) -> Result<Scenario, String> {
    let text = std::fs::read_to_string(example_dir().join("grid.toml")).unwrap();
    assert!(text.contains(from), "grid.toml has `{from}`");
    Scenario::from_toml_str_in(
        &text.replacen(from, to, 1),
        "grid.toml",
        Some(&example_dir()),
    )
    .map_err(|e| {
        let mut message = e.to_string();
        let mut source = std::error::Error::source(&e);
        while let Some(s) = source {
            message += &format!(": {s}");
            source = s.source();
        }
        message
    })
}

/// docs/model.md section 3b's surveyed-field case, from `scripts/reference_model.py --json`
/// (`grid_case`): t, x, y, z [m], roll, pitch, yaw [deg] at the truth factors, noise-free, and
/// the increments at the reference's test state.
const GRID_ROWS: [[f64; 7]; 5] = [
    [
        0.05,
        -0.005332076848195952,
        0.00014991325438030388,
        0.08720365258462694,
        0.058009659015111376,
        1.760253562308823,
        0.03007815249254123,
    ],
    [
        0.1,
        -0.02163724321216065,
        0.0005851688114373692,
        0.27619847987788587,
        0.2358283191051284,
        5.237231929625547,
        0.12191980859811845,
    ],
    [
        0.25,
        -0.1466414673108551,
        0.0037721996765018697,
        0.9357246665180966,
        1.6441845524820502,
        15.364173113007627,
        0.8074565889143004,
    ],
    [
        0.5,
        -0.729318874537874,
        0.02659262855073167,
        2.1938183912446996,
        7.351932423399658,
        30.558263551592827,
        3.5851853811805796,
    ],
    [
        1.0,
        -4.648363942556551,
        0.31034376309366063,
        4.576442373375509,
        34.969665673498625,
        55.752821539296804,
        20.7259504550074,
    ],
];
const GRID_INCREMENTS: [f64; 6] = [
    0.21054880076970875,
    0.12500021339699766,
    0.018729630814173476,
    -0.013159815153376584,
    0.08279904238080918,
    0.008107620343778824,
];

#[test]
fn a_surveyed_field_agrees_with_the_independent_implementation() {
    let scenario = grid_scenario();
    assert_flies(&scenario, &GRID_ROWS);
    let got = loads_at_the_reference_test_state(&scenario);
    for (name, (g, e)) in ["dCX", "dCY", "dCZ", "dCl", "dCm", "dCn"]
        .iter()
        .zip(got.iter().zip(GRID_INCREMENTS))
    {
        assert!((g - e).abs() < 1e-13, "{name}: {g} vs the reference's {e}");
    }
}

#[test]
fn lanes_equal_scalar_runs_bit_for_bit_with_a_surveyed_field() {
    // A field of tables goes one run at a time through the lanes (its lookups are scalar):
    // every catalogue effect, interference_decay scaling the tables' depths.
    let sim = Simulator::new(&grid_scenario());
    crate::lanes::check_lanes_against_scalar(&sim, &sim.default_times());
}

/// The guide's analytic example field (at its flight condition, nominal factors) surveyed on a
/// grid over x and z: its upwash, sidewash, dynamic pressure ratio and rolling moment as inline
/// tables in place of the analytic field.
fn survey_of_the_analytic_field() -> String {
    let depths: Vec<f64> = (0..40).map(|k| 6.0 * (k as f64 / 39.0).powi(2)).collect();
    let xs = [-6.0, 3.0];
    let g = |z: f64| (1.0 - z / 2.0) / (1.0 + z / 0.8);
    // At Mach 0.95, alpha 0: s_M = Pg(0.95) / Pg(0.85), a0 + a_alpha (0 - 2) = 2 deg.
    let s_m = (1.0 / 0.1f64.sqrt()) * (1.0 - 0.85f64 * 0.85).sqrt();
    let table = |f: &dyn Fn(f64, f64) -> f64| {
        let planes: Vec<String> = xs
            .iter()
            .map(|&x| {
                let row: Vec<String> = depths.iter().map(|&z| format!("{:?}", f(x, z))).collect();
                format!("[{}]", row.join(", "))
            })
            .collect();
        format!(
            "{{ x_m = {xs:?}, z_m = {depths:?}, values = [{}] }}",
            planes.join(", ")
        )
    };
    let start = EXAMPLE.find("upwash_deg = 3.0").unwrap();
    let end = EXAMPLE.find("\nreference_mach").unwrap() + 1;
    let field = format!(
        "upwash_deg = {}\nsidewash_deg = {}\ndynamic_pressure_ratio = {}\nroll_cl = {}\n",
        table(&|x, z| s_m * (2.0 - 1.0 * x) * g(z)),
        table(&|x, z| s_m * (-1.5 + 0.5 * x) * g(z)),
        table(&|_, z| 1.0 + s_m * (0.9 - 1.0) * g(z)),
        table(&|_, z| s_m * -0.02 * g(z)),
    );
    // The survey is at the flight condition: no scaling with Mach.
    format!("{}{field}{}", &EXAMPLE[..start], &EXAMPLE[end..])
        .replace("reference_mach = 0.85", "reference_mach = 0.95")
}

#[test]
fn a_survey_of_the_analytic_field_flies_the_analytic_release() {
    let survey = Scenario::from_toml_str(&survey_of_the_analytic_field(), "survey").unwrap();
    assert!(survey.flowfield.as_ref().unwrap().is_grid());
    let (pos_m, att_deg) = largest_difference(&conformance_scenario(), &survey, &Factors::NOMINAL);
    // Linear in x (exact on two breakpoints), the interpolation's error in z.
    assert!(pos_m < 2e-3 && att_deg < 0.05, "{pos_m} m, {att_deg} deg");
    assert!(pos_m > 0.0, "the survey is a different path");
}

#[test]
fn the_tables_scale_with_the_aircrafts_lift_and_mach() {
    // At the reference condition the tables are the field; at the zero-lift angle its angles
    // vanish and its dynamic pressure stays; at another Mach all scale by s_M.
    let at = |alpha_deg: f64, mach: f64, p: [f64; 3]| {
        let s = grid_with("alpha_deg = 0.0", &format!("alpha_deg = {alpha_deg:?}")).unwrap();
        let mut s = s;
        s.flight.mach = mach;
        let sim = Simulator::new(&s);
        let run = sim.run_setup(&Factors::NOMINAL, &EffectSet::NONE).unwrap();
        run.flowfield.unwrap().at(p)
    };
    let p = [-1.0, 0.0, 0.5]; // a grid point: upwash 1.232594 deg, q_ratio 0.897935
    let [alpha_i, beta_i, eta] = at(2.0, 0.85, p);
    assert!(
        (alpha_i - 1.232594f64.to_radians()).abs() < 1e-15,
        "{alpha_i}"
    );
    assert!((eta - 0.897935).abs() < 1e-15, "{eta}");
    let [alpha_0, beta_0, eta_0] = at(-3.0, 0.85, p);
    assert!(alpha_0 == 0.0 && beta_0 == 0.0, "{alpha_0} {beta_0}");
    assert!((eta_0 - eta).abs() < 1e-15);
    let [alpha_m, beta_m, eta_m] = at(2.0, 0.6, p);
    let s_m = (1.0 - 0.85f64 * 0.85).sqrt() / (1.0 - 0.6f64 * 0.6).sqrt();
    assert!((alpha_m - s_m * alpha_i).abs() < 1e-15);
    assert!((beta_m - s_m * beta_i).abs() < 1e-15);
    assert!(((eta_m - 1.0) - s_m * (eta - 1.0)).abs() < 1e-15);
}

#[test]
fn a_field_of_tables_that_is_not_one_is_refused_naming_the_field() {
    let upwash = "upwash_deg = { csv = \"field-grid.csv\", column = \"upwash\" }";
    let sidewash = "sidewash_deg = { csv = \"field-grid.csv\", column = \"sidewash\" }";
    let cases = [
        (
            grid_with(upwash, "upwash_deg = { csv = \"\", column = \"upwash\" }"),
            "flowfield.upwash_deg",
            "csv = \"\": cannot read table: no file named",
        ),
        (
            grid_with(
                upwash,
                "upwash_deg = { x_m = [-3.0, 3.0], z_m = [0.0, 6.0], values = [[2.0, 46.0], [2.0, 0.0]] }",
            ),
            "flowfield.upwash_deg",
            "has 46 deg at x_m = -3, z_m = 6: expected an angle within +-45 deg",
        ),
        (
            grid_with(sidewash, "sidewash_deg = -1.5"),
            "flowfield.sidewash_deg",
            "never decaying",
        ),
        (
            grid_with("\nzero_lift", "\nhalf_depth_m = 0.8\nzero_lift"),
            "flowfield.half_depth_m",
            "tables over position",
        ),
        (
            grid_with(
                "\nzero_lift",
                "\nupwash_gradient_deg_per_m = 1.0\nzero_lift",
            ),
            "flowfield.upwash_gradient_deg_per_m",
            "along x",
        ),
        (
            grid_with("\nzero_lift", "\nupwash_per_alpha = 0.5\nzero_lift"),
            "flowfield.upwash_per_alpha",
            "zero_lift_alpha_deg",
        ),
        (
            grid_with("zero_lift_alpha_deg = -3.0", "zero_lift_alpha_deg = 2.0"),
            "flowfield.zero_lift_alpha_deg",
            "reference angle of attack",
        ),
        (
            grid_with(
                "zero_lift_alpha_deg = -3.0",
                "zero_lift_alpha_deg = 1.9999999999999998",
            ),
            "flowfield.zero_lift_alpha_deg",
            "within 0.5 deg of the reference angle of attack 2",
        ),
        (
            grid_with(
                upwash,
                "upwash_deg = { x_m = [-3.0, 3.0], z_m = [0.0, 6.0], values = [[2.0, 0.0], [2.0, 0.0]] }",
            ),
            "flowfield.sidewash_deg",
            "another grid",
        ),
        (
            grid_with(
                upwash,
                "upwash_deg = { csv = \"field-grid.csv\", column = \"q_ratio\" }",
            ),
            "flowfield.upwash_deg",
            "`q_ratio [deg]`",
        ),
        (
            grid_with(
                upwash,
                "upwash_deg = { csv = \"field-grid.csv\", column = \"upwash_deg\" }",
            ),
            "flowfield.upwash_deg",
            "no value column `upwash_deg`",
        ),
        (
            grid_with("[flowfield]", "[[flowfield]]"),
            "[[flowfield]]",
            "`flowfield` is one table, written `[flowfield]`",
        ),
        (
            grid_with(
                "[flowfield]",
                "[correction]\nfield = \"aero.cm\"\n\n[flowfield]",
            ),
            "`[correction]`",
            "`correction` is a list of tables, each written `[[correction]]`",
        ),
        (
            grid_with(upwash, "upwash_deg = { csv = \"no-such.csv\" }"),
            "flowfield.upwash_deg",
            "no-such.csv",
        ),
        (
            grid_with(
                upwash,
                "upwash_deg = { mach = [0.8, 0.9], values = [1.0, 2.0] }",
            ),
            "flowfield",
            "over x, y, z only",
        ),
        (
            grid_with(
                "dynamic_pressure_ratio = { csv = \"field-grid.csv\", column = \"q_ratio\" }",
                "dynamic_pressure_ratio = { csv = \"field-grid.csv\", column = \"roll_cl\" }",
            ),
            "flowfield.dynamic_pressure_ratio",
            "a ratio above 0",
        ),
    ];
    for (result, field, reason) in cases {
        let message = result.expect_err("refused");
        assert!(
            message.contains(field) && message.contains(reason),
            "expected `{field}` ... `{reason}`, got: {message}"
        );
    }
    // The analytic field has no zero-lift angle, nor may its shape be corrected as a table's.
    let analytic = crate::flowfield::example_with(
        "\nreference_mach",
        "\nzero_lift_alpha_deg = -3.0\nreference_mach",
    );
    let message = crate::flowfield::refusal(&analytic);
    assert!(
        message.contains("flowfield.zero_lift_alpha_deg"),
        "{message}"
    );
    let correction = "\n[[correction]]\nfield = \"flowfield.half_depth_m\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n";
    let text = std::fs::read_to_string(example_dir().join("grid.toml")).unwrap() + correction;
    let message = Scenario::from_toml_str_in(&text, "grid.toml", Some(&example_dir()))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("correction[0]") && message.contains("tables over position"),
        "{message}"
    );
}
