//! Tabulated coefficients (docs/model.md sections 1 and 3, "Tables"): the default written as
//! tables reproduces the constant form, tables travel inline and are covered by the content
//! hash, leaving a table holds its edge and is recorded, and bad tables are refused with their
//! file, line and column.

use std::path::Path;

use sepval_common::effects::EffectSet;
use sepval_common::scenario::Scenario;
use sepval_common::simulation::Simulator;
use sepval_common::table::{Kind, read_csv};
use sepval_common::table_form::table_form;
use sepval_common::telemetry::Trajectory;
use sepval_core::factors::Factors;

/// Writes `form` into `dir` and loads it as a user would.
pub(crate) fn write_and_load(dir: &Path, interference: bool) -> Scenario {
    let form = table_form(&Scenario::embedded_default(), interference).unwrap();
    for (p, text) in &form.files {
        std::fs::create_dir_all(dir.join(p).parent().unwrap()).unwrap();
        std::fs::write(dir.join(p), text).unwrap();
    }
    let path = dir.join("scenario.toml");
    std::fs::write(&path, form.scenario.to_toml_string()).unwrap();
    Scenario::load(&path).unwrap()
}

/// Largest difference of positions \[m\] and angles \[deg\] between two trajectories.
fn max_difference(a: &Trajectory, b: &Trajectory) -> (f64, f64) {
    let mut d = (0.0f64, 0.0f64);
    for k in 0..a.len() {
        for j in 0..3 {
            d.0 = d.0.max((a.pos_m[k][j] - b.pos_m[k][j]).abs());
            d.1 = d.1.max((a.att_deg[k][j] - b.att_deg[k][j]).abs());
        }
    }
    d
}

#[test]
fn default_as_tables_reproduces_the_constant_form() {
    let dir = tempfile::tempdir().unwrap();
    let constant = Simulator::embedded_default();
    let times = constant.default_times();
    // Truth factors: offsets on every coefficient, multipliers on every increment.
    let reference = constant
        .simulate(&Factors::TRUTH, &EffectSet::NONE, &times)
        .unwrap();

    // The aerodynamics as tables (linear in alpha and beta: interpolated exactly to rounding).
    let aero = Simulator::new(&write_and_load(dir.path(), false));
    let (traj, log) = aero
        .simulate_logged(&Factors::TRUTH, &EffectSet::NONE, &times)
        .unwrap();
    let (dp, da) = max_difference(&traj, &reference);
    assert!(dp <= 1e-9 && da <= 1e-9, "{dp} m, {da} deg");
    assert!(aero.table_excursions(&log).is_empty());
    assert!(log.tables.evaluations >= 8000, "{}", log.tables.evaluations);
    // Mach tables that contain the flight Mach fold into constants: the contract's path, the
    // same bits.
    let mach = edited(
        "cm_q_per_rad = -80.0",
        "cm_q_per_rad = { mach = [0.5, 1.5], values = [-80.0, -80.0] }",
    );
    let folded = Simulator::new(&mach);
    let (traj, log) = folded
        .simulate_logged(&Factors::TRUTH, &EffectSet::NONE, &times)
        .unwrap();
    assert_eq!(max_difference(&traj, &reference), (0.0, 0.0));
    assert_eq!(log.tables.evaluations, 0);

    // The interference as tables too: f(s) sampled on the graded grid of `table_form`, linear
    // between breakpoints (measured: 5.9e-5 m and 3.6e-3 deg at the truth factors).
    let dir = tempfile::tempdir().unwrap();
    let all = Simulator::new(&write_and_load(dir.path(), true));
    let (traj, log) = all
        .simulate_logged(&Factors::TRUTH, &EffectSet::NONE, &times)
        .unwrap();
    let (dp, da) = max_difference(&traj, &reference);
    assert!(dp <= 1e-4 && da <= 1e-2, "{dp} m, {da} deg");
    assert!(
        dp > 1e-9,
        "the sampled interference should differ a little: {dp}"
    );
    assert!(all.table_excursions(&log).is_empty());
}

#[test]
fn tables_travel_inline_and_the_hash_covers_their_contents() {
    let dir = tempfile::tempdir().unwrap();
    let loaded = write_and_load(dir.path(), true);
    assert!(loaded.has_tables());
    assert_ne!(
        loaded.content_hash(),
        Scenario::embedded_default().content_hash()
    );
    // What a job setup carries: the TOML, tables inline, read without the files.
    let text = loaded.to_toml_string();
    assert!(!text.contains(".csv"), "tables travel inline");
    let back = Scenario::from_toml_str(&text, "setup").unwrap();
    assert_eq!(back, loaded);
    assert_eq!(back.content_hash(), loaded.content_hash());
    // One value changed in one file changes the hash.
    let path = dir.path().join("tables/aero_damping.csv");
    let csv = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, csv.replacen("-80.0", "-80.5", 1)).unwrap();
    let changed = Scenario::load(&dir.path().join("scenario.toml")).unwrap();
    assert_ne!(changed.content_hash(), loaded.content_hash());
    // A constant scenario's hash is what it was before tables existed (checkpoints keep it).
    assert_eq!(
        Scenario::embedded_default().content_hash(),
        Scenario::from_toml_str(&Scenario::embedded_default().to_toml_string(), "x")
            .unwrap()
            .content_hash()
    );
}

/// The default scenario with `replace` applied to its text (must match).
fn edited(from: &str, to: &str) -> Scenario {
    let text = sepval_common::scenario::DEFAULT_SCENARIO_TOML;
    assert!(text.contains(from), "{from}");
    Scenario::from_toml_str(&text.replace(from, to), "edited").unwrap()
}

#[test]
fn leaving_a_table_holds_its_edge_and_is_recorded() {
    // CZ tabulated over alpha within +-1 deg only: the store's alpha leaves it.
    let narrow = edited(
        "cz_alpha_per_rad = -6.0",
        "cz = { alpha_deg = [-1.0, 1.0], values = [0.10471975511965977, -0.10471975511965977] }",
    );
    let sim = Simulator::new(&narrow);
    let (_, log) = sim
        .simulate_logged(&Factors::NOMINAL, &EffectSet::NONE, &sim.default_times())
        .unwrap();
    let left = sim.table_excursions(&log);
    assert_eq!(left.len(), 1, "{left:?}");
    let e = &left[0];
    assert_eq!(e.table, "aero.cz");
    assert!(e.evaluations_outside > 0 && e.evaluations_outside <= e.evaluations);
    assert_eq!(e.axes[0].variable, "alpha_deg");
    assert_eq!(e.axes[0].range, [-1.0, 1.0]);
    assert!(e.axes[0].worst_excursion > 0.5, "{e}");
    assert!(e.to_string().starts_with("left table `aero.cz` in "), "{e}");

    // Held at the edge: inside [-1, 1] deg the table is the linear term, beyond it CZ stays at
    // the edge value, so the run differs from the constant form.
    let constant = Simulator::embedded_default();
    let a = constant
        .simulate(
            &Factors::NOMINAL,
            &EffectSet::NONE,
            &constant.default_times(),
        )
        .unwrap();
    let b = sim
        .simulate(&Factors::NOMINAL, &EffectSet::NONE, &sim.default_times())
        .unwrap();
    assert!(max_difference(&a, &b).1 > 0.01);

    // A Mach table left: every evaluation is outside.
    let mach = edited(
        "cm_q_per_rad = -80.0",
        "cm_q_per_rad = { mach = [0.5, 0.8], values = [-70.0, -80.0] }",
    );
    let sim = Simulator::new(&mach);
    let (_, log) = sim
        .simulate_logged(&Factors::NOMINAL, &EffectSet::NONE, &sim.default_times())
        .unwrap();
    let left = sim.table_excursions(&log);
    assert_eq!(left.len(), 1);
    assert_eq!(left[0].evaluations_outside, left[0].evaluations);
    assert!((left[0].axes[0].worst_excursion - 0.15).abs() < 1e-12);
    // The edge value (-80 at Mach 0.8) is the constant form's: the same run.
    let c = Simulator::embedded_default()
        .simulate(&Factors::NOMINAL, &EffectSet::NONE, &sim.default_times())
        .unwrap();
    let d = sim
        .simulate(&Factors::NOMINAL, &EffectSet::NONE, &sim.default_times())
        .unwrap();
    assert_eq!(max_difference(&c, &d), (0.0, 0.0));
}

#[test]
fn interpolation_in_mach_alpha_and_lateral_offset() {
    // A derivative at Mach 0.95 between breakpoints 0.9 and 1.0: the midpoint value.
    let s = edited(
        "cm_q_per_rad = -80.0",
        "cm_q_per_rad = { mach = [0.9, 1.0], values = [-70.0, -90.0] }",
    );
    let m = Simulator::new(&s);
    assert!((m.model().aero_at_mach.cm_q_per_rad - -80.0).abs() < 1e-12);
    // An interference increment over distance, alpha and lateral offset is accepted in nesting
    // order and refused out of it.
    let ok = "dcm0 = { distance_m = [0.0, 5.0], alpha_deg = [-10.0, 10.0], lateral_m = [-1.0, 1.0], values = [[[-1.5, -1.5], [-1.5, -1.5]], [[0.0, 0.0], [0.0, 0.0]]] }";
    let s = edited("dcm0 = -1.50", ok);
    assert!(s.has_tables());
    let bad = "dcm0 = { mach = [0.5, 1.0], distance_m = [0.0, 5.0], values = [[-1.5, 0.0], [-1.5, 0.0]] }";
    let e = Scenario::from_toml_str(
        &sepval_common::scenario::DEFAULT_SCENARIO_TOML.replace("dcm0 = -1.50", bad),
        "x.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("line 42, column 8")
            && e.contains(
                "is a table over mach: an interference increment may be tabulated over distance, alpha, lateral only"
            ),
        "{e}"
    );
    let bad = "dcm0 = { alpha_deg = [-10.0, 10.0], values = [-1.5, 0.0] }";
    let e = Scenario::from_toml_str(
        &sepval_common::scenario::DEFAULT_SCENARIO_TOML.replace("dcm0 = -1.50", bad),
        "x.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains(
            "has no distance axis: an interference increment is tabulated over distance at least"
        ),
        "{e}"
    );
    // Breakpoints outside the variable's domain (docs/model.md section 1, "Tables"): the same
    // limits as a DAVE-ML file's (docs/daveml.md).
    for (bad, said) in [
        (
            "cm_q_per_rad = { mach = [-5.0, 1.5], values = [-80.0, -80.0] }",
            "axis mach breakpoint -5 is outside mach's domain, 0 to 3",
        ),
        (
            "cm_q_per_rad = { mach = [0.5, 1e200], values = [-80.0, -80.0] }",
            "axis mach breakpoint 1e200 is outside mach's domain, 0 to 3",
        ),
        (
            "dcm0 = { distance_m = [0.0, 5.0], lateral_m = [-1e6, 1.0], values = [[-1.5, -1.5], [0.0, 0.0]] }",
            "axis lateral breakpoint -1000000 is outside lateral's domain, -100000 to 100000 m",
        ),
    ] {
        let field = bad.split_once(' ').unwrap().0;
        let old = if field == "dcm0" {
            "dcm0 = -1.50"
        } else {
            "cm_q_per_rad = -80.0"
        };
        let text = sepval_common::scenario::DEFAULT_SCENARIO_TOML.replace(old, bad);
        assert_ne!(text, sepval_common::scenario::DEFAULT_SCENARIO_TOML);
        let e = Scenario::from_toml_str(&text, "x.toml").unwrap_err();
        let chain = format!(
            "{e} {}",
            std::error::Error::source(&e)
                .map(|s| s.to_string())
                .unwrap_or_default()
        );
        assert!(chain.contains(said), "{chain}");
    }
    // Ragged inline rows.
    let bad = "cz = { mach = [0.5, 1.0], alpha_deg = [-10.0, 0.0, 10.0], values = [[1.0, 0.0, -1.0], [1.0, -1.0]] }";
    let e = Scenario::from_toml_str(
        &sepval_common::scenario::DEFAULT_SCENARIO_TOML.replace("cz_alpha_per_rad = -6.0", bad),
        "x.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("line 29, column 6")
            && e.contains(
                "`values` row 1 has 2 values, expected 3 (one per breakpoint of the alpha axis)"
            ),
        "{e}"
    );
}

/// Writes `text` as a table file and reads it as `kind`; the error message.
fn refused(text: &str, kind: Kind) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.csv");
    std::fs::write(&path, text).unwrap();
    let e = read_csv(&path, None, kind).unwrap_err().to_string();
    e.replace(&path.display().to_string(), "t.csv")
}

#[test]
fn bad_table_files_are_refused_with_file_line_and_column() {
    assert_eq!(
        refused(
            "mach [-],alpha [deg],cz [-]\n0.5,0,0\n0.5,5,1\n0.5,3,2\n",
            Kind::Static
        ),
        "t.csv: line 4, column 2 (`alpha [deg]`): breakpoints are not strictly increasing: 3 after 5 (rows are in row-major order, the first axis slowest)"
    );
    // Rows out of order (the first axis fastest): said so at the row, not "1 breakpoint".
    assert_eq!(
        refused(
            "mach [-],alpha [deg],cz [-]\n0.5,0,0\n0.9,0,0\n0.5,5,1\n0.9,5,1\n",
            Kind::Static
        ),
        "t.csv: line 3, column 1 (`mach [-]`): the rows are out of order: mach [-] changes here before alpha [deg] has gone through its breakpoints (rows list every grid point in row-major order, the first axis slowest, the last fastest): sort them so"
    );
    assert_eq!(
        refused("mach [-],cz [-]\n0.5,0\n0.9,NaN\n", Kind::Static),
        "t.csv: line 3, column 2 (`cz [-]`): expected a finite number, found `NaN`"
    );
    assert_eq!(
        refused("mach [-],cz [-]\n0.5,0\n0.9,inf\n", Kind::Static),
        "t.csv: line 3, column 2 (`cz [-]`): expected a finite number, found `inf`"
    );
    assert_eq!(
        refused("mach [-],cz [-]\n0.5,0\n0.9,1,2\n", Kind::Static),
        "t.csv: line 3: expected 2 fields as in the header, found 3"
    );
    assert_eq!(
        refused("mach,cz [-]\n0.5,0\n0.9,1\n", Kind::Static),
        "t.csv: line 1, column 1: `mach` has no unit: write it as `mach [-]`"
    );
    assert_eq!(
        refused("mach [-],cm_q [1/s]\n0.5,0\n0.9,1\n", Kind::Derivative),
        "t.csv: line 1, column 2: unknown unit in `cm_q [1/s]`: expected `cm_q [1/rad]` or `cm_q [1/deg]`"
    );
    assert_eq!(
        refused("alpha [deg],cm_q [1/rad]\n0,0\n1,1\n", Kind::Derivative),
        "t.csv: line 1, column 1: `alpha [deg]`: a derivative may be tabulated over mach only, not over alpha"
    );
    assert_eq!(
        refused(
            "# comment\nmach [-],alpha [deg],cz [-]\n0.5,0,0\n0.5,5,1\n0.9,0,0\n0.9,6,1\n",
            Kind::Static
        ),
        "t.csv: line 6, column 2 (`alpha [deg]`): expected 5 here: rows list every grid point in row-major order (the first axis slowest)"
    );
    // Units convert: alpha in rad, a derivative per degree.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.csv");
    std::fs::write(&path, "mach [-],cm_alpha [1/deg]\n0.5,0.01\n0.9,0.02\n").unwrap();
    let t = read_csv(&path, None, Kind::Derivative).unwrap();
    assert!((t.values()[1] - 0.02f64.to_degrees()).abs() < 1e-15);
    std::fs::write(&path, "alpha [rad],cz [-]\n-0.5,0\n0.5,1\n").unwrap();
    let t = read_csv(&path, None, Kind::Static).unwrap();
    assert!((t.axes()[0].breakpoints[1] - 0.5f64.to_degrees()).abs() < 1e-12);
}
