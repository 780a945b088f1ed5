//! ISA troposphere and the free-stream state of a flight condition.
//!
//! Source: `docs/model.md` section 1, "atmosphere" row:
//! `T = 288.15 - 0.0065 h`, `p = 101325 (T/288.15)^5.25588`, `rho = p / (287.053 T)`,
//! `a = sqrt(1.4 * 287.053 * T)`. Valid in the troposphere (h < 11 000 m); a scenario above it
//! is refused by the scenario validation rather than extrapolated silently. The power is
//! sepval's [`pow`] (docs/model.md section 9), not the C library's.

use crate::elementary::pow;

/// Sea-level standard temperature \[K\].
pub const T0_K: f64 = 288.15;
/// Troposphere lapse rate [K/m].
pub const LAPSE_K_PER_M: f64 = 0.0065;
/// Sea-level standard pressure \[Pa\].
pub const P0_PA: f64 = 101_325.0;
/// Pressure exponent of the troposphere (g / (R L)), as printed in docs/model.md.
pub const PRESSURE_EXPONENT: f64 = 5.25588;
/// Specific gas constant of air [J/(kg K)], as printed in docs/model.md.
pub const R_AIR_J_PER_KG_K: f64 = 287.053;
/// Ratio of specific heats of air.
pub const GAMMA_AIR: f64 = 1.4;
/// Top of the troposphere \[m\]: the formulas above stop being valid here.
pub const TROPOPAUSE_M: f64 = 11_000.0;

/// Air properties at one altitude.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AirState {
    /// Static temperature \[K\].
    pub temperature_k: f64,
    /// Static pressure \[Pa\].
    pub pressure_pa: f64,
    /// Density [kg/m^3].
    pub density_kg_m3: f64,
    /// Speed of sound [m/s].
    pub speed_of_sound_m_s: f64,
}

/// ISA troposphere at geometric altitude `altitude_m` (docs/model.md section 1).
pub fn isa_troposphere(altitude_m: f64) -> AirState {
    let temperature_k = T0_K - LAPSE_K_PER_M * altitude_m;
    let pressure_pa = P0_PA * pow(temperature_k / T0_K, PRESSURE_EXPONENT);
    let density_kg_m3 = pressure_pa / (R_AIR_J_PER_KG_K * temperature_k);
    let speed_of_sound_m_s = (GAMMA_AIR * R_AIR_J_PER_KG_K * temperature_k).sqrt();
    AirState {
        temperature_k,
        pressure_pa,
        density_kg_m3,
        speed_of_sound_m_s,
    }
}
