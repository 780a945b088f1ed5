//! An `f64` that may be infinite or not a number, in JSON: use as
//! `#[serde(with = "sepval_core::nonfinite")]`.
//!
//! JSON has no infinity: serde_json writes a non-finite `f64` as `null` and cannot read `null`
//! back into an `f64`, so a checkpoint holding one (a generation in which no member finished
//! has an infinite best goal) could not be read. Here a finite value is written as a plain
//! number and the others as the strings `"inf"`, `"-inf"` and `"nan"`; either form is read, so
//! values written before (plain numbers) still read, and every value reads back exactly (a NaN
//! reads back as [`f64::NAN`]).

use std::fmt;

use serde::de::{self, Visitor};
use serde::{Deserializer, Serializer};

/// Writes `value`: a number when finite, else `"inf"`, `"-inf"` or `"nan"`.
pub fn serialize<S: Serializer>(value: &f64, serializer: S) -> Result<S::Ok, S::Error> {
    let v = *value;
    if v.is_finite() {
        serializer.serialize_f64(v)
    } else if v.is_nan() {
        serializer.serialize_str("nan")
    } else if v > 0.0 {
        serializer.serialize_str("inf")
    } else {
        serializer.serialize_str("-inf")
    }
}

/// Reads a number or one of `"inf"`, `"-inf"`, `"nan"`.
pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
    deserializer.deserialize_any(NumberOrName)
}

struct NumberOrName;

impl Visitor<'_> for NumberOrName {
    type Value = f64;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(r#"a number, "inf", "-inf" or "nan""#)
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<f64, E> {
        Ok(v)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<f64, E> {
        Ok(v as f64)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<f64, E> {
        Ok(v as f64)
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<f64, E> {
        match v {
            "inf" => Ok(f64::INFINITY),
            "-inf" => Ok(f64::NEG_INFINITY),
            "nan" => Ok(f64::NAN),
            _ => Err(E::invalid_value(de::Unexpected::Str(v), &self)),
        }
    }
}

#[cfg(test)]
mod tests {
    use serde::{Deserialize, Serialize};

    #[derive(Debug, Serialize, Deserialize)]
    struct Wrap(#[serde(with = "super")] f64);

    fn round_trip(v: f64) -> (String, f64) {
        let json = serde_json::to_string(&Wrap(v)).unwrap();
        let back: Wrap = serde_json::from_str(&json).unwrap();
        (json, back.0)
    }

    #[test]
    fn every_value_reads_back_exactly() {
        for v in [
            0.0,
            -0.0,
            0.1014,
            f64::MIN_POSITIVE,
            f64::MAX,
            5e-324,
            1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ] {
            let (json, back) = round_trip(v);
            assert_eq!(back.to_bits(), v.to_bits(), "{v} as {json}");
        }
        assert_eq!(round_trip(f64::INFINITY).0, r#""inf""#);
        assert_eq!(round_trip(f64::NEG_INFINITY).0, r#""-inf""#);
        let (json, back) = round_trip(f64::NAN);
        assert_eq!(json, r#""nan""#);
        assert!(back.is_nan());
    }

    #[test]
    fn plain_numbers_of_earlier_files_read_and_other_text_is_refused() {
        for (json, v) in [
            ("1", 1.0_f64),
            ("-2", -2.0),
            ("0.25", 0.25),
            ("2.5e-1", 0.25),
        ] {
            let back = serde_json::from_str::<Wrap>(json).unwrap().0;
            assert_eq!(back.to_bits(), v.to_bits(), "{json}");
        }
        for json in ["null", r#""Infinity""#, r#""1.5""#, "true"] {
            let e = serde_json::from_str::<Wrap>(json).unwrap_err();
            assert!(
                e.to_string()
                    .contains(r#"a number, "inf", "-inf" or "nan""#),
                "{json}: {e}"
            );
        }
    }
}
