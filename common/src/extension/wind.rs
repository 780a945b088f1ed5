//! The `wind` family (docs/discovery.md section 11.1): a gust, the air's velocity in the launch
//! frame L changing during the release. It is not a coefficient increment: the force
//! evaluation subtracts it from the store's velocity relative to the air (section 11.2), so
//! the flow angles, the airspeed, the dynamic pressure, the Mach number, the non-dimensional
//! rates and everything read from them (interference flow, tables, the catalogue's and the
//! extension's terms) see it.
//!
//! A wind term on axis `wind_y` (along L's y, lateral) or `wind_z` (along L's z, positive down)
//! is `coefficient * shape(t)`, the coefficient the air's velocity in m/s, with one of two
//! shapes of time t since release, from `t_on_s` over a length T = `rise_s`:
//!
//! ```text
//! step (onset):  0 for t <= t_on,  (1 - cos(pi (t - t_on) / T)) / 2 on [t_on, t_on + T],  1 after
//! pulse:         (1 - cos(2 pi (t - t_on) / T)) / 2 on [t_on, t_on + T],  0 outside
//! ```
//!
//! The 1-cosine shapes are those of the discrete gust of the design criteria: the 1-cosine
//! gust of MIL-HDBK-1797 (Department of Defense, "Flying Qualities of Piloted Aircraft", 1997,
//! section on atmospheric disturbances: the discrete gust, onset and full pulse) and of the
//! FAA's discrete gust design criteria (14 CFR 25.341(a): U = (U_ds / 2)(1 - cos(pi s / H)),
//! H the gust gradient from 30 to 350 ft). `rise_s` is T: the onset reaches the full velocity
//! at t_on + T (H / V), the pulse peaks at t_on + T/2 and is over at t_on + T. When a file does
//! not give it, T is [`DEFAULT_RISE_S`]. Both shapes are continuous, with a continuous first
//! derivative, and are computed with sepval's own `cos` ([`crate::elementary`]: the same bits
//! on every host).
//!
//! There is no `wind_x`: a gust along the flight path changes only the airspeed, by w/V (1 %
//! per 3 m/s at 300 m/s), and with it every coefficient's dynamic pressure at once; the design
//! gusts above are normal to the flight path, and a diagnosis could not tell an axial gust of
//! that size from the factors (docs/model-choices.md).

use super::{Axis, TermSet};
use crate::elementary::cos;

/// The onset and pulse length T when a file does not give `rise_s` \[s\]: a gust gradient of
/// about 29 m (96 ft) at the airspeed of the default scenario (Mach 0.95 at 7 925 m, about
/// 293 m/s), within 14 CFR 25.341's 30 to 350 ft.
pub const DEFAULT_RISE_S: f64 = 0.1;

/// The 1-cosine onset: 0 before `t_on_s`, 1 after `t_on_s + rise_s`, (1 - cos(pi x)) / 2 in
/// between, x = (t - t_on) / T.
#[inline(always)]
pub fn onset(t_s: f64, t_on_s: f64, rise_s: f64) -> f64 {
    let x = (t_s - t_on_s) / rise_s;
    if x <= 0.0 {
        0.0
    } else if x >= 1.0 {
        1.0
    } else {
        0.5 * (1.0 - cos(std::f64::consts::PI * x))
    }
}

/// The 1-cosine pulse: (1 - cos(2 pi x)) / 2 for x = (t - t_on) / T in (0, 1), 0 outside.
#[inline(always)]
pub fn pulse(t_s: f64, t_on_s: f64, rise_s: f64) -> f64 {
    let x = (t_s - t_on_s) / rise_s;
    if x <= 0.0 || x >= 1.0 {
        0.0
    } else {
        0.5 * (1.0 - cos(std::f64::consts::TAU * x))
    }
}

impl TermSet {
    /// Whether any term is a wind.
    pub fn has_wind(&self) -> bool {
        self.iter().any(|t| t.axis.is_wind())
    }

    /// The air's velocity in the launch frame at time `t_s` \[m/s\]: (0, sum of the `wind_y`
    /// terms, sum of the `wind_z` terms).
    #[inline(always)]
    pub fn wind_l_m_s(&self, t_s: f64) -> [f64; 3] {
        let mut w = [0.0; 3];
        for t in self.iter().filter(|t| t.axis.is_wind()) {
            let [t_on_s, rise_s] = t.locator;
            let shape = match t.regressor {
                super::Regressor::WindPulse => pulse(t_s, t_on_s, rise_s),
                _ => onset(t_s, t_on_s, rise_s),
            };
            let j = if t.axis == Axis::WindY { 1 } else { 2 };
            w[j] += t.coefficient * shape;
        }
        w
    }
}
