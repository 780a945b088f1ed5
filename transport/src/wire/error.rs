//! What a message from another process can get wrong: one set of messages for every transport.

use sepval_common::correction::MAX_CORRECTION_VALUES;
use sepval_common::effects::MAX_ACTIVE_EFFECTS;

use super::REASON_CAPACITY;

/// What a message from another process can get wrong. One set of messages for every transport.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum WireError {
    /// More effects than a request holds.
    #[error("effect count {0} exceeds the maximum of {MAX_ACTIVE_EFFECTS}")]
    EffectCount(u32),
    /// An effect index outside the catalogue.
    #[error("effect index {0} is not in the catalogue")]
    EffectIndex(u32),
    /// Effect parameters the catalogue refuses.
    #[error(transparent)]
    Effect(#[from] sepval_common::effects::EffectError),
    /// Extension terms that cannot be run.
    #[error("extension term {index}: {reason}")]
    Term {
        /// Its index in the request.
        index: usize,
        /// Why.
        reason: String,
    },
    /// More correction values than a request holds.
    #[error("correction value count {0} exceeds the maximum of {MAX_CORRECTION_VALUES}")]
    CorrectionCount(u32),
    /// An unknown response status.
    #[error("unknown response status {0}")]
    Status(u32),
    /// A failure reason longer than its buffer or not UTF-8.
    #[error("failure reason of {0} bytes is not valid UTF-8 within {REASON_CAPACITY} bytes")]
    Reason(u32),
}
