//! Run ids: the name that isolates one run's workers and resources (the iceoryx2 prefix
//! `sepval_<RUN_ID>_`, the zenoh keys `sepval/<RUN_ID>/...`). Checked once, where it enters
//! (a flag, a fresh id), and carried as a [`RunId`] from then on.

use std::fmt;
use std::str::FromStr;

/// A run id that is 1 to 48 characters of `A-Z`, `a-z`, `0-9` and `-` (so that it is one file
/// name part and one zenoh key chunk).
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct RunId(String);

/// A run id that cannot name a run.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("run id `{0}`: expected 1 to 48 characters from A-Z, a-z, 0-9 and '-'")]
pub struct RunIdError(pub String);

impl RunId {
    /// Checks `text`.
    pub fn new(text: &str) -> Result<RunId, RunIdError> {
        let ok = !text.is_empty()
            && text.len() <= 48
            && text.chars().all(|c| c.is_ascii_alphanumeric() || c == '-');
        if ok {
            Ok(RunId(text.to_string()))
        } else {
            Err(RunIdError(text.to_string()))
        }
    }

    /// A fresh run id: the process id and the time, in hex (unique on a host; not random).
    pub fn fresh() -> RunId {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        RunId(format!(
            "r{:x}{:x}",
            std::process::id(),
            nanos & 0xffff_ffff_ffff
        ))
    }

    /// The id.
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl FromStr for RunId {
    type Err = RunIdError;
    fn from_str(s: &str) -> Result<RunId, RunIdError> {
        RunId::new(s)
    }
}

impl fmt::Display for RunId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_ids_are_checked() {
        RunId::new("run-1-A").unwrap();
        for bad in ["run_1", "", "a/b", "a b", &"x".repeat(49)] {
            assert!(RunId::new(bad).is_err(), "{bad}");
        }
        assert_eq!(
            RunId::new("a b").unwrap_err().to_string(),
            "run id `a b`: expected 1 to 48 characters from A-Z, a-z, 0-9 and '-'"
        );
        RunId::new(RunId::fresh().as_str()).unwrap();
    }
}
