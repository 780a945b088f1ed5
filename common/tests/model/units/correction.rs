//! The unit tests of `sepval_common::correction`.

use sepval_common::correction::*;
use sepval_common::table::Variable;

fn record(field: &str, variable: &str, breakpoints: &[f64]) -> CorrectionRecord {
    CorrectionRecord {
        field: field.into(),
        variable: variable.into(),
        breakpoints: breakpoints.to_vec(),
    }
}

#[test]
fn interpolation_is_linear_between_breakpoints_and_held_beyond_them() {
    let b = [0.0, 1.0, 3.0];
    let v = [2.0, 4.0, 0.0];
    for (x, want) in [
        (-5.0, 2.0),
        (0.0, 2.0),
        (0.5, 3.0),
        (1.0, 4.0),
        (2.0, 2.0),
        (3.0, 0.0),
        (9.0, 0.0),
    ] {
        assert!((interpolate(&b, &v, x) - want).abs() < 1e-15, "{x}");
        let w = weights(&b, x);
        let dot: f64 = w.iter().zip(v).map(|(w, v)| w * v).sum();
        assert!((dot - want).abs() < 1e-15, "{x}");
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }
    assert!((interpolate(&[0.7], &[1.5], 100.0) - 1.5).abs() < 1e-15);
}

#[test]
fn every_field_names_itself_and_back() {
    for t in Target::all() {
        assert_eq!(Target::of_field(&t.field()), Some(t));
    }
    assert_eq!(Target::all().len(), 19);
    for t in Target::every() {
        assert_eq!(Target::of_field(&t.field()), Some(t));
    }
    assert_eq!(
        Target::of_field("flowfield.reversal_m"),
        Some(Target::Field(FieldPart::Reversal))
    );
    assert_eq!(Target::table_of_field("flowfield.half_depth_m"), None);
    assert_eq!(
        Target::of_field("aero.cm_q_per_rad").map(Target::axis),
        Some(4)
    );
}

#[test]
fn records_are_checked_with_a_message_naming_what_is_wrong() {
    let c = record("aero.cm", "alpha_deg", &[-2.0, 0.0, 4.0])
        .correction()
        .unwrap();
    assert_eq!(c.target, Target::Static(4));
    assert_eq!(c.variable, Variable::Alpha);
    let e = record("aero.cmm", "alpha_deg", &[0.0])
        .correction()
        .unwrap_err();
    assert!(e.to_string().contains("`aero.cmm` is not a field"), "{e}");
    let e = record("interference.dcz0", "alpha_deg", &[0.0, 1.0])
        .correction()
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "`variable` `alpha_deg`: interference.dcz0 may be corrected over distance_m only"
    );
    let e = record("aero.cm_alpha_per_rad", "mach", &[0.9, 0.8])
        .correction()
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "`breakpoints` are not strictly increasing (0.9 then 0.8)"
    );
    let e = record("aero.cz", "beta_deg", &[0.0, f64::NAN])
        .correction()
        .unwrap_err();
    assert!(e.to_string().contains("NaN"), "{e}");
    let e = record("aero.cz", "beta_deg", &[]).correction().unwrap_err();
    assert!(e.to_string().contains("empty"), "{e}");
    let many: Vec<CorrectionRecord> = (0..5)
        .map(|_| {
            record(
                "aero.cm",
                "alpha_deg",
                &(0..20).map(f64::from).collect::<Vec<_>>(),
            )
        })
        .collect();
    let (at, e) = check_all(&many).unwrap_err();
    assert_eq!(at, 3);
    assert!(e.to_string().contains("at most 64"), "{e}");
}

#[test]
fn a_run_folds_mach_corrections_and_keeps_the_others_for_the_force_evaluation() {
    let corrections = check_all(&[
        record("aero.ca0", "mach", &[0.8, 1.0]),
        record("aero.cm_alpha_per_rad", "mach", &[0.9]),
        record("aero.cm", "alpha_deg", &[0.0, 10.0]),
        record("interference.dcz0", "distance_m", &[0.0, 1.0, 2.0]),
    ])
    .unwrap();
    let values = CorrectionValues::of(&[0.1, 0.3, -0.5, 0.0, 0.2, 1.0, 0.5, 0.0]).unwrap();
    let (run, folded) = CorrectionRun::new(&corrections, &values, 0.9).unwrap();
    assert!((folded.statics[0] - 0.2).abs() < 1e-15);
    assert!((folded.derivatives[2] + 0.5).abs() < 1e-15);
    assert!(!run.is_empty());
    let d = run.evaluate(5f64.to_radians(), 0.0, 0.5);
    assert!((d[4] - 0.1).abs() < 1e-15, "{d:?}");
    assert!((d[6 + 2] - 0.75).abs() < 1e-15, "{d:?}");
    assert_eq!(d.iter().filter(|x| **x != 0.0).count(), 2);
    // No values: nothing at all.
    let (none, folded) = CorrectionRun::new(&corrections, &CorrectionValues::NONE, 0.9).unwrap();
    assert!(none.is_empty());
    assert_eq!(folded, Folded::default());
    // The wrong number of values, or one not finite, is refused.
    let e = CorrectionRun::new(&corrections, &CorrectionValues::of(&[0.0; 7]).unwrap(), 0.9)
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "the candidate carries 7 correction values, the scenario's corrections have 8 breakpoints"
    );
    let mut bad = [0.0; 8];
    bad[5] = f64::INFINITY;
    let e =
        CorrectionRun::new(&corrections, &CorrectionValues::of(&bad).unwrap(), 0.9).unwrap_err();
    assert!(e.to_string().contains("correction value 5 is inf"), "{e}");
    assert!(CorrectionValues::of(&[0.0; 65]).is_err());
}

/// The guide's example store under a field with corrections of its shape over Mach.
fn field_store_with_shape_corrections() -> sepval_common::scenario::Scenario {
    let mut text = include_str!("../../../../examples/flowfield-store/scenario.toml").to_string();
    text.push_str(
        "\n[[correction]]\nfield = \"flowfield.half_depth_m\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n\
         \n[[correction]]\nfield = \"flowfield.reversal_m\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n",
    );
    sepval_common::scenario::Scenario::from_toml_str(&text, "field").unwrap()
}

#[test]
fn the_fields_shape_is_corrected_through_its_inverses_and_kept_a_field_that_decays() {
    use sepval_common::effects::EffectSet;
    use sepval_common::extension::TermSet;
    use sepval_common::model::RunSetup;
    use sepval_common::simulation::Simulator;
    use sepval_core::factors::Factors;
    let s = field_store_with_shape_corrections();
    let sim = Simulator::new(&s);
    let run = |v: &[f64]| {
        let values = CorrectionValues::of(v).unwrap();
        RunSetup::with_corrections(
            sim.model(),
            &Factors::TRUTH,
            &EffectSet::NONE,
            &TermSet::NONE,
            &values,
        )
    };
    // The example's field halves at 0.8 m and reverses at 2 m.
    let field = run(&[0.25, -0.1]).unwrap().flowfield.unwrap();
    assert!((field.inv_half_depth_per_m() - (1.0 / 0.8 + 0.25)).abs() < 1e-15);
    assert!((field.inv_reversal_per_m - (0.5 - 0.1)).abs() < 1e-15);
    // Without values the field is the scenario's, to the bit.
    let plain = run(&[]).unwrap().flowfield.unwrap();
    assert_eq!(
        plain.inv_half_depth_per_m().to_bits(),
        (1.0f64 / 0.8).to_bits()
    );
    // A field that would not decay, or would grow with depth, is refused, naming the part.
    let refused = |v: &[f64]| match run(v) {
        Ok(_) => panic!("{v:?} was not refused"),
        Err(e) => e.to_string(),
    };
    let e = refused(&[-1.25, 0.0]);
    assert!(e.contains("1 / half_depth_m"), "{e}");
    let e = refused(&[0.0, -0.6]);
    assert!(e.contains("1 / reversal_m"), "{e}");
}

#[test]
fn a_correction_of_the_fields_shape_needs_a_field() {
    use sepval_common::scenario::Scenario;
    let text = Scenario::embedded_default().to_toml_string()
        + "\n[[correction]]\nfield = \"flowfield.reversal_m\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n";
    let e = Scenario::from_toml_str(&text, "no field").unwrap_err();
    assert!(
        e.to_string()
            .contains("the scenario has no [flowfield] to correct"),
        "{e}"
    );
    let e = record("flowfield.reversal_m", "depth_m", &[0.0, 1.0])
        .correction()
        .unwrap_err();
    assert!(
        e.to_string().contains("may be corrected over mach only"),
        "{e}"
    );
}

/// The guide's example store under its field at an aircraft angle of attack of 5 deg (3 deg
/// from the field's reference), with `extra` appended.
fn field_store_at_alpha_5(extra: &str) -> sepval_common::scenario::Scenario {
    let text = include_str!("../../../../examples/flowfield-store/scenario.toml")
        .replace("alpha_deg = 0.0", "alpha_deg = 5.0")
        + extra;
    sepval_common::scenario::Scenario::from_toml_str(&text, "field").unwrap()
}

/// The run of `s` with the correction values `v` (none: the scenario's own run).
fn corrected_run(
    s: &sepval_common::scenario::Scenario,
    v: &[f64],
) -> Result<sepval_common::model::RunSetup, sepval_common::model::ModelError> {
    use sepval_common::effects::EffectSet;
    use sepval_common::extension::TermSet;
    use sepval_common::model::RunSetup;
    use sepval_common::simulation::Simulator;
    use sepval_core::factors::Factors;
    let sim = Simulator::new(s);
    RunSetup::with_corrections(
        sim.model(),
        &Factors::TRUTH,
        &EffectSet::NONE,
        &TermSet::NONE,
        &CorrectionValues::of(v).unwrap(),
    )
}

#[test]
fn the_fields_change_with_alpha_is_corrected_as_the_store_written_with_it() {
    const PER_ALPHA: &str = "\n[[correction]]\nfield = \"flowfield.upwash_per_alpha\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n\
         \n[[correction]]\nfield = \"flowfield.sidewash_per_alpha\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n";
    let s = field_store_at_alpha_5(PER_ALPHA);
    let corrected = corrected_run(&s, &[0.3, -0.2]).unwrap().flowfield.unwrap();
    // The store with a_alpha 0.5 + 0.3 and b_alpha 0 - 0.2, as `update` writes it.
    let mut merged = field_store_at_alpha_5("");
    let f = merged.flowfield.as_mut().unwrap();
    f.upwash_per_alpha += 0.3;
    f.sidewash_per_alpha -= 0.2;
    let written = corrected_run(&merged, &[]).unwrap().flowfield.unwrap();
    for p in [[0.0, 0.0, 0.0], [1.0, 0.1, 0.6], [-1.5, 0.0, 2.5]] {
        let (a, b) = (corrected.at(p), written.at(p));
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() < 1e-15, "{p:?}: {a:?} against {b:?}");
        }
    }
    // The correction changes the field: 3 deg of alpha times 0.3 deg/deg of upwash, times
    // czintfac and s_M.
    let plain = corrected_run(&s, &[]).unwrap().flowfield.unwrap();
    let up = corrected.at([0.0; 3])[0] - plain.at([0.0; 3])[0];
    let truth = sepval_core::factors::Factors::TRUTH.get(sepval_core::factors::Factor::Czintfac);
    let s_m = (1.0f64 - 0.85 * 0.85).sqrt() / 0.1f64.sqrt();
    assert!(
        (up - truth * s_m * 0.9f64.to_radians()).abs() < 1e-15,
        "{up}"
    );
    // Without values, the scenario's field to the bit.
    assert_eq!(
        plain,
        corrected_run(&field_store_at_alpha_5(""), &[])
            .unwrap()
            .flowfield
            .unwrap()
    );
}

#[test]
fn a_correction_of_the_stores_slopes_is_the_slopes_the_field_acts_through() {
    const SLOPES: &str = "\n[[correction]]\nfield = \"aero.cn_beta_per_rad\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n\
         \n[[correction]]\nfield = \"aero.cz_alpha_per_rad\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n";
    let s = field_store_at_alpha_5(SLOPES);
    let corrected = corrected_run(&s, &[0.2, 0.5]).unwrap().flowfield.unwrap();
    let mut merged = field_store_at_alpha_5("");
    let text = merged
        .to_toml_string()
        .replace(
            "cn_beta_per_rad = -0.3",
            "cn_beta_per_rad = -0.09999999999999998",
        )
        .replace("cz_alpha_per_rad = -6.0", "cz_alpha_per_rad = -5.5");
    merged = sepval_common::scenario::Scenario::from_toml_str(&text, "merged").unwrap();
    let written = corrected_run(&merged, &[]).unwrap().flowfield.unwrap();
    assert_eq!(corrected.slopes_per_rad(), written.slopes_per_rad());
    for side in 0..2 {
        for k in 0..corrected.stations {
            let (a, b) = (corrected.weights[side][k], written.weights[side][k]);
            assert!(
                (a - b).abs() < 1e-14,
                "side {side} station {k}: {a} against {b}"
            );
        }
    }
    // The weights moved: the side force's centre of pressure is another.
    let plain = corrected_run(&s, &[]).unwrap().flowfield.unwrap();
    assert!((plain.weights[1][0] - corrected.weights[1][0]).abs() > 1e-3);
}

#[test]
fn a_field_with_a_shape_table_takes_corrections_of_the_stores_data_and_its_alpha_slope() {
    let table = "shape = { depth_m = [0.0, 0.3, 0.9, 1.6, 2.5], g = [1.0, 0.62, 0.2, -0.07, 0.0] }";
    let text = include_str!("../../../../examples/flowfield-store/scenario.toml")
        .replace("alpha_deg = 0.0", "alpha_deg = 5.0")
        .replace("half_depth_m = 0.8 ", &format!("{table} #"))
        .replace("reversal_m = 2.0 ", "#")
        + "\n[[correction]]\nfield = \"aero.cm\"\nvariable = \"alpha_deg\"\nbreakpoints = [0.0, 10.0]\n\
           \n[[correction]]\nfield = \"flowfield.upwash_per_alpha\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n";
    let s = sepval_common::scenario::Scenario::from_toml_str(&text, "table").unwrap();
    let run = corrected_run(&s, &[0.01, 0.02, 0.3])
        .unwrap()
        .flowfield
        .unwrap();
    let plain = corrected_run(&s, &[]).unwrap().flowfield.unwrap();
    let up = run.at([0.0; 3])[0] - plain.at([0.0; 3])[0];
    assert!((up - plain.per_alpha_rad[0] * 0.3).abs() < 1e-15, "{up}");
    assert!(up > 0.01, "{up}");
    // Its shape is not corrected: a scenario asking it is refused, naming why.
    let e = sepval_common::scenario::Scenario::from_toml_str(
        &(text + "\n[[correction]]\nfield = \"flowfield.half_depth_m\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n"),
        "table",
    )
    .unwrap_err();
    assert!(e.to_string().contains("shape is a table"), "{e}");
}

#[test]
fn a_field_of_tables_over_position_has_no_alpha_slope_to_correct() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/flowfield-store");
    let text = std::fs::read_to_string(dir.join("grid.toml")).unwrap()
        + "\n[[correction]]\nfield = \"flowfield.sidewash_per_alpha\"\nvariable = \"mach\"\nbreakpoints = [0.95]\n";
    let e = sepval_common::scenario::Scenario::from_toml_str_in(&text, "grid.toml", Some(&dir))
        .unwrap_err();
    assert!(e.to_string().contains("correction[0]"), "{e}");
    assert!(
        e.to_string()
            .contains("no upwash_per_alpha or sidewash_per_alpha"),
        "{e}"
    );
}

/// The guide's example store at alpha 5 deg with the conformance case's shape table in place of
/// its half depth and reversal depth (docs/model.md section 3b, "The shape as a table"), and
/// `extra` appended.
fn shape_table_store(extra: &str) -> Result<sepval_common::scenario::Scenario, String> {
    let table = "shape = { depth_m = [0.0, 0.3, 0.9, 1.6, 2.5], g = [1.0, 0.62, 0.2, -0.07, 0.0] }";
    let text = include_str!("../../../../examples/flowfield-store/scenario.toml")
        .replace("alpha_deg = 0.0", "alpha_deg = 5.0")
        .replace("half_depth_m = 0.8 ", &format!("{table} #"))
        .replace("reversal_m = 2.0 ", "#")
        + extra;
    sepval_common::scenario::Scenario::from_toml_str(&text, "table").map_err(|e| e.to_string())
}

/// A correction of the shape table over depth with the breakpoints `b`.
fn shape_correction(b: &str) -> String {
    format!(
        "\n[[correction]]\nfield = \"flowfield.shape\"\nvariable = \"z_m\"\nbreakpoints = {b}\n"
    )
}

#[test]
fn a_shape_table_is_corrected_over_depth_as_the_store_written_with_it() {
    let s = shape_table_store(&shape_correction("[0.0, 0.5, 2.0]")).unwrap();
    let change = [0.0, -0.1, 0.05];
    let corrected = corrected_run(&s, &change).unwrap().flowfield.unwrap();
    // The store written: the table on the union of the depths, the sum at each.
    let (depth, g) = corrected_shape(
        &[0.0, 0.3, 0.9, 1.6, 2.5],
        &[1.0, 0.62, 0.2, -0.07, 0.0],
        &[0.0, 0.5, 2.0],
        &change,
    )
    .unwrap();
    assert_eq!(depth, [0.0, 0.3, 0.5, 0.9, 1.6, 2.0, 2.5]);
    let mut merged = shape_table_store("").unwrap();
    let shape = merged.flowfield.as_mut().unwrap().shape.as_mut().unwrap();
    (shape.depth_m, shape.g) = (depth, g);
    let written = corrected_run(&merged, &[]).unwrap().flowfield.unwrap();
    for z in [-0.2, 0.0, 0.2, 0.5, 0.7, 1.2, 1.8, 2.2, 3.0, 9.0] {
        let (a, b) = (corrected.at([0.3, 0.0, z]), written.at([0.3, 0.0, z]));
        assert_eq!(
            a.map(f64::to_bits),
            b.map(f64::to_bits),
            "z {z}: {a:?} against {b:?}"
        );
    }
    // The sum of the two piecewise-linear functions: at 0.7 m, g 0.62 + (0.2 - 0.62) 0.4/0.6
    // and c -0.1 + 0.15 (0.2/1.5).
    let g = corrected.shape.unwrap().at(0.7);
    let want = 0.62 + (0.2 - 0.62) * (0.4 / 0.6) + (-0.1 + 0.15 * (0.2 / 1.5));
    assert!((g - want).abs() < 1e-15, "{g} against {want}");
    // Without values, the table as given, to the bit.
    let plain = corrected_run(&s, &[]).unwrap().flowfield.unwrap();
    assert_eq!(
        plain,
        corrected_run(&shape_table_store("").unwrap(), &[])
            .unwrap()
            .flowfield
            .unwrap()
    );
}

#[test]
fn a_correction_of_the_shape_table_is_refused_where_it_cannot_be_one() {
    // A change at carriage would make g(0) other than 1.
    let s = shape_table_store(&shape_correction("[0.0, 1.0]")).unwrap();
    let e = match corrected_run(&s, &[0.1, 0.0]) {
        Ok(_) => panic!("a change at carriage was not refused"),
        Err(e) => e.to_string(),
    };
    assert!(e.contains("at carriage: expected 1"), "{e}");
    // Breakpoints not from depth 0.
    let e = shape_table_store(&shape_correction("[0.2, 1.0]")).unwrap_err();
    assert!(
        e.contains("correction[0]") && e.contains("starts at depth 0"),
        "{e}"
    );
    // More depths together than a table holds.
    let many: Vec<String> = (0..30).map(|k| format!("{}.05", k)).collect();
    let e =
        shape_table_store(&shape_correction(&format!("[0.0, {}]", many.join(", ")))).unwrap_err();
    assert!(e.contains("depths together: expected at most 32"), "{e}");
    // A field whose shape is analytic has no table to correct.
    let text = include_str!("../../../../examples/flowfield-store/scenario.toml").to_string()
        + &shape_correction("[0.0, 1.0]");
    let e = sepval_common::scenario::Scenario::from_toml_str(&text, "analytic").unwrap_err();
    assert!(
        e.to_string()
            .contains("no [flowfield] shape table to correct"),
        "{e}"
    );
}
