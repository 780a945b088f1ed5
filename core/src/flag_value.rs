//! Numbers given on the command line (or as the Python package's keyword arguments), checked
//! where the value's meaning is known: a count of workers or threads, a positive quantity, a
//! duration. The error names the flag and the value as given.

use std::time::Duration;

use crate::number_text::Shown;

/// The longest duration a flag may give \[s\]: a year.
pub const MAX_SECONDS: f64 = 3.2e7;

/// A flag's value refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FlagError {
    /// A count of 0.
    #[error("{flag} 0: expected at least 1")]
    Zero {
        /// The flag.
        flag: String,
    },
    /// A count above its limit.
    #[error("{flag} {value}: expected at most {max}")]
    TooMany {
        /// The flag.
        flag: String,
        /// The count given.
        value: usize,
        /// The limit.
        max: usize,
    },
    /// A number that is not finite and positive.
    #[error("{flag} = {}: expected a finite number > 0", Shown(*value))]
    NotPositive {
        /// The flag.
        flag: String,
        /// The number given.
        value: f64,
    },
    /// A duration longer than [`MAX_SECONDS`].
    #[error("{flag} = {}: expected at most 32 000 000 s (a year)", Shown(*value))]
    TooLong {
        /// The flag.
        flag: String,
        /// The duration given \[s\].
        value: f64,
    },
}

/// A count given as `flag`: at least 1; `default` when absent.
pub fn count_or(flag: &str, requested: Option<usize>, default: usize) -> Result<usize, FlagError> {
    match requested {
        Some(0) => Err(FlagError::Zero { flag: flag.into() }),
        Some(n) => Ok(n),
        None => Ok(default),
    }
}

/// A count given as `flag`: at least 1; the number of cores when absent.
pub fn count(flag: &str, requested: Option<usize>) -> Result<usize, FlagError> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    count_or(flag, requested, cores)
}

/// A strictly positive, finite number given as `flag`.
pub fn positive(flag: &str, value: f64) -> Result<f64, FlagError> {
    if !(value.is_finite() && value > 0.0) {
        return Err(FlagError::NotPositive {
            flag: flag.into(),
            value,
        });
    }
    Ok(value)
}

/// A duration in seconds given as `flag` (finite, > 0, at most a year).
pub fn seconds(flag: &str, value: f64) -> Result<Duration, FlagError> {
    let v = positive(flag, value)?;
    if v > MAX_SECONDS {
        return Err(FlagError::TooLong {
            flag: flag.into(),
            value,
        });
    }
    Ok(Duration::from_secs_f64(v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_refused_naming_the_flag() {
        assert_eq!(count_or("--workers", Some(3), 1), Ok(3));
        assert_eq!(count_or("--workers", None, 1), Ok(1));
        let zero = count("--threads", Some(0)).unwrap_err();
        assert_eq!(zero.to_string(), "--threads 0: expected at least 1");
        let nan = positive("--t-end", f64::NAN).unwrap_err();
        assert_eq!(
            nan.to_string(),
            "--t-end = NaN: expected a finite number > 0"
        );
        let long = seconds("--worker-timeout", 1e308).unwrap_err();
        assert_eq!(
            long.to_string(),
            "--worker-timeout = 1e308: expected at most 32 000 000 s (a year)"
        );
        assert_eq!(
            seconds("--join-timeout", 2.5),
            Ok(Duration::from_millis(2500))
        );
    }
}
