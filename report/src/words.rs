//! Numbers, flight conditions and CSV text fields, as every page, reading and table of sepval
//! writes them:
//! short (trailing zeros dropped, no "-0"), "-" for a value that is not a number, and the
//! same condition in the same words on every page.

/// `v` with at most `n` decimals, trailing zeros dropped: 0.95 at 3 is "0.95", 2.0 is "2".
pub fn decimals(v: f64, n: usize) -> String {
    if !v.is_finite() {
        return "-".into();
    }
    trimmed(format!("{v:.n$}"))
}

/// `v` with at most `n` significant digits (and at most 12 decimals), trailing zeros dropped:
/// a grid's 0.6 + 2 x 0.15 at 6 is "0.9", not 0.8999999999999999, and 7924.8 stays 7924.8.
pub fn significant(v: f64, n: usize) -> String {
    if !v.is_finite() {
        return "-".into();
    }
    let magnitude = v.abs().max(1e-12).log10().floor() as i32;
    let digits = (n as i32 - 1 - magnitude).clamp(0, 12) as usize;
    trimmed(format!("{v:.digits$}"))
}

/// A flight condition in words: "Mach 0.8, altitude 3000 m, aircraft alpha 2 deg, beta 0 deg,
/// flight-path angle 0 deg", each number at six significant digits.
pub fn condition(
    mach: f64,
    altitude_m: f64,
    alpha_deg: f64,
    beta_deg: f64,
    gamma_deg: f64,
) -> String {
    let s = |v: f64| significant(v, 6);
    format!(
        "Mach {}, altitude {} m, aircraft alpha {} deg, beta {} deg, flight-path angle {} deg",
        s(mach),
        s(altitude_m),
        s(alpha_deg),
        s(beta_deg),
        s(gamma_deg)
    )
}

/// A text field of a CSV file (RFC 4180): as it is, or quoted with its quotes doubled when it
/// holds a comma or a quote.
pub fn csv_text(s: &str) -> String {
    if s.contains([',', '"']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A number written with decimals, its trailing zeros (and a bare point) dropped, "-0" as "0".
fn trimmed(t: String) -> String {
    let t = if t.contains('.') {
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        t
    };
    if t == "-0" { "0".into() } else { t }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_written_as_a_reader_writes_them() {
        assert_eq!(decimals(0.95, 3), "0.95");
        assert_eq!(decimals(2.0, 3), "2");
        assert_eq!(decimals(-0.0001, 3), "0");
        assert_eq!(decimals(1234.5678, 3), "1234.568");
        assert_eq!(decimals(f64::NAN, 3), "-");
        assert_eq!(significant(0.6 + 2.0 * 0.15, 6), "0.9");
        assert_eq!(significant(7924.8, 6), "7924.8");
        assert_eq!(significant(-6.0, 6), "-6");
        assert_eq!(significant(0.0125, 6), "0.0125");
        assert_eq!(significant(0.0, 6), "0");
        assert_eq!(significant(f64::INFINITY, 6), "-");
        assert_eq!(csv_text("r1.csv"), "r1.csv");
        assert_eq!(csv_text("a,\"b\""), "\"a,\"\"b\"\"\"");
        assert_eq!(
            condition(0.8, 3000.0, 2.0, 0.0, -1.5),
            "Mach 0.8, altitude 3000 m, aircraft alpha 2 deg, beta 0 deg, flight-path angle -1.5 deg"
        );
    }
}
