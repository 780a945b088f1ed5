//! The unit tests of `sepval_common::scenario`.

use sepval_common::scenario::*;
use sepval_core::factors::{Factor, FactorTable};
use sepval_core::units::*;

#[test]
fn embedded_default_is_the_exact_conversion() {
    let s = Scenario::embedded_default();
    assert_eq!(s.store.mass_kg.to_bits(), (2000.0 * KG_PER_LB).to_bits());
    assert_eq!(
        s.store.ixx_kg_m2.to_bits(),
        (20.0 * KG_M2_PER_SLUG_FT2).to_bits()
    );
    assert_eq!(
        s.store.iyy_kg_m2.to_bits(),
        (360.0 * KG_M2_PER_SLUG_FT2).to_bits()
    );
    assert_eq!(
        s.store.izz_kg_m2.to_bits(),
        (360.0 * KG_M2_PER_SLUG_FT2).to_bits()
    );
    assert_eq!(s.store.diameter_m.to_bits(), (20.0 * M_PER_IN).to_bits());
    assert_eq!(s.store.fwd_foot_x_m.to_bits(), (0.59 * M_PER_FT).to_bits());
    assert_eq!(s.store.aft_foot_x_m.to_bits(), (-1.08 * M_PER_FT).to_bits());
    assert_eq!(s.store.stroke_m.to_bits(), (0.33 * M_PER_FT).to_bits());
    let f = 12_000.0 * N_PER_LBF;
    assert_eq!(s.ejector.curve, vec![[0.0, f], [0.33 * M_PER_FT, f]]);
    assert_eq!(
        s.flight.altitude_m.to_bits(),
        (26_000.0 * M_PER_FT).to_bits()
    );
    assert_eq!(
        s.interference.s_end_m.to_bits(),
        (30.0 * M_PER_FT).to_bits()
    );
    assert_eq!(s.factors, FactorTable::default());
}

#[test]
fn toml_round_trip_is_exact() {
    let s = Scenario::embedded_default();
    let back = Scenario::from_toml_str(&s.to_toml_string(), "round trip").unwrap();
    assert_eq!(back, s);
    assert_eq!(back.content_hash(), s.content_hash());
}

#[test]
fn refusals_name_the_field() {
    let text = DEFAULT_SCENARIO_TOML.replace("stroke_m = 0.100584", "stroke_m = 0.2");
    let e = Scenario::from_toml_str(&text, "x.toml")
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "scenario x.toml: `ejector.curve` covers [0, 0.100584] m: it must cover [0, stroke] = [0, 0.2] m"
    );
    let text = DEFAULT_SCENARIO_TOML.replace("mass_kg = 907.18474", "mass_kg = -1.0");
    let e = Scenario::from_toml_str(&text, "x.toml")
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "scenario x.toml: `store.mass_kg` = -1: expected a finite value > 0"
    );
    let text = DEFAULT_SCENARIO_TOML.replace("mach = 0.95", "mach = 0.95\nmahc = 1");
    let e = Scenario::from_toml_str(&text, "x.toml")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("unknown field `mahc`") && e.contains("line"),
        "{e}"
    );
    let text = DEFAULT_SCENARIO_TOML.replace("cloff = {", "clof = {");
    let e = Scenario::from_toml_str(&text, "x.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown factor `clof`"), "{e}");
    let text = DEFAULT_SCENARIO_TOML.replace(
        "fwdfac = { min = 0.2, max = 1.0, bits = 5 }",
        "fwdfac = { min = 1.2, max = 1.0, bits = 5 }",
    );
    let e = Scenario::from_toml_str(&text, "x.toml")
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "scenario x.toml: `factors` factor `fwdfac`: min 1.2 must be below max 1"
    );
}

#[test]
fn partial_factor_table_keeps_table_one_for_the_rest() {
    let start = DEFAULT_SCENARIO_TOML.find("[factors]").unwrap();
    let text = format!(
        "{}[factors]\ncmoff = {{ min = -0.3, max = 0.3, bits = 8 }}\n",
        &DEFAULT_SCENARIO_TOML[..start]
    );
    let s = Scenario::from_toml_str(&text, "x.toml").unwrap();
    assert_eq!(s.factors.spec(Factor::Cmoff).bits, 8);
    assert_eq!(
        s.factors.spec(Factor::Fwdfac),
        FactorTable::default().spec(Factor::Fwdfac)
    );
}
