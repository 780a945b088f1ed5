//! Numbers written back in messages (issue 33, item 13: `1e308` was echoed as its 309 digits).
//! [`Shown`] writes a number in the shortest form that reads back as the same double, in
//! scientific notation when that is shorter than its digits (beyond 1e15 or below 1e-5 in
//! magnitude): `0.95`, `3600`, `1e308`, `1.5e-7`.

/// A number as a message shows it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shown(pub f64);

impl std::fmt::Display for Shown {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0;
        let magnitude = v.abs();
        if v.is_finite() && magnitude > 0.0 && !(1e-5..1e15).contains(&magnitude) {
            write!(f, "{v:e}")
        } else {
            write!(f, "{v}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Shown;

    #[test]
    fn numbers_are_shown_short_and_exact() {
        for (v, text) in [
            (0.95, "0.95"),
            (3600.0, "3600"),
            (-2.5, "-2.5"),
            (0.0, "0"),
            (1e308, "1e308"),
            (-1.7976931348623157e308, "-1.7976931348623157e308"),
            (1.5e-7, "1.5e-7"),
            (123456789012345.0, "123456789012345"),
            (1e15, "1e15"),
            (f64::NAN, "NaN"),
            (f64::INFINITY, "inf"),
        ] {
            assert_eq!(Shown(v).to_string(), text);
            if v.is_finite() {
                assert_eq!(text.parse::<f64>().unwrap().to_bits(), v.to_bits());
            }
        }
    }
}
