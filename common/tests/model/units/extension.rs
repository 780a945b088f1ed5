//! The unit tests of `sepval_common::extension`.

use sepval_common::extension::*;

use crate::wind::gust;

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
        "extension e.toml: line 5, term 1, `family` `wobble` is not a family of the library (expected flow_angle, rate, interference, interference_flow_angle, mach, step, oscillation, ejector_stroke, wind)"
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
        "extension e.toml: line 4, term 1, `axis` `Cz` is not an axis (expected CA, CY, CZ, Cl, Cm, Cn, ejector, wind_y or wind_z)"
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

#[test]
fn wind_shapes_are_the_one_minus_cosine_onset_and_pulse() {
    let (t_on, rise) = (0.2, 0.1);
    // Values: zero before, half at mid-length (onset), peak at mid-length (pulse), one (onset)
    // and zero (pulse) after.
    let cases = [
        (0.1, 0.0, 0.0),
        (0.2, 0.0, 0.0),
        (
            0.225,
            0.5 * (1.0 - (std::f64::consts::FRAC_PI_4).cos()),
            0.5,
        ),
        (0.25, 0.5, 1.0),
        (
            0.275,
            0.5 * (1.0 - (0.75 * std::f64::consts::PI).cos()),
            0.5,
        ),
        (0.3, 1.0, 0.0),
        (0.9, 1.0, 0.0),
    ];
    for (t, step, pulse) in cases {
        let got = (wind::onset(t, t_on, rise), wind::pulse(t, t_on, rise));
        assert!((got.0 - step).abs() < 1e-15, "onset at {t}: {}", got.0);
        assert!((got.1 - pulse).abs() < 1e-15, "pulse at {t}: {}", got.1);
    }
    // Continuity at both ends, with a slope that goes to zero there (1-cosine): a step of
    // 1 us inside changes the shape by less than (pi 1e-6 / T)^2.
    let eps = 1e-6;
    let bound = (std::f64::consts::TAU * eps / rise).powi(2);
    for f in [wind::onset, wind::pulse] {
        assert!(f(t_on + eps, t_on, rise) < bound);
        assert!((f(t_on + rise - eps, t_on, rise) - f(t_on + rise, t_on, rise)).abs() < bound);
    }
    // Through a term set: the wind in L, (0, wind_y, wind_z), sums the terms of an axis.
    let set = TermSet::of(&[
        gust(Axis::WindY, Regressor::WindStep, t_on, rise, 2.0),
        gust(Axis::WindY, Regressor::WindPulse, t_on, rise, 1.0),
        gust(Axis::WindZ, Regressor::WindStep, 0.0, 0.05, -3.0),
    ])
    .unwrap();
    assert!(set.has_wind() && !set.has_aero() && !set.has_ejector());
    let w = set.wind_l_m_s(0.25);
    assert!(w[0].abs() < f64::MIN_POSITIVE && (w[1] - 2.0).abs() < 1e-15);
    assert!((w[2] + 3.0).abs() < 1e-15);
    assert!(
        set.aero_increments(&input())
            .iter()
            .all(|d| d.abs() < f64::MIN_POSITIVE)
    );
}

#[test]
fn wind_acts_on_the_wind_axes_only_and_only_wind_acts_there() {
    for axis in Axis::ALL {
        for (r, family, _) in Regressor::ALL {
            let wind_pair = family == Family::Wind;
            if wind_pair != axis.is_wind() {
                assert!(!r.fits(axis), "{r:?} on {axis:?}");
            }
        }
        assert_eq!(Regressor::WindPulse.fits(axis), axis.is_wind());
    }
    assert_eq!(
        gust(Axis::CY, Regressor::WindStep, 0.2, 0.1, 1.0)
            .check()
            .unwrap_err()
            .to_string(),
        "the wind regressor `step` cannot act on axis CY"
    );
    let step_on_wind = Term {
        axis: Axis::WindY,
        regressor: Regressor::Step,
        locator: [0.2, 0.0],
        coefficient: 1.0,
    };
    assert_eq!(
        step_on_wind.check().unwrap_err().to_string(),
        "the step regressor `step` cannot act on axis wind_y"
    );
    assert_eq!(
        gust(Axis::WindZ, Regressor::WindPulse, 0.2, 0.0, 1.0)
            .check()
            .unwrap_err()
            .to_string(),
        "rise_s = 0: expected a length in [0.001, 7200] s"
    );
}

#[test]
fn wind_terms_round_trip_through_files_and_bad_ones_name_their_field() {
    let terms = [
        gust(Axis::WindY, Regressor::WindStep, 0.2, 0.08, 2.1),
        gust(Axis::WindZ, Regressor::WindPulse, 0.45, 0.2, -1.5),
    ];
    let text = extension_toml(&terms.iter().map(TermRecord::of).collect::<Vec<_>>());
    assert!(text.contains("rise_s = 0.08"), "{text}");
    assert_eq!(parse_extension(&text, "gust.toml").unwrap(), terms);
    let head = "format = \"sepval-extension/1\"\n\n[[term]]\n";
    let read = |body: &str| parse_extension(&format!("{head}{body}"), "gust.toml");
    // rise_s not written: the documented default.
    let t = read("axis = \"wind_y\"\nfamily = \"wind\"\nregressor = \"step\"\nt_on_s = 0.2\ncoefficient = 2.0\n")
        .unwrap();
    assert_eq!(
        t[0].locator.map(f64::to_bits),
        [0.2, wind::DEFAULT_RISE_S].map(f64::to_bits)
    );
    let err = |body: &str| read(body).unwrap_err().to_string();
    assert_eq!(
        err(
            "axis = \"CY\"\nfamily = \"wind\"\nregressor = \"step\"\nt_on_s = 0.2\ncoefficient = 2.0\n"
        ),
        "extension gust.toml: line 4, term 1, `axis` the wind regressor `step` cannot act on axis CY"
    );
    assert_eq!(
        err(
            "axis = \"wind_y\"\nfamily = \"wind\"\nregressor = \"pulse\"\nt_on_s = 0.2\nrise_s = 1e-4\ncoefficient = 2.0\n"
        ),
        "extension gust.toml: line 8, term 1, `rise_s` rise_s = 0.0001: expected a length in [0.001, 7200] s"
    );
    assert_eq!(
        err(
            "axis = \"wind_z\"\nfamily = \"wind\"\nregressor = \"pulse\"\nt_on_s = 9000\ncoefficient = 2.0\n"
        ),
        "extension gust.toml: line 7, term 1, `t_on_s` t_on_s = 9000: expected a time in [-7200, 7200] s"
    );
    assert_eq!(
        err(
            "axis = \"CY\"\nfamily = \"step\"\nregressor = \"step\"\nt_on_s = 0.2\nrise_s = 0.1\ncoefficient = 2.0\n"
        ),
        "extension gust.toml: line 8, term 1, `rise_s` is not a locator of step"
    );
    assert_eq!(
        err(
            "axis = \"wind_y\"\nfamily = \"wind\"\nregressor = \"gust\"\nt_on_s = 0.2\ncoefficient = 2.0\n"
        ),
        "extension gust.toml: line 6, term 1, `regressor` `gust` is not a regressor of wind (expected step, pulse)"
    );
}
