//! The axial force at zero angle of attack, CA0 = friction + base + wave, on S_ref.
//!
//! - **Skin friction**: the turbulent flat plate with compressibility, Cf = 0.455 /
//!   ((log10 Re)^2.58 (1 + 0.144 M^2)^0.65) (D. P. Raymer, *Aircraft Design: A Conceptual
//!   Approach*, AIAA, eq. 12.27, after Schlichting), Re on the body's length or the fins' mean
//!   chord, with the form factors 1 + 60 / f^3 + f / 400 of a body of fineness f (Raymer eq.
//!   12.31) and 1 + 2 t/c + 60 (t/c)^4 of a fin (S. F. Hoerner, *Fluid-Dynamic Drag*, 1965,
//!   ch. 6), which fall to 1 across the transonic bridge (the supersonic value is the plate's).
//! - **Base drag**: 0.12 + 0.13 M^2 below Mach 1 and 0.25 / M above, on the base area (S.
//!   Niskanen, *OpenRocket technical documentation*, 2013, section 3.4.4, after Hoerner and
//!   Fleeman).
//! - **Nose wave drag** above Mach 1: (1.586 + 1.834 / M^2) (atan(0.5 / (L_n / d)))^1.69 of a
//!   sharp cone of the nose's fineness (E. L. Fleeman, *Tactical Missile Design*, 2nd ed.,
//!   AIAA 2006, section 2.4), used for the ogive too (an overestimate: an ogive of the same
//!   fineness has less), rising linearly from 0 at Mach 0.8 to its Mach 1 value.
//! - **Fin wave drag** from M_sup: Ackeret's 4 (t/c)^2 / beta of a thin section on each
//!   panel's area (Jones and Cohen 1960), bridged from 0 at Mach 0.8.
//!
//! Sutherland's viscosity mu = 1.458e-6 T^1.5 / (T + 110.4) [Pa s] gives Re at the
//! condition's ISA temperature and density. Missile DATCOM's accuracy goal for the axial force
//! is +-20 % (as commonly quoted; docs/aero.md).

use sepval_common::atmosphere::AirState;

use crate::config::Configuration;
use crate::fins::{M_SUBSONIC_END, m_supersonic};

/// The parts of CA0 at one Mach number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxialParts {
    /// Body and fin friction.
    pub friction: f64,
    /// Base drag.
    pub base: f64,
    /// Nose and fin wave drag.
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
    let mut wave = 0.0;
    if let Some(p) = &c.fins {
        let tc = p.thickness_m / p.mac_m;
        let ff_fin = 1.0 + (1.0 - w) * (2.0 * tc + 60.0 * tc.powi(4));
        let wetted = 2.0 * p.area_m2 * f64::from(p.count);
        friction += cf(re_per_m * p.mac_m, mach) * ff_fin * wetted / c.area_ref_m2;
        let m_sup = m_supersonic(p.aspect_ratio);
        let at = mach.max(m_sup);
        let fin_wave = 4.0 * tc * tc / (at * at - 1.0).sqrt();
        wave += w * fin_wave * f64::from(p.count) * p.area_m2 / c.area_ref_m2;
    }
    let cone = (0.5 * c.diameter_m / c.nose_length_m).atan().powf(1.69);
    let nose_wave = |m: f64| (1.586 + 1.834 / (m * m)) * cone;
    wave += if mach >= 1.0 {
        nose_wave(mach)
    } else {
        ((mach - M_SUBSONIC_END) / (1.0 - M_SUBSONIC_END)).clamp(0.0, 1.0) * nose_wave(1.0)
    };
    let base_cd = if mach < 1.0 {
        0.12 + 0.13 * mach * mach
    } else {
        0.25 / mach
    };
    let base = base_cd * (c.base_diameter_m / c.diameter_m).powi(2);
    AxialParts {
        friction,
        base,
        wave,
    }
}
