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

use crate::factors::{Factor, Factors};
use crate::table::AeroAtMach;

/// The flow seen by the store at one force evaluation; effects' coefficient terms read it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flow {
    /// Angle of attack atan2(w, u) \[rad\].
    pub alpha_rad: f64,
    /// Sideslip asin(v / V) \[rad\].
    pub beta_rad: f64,
    /// Non-dimensional roll rate p d / 2V.
    pub p_hat: f64,
    /// Non-dimensional pitch rate q d / 2V.
    pub q_hat: f64,
    /// Non-dimensional yaw rate r d / 2V.
    pub r_hat: f64,
    /// Air-relative speed V [m/s].
    pub speed_m_s: f64,
    /// Interference decay factor f(s) in [0, 1].
    pub interference_factor: f64,
    /// Time of the evaluation (the RK4 stage's) \[s\].
    pub t_s: f64,
    /// Distance of the CG from carriage \[m\].
    pub distance_m: f64,
    /// The store's Mach number V / a.
    pub mach: f64,
}

/// Body-axis force and moment coefficients.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[allow(missing_docs)]
pub struct Coefficients {
    pub cx: f64,
    pub cy: f64,
    pub cz: f64,
    pub cl: f64,
    pub cm: f64,
    pub cn: f64,
}

/// The freestream database with the factor offsets folded in, for one run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AeroConstants {
    /// -(CA0 + caoff).
    pub cx0: f64,
    /// CY_beta [1/rad].
    pub cy_beta: f64,
    /// cyoff.
    pub cy0: f64,
    /// CZ_alpha [1/rad].
    pub cz_alpha: f64,
    /// czoff.
    pub cz0: f64,
    /// Cl_p [1/rad].
    pub cl_p: f64,
    /// cloff.
    pub cl0: f64,
    /// Cm_alpha [1/rad].
    pub cm_alpha: f64,
    /// Cm_q [1/rad].
    pub cm_q: f64,
    /// cmoff.
    pub cm0: f64,
    /// Cn_beta [1/rad].
    pub cn_beta: f64,
    /// Cn_r [1/rad].
    pub cn_r: f64,
    /// cnoff.
    pub cn0: f64,
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

    /// The coefficients of docs/model.md section 3 (without the catalogue's terms).
    /// `increments` are the interference increments times their multipliers,
    /// (dCX, dCY, dCZ, dCl, dCm, dCn).
    #[inline(always)]
    pub fn coefficients(&self, flow: &Flow, increments: &[f64; 6]) -> Coefficients {
        let f = flow.interference_factor;
        // Each sum as fused multiply-adds, interference term innermost.
        let lin = |slope: f64, x: f64, rest: f64| slope.mul_add(x, rest);
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
