//! The fit's parameters as the model sees them.

use sepval_common::factors::{FACTOR_COUNT, Factors};

/// Factors from a slice of (at least) 17 values.
pub fn factors_of(values: &[f64]) -> Factors {
    let mut f = [0.0; FACTOR_COUNT];
    f.copy_from_slice(&values[..FACTOR_COUNT]);
    Factors(f)
}
