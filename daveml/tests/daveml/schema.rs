//! What sepval writes, checked against the DAVE-ML 2.0 document structure: the content models
//! of the elements sepval writes, after the DAVE-ML 2.0 DTD (`DAVEfunc.dtd`, public identifier
//! `-//AIAA//DTD for Flight Dynamic Models - Functions 2.0//EN`; the element order of ANSI/AIAA
//! S-119-2011 section 5), each an ordered list of (allowed names, least, most) that an
//! element's children must follow in order. The DTD itself could not be fetched where this was
//! written: the models are encoded from the standard's structure as documented, and agree with
//! DAVE-ML 2.0 files other tools write (NASA's F-16 model: the namespace, `creationDate`,
//! `internalValues` between `checkInputs` and `checkOutputs`). Elements sepval never writes
//! (provenance, reference, calculation, ...) appear only where they fix the order of those it
//! does. Check against the published DTD when it is at hand.

use roxmltree::{Document, Node};
use sepval_common::scenario::Scenario;
use sepval_daveml::{Band, Provenance, to_daveml};

const MANY: usize = usize::MAX;

/// The content model of `name`: its children in order, or `None` for an element sepval writes
/// with text or nothing.
fn content_model(name: &str) -> Option<Vec<(&'static [&'static str], usize, usize)>> {
    Some(match name {
        "DAVEfunc" => vec![
            (&["fileHeader"][..], 1, 1),
            (&["variableDef"], 1, MANY),
            (&["breakpointDef"], 0, MANY),
            (&["griddedTableDef"], 0, MANY),
            (&["ungriddedTableDef"], 0, MANY),
            (&["function"], 0, MANY),
            (&["checkData"], 0, 1),
        ],
        "fileHeader" => vec![
            (&["author"][..], 1, MANY),
            (&["creationDate", "fileCreationDate"], 1, 1),
            (&["fileVersion"], 0, 1),
            (&["description"], 0, 1),
            (&["reference"], 0, MANY),
            (&["modificationRecord"], 0, MANY),
            (&["provenance"], 0, MANY),
        ],
        "variableDef" => vec![
            (&["description"][..], 0, 1),
            (&["provenance", "provenanceRef"], 0, 1),
            (&["calculation"], 0, 1),
            (&["isOutput"], 0, 1),
            (&["isState"], 0, 1),
            (&["isStateDeriv"], 0, 1),
            (&["isStdAIAA"], 0, 1),
            (&["uncertainty"], 0, 1),
        ],
        "breakpointDef" => vec![(&["description"][..], 0, 1), (&["bpVals"], 1, 1)],
        "griddedTableDef" => vec![
            (&["description"][..], 0, 1),
            (&["provenance", "provenanceRef"], 0, 1),
            (&["breakpointRefs"], 1, 1),
            (&["uncertainty"], 0, 1),
            (&["dataTable"], 1, 1),
        ],
        "breakpointRefs" => vec![(&["bpRef"][..], 1, MANY)],
        "uncertainty" => vec![(&["normalPDF", "uniformPDF"][..], 1, 1)],
        "normalPDF" => vec![
            (&["bounds"][..], 1, 1),
            (&["correlatesWith"], 0, MANY),
            (&["correlation"], 0, MANY),
        ],
        "bounds" => vec![(&["dataTable", "variableDef", "variableRef"][..], 1, 1)],
        "function" => vec![
            (&["description"][..], 0, 1),
            (&["provenance", "provenanceRef"], 0, 1),
            (&["independentVarRef"], 1, MANY),
            (&["dependentVarRef"], 1, 1),
            (&["functionDefn"], 1, 1),
        ],
        "functionDefn" => vec![(
            &[
                "griddedTableRef",
                "griddedTableDef",
                "ungriddedTableRef",
                "ungriddedTableDef",
            ][..],
            1,
            1,
        )],
        "checkData" => vec![
            (&["provenance", "provenanceRef"][..], 0, MANY),
            (&["staticShot"], 1, MANY),
        ],
        "staticShot" => vec![
            (&["description"][..], 0, 1),
            (&["provenance", "provenanceRef"], 0, 1),
            (&["checkInputs"], 1, 1),
            (&["internalValues"], 0, 1),
            (&["checkOutputs"], 1, 1),
        ],
        "checkInputs" | "checkOutputs" => vec![(&["signal"][..], 1, MANY)],
        "signal" => vec![
            (&["signalName"][..], 1, 1),
            (&["signalUnits"], 1, 1),
            (&["signalValue"], 1, 1),
            (&["tol"], 0, 1),
        ],
        "author" | "creationDate" | "fileVersion" | "description" | "bpVals" | "bpRef"
        | "dataTable" | "isOutput" | "independentVarRef" | "dependentVarRef"
        | "griddedTableRef" | "correlatesWith" | "correlation" | "signalName" | "signalUnits"
        | "signalValue" | "tol" => return None,
        other => panic!("sepval wrote <{other}>, an element this check does not know"),
    })
}

/// Checks `n` and its descendants against their content models.
fn conforms(n: Node) {
    let name = n.tag_name().name();
    let children: Vec<Node> = n.children().filter(Node::is_element).collect();
    let Some(model) = content_model(name) else {
        assert!(children.is_empty(), "<{name}> has child elements");
        return;
    };
    let mut k = 0;
    for (names, least, most) in &model {
        let mut count = 0;
        while k < children.len() && names.contains(&children[k].tag_name().name()) {
            count += 1;
            k += 1;
        }
        assert!(
            count >= *least && count <= *most,
            "<{name}>: {count} of {names:?}, expected {least} to {most}"
        );
    }
    assert!(
        k == children.len(),
        "<{name}>: <{}> out of order or not allowed",
        children[k].tag_name().name()
    );
    for c in children {
        conforms(c);
    }
}

fn provenance() -> Provenance {
    Provenance {
        sepval_version: "0.1.0".into(),
        date: "2026-11-27".into(),
        releases: vec!["a.csv".into(), "b & c.csv".into()],
        source: "the test's scenario".into(),
    }
}

#[test]
fn what_sepval_writes_follows_the_daveml_2_element_order() {
    let dir = tempfile::tempdir().unwrap();
    let s = super::round_trip::default_as_tables(dir.path());
    let cm = sepval_common::correction::Target::of_field("aero.cm").unwrap();
    let cz = sepval_common::correction::Target::of_field("aero.cz").unwrap();
    let n = match sepval_daveml::assemble::field(&s, cm) {
        Some(sepval_common::table::Coefficient::Table(t)) => t.values().len(),
        _ => panic!(),
    };
    let band = Band {
        target: cm,
        sigma: vec![0.01; n],
        correlations: vec![(cz, -0.3)],
    };
    let text = to_daveml(&s, &[band], &provenance()).unwrap();
    let doc = Document::parse(&text).unwrap();
    let root = doc.root_element();
    assert_eq!(
        root.tag_name().namespace(),
        Some(sepval_daveml::export::NAMESPACE)
    );
    conforms(root);
    // The provenance: sepval's version, the releases (escaped), the date.
    assert!(text.contains("<author name=\"sepval 0.1.0\" org=\"sepval\"/>"));
    assert!(text.contains("<creationDate date=\"2026-11-27\"/>"));
    assert!(text.contains("the releases a.csv, b &amp; c.csv"));
    assert!(text.contains("<correlation varID=\"CZ\" corrCoef=\"-0.3\"/>"));
    // Breakpoint sets shared: the six static tables over one Mach, one alpha, one beta set.
    assert_eq!(
        text.matches("<breakpointDef ").count(),
        4,
        "mach, alpha, beta, distance"
    );
}

#[test]
fn a_band_that_does_not_fit_its_table_is_refused() {
    let s = Scenario::embedded_default();
    let cm = sepval_common::correction::Target::of_field("aero.cm_q_per_rad").unwrap();
    let e = to_daveml(
        &s,
        &[Band {
            target: cm,
            sigma: vec![0.1],
            correlations: vec![],
        }],
        &provenance(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("not one per value of its table"), "{e}");
}
