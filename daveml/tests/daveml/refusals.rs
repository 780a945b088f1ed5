//! Bad files refused, each naming the line and the element (and nothing written: the CLI's
//! tests check the directory; here the stages return before the write stage).

use sepval_common::scenario::Scenario;
use sepval_daveml::{DavemlError, Map, import_model, load_map, read_model};

use super::{fixture, fixture_text};

/// The error of the fixture with `from` replaced by `to`, read with its map.
fn refused(from: &str, to: &str) -> String {
    let text = fixture_text("other_tool.dml");
    assert!(text.contains(from), "{from}");
    let map = load_map(Some(&fixture("other_tool.toml"))).unwrap();
    import_model(
        &text.replacen(from, to, 1),
        "t.dml",
        &map,
        &Scenario::embedded_default(),
    )
    .unwrap_err()
    .to_string()
}

#[test]
fn an_unknown_variable_is_refused_at_its_reference() {
    let e = refused(
        "<independentVarRef varID=\"alprad\"/>",
        "<independentVarRef varID=\"alfa\"/>",
    );
    assert_eq!(
        e,
        "t.dml line 66, <independentVarRef>: unknown variable `alfa`: no <variableDef> has this varID"
    );
}

#[test]
fn a_table_of_the_wrong_size_is_refused_at_its_table() {
    let e = refused("-1.2, 0.0, 1.2", "-1.2, 0.0");
    assert_eq!(
        e,
        "t.dml line 37, <griddedTableDef>: the dataTable has 8 values for a grid of 9 points (3 x 3)"
    );
}

#[test]
fn breakpoints_not_increasing_are_refused_at_their_set() {
    let e = refused("0, 5, 10, 30", "0, 5, 5, 30");
    assert_eq!(
        e,
        "t.dml line 33, <breakpointDef>: breakpoint set `DIST_bp` is not strictly increasing: 5.0 after 5.0"
    );
}

#[test]
fn extrapolation_sepval_cannot_honour_is_refused() {
    let e = refused(
        "extrapolate=\"neither\" interpolate",
        "extrapolate=\"both\" interpolate",
    );
    assert!(
        e.starts_with("t.dml line 61, <independentVarRef>: extrapolate=\"both\" on `alprad`: sepval's tables hold their edge value"),
        "{e}"
    );
    let e = refused("interpolate=\"linear\"", "interpolate=\"cubicSpline\"");
    assert!(e.contains("interpolate=\"cubicSpline\""), "{e}");
}

#[test]
fn a_calculation_is_refused_at_its_element() {
    let e = refused(
        "<variableDef name=\"CA\" varID=\"CA\" units=\"nd\" initialValue=\"0.35\"/>",
        "<variableDef name=\"CA\" varID=\"CA\" units=\"nd\">\n<calculation><math><apply><plus/><ci>CA0</ci><ci>dCA</ci></apply></math></calculation></variableDef>",
    );
    assert!(
        e.starts_with(
            "t.dml line 25, <calculation>: `CA` (sepval field aero.ca0) is a MathML calculation"
        ),
        "{e}"
    );
}

#[test]
fn more_inputs_than_a_table_takes_are_refused() {
    let e = refused(
        "<independentVarRef varID=\"MACH\"/>\n    <dependentVarRef varID=\"Clp\"/>",
        "<independentVarRef varID=\"MACH\"/><independentVarRef varID=\"alprad\"/>\n    <dependentVarRef varID=\"Clp\"/>",
    );
    assert!(
        e.contains("Clp") && e.contains("independentVarRef(s)"),
        "{e}"
    );
}

#[test]
fn a_check_case_the_tables_do_not_reproduce_is_refused() {
    let e = refused(
        "<signalValue>-0.055</signalValue>",
        "<signalValue>-0.056</signalValue>",
    );
    assert!(
        e.starts_with("t.dml line 112, <signal>: check case `inside`: Cm is -0.055 through the imported tables, -0.056 in the file"),
        "{e}"
    );
}

#[test]
fn a_negative_tolerance_is_refused_at_its_element() {
    let e = refused("<tol>1e-9</tol>", "<tol>-1</tol>");
    assert!(
        e.starts_with("t.dml line 111, <tol>: tolerance -1 is negative"),
        "{e}"
    );
}

#[test]
fn a_file_that_is_not_xml_is_refused_with_its_position() {
    let e = import_model(
        "CN,alpha\n1,2\n",
        "x.dml",
        &Map::default(),
        &Scenario::embedded_default(),
    )
    .unwrap_err();
    assert!(matches!(e, DavemlError::NotXml { .. }), "{e}");
    assert!(e.to_string().starts_with("x.dml: not XML: "), "{e}");
    let e = import_model(
        "<a><b></a>",
        "x.dml",
        &Map::default(),
        &Scenario::embedded_default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("1:"), "{e}");
    let e = import_model(
        "<svg/>",
        "x.dml",
        &Map::default(),
        &Scenario::embedded_default(),
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "x.dml line 1, <svg>: the root element is not <DAVEfunc>: not a DAVE-ML model"
    );
}

#[test]
fn a_gigabyte_file_is_refused_before_it_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("big.dml");
    let f = std::fs::File::create(&p).unwrap();
    f.set_len(1 << 30).unwrap(); // sparse: no disk used
    let e = read_model(&p, &Map::default(), &Scenario::embedded_default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("the DAVE-ML file is 1073741824 bytes, more than the limit of 268435456 bytes"),
        "{e}"
    );
}

#[test]
fn limits_sepval_cannot_honour_are_refused_at_their_variable() {
    // An output saturated below its table's values.
    let e = refused(
        "<variableDef name=\"Cm\" varID=\"Cm\" units=\"nd\">",
        "<variableDef name=\"Cm\" varID=\"Cm\" units=\"nd\" maxValue=\"0.12\">",
    );
    assert_eq!(
        e,
        "t.dml line 20, <variableDef>: minValue/maxValue of `Cm` limit its table (a value 0.14 lies beyond them): sepval's tables are not saturated"
    );
    // An input limited inside its breakpoints.
    let e = refused(
        "<variableDef name=\"MACH\" varID=\"MACH\" units=\"nd\"/>",
        "<variableDef name=\"MACH\" varID=\"MACH\" units=\"nd\" minValue=\"0.7\"/>",
    );
    assert!(
        e.starts_with("t.dml line 15, <variableDef>: minValue/maxValue of `MACH` lie inside the breakpoints MACH_bp"),
        "{e}"
    );
    // Limits at or beyond the table change nothing.
    let text = fixture_text("other_tool.dml").replacen(
        "<variableDef name=\"MACH\" varID=\"MACH\" units=\"nd\"/>",
        "<variableDef name=\"MACH\" varID=\"MACH\" units=\"nd\" minValue=\"0.0\" maxValue=\"1.2\"/>",
        1,
    );
    let map = load_map(Some(&fixture("other_tool.toml"))).unwrap();
    import_model(&text, "t.dml", &map, &Scenario::embedded_default()).unwrap();
}

/// The error of the fixture without its `checkData` and its one `min`/`max` (so nothing but
/// the domain can refuse it), with `from` replaced by `to`.
fn unchecked(from: &str, to: &str) -> Result<sepval_daveml::ImportedModel, DavemlError> {
    let text = fixture_text("other_tool.dml");
    let (head, rest) = text.split_once("  <checkData>").unwrap();
    let (_, tail) = rest.split_once("</checkData>").unwrap();
    let text = format!("{head}{tail}").replacen(" min=\"0.6\" max=\"1.2\"", "", 1);
    assert!(!text.contains("min=") && text.contains(from), "{from}");
    let map = load_map(Some(&fixture("other_tool.toml"))).unwrap();
    import_model(
        &text.replacen(from, to, 1),
        "t.dml",
        &map,
        &Scenario::embedded_default(),
    )
}

fn refused_unchecked(from: &str, to: &str) -> String {
    unchecked(from, to).unwrap_err().to_string()
}

#[test]
fn breakpoints_outside_the_models_domain_are_refused_at_their_set() {
    let e = refused_unchecked("0.6, 0.9, 1.2", "-5, 0.9, 1.2");
    assert!(
        e.starts_with("t.dml line 26, <breakpointDef>: breakpoint set `MACH_bp` of `MACH` (sepval's mach): breakpoint -5.0 is outside mach's domain, 0 to 3 ("),
        "{e}"
    );
    let e = refused_unchecked("0.6, 0.9, 1.2", "0.6, 0.9, 1e200");
    assert!(
        e.contains("breakpoint 1e200 is outside mach's domain, 0 to 3"),
        "{e}"
    );
    // In the file's unit, and in sepval's: 4 rad is 229 deg, beyond atan2's range.
    let e = refused_unchecked("-0.2 0.0 0.2", "-0.2 0.0 4.0");
    assert!(
        e.starts_with("t.dml line 30, <breakpointDef>: breakpoint set `ALPHA_bp` of `alprad` (sepval's alpha): breakpoint 4.0 (229.1831180523293 deg) is outside alpha's domain, -180 to 180 deg ("),
        "{e}"
    );
    let e = refused_unchecked("0, 5, 10, 30", "-1, 5, 10, 30");
    assert!(
        e.contains("breakpoint -1.0 (-0.3048 m) is outside distance's domain, 0 to 100000 m"),
        "{e}"
    );
    // The domain's edges are inside.
    unchecked("0.6, 0.9, 1.2", "0, 0.9, 3").unwrap();
}
