//! A DAVE-ML file as another tool writes it (radians, feet, a breakpoint set shared by three
//! tables, inputs out of sepval's order, a derivative per degree, a uniformPDF, checkData) read
//! into a scenario.

use sepval_common::correction::Target;
use sepval_common::scenario::Scenario;
use sepval_common::table::{Coefficient, Variable};
use sepval_daveml::{Map, import_model, load_map, read_model};

use super::{fixture, fixture_text};

fn table(s: &Scenario, field: &str) -> sepval_common::table::Table {
    let t = Target::of_field(field).unwrap();
    match sepval_daveml::assemble::field(s, t) {
        Some(Coefficient::Table(t)) => t.clone(),
        other => panic!("{field}: {other:?}"),
    }
}

/// The fixture's check cases, worked out: at Mach 0.75 (half-way from 0.6 to 0.9) and alpha
/// 0.1 rad (half-way from 0 to 0.2), CN is the mean of 0.5 (Mach 0.6) and 0.55 (Mach 0.9),
/// 0.525; Cm the mean of 0 and -0.11, -0.055; Clp -0.55 per deg; dCZ at 2.5 ft (half-way from 0
/// to 5 ft) -0.45. Beyond every table (Mach 1.5, alpha -0.3 rad, 40 ft) each is held at its
/// corner: CN -1.2, Cm 0.14, Clp -0.7, dCZ 0.
#[test]
fn another_tools_file_reads_with_units_converted_and_checks_passing() {
    let map = load_map(Some(&fixture("other_tool.toml"))).unwrap();
    let base = Scenario::embedded_default();
    let m = read_model(&fixture("other_tool.dml"), &map, &base).unwrap();
    assert_eq!(
        m.fields,
        [
            "aero.cz",
            "aero.cm",
            "aero.cl_p_per_rad",
            "interference.dcz0",
            "aero.ca0"
        ]
    );
    // Two cases: 5 + 4 outputs compared (CL is ignored by the map).
    assert_eq!(m.checked, 9);
    assert!(
        m.notes.iter().any(|n| n.contains("uniformPDF")),
        "{:?}",
        m.notes
    );
    assert!(m.notes.iter().any(|n| n.contains("CL")), "{:?}", m.notes);

    // CN = -CZ; alpha breakpoints from radians to degrees (to_degrees), Mach shared.
    let cz = table(&m.scenario, "aero.cz");
    assert_eq!(cz.axes()[0].variable, Variable::Mach);
    assert_eq!(cz.axes()[0].breakpoints, [0.6, 0.9, 1.2]);
    assert_eq!(cz.axes()[1].variable, Variable::Alpha);
    assert_eq!(cz.axes()[1].breakpoints[2], 0.2f64.to_degrees());
    assert_eq!(cz.values()[..3], [1.0, -0.0, -1.0]);
    // Cm was given over (alpha, Mach): put in sepval's order (Mach, alpha), values transposed.
    let cm = table(&m.scenario, "aero.cm");
    assert_eq!(cm.axes()[0].variable, Variable::Mach);
    assert_eq!(
        cm.values(),
        [0.10, 0.0, -0.10, 0.12, 0.0, -0.12, 0.14, 0.0, -0.14]
    );
    // Per degree to per radian; feet to metres, exactly.
    let clp = table(&m.scenario, "aero.cl_p_per_rad");
    assert_eq!(clp.values()[0], (-0.5f64).to_degrees());
    let dcz = table(&m.scenario, "interference.dcz0");
    assert_eq!(dcz.axes()[0].breakpoints, [0.0, 1.524, 3.048, 9.144]);
    // The static tables replace their slopes' linear terms; CA is a constant.
    assert!(m.scenario.aero.cz_alpha_per_rad.is_none());
    assert!(m.scenario.aero.cm_alpha_per_rad.is_none());
    assert_eq!(m.scenario.aero.ca0.as_constant(), Some(0.35));
    // The rest is the base's.
    assert_eq!(m.scenario.store, base.store);
    assert_eq!(m.scenario.aero.cy_beta_per_rad, base.aero.cy_beta_per_rad);
}

#[test]
fn without_its_map_the_files_own_names_are_refused_naming_them() {
    let e = import_model(
        &fixture_text("other_tool.dml"),
        "other_tool.dml",
        &Map::default(),
        &Scenario::embedded_default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("other_tool.dml line 82, <independentVarRef>: the function's input `dist_ft` is not in the map"),
        "{e}"
    );
}

#[test]
fn a_map_file_names_fields_and_inputs_and_its_errors_name_the_entry() {
    let text =
        "[inputs]\naoa_r = \"alpha\"\n[outputs]\nCNtot = { field = \"aero.cz\", negate = true }\n";
    let map = Map::with_file(text, "m.toml").unwrap();
    assert!(matches!(
        map.role("aoa_r", ""),
        Some(sepval_daveml::map::Role::Input(Variable::Alpha))
    ));
    let e = Map::with_file("[outputs]\nX = { field = \"aero.cq\" }\n", "m.toml")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("map m.toml: [outputs] X: field `aero.cq` is not a field"),
        "{e}"
    );
    let e = Map::with_file("[inputs]\nq = \"altitude\"\n", "m.toml")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("expected mach, alpha, beta, distance or lateral"),
        "{e}"
    );
}

/// A table of three inputs listed as (beta, Mach, alpha): read in sepval's order (Mach, alpha,
/// beta), every grid point the same value.
#[test]
fn three_inputs_in_another_order_are_nested_with_their_values() {
    let (mach, alpha, beta) = ([0.5, 1.0], [-4.0, 0.0, 4.0], [-2.0, 0.0, 2.0, 6.0]);
    let f = |m: f64, a: f64, b: f64| 100.0 * m + 10.0 * a + b;
    let mut data = Vec::new();
    for b in beta {
        for m in mach {
            for a in alpha {
                data.push(f(m, a, b).to_string());
            }
        }
    }
    let list = |v: &[f64]| v.iter().map(f64::to_string).collect::<Vec<_>>().join(",");
    let text = format!(
        r#"<DAVEfunc>
  <fileHeader><author name="x" org="y"/><creationDate date="2020-01-01"/></fileHeader>
  <variableDef varID="mach" units="nd"/><variableDef varID="alpha" units="deg"/>
  <variableDef varID="beta" units="deg"/><variableDef varID="Cl" units="nd"/>
  <breakpointDef bpID="m"><bpVals>{}</bpVals></breakpointDef>
  <breakpointDef bpID="a"><bpVals>{}</bpVals></breakpointDef>
  <breakpointDef bpID="b"><bpVals>{}</bpVals></breakpointDef>
  <function name="Cl">
    <independentVarRef varID="beta"/><independentVarRef varID="mach"/><independentVarRef varID="alpha"/>
    <dependentVarRef varID="Cl"/>
    <functionDefn><griddedTableDef><breakpointRefs><bpRef bpID="b"/><bpRef bpID="m"/><bpRef bpID="a"/></breakpointRefs>
      <dataTable>{}</dataTable></griddedTableDef></functionDefn>
  </function>
</DAVEfunc>"#,
        list(&mach),
        list(&alpha),
        list(&beta),
        data.join(",")
    );
    let m = import_model(
        &text,
        "t.dml",
        &Map::default(),
        &Scenario::embedded_default(),
    )
    .unwrap();
    let t = table(&m.scenario, "aero.cl");
    let vars: Vec<Variable> = t.axes().iter().map(|a| a.variable).collect();
    assert_eq!(vars, [Variable::Mach, Variable::Alpha, Variable::Beta]);
    let mut k = 0;
    for mm in mach {
        for a in alpha {
            for b in beta {
                assert_eq!(t.values()[k], f(mm, a, b), "at {mm}, {a}, {b}");
                k += 1;
            }
        }
    }
}

/// The AIAA standard names (as NASA's F-16 model writes them: short varIDs, standard names)
/// read with the default map; X is negated (CX = -CA), the moments are sepval's.
#[test]
fn aiaa_standard_names_read_with_the_default_map() {
    let text = r#"<?xml version="1.0"?>
<DAVEfunc xmlns="http://daveml.org/2010/DAVEML">
  <fileHeader><author name="x" org="y"/><creationDate date="2013-10-21"/></fileHeader>
  <variableDef name="angleOfAttack" varID="alpha" units="deg"><isStdAIAA/></variableDef>
  <variableDef name="aeroBodyForceCoefficient_X" varID="cx" units="nd"><isStdAIAA/></variableDef>
  <variableDef name="aeroBodyMomentCoefficient_Pitch" varID="cm" units="nd"><isStdAIAA/></variableDef>
  <breakpointDef bpID="ALPHA1" units="deg"><bpVals>-10 0 10</bpVals></breakpointDef>
  <function name="cx_fn">
    <independentVarRef varID="alpha" min="-10" max="10" extrapolate="neither"/>
    <dependentVarRef varID="cx"/>
    <functionDefn><griddedTableDef><breakpointRefs><bpRef bpID="ALPHA1"/></breakpointRefs>
      <dataTable>-0.05 -0.02 -0.05</dataTable></griddedTableDef></functionDefn>
  </function>
  <function name="cm_fn">
    <independentVarRef varID="alpha" min="-10" max="10" extrapolate="neither"/>
    <dependentVarRef varID="cm"/>
    <functionDefn><griddedTableDef><breakpointRefs><bpRef bpID="ALPHA1"/></breakpointRefs>
      <dataTable>0.1 0 -0.1</dataTable></griddedTableDef></functionDefn>
  </function>
</DAVEfunc>"#;
    let m = import_model(
        text,
        "f.dml",
        &Map::default(),
        &Scenario::embedded_default(),
    )
    .unwrap();
    assert_eq!(m.fields, ["aero.ca0", "aero.cm"]);
    assert_eq!(table(&m.scenario, "aero.ca0").values(), [0.05, 0.02, 0.05]);
    assert_eq!(table(&m.scenario, "aero.cm").values(), [0.1, 0.0, -0.1]);
}
