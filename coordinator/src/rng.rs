//! The search's random generator and its saved state.
//!
//! ChaCha8 (`rand_chacha`): portable (same numbers on every platform) and its complete state is
//! three numbers (seed, stream, word position), so a checkpoint holds it exactly and a resumed
//! search draws the very numbers the uninterrupted one would have drawn.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// The generator used by every search.
pub type SearchRng = ChaCha8Rng;

/// A generator seeded from a user's seed.
pub fn seeded(seed: u64) -> SearchRng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// The complete state of a [`SearchRng`].
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RngState {
    /// The 256-bit key, hex.
    pub seed_hex: String,
    /// The stream number.
    pub stream: u64,
    /// The position in the stream, in 32-bit words (decimal text: it is a u128).
    pub word_pos: String,
}

/// Errors restoring a generator.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum RngStateError {
    /// The seed is not 64 hex digits.
    #[error("generator seed `{0}` is not 64 hexadecimal digits")]
    Seed(String),
    /// The word position is not a number.
    #[error("generator position `{0}` is not a non-negative integer")]
    Position(String),
}

impl RngState {
    /// The state of `rng`.
    pub fn of(rng: &SearchRng) -> Self {
        RngState {
            seed_hex: rng.get_seed().iter().map(|b| format!("{b:02x}")).collect(),
            stream: rng.get_stream(),
            word_pos: rng.get_word_pos().to_string(),
        }
    }

    /// A generator in this state.
    pub fn restore(&self) -> Result<SearchRng, RngStateError> {
        let bad = || RngStateError::Seed(self.seed_hex.clone());
        if self.seed_hex.len() != 64 {
            return Err(bad());
        }
        let mut seed = [0u8; 32];
        for (i, b) in seed.iter_mut().enumerate() {
            *b = u8::from_str_radix(&self.seed_hex[2 * i..2 * i + 2], 16).map_err(|_| bad())?;
        }
        let pos: u128 = self
            .word_pos
            .parse()
            .map_err(|_| RngStateError::Position(self.word_pos.clone()))?;
        let mut rng = ChaCha8Rng::from_seed(seed);
        rng.set_stream(self.stream);
        rng.set_word_pos(pos);
        Ok(rng)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    #[test]
    fn restored_generator_continues_the_sequence() {
        let mut a = seeded(42);
        let _: [u64; 7] = std::array::from_fn(|_| a.random());
        let saved = RngState::of(&a);
        let json = serde_json::to_string(&saved).unwrap();
        let mut b = serde_json::from_str::<RngState>(&json)
            .unwrap()
            .restore()
            .unwrap();
        for _ in 0..100 {
            assert_eq!(a.random::<u64>(), b.random::<u64>());
        }
        let mut bad = saved.clone();
        bad.seed_hex.pop();
        assert!(bad.restore().is_err());
    }
}
