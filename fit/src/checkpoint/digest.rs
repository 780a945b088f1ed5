//! The digest of a checkpoint's content (rule in the documentation of [`crate::checkpoint`]),
//! the short digests of its parts that name what was edited, and the keys of a file that are
//! not read.

use std::collections::{BTreeMap, BTreeSet};

use sepval_common::scenario::hex_sha256;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::Checkpoint;
use super::content::DigestMismatch;
use sepval_solve::ga::GaState;

/// Hex digits of a part's digest.
const PART_HEX: usize = 16;

/// Most parts named in a message.
const NAMED: usize = 6;

/// The digest of a checkpoint.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Digest {
    /// SHA-256, lower-case hex, of the canonical form: the compact JSON of the checkpoint
    /// without its `digest` field.
    pub sha256: String,
    /// The first 16 hex digits of the SHA-256 of each part's compact JSON, by the part's name:
    /// each field of the checkpoint (`format`, `arithmetic` when present, `method`, `settings`, `hill`, `sigma`,
    /// `data_sha256`, `scenario_sha256`, `inputs`, `probes`), each field of its state
    /// (`state.generation`, `state.evaluations`, `state.rng`, `state.history`), and each member
    /// of the population and of the archive (`state.population[i]`, `state.archive[i]`).
    pub parts: BTreeMap<String, String>,
}

impl Checkpoint {
    /// The canonical form of the content: the compact JSON of the checkpoint without `digest`.
    pub fn canonical_form(&self) -> Vec<u8> {
        let json = if self.digest.is_none() {
            serde_json::to_vec(self)
        } else {
            serde_json::to_vec(&Checkpoint {
                digest: None,
                ..self.clone()
            })
        };
        json.expect("a checkpoint serialises")
    }

    /// The digest of the content (whatever `digest` holds is ignored).
    pub fn compute_digest(&self) -> Digest {
        Digest {
            sha256: hex_sha256(&self.canonical_form()),
            parts: self.parts().into_iter().collect(),
        }
    }

    /// Every part with its short digest, in the order of the file.
    fn parts(&self) -> Vec<(String, String)> {
        // Destructured so that a new field cannot be left out of the parts unnoticed.
        let Checkpoint {
            format,
            digest: _,
            arithmetic,
            method,
            settings,
            hill,
            sigma,
            data_sha256,
            scenario_sha256,
            inputs,
            state,
            probes,
        } = self;
        let GaState {
            generation,
            evaluations,
            population,
            archive,
            rng,
            history,
        } = state;
        let mut parts = vec![part("format", format)];
        // Absent from checkpoints written before it was recorded, whose parts it must not change.
        if let Some(a) = arithmetic {
            parts.push(part("arithmetic", a));
        }
        parts.extend([
            part("method", method),
            part("settings", settings),
            part("hill", hill),
            part("sigma", sigma),
            part("data_sha256", data_sha256),
            part("scenario_sha256", scenario_sha256),
            part("inputs", inputs),
            part("state.generation", generation),
            part("state.evaluations", evaluations),
        ]);
        for (i, m) in population.iter().enumerate() {
            parts.push(part(&format!("state.population[{i}]"), m));
        }
        for (i, m) in archive.iter().enumerate() {
            parts.push(part(&format!("state.archive[{i}]"), m));
        }
        parts.push(part("state.rng", rng));
        parts.push(part("state.history", history));
        parts.push(part("probes", probes));
        parts
    }

    /// Checks `stored` against the content; on a mismatch, says what differs.
    pub(super) fn check_digest(&self, stored: &Digest) -> Result<(), DigestMismatch> {
        let parts = self.parts();
        let whole = hex_sha256(&self.canonical_form()) == stored.sha256;
        let changed: Vec<String> = parts
            .iter()
            .filter(|(name, hash)| stored.parts.get(name) != Some(hash))
            .map(|(name, _)| name.clone())
            .collect();
        let names: BTreeSet<&str> = parts.iter().map(|(name, _)| name.as_str()).collect();
        let gone: Vec<String> = stored
            .parts
            .keys()
            .filter(|name| !names.contains(name.as_str()))
            .cloned()
            .collect();
        if whole && changed.is_empty() && gone.is_empty() {
            return Ok(());
        }
        // When the content is the one digested, the record of its parts was edited.
        Err(DigestMismatch {
            changed,
            gone,
            parts_only: whole,
        })
    }
}

/// The name and short digest of a part.
fn part<T: Serialize + ?Sized>(name: &str, value: &T) -> (String, String) {
    let json = serde_json::to_vec(value).expect("a checkpoint serialises");
    let mut hash = hex_sha256(&json);
    hash.truncate(PART_HEX);
    (name.to_string(), hash)
}

/// `a, b, c and 4 more`.
pub(super) fn listed(names: &[String]) -> String {
    let mut text = names[..names.len().min(NAMED)].join(", ");
    if names.len() > NAMED {
        text.push_str(&format!(" and {} more", names.len() - NAMED));
    }
    text
}

/// The first key (as a path: `state.population[3].note`) of the file's JSON `file` that is not
/// in `read`, the JSON of what was read from it (the top-level `digest` aside).
pub(super) fn unread_key(file: &Value, read: &Value) -> Option<String> {
    fn walk(file: &Value, read: &Value, path: &str) -> Option<String> {
        match (file, read) {
            (Value::Object(f), Value::Object(r)) => f.iter().find_map(|(key, fv)| {
                if path.is_empty() && key == "digest" {
                    return None;
                }
                let here = if path.is_empty() {
                    key.clone()
                } else {
                    format!("{path}.{key}")
                };
                match r.get(key) {
                    None => Some(here),
                    Some(rv) => walk(fv, rv, &here),
                }
            }),
            (Value::Array(f), Value::Array(r)) => f
                .iter()
                .zip(r)
                .enumerate()
                .find_map(|(i, (fv, rv))| walk(fv, rv, &format!("{path}[{i}]"))),
            _ => None,
        }
    }
    walk(file, read, "")
}
