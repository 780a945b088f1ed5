//! The domain of each locator of the library's families (docs/discovery.md section 11.2): the
//! values a term may take, chosen so that every accepted value simulates, i.e. its regressor
//! is a finite number at every state a run reaches (issue 21, item 13: a decay length of 1e300
//! m, a frequency of 1e308 Hz or a reference Mach number of 1e300 made NaN at the first force
//! evaluation). A value outside is refused when the term is read, naming the field and the
//! domain.
//!
//! Why each bound:
//! - `lambda_m` in (0, 1000] m. The decay shape divides by 1 - exp(-s_end/lambda), which is 0
//!   (0/0, NaN) once s_end/lambda is below 2^-53; at 1000 m it is nonzero for the scenario's
//!   `s_end_m` down to 1e-12 m (the default's is 9.144 m; a decay longer than a kilometre is a
//!   constant over any separation). Small lengths are harmless: exp(-s/lambda) goes to 0.
//! - `mach0` in (0, 1000]: (M - M0)^2 stays far from overflow for any Mach number a store
//!   reaches; the diagnosis's library uses the events' flight Mach number.
//! - `t_on_s` in [-7200, 7200] s, twice the longest event (`limits::MAX_SPAN_S`): a step
//!   further out is constant over any event; the library's steps lie inside the record.
//! - `rise_s` in [0.001, 7200] s (the length T of a `wind` onset or pulse): the shapes divide
//!   t - t_on by T, which stays finite for any positive T and any time of an event; below 1 ms
//!   (two steps of the default 0.5 ms integrator) a gust is a jump the integrator cannot
//!   resolve, and beyond twice the longest event it never completes.
//! - `f_hz` in [0, 1e6] Hz: 2 pi f t stays finite for every time of an event (a frequency
//!   beyond half the integration rate is aliased, but it still simulates); the library tries 1 to
//!   50 Hz.
//!
//! The diagnosis's own locators (`diagnose/src/library.rs` and the refits of `discover/`:
//! decay lengths about 0.1 to 3.6 m, steps and gusts within the record, gust lengths 0.05 to
//! 0.2 s, 1 to 50.5 Hz) lie well inside.

use sepval_core::limits::MAX_SPAN_S;

/// The domain of one locator: `min` (excluded when `min_open`) to `max` (included).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocatorDomain {
    /// Its field in files.
    pub name: &'static str,
    /// The smallest value (or the bound values stay above when `min_open`).
    pub min: f64,
    /// Whether `min` itself is refused.
    pub min_open: bool,
    /// The largest value accepted.
    pub max: f64,
    /// What a refusal says is expected (it states the domain).
    pub expected: &'static str,
}

impl LocatorDomain {
    /// The next double above `max`, the first value refused above the domain (`f64::next_up`
    /// needs Rust 1.86; `max` is positive and finite).
    pub fn above_max(&self) -> f64 {
        f64::from_bits(self.max.to_bits() + 1)
    }

    /// Whether `v` is in the domain (NaN is not).
    pub fn contains(&self, v: f64) -> bool {
        let above = if self.min_open {
            v > self.min
        } else {
            v >= self.min
        };
        above && v <= self.max
    }
}

/// Decay length of `interference` and `interference_flow_angle` \[m\].
pub const LAMBDA_M: LocatorDomain = LocatorDomain {
    name: "lambda_m",
    min: 0.0,
    min_open: true,
    max: 1000.0,
    expected: "expected a decay length in (0, 1000] m",
};

/// Reference Mach number of `mach`.
pub const MACH0: LocatorDomain = LocatorDomain {
    name: "mach0",
    min: 0.0,
    min_open: true,
    max: 1000.0,
    expected: "expected a Mach number in (0, 1000]",
};

/// Step time of `step` \[s\].
pub const T_ON_S: LocatorDomain = LocatorDomain {
    name: "t_on_s",
    min: -2.0 * MAX_SPAN_S,
    min_open: false,
    max: 2.0 * MAX_SPAN_S,
    expected: "expected a time in [-7200, 7200] s",
};

/// Onset or pulse length of `wind` \[s\].
pub const RISE_S: LocatorDomain = LocatorDomain {
    name: "rise_s",
    min: 1e-3,
    min_open: false,
    max: 2.0 * MAX_SPAN_S,
    expected: "expected a length in [0.001, 7200] s",
};

/// Frequency of `oscillation` \[Hz\].
pub const F_HZ: LocatorDomain = LocatorDomain {
    name: "f_hz",
    min: 0.0,
    min_open: false,
    max: 1e6,
    expected: "expected a frequency in [0, 1000000] Hz",
};
