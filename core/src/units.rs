//! Exact unit conversions.
//!
//! Source: `docs/model.md`, preamble: "Constants are defined in the units in which they
//! are given and converted exactly, in double precision, never rounded". Every constant below is
//! the exact definition of the unit (international foot and pound, standard gravity-based
//! pound-force), so converting with them costs at most the rounding of one multiplication.

/// Metres per international foot (exact).
pub const M_PER_FT: f64 = 0.3048;
/// Metres per inch (exact: 1 in = 1/12 ft = 0.0254 m).
pub const M_PER_IN: f64 = 0.0254;
/// Kilograms per avoirdupois pound (exact).
pub const KG_PER_LB: f64 = 0.45359237;
/// Newtons per pound-force (exact: 0.45359237 kg x 9.80665 m/s^2).
pub const N_PER_LBF: f64 = 4.4482216152605;
/// kg m^2 per slug ft^2, as given by docs/model.md (slug = lbf s^2 / ft).
pub const KG_M2_PER_SLUG_FT2: f64 = 1.3558179483314004;

/// Degrees to radians.
#[inline]
pub fn deg_to_rad(deg: f64) -> f64 {
    deg.to_radians()
}

/// Radians to degrees.
#[inline]
pub fn rad_to_deg(rad: f64) -> f64 {
    rad.to_degrees()
}
