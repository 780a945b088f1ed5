//! Aerodynamic coefficients: freestream database, factor offsets and interference.
//!
//! Source: `docs/model.md` section 3:
//!
//! ```text
//! CX = -(CA0 + caoff)                        + caintfac * dCX0 * f(s)
//! CY = CY_beta beta + cyoff                  + cyintfac * dCY0 * f(s)
//! CZ = CZ_alpha alpha + czoff                + czintfac * dCZ0 * f(s)
//! Cl = Cl_p p^ + cloff                       + clintfac * dCl0 * f(s)
//! Cm = Cm_alpha alpha + Cm_q q^ + cmoff      + cmintfac * dCm0 * f(s)
//! Cn = Cn_beta beta + Cn_r r^ + cnoff        + cnintfac * dCn0 * f(s)
//! ```

use super::tables::AeroAtMach;
use crate::lanes::Real;
use sepval_core::factors::{Factor, Factors};

/// The flow seen by the store at one force evaluation; effects' coefficient terms read it.
/// (`R`: one run's doubles, or one lane per run; see [`crate::lanes`].)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flow<R = f64> {
    /// Angle of attack atan2(w, u) \[rad\].
    pub alpha_rad: R,
    /// Sideslip asin(v / V) \[rad\].
    pub beta_rad: R,
    /// Non-dimensional roll rate p d / 2V.
    pub p_hat: R,
    /// Non-dimensional pitch rate q d / 2V.
    pub q_hat: R,
    /// Non-dimensional yaw rate r d / 2V.
    pub r_hat: R,
    /// Air-relative speed V [m/s].
    pub speed_m_s: R,
    /// Interference decay factor f(s) in [0, 1] (0 with a flowfield, section 3b, which replaces
    /// the decay increments).
    pub interference_factor: R,
    /// Time of the evaluation (the RK4 stage's) \[s\].
    pub t_s: R,
    /// Distance of the CG from carriage \[m\].
    pub distance_m: R,
    /// The store's Mach number V / a.
    pub mach: R,
}

/// Body-axis force and moment coefficients.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[allow(missing_docs)]
pub struct Coefficients<R = f64> {
    pub cx: R,
    pub cy: R,
    pub cz: R,
    pub cl: R,
    pub cm: R,
    pub cn: R,
}

/// The freestream database with the factor offsets folded in, for one run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AeroConstants<R = f64> {
    /// -(CA0 + caoff).
    pub cx0: R,
    /// CY_beta [1/rad].
    pub cy_beta: R,
    /// cyoff.
    pub cy0: R,
    /// CZ_alpha [1/rad].
    pub cz_alpha: R,
    /// czoff.
    pub cz0: R,
    /// Cl_p [1/rad].
    pub cl_p: R,
    /// cloff.
    pub cl0: R,
    /// Cm_alpha [1/rad].
    pub cm_alpha: R,
    /// Cm_q [1/rad].
    pub cm_q: R,
    /// cmoff.
    pub cm0: R,
    /// Cn_beta [1/rad].
    pub cn_beta: R,
    /// Cn_r [1/rad].
    pub cn_r: R,
    /// cnoff.
    pub cn0: R,
}

impl AeroConstants {
    /// Folds the offsets of `factors` into the database (at the flight Mach).
    pub fn new(aero: &AeroAtMach, factors: &Factors) -> Self {
        AeroConstants {
            cx0: -(aero.ca0 + factors.get(Factor::Caoff)),
            cy_beta: aero.cy_beta_per_rad,
            cy0: factors.get(Factor::Cyoff),
            cz_alpha: aero.cz_alpha_per_rad,
            cz0: factors.get(Factor::Czoff),
            cl_p: aero.cl_p_per_rad,
            cl0: factors.get(Factor::Cloff),
            cm_alpha: aero.cm_alpha_per_rad,
            cm_q: aero.cm_q_per_rad,
            cm0: factors.get(Factor::Cmoff),
            cn_beta: aero.cn_beta_per_rad,
            cn_r: aero.cn_r_per_rad,
            cn0: factors.get(Factor::Cnoff),
        }
    }
}

impl<R: Real> AeroConstants<R> {
    /// The constants of one run per lane (`runs(i)`: lane `i`'s).
    pub(crate) fn gather<'a>(runs: impl Fn(usize) -> &'a AeroConstants) -> Self {
        let g = |f: fn(&AeroConstants) -> f64| crate::lanes::gather::<R>(|i| f(runs(i)));
        AeroConstants {
            cx0: g(|a| a.cx0),
            cy_beta: g(|a| a.cy_beta),
            cy0: g(|a| a.cy0),
            cz_alpha: g(|a| a.cz_alpha),
            cz0: g(|a| a.cz0),
            cl_p: g(|a| a.cl_p),
            cl0: g(|a| a.cl0),
            cm_alpha: g(|a| a.cm_alpha),
            cm_q: g(|a| a.cm_q),
            cm0: g(|a| a.cm0),
            cn_beta: g(|a| a.cn_beta),
            cn_r: g(|a| a.cn_r),
            cn0: g(|a| a.cn0),
        }
    }

    /// The coefficients of docs/model.md section 3 (without the catalogue's terms).
    /// `increments` are the interference increments times their multipliers,
    /// (dCX, dCY, dCZ, dCl, dCm, dCn).
    #[inline(always)]
    pub fn coefficients(&self, flow: &Flow<R>, increments: &[R; 6]) -> Coefficients<R> {
        let f = flow.interference_factor;
        // Each sum as fused multiply-adds, interference term innermost.
        let lin = |slope: R, x: R, rest: R| slope.mul_add(x, rest);
        Coefficients {
            cx: increments[0].mul_add(f, self.cx0),
            cy: lin(
                self.cy_beta,
                flow.beta_rad,
                increments[1].mul_add(f, self.cy0),
            ),
            cz: lin(
                self.cz_alpha,
                flow.alpha_rad,
                increments[2].mul_add(f, self.cz0),
            ),
            cl: lin(self.cl_p, flow.p_hat, increments[3].mul_add(f, self.cl0)),
            cm: lin(
                self.cm_alpha,
                flow.alpha_rad,
                lin(self.cm_q, flow.q_hat, increments[4].mul_add(f, self.cm0)),
            ),
            cn: lin(
                self.cn_beta,
                flow.beta_rad,
                lin(self.cn_r, flow.r_hat, increments[5].mul_add(f, self.cn0)),
            ),
        }
    }
}
