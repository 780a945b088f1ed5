//! The round trip scenario -> DAVE-ML -> scenario: the same fields, and the same trajectory bit
//! for bit, on the embedded default written in table form and on a scenario of
//! multi-dimensional tables; and again through the directory the import writes.

use std::path::Path;

use sepval_common::effects::EffectSet;
use sepval_common::scenario::Scenario;
use sepval_common::simulation::Simulator;
use sepval_common::table::{Axis, Coefficient, Kind, Table, Tabulated, Variable};
use sepval_common::table_form::table_form;
use sepval_core::factors::Factors;
use sepval_daveml::output::write_table_dir;
use sepval_daveml::{Map, Provenance, import_model, to_daveml};

/// The embedded default in table form, interference included, read back from `dir`.
pub fn default_as_tables(dir: &Path) -> Scenario {
    let form = table_form(&Scenario::embedded_default(), true).unwrap();
    for (p, text) in &form.files {
        std::fs::create_dir_all(dir.join(p).parent().unwrap()).unwrap();
        std::fs::write(dir.join(p), text).unwrap();
    }
    let path = dir.join("scenario.toml");
    std::fs::write(&path, form.scenario.to_toml_string()).unwrap();
    Scenario::load(&path).unwrap()
}

/// A scenario with tables of two and three axes, non-linear values and constants beside them.
fn multi_dimensional() -> Scenario {
    let mut s = Scenario::embedded_default();
    let axis = |variable, breakpoints: &[f64]| Axis {
        variable,
        breakpoints: breakpoints.to_vec(),
    };
    let mach = [0.6, 0.95, 1.3];
    let angles = [-30.0, -7.5, 0.0, 2.5, 12.0, 40.0];
    let mut values = Vec::new();
    for m in mach {
        for a in angles {
            for b in angles {
                values.push(0.01 * m * (a / 7.0f64).sin() + 1e-3 * a * b / 3.0);
            }
        }
    }
    let cm = Table::new(
        vec![
            axis(Variable::Mach, &mach),
            axis(Variable::Alpha, &angles),
            axis(Variable::Beta, &angles),
        ],
        values,
        Kind::Static,
    )
    .unwrap();
    s.aero.cm = Some(Tabulated::table(cm).unwrap());
    let distance = [0.0, 0.1, 0.37, 1.0, 2.0, 9.0, 100.0];
    let lateral = [-1.0, 0.0, 1.0 / 3.0];
    let mut values = Vec::new();
    for d in distance {
        for a in angles {
            for l in lateral {
                values.push(-0.6 * (-d / 0.6f64).exp() * (1.0 + 0.01 * a) + 0.05 * l);
            }
        }
    }
    let dcz = Table::new(
        vec![
            axis(Variable::Distance, &distance),
            axis(Variable::Alpha, &angles),
            axis(Variable::Lateral, &lateral),
        ],
        values,
        Kind::Interference,
    )
    .unwrap();
    s.interference.dcz0 = Tabulated::table(dcz).unwrap();
    let cmq = Table::new(
        vec![axis(Variable::Mach, &[0.5, 0.9, 1.0, 1.6])],
        vec![-70.0, -80.0, -95.5, -60.125],
        Kind::Derivative,
    )
    .unwrap();
    s.aero.cm_q_per_rad = Tabulated::table(cmq).unwrap();
    s.validate("multi-dimensional").unwrap();
    s
}

fn bits(s: &Scenario) -> Vec<u64> {
    let sim = Simulator::new(s);
    let times = sim.default_times();
    let t = sim
        .simulate(&Factors::TRUTH, &EffectSet::NONE, &times)
        .unwrap();
    t.pos_m
        .iter()
        .chain(&t.att_deg)
        .flat_map(|v| v.iter().map(|x| x.to_bits()))
        .collect()
}

/// Writes `s` as DAVE-ML, reads it back into the constant-form default, and checks the fields,
/// the simulation's bits and the directory the import writes.
fn round_trip(s: &Scenario) {
    let prov = Provenance {
        sepval_version: "0.1.0".into(),
        date: "2026-11-27".into(),
        releases: vec![],
        source: "a test".into(),
    };
    let text = to_daveml(s, &[], &prov).unwrap();
    let base = Scenario::embedded_default();
    let back = import_model(&text, "round.dml", &Map::default(), &base).unwrap();
    // sepval's own checkData: three cases, every field compared.
    let shots = if s.has_tables() { 3 } else { 1 };
    assert_eq!(back.checked, shots * back.fields.len());
    assert_eq!(back.scenario.aero, s.aero);
    assert_eq!(back.scenario.interference, s.interference);
    let expected = bits(s);
    assert!(expected.len() > 1000);
    assert!(
        bits(&back.scenario) == expected,
        "the round trip changed the simulation"
    );
    // Through the directory in table form, as `sepval scenario --from-daveml` writes it.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("imported");
    write_table_dir(&back.scenario, &out, "round.dml").unwrap();
    let loaded = Scenario::load(&out.join("scenario.toml")).unwrap();
    assert!(
        bits(&loaded) == expected,
        "the directory changed the simulation"
    );
    let again = to_daveml(&loaded, &[], &prov).unwrap();
    assert_eq!(
        again,
        text.replace(&s.name, &loaded.name),
        "a second trip writes the same file"
    );
}

#[test]
fn the_default_in_table_form_round_trips_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let s = default_as_tables(dir.path());
    assert!(matches!(s.aero.ca0.value, Coefficient::Table(_)));
    round_trip(&s);
}

#[test]
fn multi_dimensional_tables_round_trip_bit_for_bit() {
    round_trip(&multi_dimensional());
}

#[test]
fn the_constant_form_round_trips_bit_for_bit() {
    round_trip(&Scenario::embedded_default());
}
