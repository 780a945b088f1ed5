//! Plain-language physical readings of discovered terms: one sentence per family and axis, from
//! the table in `docs/discovery.md` section 11.4. A reading says what a store-separation engineer
//! would suspect first; it is a reading of the term's shape, not a proof of the mechanism.
//!
//! | family | reading |
//! |---|---|
//! | `flow_angle` | `<quantity> changing with <alpha, beta, ...>: a static derivative or nonlinearity the model lacks` |
//! | `rate` (own axis: Cl-p, Cm-q, Cn-r) | `<roll/pitch/yaw> damping differs from the model's (stronger or weaker)` |
//! | `rate` (cross axis) | `<quantity> due to <roll/pitch/yaw> rate: a cross derivative the model lacks` |
//! | `interference` | `<quantity> near the aircraft decaying over about lambda m: interference stronger (or weaker) or shaped otherwise than modelled` (stronger when the term has the sign of the scenario's carriage increment on that axis) |
//! | `interference_flow_angle` | `<quantity> growing with <sideslip/angle of attack/rate> near the aircraft: attitude-dependent interference` |
//! | `mach` | `<quantity> changing with Mach number: compressibility (for example a transonic drag rise)` |
//! | `step` | `<quantity> step at t s: a gust or a release transient` |
//! | `oscillation` | `<quantity> oscillating at f Hz: buffet (or a structural or flow oscillation)` |
//! | `ejector_stroke` (`stroke`) | `ejector force falls (or rises) along the stroke` |
//! | `ejector_stroke` (`stroke2`) | `ejector force peaks (or dips) mid-stroke` |
//! | `wind` (`step`, `pulse`) | `a lateral (or vertical) gust (or gust pulse) of w m/s toward +y (starboard) / -y (port) / +z (down) / -z (up) from t = t_on s over T s: the air moved during the release` |

use sepval_common::extension::{Axis, Family, Regressor, Term};
use sepval_common::scenario::Interference;

/// The quantity an axis changes, in words.
pub fn quantity(axis: Axis) -> &'static str {
    match axis {
        Axis::CA => "axial force",
        Axis::CY => "side force",
        Axis::CZ => "normal force",
        Axis::Cl => "roll moment",
        Axis::Cm => "pitch moment",
        Axis::Cn => "yaw moment",
        Axis::Ejector => "ejector force",
        Axis::WindY => "lateral wind",
        Axis::WindZ => "vertical wind",
    }
}

fn capitalised(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_uppercase().collect::<String>() + c.as_str(),
        None => String::new(),
    }
}

/// What a regressor reads, in words.
fn variable(r: Regressor) -> &'static str {
    match r {
        Regressor::Alpha | Regressor::FAlpha => "angle of attack",
        Regressor::Beta | Regressor::FBeta => "sideslip",
        Regressor::Alpha2 => "the square of angle of attack",
        Regressor::Beta2 => "the square of sideslip",
        Regressor::Alpha3 => "the cube of angle of attack",
        Regressor::Beta3 => "the cube of sideslip",
        Regressor::AlphaBeta => "angle of attack times sideslip",
        Regressor::P | Regressor::FP => "roll rate",
        Regressor::Q | Regressor::FQ => "pitch rate",
        Regressor::R | Regressor::FR => "yaw rate",
        _ => "",
    }
}

/// The modelled carriage increment on `axis`, signed as a term on that axis adds (a term on
/// `CA` subtracts from CX, docs/discovery.md section 11.2); `None` for the ejector and for a
/// tabulated increment (it has no single sign).
pub fn carriage_increment(interference: &Interference, axis: Axis) -> Option<f64> {
    // The aerodynamic axes are in the order of the increments (dCX0, dCY0, ... dCn0).
    let (_, c) = *interference.increments().get(axis.index())?;
    let v = c.as_constant()?;
    Some(if axis == Axis::CA { -v } else { v })
}

/// The reading of `term` (its coefficient signed as fitted; for an oscillation, either of its
/// pair). `interference` is the scenario's carriage interference: an interference term with the
/// sign of its increment makes the interference stronger, one against it weaker.
pub fn reading(term: &Term, interference: &Interference) -> String {
    let q = quantity(term.axis);
    let [locator, _] = term.locator;
    let c = term.coefficient;
    match term.regressor.family() {
        Family::FlowAngle => format!(
            "{} changing with {}: a static derivative or nonlinearity the model lacks",
            capitalised(q),
            variable(term.regressor)
        ),
        Family::Rate => {
            let own = matches!(
                (term.axis, term.regressor),
                (Axis::Cl, Regressor::P) | (Axis::Cm, Regressor::Q) | (Axis::Cn, Regressor::R)
            );
            if own {
                let motion = match term.axis {
                    Axis::Cl => "roll",
                    Axis::Cm => "pitch",
                    _ => "yaw",
                };
                // A negative derivative opposes the motion: more damping.
                let how = if c < 0.0 { "stronger" } else { "weaker" };
                format!("{} damping {how} than the model's", capitalised(motion))
            } else {
                format!(
                    "{} due to {}: a cross derivative the model lacks",
                    capitalised(q),
                    variable(term.regressor)
                )
            }
        }
        Family::Interference => {
            let how = match carriage_increment(interference, term.axis) {
                Some(c0) if c0 != 0.0 && (c0 > 0.0) == (c > 0.0) => "stronger",
                Some(c0) if c0 != 0.0 => "weaker",
                _ => "that the model lacks,",
            };
            format!(
                "{} near the aircraft decaying over about {} m: interference {how} or shaped otherwise than modelled",
                capitalised(q),
                fmt_num(locator),
            )
        }
        Family::InterferenceFlowAngle => format!(
            "{} growing with {} near the aircraft: attitude-dependent interference",
            capitalised(q),
            variable(term.regressor)
        ),
        Family::Mach => format!(
            "{} changing with Mach number: compressibility{}",
            capitalised(q),
            if term.axis == Axis::CA {
                " (for example a transonic drag rise)"
            } else {
                ""
            }
        ),
        Family::Step => format!(
            "{} step at {} s: a gust or a release transient",
            capitalised(q),
            fmt_num(locator)
        ),
        Family::Oscillation => format!(
            "{} oscillating at {} Hz: buffet (or a structural or flow oscillation)",
            capitalised(q),
            fmt_num(locator)
        ),
        Family::EjectorStroke => match term.regressor {
            Regressor::Stroke2 => format!(
                "Ejector force {} mid-stroke",
                if c < 0.0 { "peaks" } else { "dips" }
            ),
            _ => format!(
                "Ejector force {} along the stroke",
                if c < 0.0 { "falls" } else { "rises" }
            ),
        },
        Family::Wind => gust(term),
        Family::Window => format!("{} differs in a window of time", capitalised(q)),
    }
}

/// A `wind` term in words: which way the air moved, how fast, when and how long.
fn gust(term: &Term) -> String {
    let [t_on_s, rise_s] = term.locator;
    let w = term.coefficient;
    let (axis, toward) = match (term.axis, w < 0.0) {
        (Axis::WindZ, false) => ("vertical", "+z (down)"),
        (Axis::WindZ, true) => ("vertical", "-z (up)"),
        (_, false) => ("lateral", "+y (starboard)"),
        (_, true) => ("lateral", "-y (port)"),
    };
    let (what, over) = match term.regressor {
        Regressor::WindPulse => ("gust pulse", "lasting"),
        _ => ("gust", "building up over"),
    };
    format!(
        "A {axis} {what} of {} m/s toward {toward} from t = {} s, {over} {} s: the air moved during the release",
        fmt_num(w.abs()),
        fmt_num(t_on_s),
        fmt_num(rise_s)
    )
}

/// A number with at most three decimals and no trailing zeros
/// ([`sepval_report::words::decimals`]).
pub fn fmt_num(v: f64) -> String {
    sepval_report::words::decimals(v, 3)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn term(axis: Axis, regressor: Regressor, locator: f64, c: f64) -> Term {
        Term {
            axis,
            regressor,
            locator: [locator, 0.0],
            coefficient: c,
        }
    }

    fn reading(term: &Term) -> String {
        super::reading(term, &carriage())
    }

    fn carriage() -> Interference {
        use sepval_common::table::Tabulated;
        Interference {
            dcx0: Tabulated::constant(0.1),
            dcy0: Tabulated::constant(0.0),
            dcz0: Tabulated::constant(-0.2),
            dcl0: Tabulated::constant(0.0),
            dcm0: Tabulated::constant(-0.05),
            dcn0: Tabulated::constant(0.02),
            lambda_m: 0.6,
            s_end_m: 3.0,
        }
    }

    #[test]
    fn interference_strength_reads_against_the_carriage_increment() {
        // dCZ0 < 0: a negative CZ term strengthens it, a positive one weakens it.
        assert!(reading(&term(Axis::CZ, Regressor::F, 0.5, -0.1)).contains("stronger"));
        assert!(reading(&term(Axis::CZ, Regressor::F, 0.5, 0.1)).contains("weaker"));
        // dCX0 > 0 is -0.1 in CA: a negative CA term strengthens it.
        assert!(reading(&term(Axis::CA, Regressor::F, 0.5, -0.1)).contains("stronger"));
        // No modelled increment on CY: neither.
        let cy = reading(&term(Axis::CY, Regressor::F, 0.5, 0.1));
        assert!(cy.contains("that the model lacks"), "{cy}");
    }

    #[test]
    fn readings_name_the_physics() {
        assert_eq!(
            reading(&term(Axis::CY, Regressor::Step, 0.45, 0.01)),
            "Side force step at 0.45 s: a gust or a release transient"
        );
        assert_eq!(
            reading(&term(Axis::Cl, Regressor::Sin, 5.0, 0.01)),
            "Roll moment oscillating at 5 Hz: buffet (or a structural or flow oscillation)"
        );
        assert_eq!(
            reading(&term(Axis::Cn, Regressor::FBeta, 0.6, 0.2)),
            "Yaw moment growing with sideslip near the aircraft: attitude-dependent interference"
        );
        assert_eq!(
            reading(&term(Axis::Ejector, Regressor::Stroke, 0.0, -0.4)),
            "Ejector force falls along the stroke"
        );
        assert_eq!(
            reading(&term(Axis::Cl, Regressor::P, 0.0, -0.5)),
            "Roll damping stronger than the model's"
        );
        assert!(reading(&term(Axis::Cm, Regressor::P, 0.0, -0.5)).contains("cross derivative"));
        assert!(reading(&term(Axis::CA, Regressor::Dm, 0.9, 0.1)).contains("drag rise"));
    }

    #[test]
    fn a_gust_reads_as_the_air_moving() {
        let gust = |axis, regressor, w| Term {
            axis,
            regressor,
            locator: [0.2, 0.1],
            coefficient: w,
        };
        assert_eq!(
            reading(&gust(Axis::WindY, Regressor::WindStep, 2.1)),
            "A lateral gust of 2.1 m/s toward +y (starboard) from t = 0.2 s, building up over 0.1 s: the air moved during the release"
        );
        let pulse = reading(&gust(Axis::WindZ, Regressor::WindPulse, -3.0));
        assert!(
            pulse.starts_with(
                "A vertical gust pulse of 3 m/s toward -z (up) from t = 0.2 s, lasting 0.1 s"
            ),
            "{pulse}"
        );
    }
}
