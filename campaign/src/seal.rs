//! The campaign's records sealed part by part (docs/campaign.md, "Files"): campaign.json,
//! `rounds/NN/assessment.json` and next.json carry `digests`, the SHA-256 of each top-level
//! part's canonical form, one per element where the part is a list, so that an edited record
//! is refused naming the part that changed (`rounds[1]`, `settled`, `conditions[7]`), not only
//! that something did. Before 2026-12-01 they carried none, and a count, the `settled` flag, a
//! grid value or a state edited by hand was believed by `status`, `add` and `next`.
//!
//! The canonical form is that of the fit's and the diagnosis's records
//! ([`sepval_run::sealed`]): the compact JSON of the part's value, keys sorted, numbers in
//! serde_json's shortest form that reads back exactly; whitespace, key order and `0.5` against
//! `5e-1` do not matter, every change of a value does, and so does a part added or removed.
//! Like theirs the digests detect edits; they are no signature.
//!
//! A record without `digests` (written by an earlier sepval, or with its digests deleted) is
//! refused as well: accepting it would let any edit pass by removing them.

use std::path::Path;

use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::{Map, Value};

use sepval_common::scenario::hex_sha256;
use sepval_core::atomic_file::write_atomically;

use crate::CampaignError;
use crate::record::{ASSESSMENT_FORMAT, AssessmentFile, RoundRecord, check_recorded, record_error};
use crate::state::Assessed;

/// The key of the parts' digests in a sealed record.
pub const DIGESTS_KEY: &str = "digests";
/// The largest record read \[bytes\].
const MAX_RECORD_BYTES: u64 = 64 << 20;

/// The digest of one value: the SHA-256 of its compact JSON.
fn digest(v: &Value) -> String {
    hex_sha256(&serde_json::to_vec(v).expect("a JSON value serialises"))
}

/// The digests of a part: one string, or one per element of a list.
fn part_digests(v: &Value) -> Value {
    match v {
        Value::Array(items) => Value::Array(items.iter().map(|i| digest(i).into()).collect()),
        other => digest(other).into(),
    }
}

/// The digests of every part of `record` (its `digests` left out).
fn digests_of(record: &Map<String, Value>) -> Map<String, Value> {
    record
        .iter()
        .filter(|(k, _)| k.as_str() != DIGESTS_KEY)
        .map(|(k, v)| (k.clone(), part_digests(v)))
        .collect()
}

/// `record` as pretty JSON with its parts' digests as the last key.
pub fn sealed<T: Serialize>(record: &T) -> Vec<u8> {
    let value = serde_json::to_value(record).expect("a record serialises");
    let Value::Object(map) = value else {
        panic!("a sealed record is a JSON object");
    };
    #[derive(Serialize)]
    struct Sealed<'a, T> {
        #[serde(flatten)]
        record: &'a T,
        digests: Map<String, Value>,
    }
    let digests = digests_of(&map);
    let mut text = serde_json::to_vec_pretty(&Sealed { record, digests }).expect("serialises");
    text.push(b'\n');
    text
}

/// Writes `record` to `path` atomically, sealed; returns the SHA-256 of the file written.
pub fn write_sealed<T: Serialize>(path: &Path, record: &T) -> Result<String, CampaignError> {
    let bytes = sealed(record);
    write_atomically(path, &bytes).map_err(|e| record_error(path, e))?;
    Ok(hex_sha256(&bytes))
}

/// The first part of `found` whose digest differs from `stored` (a part added or removed
/// included), named as a path in the record: `settled`, `rounds[1]`, `rounds` (an element
/// added or removed).
fn changed_part(found: &Map<String, Value>, stored: &Map<String, Value>) -> Option<String> {
    let now = digests_of(found);
    for (key, d) in &now {
        match (d, stored.get(key)) {
            (_, None) => return Some(format!("`{key}` (a part the record did not hold)")),
            (Value::Array(a), Some(Value::Array(b))) if a.len() == b.len() => {
                if let Some(i) = (0..a.len()).find(|&i| a[i] != b[i]) {
                    return Some(format!("`{key}[{i}]`"));
                }
            }
            (Value::Array(a), Some(Value::Array(b))) => {
                return Some(format!(
                    "`{key}` ({} entries where it held {})",
                    a.len(),
                    b.len()
                ));
            }
            (a, Some(b)) if a != b => return Some(format!("`{key}`")),
            _ => {}
        }
    }
    stored
        .keys()
        .find(|k| !now.contains_key(*k))
        .map(|k| format!("`{k}` (removed)"))
}

/// Reads the sealed record at `path` whose `format` must be `format`, refusing an edit and
/// naming the part that changed.
pub fn read_sealed<T: DeserializeOwned>(path: &Path, format: &str) -> Result<T, CampaignError> {
    let bad = |message: String| record_error(path, message);
    let text = sepval_core::input_file::read_string(path, "campaign record", MAX_RECORD_BYTES)
        .map_err(|e| bad(e.to_string()))?;
    let value: Value = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
    let Value::Object(mut map) = value else {
        return Err(bad(
            "not a JSON object: not a record of this sepval's campaigns".into(),
        ));
    };
    let found = map.get("format").and_then(|f| f.as_str()).unwrap_or("");
    if found != format {
        return Err(bad(format!(
            "format `{found}`, expected `{format}`: not a record of this sepval's campaigns"
        )));
    }
    let Some(Value::Object(stored)) = map.remove(DIGESTS_KEY) else {
        return Err(bad(format!(
            "records no digests of its parts (`{DIGESTS_KEY}`): written by an earlier sepval or edited by hand; a campaign record without them is not used (begin the campaign again with this sepval)"
        )));
    };
    if let Some(part) = changed_part(&map, &stored) {
        return Err(CampaignError::Edited {
            path: path.display().to_string(),
            part,
        });
    }
    serde_json::from_value(Value::Object(map)).map_err(|e| bad(e.to_string()))
}

/// The envelope of round `r` of the campaign in `dir`: its assessment.json, sealed and the one
/// campaign.json records.
pub fn read_round(dir: &Path, r: &RoundRecord) -> Result<Vec<Assessed>, CampaignError> {
    read_round_file(dir, r).map(|f| f.conditions)
}

/// [`read_round`], the whole file (with the narrowing the prior's round may hold).
pub fn read_round_file(dir: &Path, r: &RoundRecord) -> Result<AssessmentFile, CampaignError> {
    let path = dir.join(&r.dir).join("assessment.json");
    // The seal first, which names the part edited; then the hash, which refuses a round's
    // assessment replaced whole by another (itself sealed).
    let file: AssessmentFile = read_sealed(&path, ASSESSMENT_FORMAT)?;
    check_recorded(&path, &r.assessment_sha256)?;
    if file.conditions.len() != r.counts.conditions {
        return Err(record_error(
            &path,
            format!(
                "holds {} conditions where campaign.json's round {} counts {}",
                file.conditions.len(),
                r.round,
                r.counts.conditions
            ),
        ));
    }
    Ok(file)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, PartialEq, Serialize, serde::Deserialize)]
    struct R {
        format: String,
        rounds: Vec<u32>,
        settled: bool,
    }

    fn r() -> R {
        R {
            format: "f/1".into(),
            rounds: vec![1, 2, 3],
            settled: false,
        }
    }

    #[test]
    fn a_sealed_record_reads_back_and_an_edit_is_refused_naming_its_part() {
        let tmp = tempfile::tempdir().unwrap();
        let p = tmp.path().join("r.json");
        write_sealed(&p, &r()).unwrap();
        assert_eq!(read_sealed::<R>(&p, "f/1").unwrap(), r());
        let text = std::fs::read_to_string(&p).unwrap();
        // Whitespace does not matter.
        std::fs::write(&p, text.replace("\n", "\n  ")).unwrap();
        assert_eq!(read_sealed::<R>(&p, "f/1").unwrap(), r());
        let v: Value = serde_json::from_str(&text).unwrap();
        for (edit, names) in [
            (serde_json::json!({"settled": true}), "`settled`"),
            (serde_json::json!({"rounds": [1, 5, 3]}), "`rounds[1]`"),
            (
                serde_json::json!({"rounds": [1, 2]}),
                "`rounds` (2 entries where it held 3)",
            ),
            (
                serde_json::json!({"extra": 1}),
                "`extra` (a part the record did not hold)",
            ),
        ] {
            let mut e = v.clone();
            for (k, x) in edit.as_object().unwrap() {
                e[k] = x.clone();
            }
            std::fs::write(&p, serde_json::to_string(&e).unwrap()).unwrap();
            let err = read_sealed::<R>(&p, "f/1").unwrap_err().to_string();
            assert!(err.contains(names), "{err}");
        }
        let mut e = v.clone();
        e.as_object_mut().unwrap().remove("digests");
        std::fs::write(&p, serde_json::to_string(&e).unwrap()).unwrap();
        let err = read_sealed::<R>(&p, "f/1").unwrap_err().to_string();
        assert!(err.contains("records no digests"), "{err}");
    }
}
