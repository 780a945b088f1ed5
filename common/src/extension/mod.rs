//! Model extensions: terms added to the baseline model beyond the effect catalogue, each a
//! coefficient times a regressor evaluated at every force evaluation (`docs/model.md` section
//! 11). A diagnosis discovers them (`sepval diagnose` writes `DIR/extension.toml`), and
//! `simulate`, `fit` and `diagnose` accept them back with `--extension FILE`, so an extended
//! model is usable, not only reported.
//!
//! A term acts on one axis: an aerodynamic coefficient increment (`CA` positive aft, so
//! `CX -= dCA`; `CY`, `CZ`, `Cl`, `Cm`, `Cn` added as they are), the ejector force (`ejector`:
//! a fraction of each foot's force, `F_i (1 + dE)`, while the foot pushes), or the air's
//! velocity in the launch frame (`wind_y`, `wind_z` \[m/s\]: a gust, seen by every coefficient
//! through the flow angles, the airspeed and the Mach number; [`wind`]). Its regressor comes
//! from a documented library of families (the names are the ones the diagnosis reports):
//!
//! | family | regressors | locator |
//! |---|---|---|
//! | `flow_angle` | `alpha`, `beta`, `alpha2`, `beta2`, `alpha3`, `beta3`, `alpha_beta` (local flow angles \[rad\]) | - |
//! | `rate` | `p`, `q`, `r` (p d/2V, q d/2V, r d/2V) | - |
//! | `interference` | `f` = f_lambda(s), the decay shape of section 3 with decay length lambda | `lambda_m` |
//! | `interference_flow_angle` | `f_alpha`, `f_beta`, `f_p`, `f_q`, `f_r`: f_lambda(s) times alpha, beta or a rate | `lambda_m` |
//! | `mach` | `dm`, `dm2`: (M - M0) and its square, M = V / a the store's own Mach number | `mach0` |
//! | `step` | `step`: (1 + tanh((t - t_on) / w)) / 2, w = 5 ms | `t_on_s` |
//! | `oscillation` | `sin`, `cos`: sin(2 pi f t), cos(2 pi f t) | `f_hz` |
//! | `ejector_stroke` | `stroke`, `stroke2`: sigma - 1/2 and (sigma - 1/2)^2 - 1/12, sigma = clamp(s_i, 0, stroke) / stroke (ejector axis only) | - |
//! | `wind` | `step`, `pulse`: the 1-cosine onset and pulse of length T (wind axes only; the only family on them) | `t_on_s`, `rise_s` (T) |
//!
//! A diagnosis also uses time windows (`window`: 1 for t0 <= t < t1) to reconstruct the missing
//! force and moment as time histories; they are not a family of the library and cannot be
//! written to an extension file.
//!
//! Terms are `Copy` and fixed in number ([`MAX_TERMS`] per run), like effects, so a candidate
//! with terms travels to the workers without allocation.

use serde::{Deserialize, Serialize};

use crate::lanes::Real;

mod file;
pub mod locator;
mod set;
pub mod wind;
pub use file::{
    EXTENSION_FORMAT, ExtensionError, TermRecord, extension_toml, load_extension, parse_extension,
};
pub use set::TermSet;

/// Most terms one run carries (an extension's and a candidate's together).
pub const MAX_TERMS: usize = 8;
/// Width of the smooth step \[s\].
pub const STEP_WIDTH_S: f64 = 0.005;

/// The quantity a term changes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Axis {
    /// Axial force coefficient (positive aft).
    CA,
    /// Side force coefficient.
    CY,
    /// Normal-axis force coefficient (body z).
    CZ,
    /// Rolling moment coefficient.
    Cl,
    /// Pitching moment coefficient.
    Cm,
    /// Yawing moment coefficient.
    Cn,
    /// The ejector force, as a fraction of each foot's force.
    #[serde(rename = "ejector")]
    Ejector,
    /// The air's velocity along the launch frame's y (lateral) \[m/s\].
    #[serde(rename = "wind_y")]
    WindY,
    /// The air's velocity along the launch frame's z (vertical, positive down) \[m/s\].
    #[serde(rename = "wind_z")]
    WindZ,
}

impl Axis {
    /// Every axis, in this order (the wire's axis index is the position here).
    pub const ALL: [Axis; 9] = [
        Axis::CA,
        Axis::CY,
        Axis::CZ,
        Axis::Cl,
        Axis::Cm,
        Axis::Cn,
        Axis::Ejector,
        Axis::WindY,
        Axis::WindZ,
    ];

    /// The force and moment axes: the coefficient increments and the ejector's, in this order
    /// (what a diagnosis reconstructs as time histories; the wind axes are not among them).
    pub const FORCE_AND_MOMENT: [Axis; 7] = [
        Axis::CA,
        Axis::CY,
        Axis::CZ,
        Axis::Cl,
        Axis::Cm,
        Axis::Cn,
        Axis::Ejector,
    ];

    /// The wind axes.
    pub const WIND: [Axis; 2] = [Axis::WindY, Axis::WindZ];

    /// Its name in files and reports.
    pub fn name(self) -> &'static str {
        match self {
            Axis::CA => "CA",
            Axis::CY => "CY",
            Axis::CZ => "CZ",
            Axis::Cl => "Cl",
            Axis::Cm => "Cm",
            Axis::Cn => "Cn",
            Axis::Ejector => "ejector",
            Axis::WindY => "wind_y",
            Axis::WindZ => "wind_z",
        }
    }

    /// The axis of a name.
    pub fn from_name(name: &str) -> Option<Axis> {
        Axis::ALL.into_iter().find(|a| a.name() == name)
    }

    /// Index 0..9, its position in [`Axis::ALL`] (0..6: the coefficients CA ... Cn).
    pub fn index(self) -> usize {
        self as usize
    }

    /// Whether it is an aerodynamic coefficient (CA ... Cn).
    pub fn is_coefficient(self) -> bool {
        self.index() < 6
    }

    /// Whether it is a wind axis.
    pub fn is_wind(self) -> bool {
        matches!(self, Axis::WindY | Axis::WindZ)
    }
}

/// A family of regressors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Family {
    /// Local flow angles and their powers.
    FlowAngle,
    /// Non-dimensional body rates.
    Rate,
    /// An interference decay shape.
    Interference,
    /// An interference decay shape times a flow angle or rate.
    InterferenceFlowAngle,
    /// The store's Mach number.
    Mach,
    /// A smooth step in time.
    Step,
    /// A sine or cosine in time.
    Oscillation,
    /// The ejector force's shape along the stroke.
    EjectorStroke,
    /// A gust: the air's velocity in time.
    Wind,
    /// A time window (reconstruction only).
    Window,
}

impl Family {
    /// The families of the library, in report order.
    pub const LIBRARY: [Family; 9] = [
        Family::FlowAngle,
        Family::Rate,
        Family::Interference,
        Family::InterferenceFlowAngle,
        Family::Mach,
        Family::Step,
        Family::Oscillation,
        Family::EjectorStroke,
        Family::Wind,
    ];

    /// Its name in files and reports.
    pub fn name(self) -> &'static str {
        match self {
            Family::FlowAngle => "flow_angle",
            Family::Rate => "rate",
            Family::Interference => "interference",
            Family::InterferenceFlowAngle => "interference_flow_angle",
            Family::Mach => "mach",
            Family::Step => "step",
            Family::Oscillation => "oscillation",
            Family::EjectorStroke => "ejector_stroke",
            Family::Wind => "wind",
            Family::Window => "window",
        }
    }

    /// The family of a name (the library's only).
    pub fn from_name(name: &str) -> Option<Family> {
        Family::LIBRARY.into_iter().find(|f| f.name() == name)
    }

    /// The name of its (first) locator in files, if it has one; `wind` has a second,
    /// `rise_s` ([`wind`]).
    pub fn locator(self) -> Option<&'static str> {
        match self {
            Family::Interference | Family::InterferenceFlowAngle => Some("lambda_m"),
            Family::Mach => Some("mach0"),
            Family::Step | Family::Wind => Some("t_on_s"),
            Family::Oscillation => Some("f_hz"),
            Family::Window => Some("t0_s"),
            _ => None,
        }
    }
}

/// One regressor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[allow(missing_docs)]
pub enum Regressor {
    Alpha,
    Beta,
    Alpha2,
    Beta2,
    Alpha3,
    Beta3,
    AlphaBeta,
    P,
    Q,
    R,
    F,
    FAlpha,
    FBeta,
    FP,
    FQ,
    FR,
    Dm,
    Dm2,
    Step,
    Sin,
    Cos,
    Stroke,
    Stroke2,
    Window,
    WindStep,
    WindPulse,
}

impl Regressor {
    /// Every regressor, with its family and name.
    pub const ALL: [(Regressor, Family, &'static str); 26] = [
        (Regressor::Alpha, Family::FlowAngle, "alpha"),
        (Regressor::Beta, Family::FlowAngle, "beta"),
        (Regressor::Alpha2, Family::FlowAngle, "alpha2"),
        (Regressor::Beta2, Family::FlowAngle, "beta2"),
        (Regressor::Alpha3, Family::FlowAngle, "alpha3"),
        (Regressor::Beta3, Family::FlowAngle, "beta3"),
        (Regressor::AlphaBeta, Family::FlowAngle, "alpha_beta"),
        (Regressor::P, Family::Rate, "p"),
        (Regressor::Q, Family::Rate, "q"),
        (Regressor::R, Family::Rate, "r"),
        (Regressor::F, Family::Interference, "f"),
        (Regressor::FAlpha, Family::InterferenceFlowAngle, "f_alpha"),
        (Regressor::FBeta, Family::InterferenceFlowAngle, "f_beta"),
        (Regressor::FP, Family::InterferenceFlowAngle, "f_p"),
        (Regressor::FQ, Family::InterferenceFlowAngle, "f_q"),
        (Regressor::FR, Family::InterferenceFlowAngle, "f_r"),
        (Regressor::Dm, Family::Mach, "dm"),
        (Regressor::Dm2, Family::Mach, "dm2"),
        (Regressor::Step, Family::Step, "step"),
        (Regressor::Sin, Family::Oscillation, "sin"),
        (Regressor::Cos, Family::Oscillation, "cos"),
        (Regressor::Stroke, Family::EjectorStroke, "stroke"),
        (Regressor::Stroke2, Family::EjectorStroke, "stroke2"),
        (Regressor::Window, Family::Window, "window"),
        (Regressor::WindStep, Family::Wind, "step"),
        (Regressor::WindPulse, Family::Wind, "pulse"),
    ];

    /// Its family.
    pub fn family(self) -> Family {
        Regressor::ALL[self as usize].1
    }

    /// Its name in files and reports.
    pub fn name(self) -> &'static str {
        Regressor::ALL[self as usize].2
    }

    /// The regressor `name` of `family`.
    pub fn from_names(family: Family, name: &str) -> Option<Regressor> {
        Regressor::ALL
            .iter()
            .find(|(_, f, n)| *f == family && *n == name)
            .map(|(r, _, _)| *r)
    }

    /// Whether it may act on `axis` (the stroke shapes act on the ejector only, the ejector
    /// only through them, time windows and steps; the wind shapes act on the wind axes only,
    /// and nothing else does).
    pub fn fits(self, axis: Axis) -> bool {
        match (self.family(), axis) {
            (Family::Wind, a) => a.is_wind(),
            (_, a) if a.is_wind() => false,
            (Family::EjectorStroke, a) => a == Axis::Ejector,
            (Family::Window | Family::Step, _) => true,
            (_, a) => a != Axis::Ejector,
        }
    }
}

/// What a regressor reads at one force evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TermInput {
    /// Time \[s\].
    pub t_s: f64,
    /// Angle of attack \[rad\].
    pub alpha_rad: f64,
    /// Sideslip \[rad\].
    pub beta_rad: f64,
    /// p d / 2V, q d / 2V, r d / 2V.
    pub rates_hat: [f64; 3],
    /// The store's Mach number V / a.
    pub mach: f64,
    /// Distance of the CG from carriage \[m\].
    pub distance_m: f64,
    /// The interference cut-off distance \[m\].
    pub s_end_m: f64,
}

/// One term: `coefficient * regressor(locator)` on `axis`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Term {
    /// The axis.
    pub axis: Axis,
    /// The regressor.
    pub regressor: Regressor,
    /// Its locator (`lambda_m`, `mach0`, `t_on_s`, `f_hz`; a window's `[t0_s, t1_s]`; a
    /// wind's `[t_on_s, rise_s]`).
    pub locator: [f64; 2],
    /// Its coefficient (dimensionless; for the ejector, a fraction of the force; for a wind
    /// axis, the air's velocity \[m/s\]).
    pub coefficient: f64,
}

/// Terms that cannot be run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TermError {
    /// More terms than a run holds.
    #[error("more than {MAX_TERMS} terms")]
    TooMany,
    /// A regressor on an axis it cannot act on.
    #[error("the {family} regressor `{regressor}` cannot act on axis {axis}")]
    Axis {
        /// The family.
        family: &'static str,
        /// The regressor.
        regressor: &'static str,
        /// The axis.
        axis: &'static str,
    },
    /// A value that is not a finite number, or outside its domain.
    #[error("{what} = {}: {expected}", readable(*value))]
    Value {
        /// Which value.
        what: &'static str,
        /// The value.
        value: f64,
        /// What is expected.
        expected: &'static str,
    },
}

impl Term {
    /// Checks the term: its axis fits its regressor, its numbers are finite and its locator in
    /// its domain ([`locator`]: every value in it simulates).
    pub fn check(&self) -> Result<(), TermError> {
        let value = |what, value: f64, ok: bool, expected| {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(TermError::Value {
                    what,
                    value,
                    expected,
                })
            }
        };
        let domain =
            |d: locator::LocatorDomain, v: f64| value(d.name, v, d.contains(v), d.expected);
        if !self.regressor.fits(self.axis) {
            return Err(TermError::Axis {
                family: self.regressor.family().name(),
                regressor: self.regressor.name(),
                axis: self.axis.name(),
            });
        }
        value(
            "coefficient",
            self.coefficient,
            true,
            "expected a finite number",
        )?;
        let [a, b] = self.locator;
        match self.regressor.family() {
            Family::Interference | Family::InterferenceFlowAngle => domain(locator::LAMBDA_M, a),
            Family::Mach => domain(locator::MACH0, a),
            Family::Step => domain(locator::T_ON_S, a),
            Family::Oscillation => domain(locator::F_HZ, a),
            Family::Wind => domain(locator::T_ON_S, a).and(domain(locator::RISE_S, b)),
            Family::Window => {
                value("t0_s", a, true, "expected a finite time")?;
                value("t1_s", b, b > a, "expected a time after t0_s")
            }
            _ => Ok(()),
        }
    }

    /// The regressor's value (aerodynamic axes; for a wind regressor, its shape in time).
    /// Inlined always, as the kernels it calls: the simulation calls it from the propagators'
    /// copies compiled for FMA units (`model::term_lanes`, for lanes whose terms differ in
    /// kind), and only code inlined there uses them.
    #[inline(always)]
    pub fn regressor_value(&self, x: &TermInput) -> f64 {
        let [a, b] = self.locator;
        // A macro, not a closure: a closure is a function of its own that the compiler may
        // leave out of line, compiled without the caller's FMA units.
        macro_rules! f {
            () => {
                decay(x.distance_m, a, x.s_end_m)
            };
        }
        match self.regressor {
            Regressor::Alpha => x.alpha_rad,
            Regressor::Beta => x.beta_rad,
            Regressor::Alpha2 => x.alpha_rad * x.alpha_rad,
            Regressor::Beta2 => x.beta_rad * x.beta_rad,
            Regressor::Alpha3 => x.alpha_rad * x.alpha_rad * x.alpha_rad,
            Regressor::Beta3 => x.beta_rad * x.beta_rad * x.beta_rad,
            Regressor::AlphaBeta => x.alpha_rad * x.beta_rad,
            Regressor::P => x.rates_hat[0],
            Regressor::Q => x.rates_hat[1],
            Regressor::R => x.rates_hat[2],
            Regressor::F => f!(),
            Regressor::FAlpha => f!() * x.alpha_rad,
            Regressor::FBeta => f!() * x.beta_rad,
            Regressor::FP => f!() * x.rates_hat[0],
            Regressor::FQ => f!() * x.rates_hat[1],
            Regressor::FR => f!() * x.rates_hat[2],
            Regressor::Dm => x.mach - a,
            Regressor::Dm2 => (x.mach - a) * (x.mach - a),
            Regressor::Step => step(x.t_s, a),
            Regressor::Sin => crate::elementary::sin(self.oscillation_argument(x.t_s)),
            Regressor::Cos => crate::elementary::cos(self.oscillation_argument(x.t_s)),
            Regressor::Window => f64::from(u8::from(x.t_s >= a && x.t_s < b)),
            Regressor::Stroke | Regressor::Stroke2 => 0.0,
            Regressor::WindStep => wind::onset(x.t_s, a, b),
            Regressor::WindPulse => wind::pulse(x.t_s, a, b),
        }
    }

    /// The argument 2 pi f t of an oscillation's sine or cosine at time `t_s` (f its locator).
    #[inline(always)]
    pub(crate) fn oscillation_argument(&self, t_s: f64) -> f64 {
        std::f64::consts::TAU * self.locator[0] * t_s
    }

    /// The regressor's value on the ejector axis, for a foot at stroke fraction `sigma`.
    #[inline(always)]
    pub fn ejector_value(&self, t_s: f64, sigma: f64) -> f64 {
        let [a, b] = self.locator;
        match self.regressor {
            Regressor::Stroke => sigma - 0.5,
            Regressor::Stroke2 => (sigma - 0.5) * (sigma - 0.5) - 1.0 / 12.0,
            Regressor::Step => step(t_s, a),
            Regressor::Window => f64::from(u8::from(t_s >= a && t_s < b)),
            _ => 0.0,
        }
    }

    /// A readable formula, e.g. `beta*exp(-s/0.6)` or `sin(2 pi 5 t)`.
    pub fn formula(&self) -> String {
        let [a, b] = self.locator.map(short);
        let f = |x: &str| format!("{x}*f(s; lambda={a} m)");
        match self.regressor {
            Regressor::Alpha => "alpha".into(),
            Regressor::Beta => "beta".into(),
            Regressor::Alpha2 => "alpha^2".into(),
            Regressor::Beta2 => "beta^2".into(),
            Regressor::Alpha3 => "alpha^3".into(),
            Regressor::Beta3 => "beta^3".into(),
            Regressor::AlphaBeta => "alpha*beta".into(),
            Regressor::P => "p d/2V".into(),
            Regressor::Q => "q d/2V".into(),
            Regressor::R => "r d/2V".into(),
            Regressor::F => format!("f(s; lambda={a} m)"),
            Regressor::FAlpha => f("alpha"),
            Regressor::FBeta => f("beta"),
            Regressor::FP => f("p d/2V"),
            Regressor::FQ => f("q d/2V"),
            Regressor::FR => f("r d/2V"),
            Regressor::Dm => format!("(M - {a})"),
            Regressor::Dm2 => format!("(M - {a})^2"),
            Regressor::Step => format!("step(t - {a} s)"),
            Regressor::Sin => format!("sin(2 pi {a} Hz t)"),
            Regressor::Cos => format!("cos(2 pi {a} Hz t)"),
            Regressor::Stroke => "(sigma - 1/2)".into(),
            Regressor::Stroke2 => "((sigma - 1/2)^2 - 1/12)".into(),
            Regressor::Window => format!("[{a} s <= t < {b} s]"),
            Regressor::WindStep => format!("onset(t - {a} s; {b} s)"),
            Regressor::WindPulse => format!("pulse(t - {a} s; {b} s)"),
        }
    }
}

/// A value for a message: as written, in exponent form when very large or small (1e300, not
/// three hundred digits).
fn readable(v: f64) -> String {
    if v.is_finite() && v != 0.0 && !(1e-6..1e16).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// A locator for formulas: at most four decimals, no trailing zeros.
fn short(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}

/// f_lambda(s) of docs/model.md section 3 for decay length `lambda_m`.
#[inline(always)]
fn decay(s_m: f64, lambda_m: f64, s_end_m: f64) -> f64 {
    if s_m >= s_end_m {
        return 0.0;
    }
    decay_inside(s_m, lambda_m, decay_end(s_end_m, lambda_m))
}

/// exp(-s_end / lambda): the decay shape's value at the cut-off, before it is taken off.
#[inline(always)]
pub(crate) fn decay_end<R: Real>(s_end_m: R, lambda_m: R) -> R {
    crate::elementary::exp(-s_end_m / lambda_m)
}

/// f_lambda(s) inside the cut-off (s < s_end), `e_end` being [`decay_end`]: (exp(-s / lambda) -
/// e_end) / (1 - e_end).
#[inline(always)]
pub(crate) fn decay_inside<R: Real>(s_m: R, lambda_m: R, e_end: R) -> R {
    (crate::elementary::exp(-s_m / lambda_m) - e_end) / (R::splat(1.0) - e_end)
}

/// The smooth step (1 + tanh((t - t_on) / w)) / 2 = 1 / (1 + exp(-2 (t - t_on) / w)).
#[inline(always)]
pub(crate) fn step<R: Real>(t_s: R, t_on_s: R) -> R {
    R::splat(1.0)
        / (R::splat(1.0)
            + crate::elementary::exp(R::splat(-2.0) * (t_s - t_on_s) / R::splat(STEP_WIDTH_S)))
}
