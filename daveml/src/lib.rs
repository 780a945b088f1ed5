//! The store's aerodynamic data in the field's exchange format: DAVE-ML (the Dynamic Aerospace
//! Vehicle Exchange Markup Language, the XML of ANSI/AIAA S-119-2011; DAVE-ML 2.0), read into a
//! scenario's tables and written from them (docs/daveml.md).
//!
//! Reading is a pipeline of named stages ([`import_model`] shows it whole):
//!
//! 1. **parse** ([`parse::parse`]): the XML (roxmltree) read into plain data, each item with the
//!    line of its element ([`parse::Parsed`]);
//! 2. **map** ([`import::import`]): each `function` and constant the [`map::Map`] names turned
//!    into a sepval table of its field, units converted, axes put in sepval's nesting order,
//!    whatever sepval cannot represent refused naming element and line ([`import::Imported`]);
//! 3. **assemble** ([`assemble::assemble`]): the fields put into a base scenario, validated;
//! 4. **check** ([`check::check`]): the file's `checkData` cases evaluated through the
//!    scenario's tables;
//! 5. **write** ([`output::write_table_dir`]): the scenario in table form, staged and renamed,
//!    so a refusal leaves nothing written.
//!
//! Writing ([`export::to_daveml`]) is the scenario's fields (and an update's bands as
//! `uncertainty`) as a DAVE-ML 2.0 document with `fileHeader` provenance and `checkData` cases
//! sepval computes ([`shots`]); the text by a small escaping writer ([`xml`]).
//!
//! No DAVE-ML crate was found (the crates.io package list and a docs.rs search, 2026-11-27);
//! the parser is roxmltree, which gives each node's position in the text.

#![deny(clippy::float_cmp)]

pub mod assemble;
pub mod bands;
pub mod check;
pub mod doctype;
pub mod error;
pub mod export;
pub mod import;
pub mod map;
pub mod names;
pub mod output;
pub mod parse;
pub mod shots;
pub mod spread;
pub mod units;
pub mod xml;

use std::path::Path;

use sepval_common::scenario::Scenario;
use sepval_core::atomic_file::write_atomically;
use sepval_core::input_file::read_string;

pub use bands::{CorrectionSpread, bands};
pub use error::{DavemlError, ExportError, Mismatch, Place};
pub use export::{Band, Provenance, to_daveml};
pub use map::Map;

/// Largest DAVE-ML file sepval reads \[bytes\]: 256 MiB, room for tables of several million
/// values in full precision (six static tables of the most grid points a table may hold,
/// `sepval_core::limits::MAX_TABLE_VALUES`, take about 150 MB); checked against the file's
/// size before it is read.
pub const MAX_DAVEML_BYTES: u64 = 256 << 20;
/// Largest map file \[bytes\]: 1 MiB.
pub const MAX_MAP_BYTES: u64 = 1 << 20;

/// A DAVE-ML model read into a scenario.
#[derive(Debug, Clone)]
pub struct ImportedModel {
    /// The scenario: the base with the file's fields, validated.
    pub scenario: Scenario,
    /// The fields the file gave (TOML paths), in its order.
    pub fields: Vec<String>,
    /// The check cases' outputs compared (0 when the file has no `checkData`).
    pub checked: usize,
    /// What was read and not carried, to say to the user.
    pub notes: Vec<String>,
    /// Every field the file gave, with its value and its uncertainty if it has one.
    pub given: Vec<import::ImportedField>,
}

/// The map: the default, with the map file's entries when one is given.
pub fn load_map(path: Option<&Path>) -> Result<Map, DavemlError> {
    match path {
        None => Ok(Map::default()),
        Some(p) => {
            let text = read_string(p, "DAVE-ML map", MAX_MAP_BYTES)?;
            Map::with_file(&text, &p.display().to_string())
        }
    }
}

/// Reads the DAVE-ML model `text` (named `file`) into `base` with `map`: parse, map, assemble,
/// check.
pub fn import_model(
    text: &str,
    file: &str,
    map: &Map,
    base: &Scenario,
) -> Result<ImportedModel, DavemlError> {
    let parsed = parse::parse(text, file)?;
    let imported = import::import(&parsed, map)?;
    let scenario = assemble::assemble(base, &imported, file)?;
    let checked = check::check(&parsed, map, &scenario)?;
    Ok(ImportedModel {
        scenario,
        fields: imported.fields.iter().map(|f| f.target.field()).collect(),
        checked,
        notes: imported.notes,
        given: imported.fields,
    })
}

/// Reads the DAVE-ML file `path` (within [`MAX_DAVEML_BYTES`]) into `base` with `map`.
pub fn read_model(path: &Path, map: &Map, base: &Scenario) -> Result<ImportedModel, DavemlError> {
    let text = read_string(path, "DAVE-ML file", MAX_DAVEML_BYTES)?;
    import_model(&text, &path.display().to_string(), map, base)
}

/// Writes the scenario's fields (with `bands`) as DAVE-ML 2.0 to `path`, atomically.
pub fn write_model(
    path: &Path,
    s: &Scenario,
    bands: &[Band],
    prov: &Provenance,
) -> Result<(), DavemlError> {
    let text = to_daveml(s, bands, prov).map_err(|reason| DavemlError::Output {
        path: path.to_path_buf(),
        reason,
    })?;
    write_atomically(path, text.as_bytes())?;
    Ok(())
}

/// Today's date (UTC) as `YYYY-MM-DD`, for a [`Provenance`].
pub fn today() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    civil_date((secs / 86_400) as i64)
}

/// The date of a day counted from 1970-01-01 (H. Hinnant, "chrono-Compatible Low-Level Date
/// Algorithms", `civil_from_days`).
fn civil_date(days: i64) -> String {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}

#[cfg(test)]
mod tests {
    #[test]
    fn civil_dates() {
        assert_eq!(super::civil_date(0), "1970-01-01");
        assert_eq!(super::civil_date(20_419), "2025-11-27");
        assert_eq!(super::civil_date(11_016), "2000-02-29");
    }
}
