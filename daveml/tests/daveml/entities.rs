//! Entity declarations refused before the XML parser sees the text (docs/daveml.md section 1):
//! DAVE-ML needs none, and an internal entity expanded thousands of times takes gigabytes and
//! seconds inside the parser. The standard's own `<!DOCTYPE DAVEfunc PUBLIC ...>` (no internal
//! subset) is still read.

use sepval_common::scenario::Scenario;
use sepval_daveml::{DavemlError, import_model, load_map};

use super::{fixture, fixture_text};

/// The fixture with `prolog` put between its XML declaration and its first comment, and
/// `body` at the start of its `fileHeader`'s description.
fn with_doctype(prolog: &str, body: &str) -> String {
    let text = fixture_text("other_tool.dml");
    let (decl, rest) = text.split_once('\n').unwrap();
    let rest = rest.replacen(
        "<description>Test store",
        &format!("<description>{body}Test store"),
        1,
    );
    format!("{decl}\n{prolog}\n{rest}")
}

fn import(text: &str) -> Result<sepval_daveml::ImportedModel, DavemlError> {
    let map = load_map(Some(&fixture("other_tool.toml"))).unwrap();
    import_model(text, "t.dml", &map, &Scenario::embedded_default())
}

fn refusal(text: &str) -> String {
    let e = import(text).unwrap_err();
    assert!(matches!(e, DavemlError::Entity { .. }), "{e:?}");
    e.to_string()
}

#[test]
fn an_amplified_internal_entity_is_refused_at_its_declaration() {
    // 10 kB expanded 2000 times: 20 MB of text from a 30 kB file (the review's 1 MB file
    // expands to 4 GB and aborts the process).
    let entity = "x".repeat(10_000);
    let uses = "&big;".repeat(2_000);
    let text = with_doctype(
        &format!("<!DOCTYPE DAVEfunc [\n  <!-- a comment -->\n  <!ENTITY big \"{entity}\">\n]>"),
        &uses,
    );
    assert!(text.len() < 40_000);
    let e = refusal(&text);
    assert!(
        e.starts_with("t.dml line 4: the DOCTYPE declares the entity `big`"),
        "{e}"
    );
}

#[test]
fn billion_laughs_is_refused_at_its_first_entity() {
    let mut decls = String::from("<!ENTITY lol \"lol\">\n");
    for k in 1..10 {
        let prev = if k == 1 {
            "lol".to_string()
        } else {
            format!("lol{}", k - 1)
        };
        decls.push_str(&format!(
            "<!ENTITY lol{k} \"{}\">\n",
            format!("&{prev};").repeat(10)
        ));
    }
    let e = refusal(&with_doctype(
        &format!("<!DOCTYPE lolz [\n{decls}]>"),
        "&lol9;",
    ));
    assert!(
        e.starts_with("t.dml line 3: the DOCTYPE declares the entity `lol`"),
        "{e}"
    );
}

#[test]
fn external_and_parameter_entities_are_refused() {
    let e = refusal(&with_doctype(
        "<!DOCTYPE DAVEfunc [<!ENTITY xxe SYSTEM \"file:///etc/passwd\">]>",
        "&xxe;",
    ));
    assert!(
        e.starts_with("t.dml line 2: the DOCTYPE declares the entity `xxe`"),
        "{e}"
    );
    let e = refusal(&with_doctype(
        "<!DOCTYPE DAVEfunc [\n<!ATTLIST DAVEfunc x CDATA \"]>\">\n<!ENTITY % ext SYSTEM \"http://example.com/e.dtd\"> %ext;\n]>",
        "",
    ));
    assert!(
        e.starts_with("t.dml line 4: the DOCTYPE declares the parameter entity `ext`"),
        "{e}"
    );
}

#[test]
fn the_standard_doctype_without_entities_is_read() {
    let public = "<!DOCTYPE DAVEfunc PUBLIC \"-//AIAA//DTD DAVE-ML 2.0//EN\"\n  \"http://daveml.org/DTDs/2p0/DAVEfunc.dtd\">";
    let m = import(&with_doctype(public, "")).unwrap();
    assert_eq!(m.checked, 9);
    // An internal subset without entity declarations (a comment naming one) is harmless.
    let subset = "<!DOCTYPE DAVEfunc SYSTEM \"DAVEfunc.dtd\" [\n  <!-- no <!ENTITY here -->\n  <!ELEMENT note (#PCDATA)>\n]>";
    assert_eq!(
        import(&with_doctype(subset, "&amp;&#x41;"))
            .unwrap()
            .checked,
        9
    );
}
