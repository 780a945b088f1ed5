//! A section written in the other of TOML's two table forms: `[[flowfield]]` where the
//! scenario has one flowfield, or `[correction]` where it has a list. The typed parse reports
//! either as serde's `invalid type: map, expected usize` (a list read as the struct's fields in
//! order) or `expected a sequence`, which names neither the section nor the fix; this names both.

/// The scenario's sections that are one table each, written `[name]`.
const ONE_TABLE: [&str; 9] = [
    "store",
    "ejector",
    "aero",
    "interference",
    "flowfield",
    "flight",
    "integrator",
    "initial",
    "factors",
];

/// The scenario's sections that are lists of tables, each written `[[name]]`.
const TABLE_LISTS: [&str; 2] = ["extension", "correction"];

/// Why `text` (which did not parse as a scenario) has a section in the wrong form, with the
/// line of its first header when it has one; `None` when every section has its form (or the
/// text is not TOML at all).
pub(super) fn misformed(text: &str) -> Option<String> {
    let value: toml::Table = toml::from_str(text).ok()?;
    let (name, list) = ONE_TABLE
        .iter()
        .map(|n| (*n, false))
        .chain(TABLE_LISTS.iter().map(|n| (*n, true)))
        .find(|(n, list)| match value.get(*n) {
            Some(toml::Value::Array(_)) => !list,
            Some(toml::Value::Table(_)) => *list,
            _ => false,
        })?;
    let (written, form) = if list {
        (
            format!("[{name}]"),
            format!("a list of tables, each written `[[{name}]]`"),
        )
    } else {
        (
            format!("[[{name}]]"),
            format!("one table, written `[{name}]`"),
        )
    };
    let line = text
        .lines()
        .position(|l| {
            let l: String = l.chars().filter(|c| !c.is_whitespace()).collect();
            l.starts_with(&written)
        })
        .map(|i| format!("line {}: ", i + 1))
        .unwrap_or_default();
    Some(format!(
        "{line}`{written}`: `{name}` is {form} (a scenario has {})",
        if list { "any number of them" } else { "one" }
    ))
}
