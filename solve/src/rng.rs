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
    #[error("generator seed `{seed_hex}` is not 64 hexadecimal digits")]
    Seed {
        /// The seed read.
        seed_hex: String,
    },
    /// The word position is not a number.
    #[error("generator position `{word_pos}` is not a non-negative integer")]
    Position {
        /// The position read.
        word_pos: String,
    },
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
        let bad = || RngStateError::Seed {
            seed_hex: self.seed_hex.clone(),
        };
        // Checked byte by byte before any slicing: text that is not ASCII (or holds a sign,
        // which `from_str_radix` would take) is refused, never sliced inside a character.
        let hex = self.seed_hex.as_bytes();
        if hex.len() != 64 || !hex.iter().all(u8::is_ascii_hexdigit) {
            return Err(bad());
        }
        let mut seed = [0u8; 32];
        for (b, pair) in seed.iter_mut().zip(hex.chunks_exact(2)) {
            let digit = |c: u8| (c as char).to_digit(16).expect("checked hex digit") as u8;
            *b = digit(pair[0]) << 4 | digit(pair[1]);
        }
        let digits = self.word_pos.as_bytes();
        if digits.is_empty() || !digits.iter().all(u8::is_ascii_digit) {
            return Err(RngStateError::Position {
                word_pos: self.word_pos.clone(),
            });
        }
        let pos: u128 = self.word_pos.parse().map_err(|_| RngStateError::Position {
            word_pos: self.word_pos.clone(),
        })?;
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

    #[test]
    fn text_that_is_not_a_state_is_refused_not_a_panic() {
        let good = RngState::of(&seeded(3));
        let seed = |s: String| RngState {
            seed_hex: s,
            ..good.clone()
        };
        // 64 bytes, but a two-byte character straddles a pair boundary.
        let straddling = format!("0{}{}", "é", "0".repeat(61));
        assert_eq!(straddling.len(), 64);
        for text in [
            straddling,
            format!("+f{}", "0".repeat(62)),
            format!("{}g", "0".repeat(63)),
        ] {
            assert_eq!(
                seed(text.clone()).restore().map(|_| ()),
                Err(RngStateError::Seed { seed_hex: text })
            );
        }
        for pos in [
            "",
            "+7",
            "-1",
            "7 ",
            "٣",
            "340282366920938463463374607431768211456",
        ] {
            let s = RngState {
                word_pos: pos.to_string(),
                ..good.clone()
            };
            assert_eq!(
                s.restore().map(|_| ()),
                Err(RngStateError::Position {
                    word_pos: pos.to_string()
                })
            );
        }
        assert!(good.restore().is_ok());
    }
}
