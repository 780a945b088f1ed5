//! The axial force at zero angle of attack, CA0 = friction + base + wave, on S_ref.
//!
//! - **Skin friction**: the turbulent flat plate with compressibility, Cf = 0.455 /
//!   ((log10 Re)^2.58 (1 + 0.144 M^2)^0.65) (D. P. Raymer, *Aircraft Design: A Conceptual
//!   Approach*, AIAA, eq. 12.27, after Schlichting), Re on the body's length or the fins' mean
//!   chord, with the form factors 1 + 60 / f^3 + f / 400 of a body of fineness f (Raymer eq.
//!   12.31) and 1 + 2 t/c + 60 (t/c)^4 of a fin (S. F. Hoerner, *Fluid-Dynamic Drag*, 1965,
//!   ch. 6), which fall to 1 across the transonic bridge (the supersonic value is the plate's).
//! - **The body's pressure drag: nose, boattail and base**, by R. L. McCoy, *"MC DRAG" - A
//!   Computer Program for Estimating the Drag Coefficients of Projectiles*, ARBRL-TR-02293,
//!   Ballistic Research Laboratory, 1981 (its equations as transcribed in a public
//!   implementation, J. Merritt's McDrag module; the report itself was not opened here). In
//!   calibres, tau = 1 / l_N (no meplat), h = R_T / R (1 a tangent ogive, 0 a cone),
//!   chi = (M^2 - 1) / (2.4 M^2):
//!   - nose: 0 below the critical Mach number M_c = (1 + 0.552 tau^0.8)^-0.5;
//!     0.368 tau^1.8 + 1.6 tau chi from M_c to 1 (the transonic drag rise, 0 at M_c);
//!     above 1, (c1 - c2 tau^2) / z^2 (tau z)^(c3 + c4 tau), c1 = 0.7156 - 0.5313 h + 0.595 h^2,
//!     c2 = 0.0796 + 0.0779 h, c3 = 1.587 + 0.049 h, c4 = 0.1122 + 0.1658 h, z = sqrt(M^2 - 1)
//!     held at its value at M_s = 1 + 0.368 tau^1.85 below M_s (McCoy's program: a step at
//!     Mach 1, which the tables' grid spreads over its interval there);
//!   - boattail (conical, t_b = (1 - d_B) / (2 l_BT), the tangent of its angle): 0 to Mach
//!     0.85; 2 (2 t_b^2 + t_b^3) B / (0.564 + 1260 chi^2) to Mach 1 and
//!     2 (2 t_b^2 + t_b^3) B (1.774 - 9.3 chi) to 1.1, B = 1 - e^(-2 l_BT) + 2 t_b (e^(-2 l_BT)
//!     (l_BT + 1/2) - 1/2); above 1.1 McCoy's supersonic boattail (his eq. 9, a similarity
//!     solution: [`boattail_supersonic`]);
//!   - base: C_DB = (2 d_B^2 / (1.4 M^2)) (1 - p_B / p), p_B / p = P_2 P_4, P_2 = 1 / (1 +
//!     0.1875 M^2 + 0.0531 M^4) below Mach 1 and 1 / (1 + 0.2477 M^2 + 0.0345 M^4) above,
//!     P_4 = (1 + 0.09 M^2 (1 - e^(-l_C))) (1 + 0.25 M^2 (1 - d_B)), l_C the length behind the
//!     nose: a boattail raises the base pressure and shrinks the base.
//!   - the domain: McCoy fitted these to projectiles (Mach 0.5 to 5); a finned store's fins are
//!     added apart.
//! - **Fin wave drag** from M_sup: Ackeret's 4 (t/c)^2 / beta of a thin section on each
//!   panel's area (Jones and Cohen 1960), bridged from 0 at Mach 0.8.
//!
//! Sutherland's viscosity mu = 1.458e-6 T^1.5 / (T + 110.4) [Pa s] gives Re at the
//! condition's ISA temperature and density. Missile DATCOM's accuracy goal for the axial force
//! is +-20 % (as commonly quoted; docs/aero.md).

use sepval_common::atmosphere::AirState;
use sepval_geometry::Nose;

use crate::config::{Configuration, Panel};
use crate::fins::{M_SUBSONIC_END, m_supersonic};

/// McCoy's boattail drag is 0 up to this Mach number.
const BOATTAIL_ONSET_MACH: f64 = 0.85;

/// The parts of CA0 at one Mach number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxialParts {
    /// Body and fin friction.
    pub friction: f64,
    /// Base drag.
    pub base: f64,
    /// Nose, boattail and fin wave (pressure) drag.
    pub wave: f64,
}

impl AxialParts {
    /// CA0, their sum.
    pub fn total(&self) -> f64 {
        self.friction + self.base + self.wave
    }
}

fn cf(re: f64, mach: f64) -> f64 {
    0.455 / (re.log10().powf(2.58) * (1.0 + 0.144 * mach * mach).powf(0.65))
}

/// McCoy's chi = (M^2 - 1) / ((gamma + 1) M^2).
fn chi(mach: f64) -> f64 {
    (mach * mach - 1.0) / (2.4 * mach * mach)
}

/// The nose's pressure drag (McCoy 1981) of fineness `l_n_cal` and shape `h` = R_T / R.
pub fn nose_drag(mach: f64, l_n_cal: f64, h: f64) -> f64 {
    let tau = 1.0 / l_n_cal;
    let m_crit = (1.0 + 0.552 * tau.powf(0.8)).powf(-0.5);
    if mach <= m_crit {
        return 0.0;
    }
    if mach <= 1.0 {
        return 0.368 * tau.powf(1.8) + 1.6 * tau * chi(mach);
    }
    let m_s = 1.0 + 0.368 * tau.powf(1.85);
    let z = (mach.max(m_s).powi(2) - 1.0).sqrt();
    let c1 = 0.7156 - 0.5313 * h + 0.595 * h * h;
    let c2 = 0.0796 + 0.0779 * h;
    let c3 = 1.587 + 0.049 * h;
    let c4 = 0.1122 + 0.1658 * h;
    (c1 - c2 * tau * tau) / (z * z) * (tau * z).powf(c3 + c4 * tau)
}

/// The boattail's geometry in calibres, for McCoy's equations.
#[derive(Debug, Clone, Copy)]
pub struct Afterbody {
    /// Nose length l_N.
    pub nose_cal: f64,
    /// Nose shape h = R_T / R.
    pub shape: f64,
    /// Cylinder length between nose and boattail.
    pub cylinder_cal: f64,
    /// Boattail length l_BT (> 0).
    pub boattail_cal: f64,
    /// Base diameter d_B.
    pub base_cal: f64,
}

/// McCoy's boattail drag.
pub fn boattail_drag(mach: f64, a: &Afterbody) -> f64 {
    if mach <= BOATTAIL_ONSET_MACH {
        return 0.0;
    }
    let (l, tb) = (a.boattail_cal, (1.0 - a.base_cal) / (2.0 * a.boattail_cal));
    let tb23 = 2.0 * tb * tb + tb.powi(3);
    let e = (-2.0 * l).exp();
    let bbt = 1.0 - e + 2.0 * tb * (e * (l + 0.5) - 0.5);
    let x = chi(mach);
    if mach <= 1.0 {
        2.0 * tb23 * bbt / (0.564 + 1260.0 * x * x)
    } else if mach <= 1.1 {
        2.0 * tb23 * bbt * (1.774 - 9.3 * x)
    } else {
        boattail_supersonic(mach, a, tb).max(0.0)
    }
}

/// McCoy's supersonic boattail drag (his eq. 9): 4 A t_b (1 - e^(-k l) + 2 t_b (e^(-k l)
/// (l + 1/k) - 1/k)) / k, k = 0.85 / beta, A = A_1 e^(-(1.1952 / M) l_C) - (2.4 M^4 - 4
/// beta^2) t_b^2 / (2 beta^4) + 2 t_b / beta, A_1 = (1 - 0.6 h / M) (5 tau / (6 beta) +
/// (tau / 2)^2 - 0.7435 (tau M)^1.6 / M^2).
pub fn boattail_supersonic(mach: f64, a: &Afterbody, tb: f64) -> f64 {
    let (m2, l) = (mach * mach, a.boattail_cal);
    let be2 = m2 - 1.0;
    let be = be2.sqrt();
    let tau = 1.0 / a.nose_cal;
    let a1 = (1.0 - 0.6 * a.shape / mach)
        * (5.0 * tau / (6.0 * be) + (0.5 * tau).powi(2) - 0.7435 / m2 * (tau * mach).powf(1.6));
    let big_a = a1 * (-1.1952 / mach * a.cylinder_cal).exp()
        - (2.4 * m2 * m2 - 4.0 * be2) * tb * tb / (2.0 * be2 * be2)
        + 2.0 * tb / be;
    let k = 0.85 / be;
    let e = (-k * l).exp();
    4.0 * big_a * tb * (1.0 - e + 2.0 * tb * (e * (l + 1.0 / k) - 1.0 / k)) / k
}

/// McCoy's base drag of a base `base_cal` calibres across, `behind_nose_cal` behind the nose.
pub fn base_drag(mach: f64, base_cal: f64, behind_nose_cal: f64) -> f64 {
    let m2 = mach * mach;
    let p2 = if mach < 1.0 {
        1.0 / (1.0 + 0.1875 * m2 + 0.0531 * m2 * m2)
    } else {
        1.0 / (1.0 + 0.2477 * m2 + 0.0345 * m2 * m2)
    };
    let p4 =
        (1.0 + 0.09 * m2 * (1.0 - (-behind_nose_cal).exp())) * (1.0 + 0.25 * m2 * (1.0 - base_cal));
    2.0 * base_cal * base_cal / (1.4 * m2) * (1.0 - p2 * p4)
}

/// The body's pressure drag (nose, boattail) and base drag of `c` at `mach`.
fn body_pressure(c: &Configuration, mach: f64) -> (f64, f64) {
    let d = c.diameter_m;
    let shape = match c.nose {
        Nose::Cone => 0.0,
        // A tangent ogive (the geometry's only other nose, as config.rs's profile reads it).
        _ => 1.0,
    };
    let nose_cal = c.nose_length_m / d;
    let base_cal = c.base_diameter_m / d;
    let behind_nose_cal = (c.length_m - c.nose_length_m) / d;
    let mut wave = nose_drag(mach, nose_cal, shape);
    if c.boattail_length_m > 0.0 {
        let a = Afterbody {
            nose_cal,
            shape,
            cylinder_cal: (c.length_m - c.nose_length_m - c.boattail_length_m) / d,
            boattail_cal: c.boattail_length_m / d,
            base_cal,
        };
        wave += boattail_drag(mach, &a);
    }
    (wave, base_drag(mach, base_cal, behind_nose_cal))
}

/// CA0 of `c` at `mach` in `air`, the body's wetted area `wetted_m2`.
pub fn axial(c: &Configuration, mach: f64, air: &AirState, wetted_m2: f64) -> AxialParts {
    let t = air.temperature_k;
    let mu = 1.458e-6 * t.powf(1.5) / (t + 110.4);
    let re_per_m = air.density_kg_m3 * mach * air.speed_of_sound_m_s / mu;
    let a = c.fins.as_ref().map_or(1.0, |p| p.aspect_ratio);
    let w = ((mach - M_SUBSONIC_END) / (m_supersonic(a) - M_SUBSONIC_END)).clamp(0.0, 1.0);
    let f = c.length_m / c.diameter_m;
    let ff_body = 1.0 + (1.0 - w) * (60.0 / f.powi(3) + f / 400.0);
    let mut friction = cf(re_per_m * c.length_m, mach) * ff_body * wetted_m2 / c.area_ref_m2;
    let (mut wave, base) = body_pressure(c, mach);
    if let Some(p) = &c.fins {
        let tc = p.thickness_m / p.mac_m;
        let ff_fin = 1.0 + (1.0 - w) * (2.0 * tc + 60.0 * tc.powi(4));
        let wetted = 2.0 * p.area_m2 * f64::from(p.count);
        friction += cf(re_per_m * p.mac_m, mach) * ff_fin * wetted / c.area_ref_m2;
        let at = mach.max(m_supersonic(p.aspect_ratio));
        let fin_wave = fin_wave_per_area(p, at);
        wave += w * fin_wave * f64::from(p.count) * p.area_m2 / c.area_ref_m2;
    }
    AxialParts {
        friction,
        base,
        wave,
    }
}

/// A fin's wave drag on its own area by Ackeret's 4 (t/c)^2 / beta at `mach` (> 1).
fn fin_wave_per_area(p: &Panel, mach: f64) -> f64 {
    let tc = p.thickness_m / p.mac_m;
    4.0 * tc * tc / (mach * mach - 1.0).sqrt()
}

/// The fins' wave drag on S_ref at M_sup, the end of the bridge from which it is carried.
pub fn fin_wave_at_m_sup(c: &Configuration, p: &Panel) -> f64 {
    let m_sup = m_supersonic(p.aspect_ratio);
    fin_wave_per_area(p, m_sup) * f64::from(p.count) * p.area_m2 / c.area_ref_m2
}

#[cfg(test)]
mod tests {
    use super::*;

    /// McCoy's forms by hand at their joins: the nose's drag rise starts from 0 at its
    /// critical Mach number, the boattail's two transonic forms meet at Mach 1, and a base as
    /// wide as the body at Mach 1 has p_B / p = P_2 P_4 by hand.
    #[test]
    fn mccoy_joins_by_hand() {
        let (l_n, h) = (2.0, 1.0);
        let tau: f64 = 0.5;
        let m_crit = (1.0 + 0.552 * tau.powf(0.8)).powf(-0.5);
        assert!(nose_drag(m_crit - 1e-9, l_n, h).abs() <= 0.0);
        assert!(nose_drag(m_crit + 1e-9, l_n, h).abs() < 1e-7);
        assert!((nose_drag(1.0, l_n, h) - 0.368 * tau.powf(1.8)).abs() < 1e-12);
        let a = Afterbody {
            nose_cal: l_n,
            shape: h,
            cylinder_cal: 3.0,
            boattail_cal: 1.0,
            base_cal: 0.7,
        };
        let below = boattail_drag(1.0, &a);
        let above = boattail_drag(1.0 + 1e-9, &a);
        assert!((below - above).abs() < 1e-3 * below, "{below} {above}");
        assert!(boattail_drag(0.85, &a).abs() <= 0.0);
        let p = 1.0 / (1.0 + 0.2477 + 0.0345) * (1.0 + 0.09 * (1.0 - (-4.0f64).exp()));
        assert!((base_drag(1.0, 1.0, 4.0) - 2.0 / 1.4 * (1.0 - p)).abs() < 1e-12);
    }
}
