//! The unit tests of `sepval_common::atmosphere`.

use sepval_common::atmosphere::*;

/// docs/model.md section 1 prints rho = 0.52981 kg/m^3 and V = 292.96 m/s at Mach 0.95,
/// 26 000 ft (for orientation; the values are derived, not given).
#[test]
fn default_condition_matches_the_printed_orientation_values() {
    let air = isa_troposphere(26_000.0 * sepval_core::units::M_PER_FT);
    assert!(
        (air.density_kg_m3 - 0.52981).abs() < 5e-6,
        "{}",
        air.density_kg_m3
    );
    let v = 0.95 * air.speed_of_sound_m_s;
    assert!((v - 292.96).abs() < 5e-3, "{v}");
}
