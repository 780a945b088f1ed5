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
        Some(Target::Field(FieldShape::Reversal))
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
