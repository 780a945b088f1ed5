use super::*;

fn input() -> TermInput {
    TermInput {
        t_s: 0.3,
        alpha_rad: 0.1,
        beta_rad: -0.05,
        rates_hat: [0.01, 0.02, 0.03],
        mach: 0.9,
        distance_m: 0.6,
        s_end_m: 9.144,
    }
}

#[test]
fn regressors_are_what_the_table_says() {
    let t = |regressor, locator: [f64; 2]| Term {
        axis: Axis::Cn,
        regressor,
        locator,
        coefficient: 2.0,
    };
    let x = input();
    assert!((t(Regressor::AlphaBeta, [0.0; 2]).regressor_value(&x) + 0.005).abs() < 1e-15);
    let e1 = (-1.0f64).exp();
    let e_end = (-9.144f64 / 0.6).exp();
    let f = (e1 - e_end) / (1.0 - e_end);
    let got = t(Regressor::FBeta, [0.6, 0.0]).regressor_value(&x);
    assert!((got - f * -0.05).abs() < 1e-15, "{got}");
    assert!((t(Regressor::Dm2, [0.95, 0.0]).regressor_value(&x) - 0.0025).abs() < 1e-15);
    assert!((t(Regressor::Step, [0.3, 0.0]).regressor_value(&x) - 0.5).abs() < 1e-15);
    assert!(t(Regressor::Step, [0.2, 0.0]).regressor_value(&x) > 1.0 - 1e-15);
    assert!((t(Regressor::Sin, [5.0, 0.0]).regressor_value(&x)).abs() < 1e-12);
    assert!((t(Regressor::Window, [0.3, 0.31]).regressor_value(&x) - 1.0).abs() < 1e-15);
    let mut s = TermSet::NONE;
    s.push(t(Regressor::Beta, [0.0; 2])).unwrap();
    s.push(Term {
        axis: Axis::Ejector,
        regressor: Regressor::Stroke,
        locator: [0.0; 2],
        coefficient: -0.4,
    })
    .unwrap();
    assert!((s.aero_increments(&x)[5] + 0.1).abs() < 1e-15);
    assert!((s.ejector_factor(0.0, 1.0) - 0.8).abs() < 1e-15);
    // However negative the term, the foot does not pull.
    let mut pull = TermSet::NONE;
    pull.push(Term {
        axis: Axis::Ejector,
        regressor: Regressor::Stroke,
        locator: [0.0; 2],
        coefficient: -5.0,
    })
    .unwrap();
    assert!(pull.ejector_factor(0.0, 1.0).abs() < f64::MIN_POSITIVE);
}

#[test]
fn bad_terms_are_refused_by_name() {
    let bad = Term {
        axis: Axis::Ejector,
        regressor: Regressor::Beta,
        locator: [0.0; 2],
        coefficient: 1.0,
    };
    assert_eq!(
        bad.check().unwrap_err().to_string(),
        "the flow_angle regressor `beta` cannot act on axis ejector"
    );
    let nan = Term {
        axis: Axis::Cl,
        regressor: Regressor::F,
        locator: [0.0; 2],
        coefficient: f64::NAN,
    };
    assert_eq!(
        nan.check().unwrap_err().to_string(),
        "coefficient = NaN: expected a finite number"
    );
    let lam = Term {
        coefficient: 1.0,
        ..nan
    };
    assert_eq!(
        lam.check().unwrap_err().to_string(),
        "lambda_m = 0: expected a decay length in (0, 1000] m"
    );
}

#[test]
fn extension_files_round_trip_and_bad_ones_name_line_and_field() {
    let terms = [
        Term {
            axis: Axis::Cn,
            regressor: Regressor::FBeta,
            locator: [0.6, 0.0],
            coefficient: -0.8,
        },
        Term {
            axis: Axis::Ejector,
            regressor: Regressor::Stroke,
            locator: [0.0; 2],
            coefficient: -0.3,
        },
    ];
    let text = extension_toml(&terms.iter().map(TermRecord::of).collect::<Vec<_>>());
    assert_eq!(parse_extension(&text, "e.toml").unwrap(), terms);
    let err = |text: &str| parse_extension(text, "e.toml").unwrap_err().to_string();
    let head = "format = \"sepval-extension/1\"\n\n";
    assert_eq!(
        err(&format!(
            "{head}[[term]]\naxis = \"Cn\"\nfamily = \"wobble\"\nregressor = \"x\"\ncoefficient = 1.0\n"
        )),
        "extension e.toml: line 5, term 1, `family` `wobble` is not a family of the library (expected flow_angle, rate, interference, interference_flow_angle, mach, step, oscillation, ejector_stroke)"
    );
    assert!(
        err(&format!(
            "{head}[[term]]\naxis = \"Cn\"\nfamily = \"rate\"\nregressor = \"r\"\n"
        ))
        .contains("missing field `coefficient`")
    );
    assert_eq!(
        err(&format!(
            "{head}[[term]]\naxis = \"Cn\"\nfamily = \"rate\"\nregressor = \"r\"\ncoefficient = nan\n"
        )),
        "extension e.toml: line 7, term 1, `coefficient` coefficient = NaN: expected a finite number"
    );
    assert_eq!(
        err(&format!(
            "{head}[[term]]\naxis = \"Cz\"\nfamily = \"rate\"\nregressor = \"r\"\ncoefficient = 1\n"
        )),
        "extension e.toml: line 4, term 1, `axis` `Cz` is not an axis (expected CA, CY, CZ, Cl, Cm, Cn or ejector)"
    );
    assert_eq!(
        err(&format!(
            "{head}[[term]]\naxis = \"ejector\"\nfamily = \"rate\"\nregressor = \"r\"\ncoefficient = 1\n"
        )),
        "extension e.toml: line 4, term 1, `axis` the rate regressor `r` cannot act on axis ejector"
    );
    assert_eq!(
        err(&format!(
            "{head}[[term]]\naxis = \"Cn\"\nfamily = \"step\"\nregressor = \"step\"\ncoefficient = 1\n"
        )),
        "extension e.toml: line 3, term 1, `t_on_s` is missing: step needs it"
    );
}
