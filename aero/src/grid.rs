//! The Mach and alpha grids of an estimate, `LO:HI:N` (N equally spaced points from LO to HI),
//! each within its domain: Mach 0.05 to 2 (the methods' span: docs/aero.md), alpha -30 to 30
//! deg (the model's domain of aircraft flow angles, docs/model.md section 1, and the
//! crossflow's subcritical c_dc).

use crate::AeroError;

/// The Mach domain of the estimate.
pub const MACH_DOMAIN: (f64, f64) = (0.05, 2.0);
/// The alpha domain of the estimate \[deg\].
pub const ALPHA_DOMAIN_DEG: (f64, f64) = (-30.0, 30.0);
/// Most points on one axis.
pub const MAX_POINTS: usize = 1000;

/// The default Mach grid: 0.3 to 1.5, 13 points (every 0.1).
pub const DEFAULT_MACH: &str = "0.3:1.5:13";
/// The default alpha grid: -20 to 20 deg, 9 points (every 5 deg).
pub const DEFAULT_ALPHA_DEG: &str = "-20:20:9";

/// The points of `value` (`LO:HI:N`) of flag `flag`, within `domain`.
pub fn parse(flag: &str, value: &str, domain: (f64, f64)) -> Result<Vec<f64>, AeroError> {
    let refuse = |what: String| AeroError::Grid {
        flag: flag.to_string(),
        value: value.to_string(),
        what,
    };
    let parts: Vec<&str> = value.split(':').collect();
    let [lo, hi, n] = parts[..] else {
        return Err(refuse("expected LO:HI:N (e.g. 0.3:1.5:13)".into()));
    };
    let number = |s: &str, what: &str| {
        s.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| refuse(format!("{what} `{s}` is not a finite number")))
    };
    let (lo, hi) = (number(lo, "LO")?, number(hi, "HI")?);
    let n: usize = n
        .trim()
        .parse()
        .map_err(|_| refuse(format!("N `{n}` is not a whole number")))?;
    if !(2..=MAX_POINTS).contains(&n) {
        return Err(refuse(format!(
            "N = {n}: expected 2 to {MAX_POINTS} points"
        )));
    }
    if lo >= hi {
        return Err(refuse(format!("LO = {lo} is not below HI = {hi}")));
    }
    if lo < domain.0 || hi > domain.1 {
        return Err(refuse(format!(
            "outside the estimate's domain, {} to {}",
            domain.0, domain.1
        )));
    }
    let step = (hi - lo) / (n - 1) as f64;
    Ok((0..n)
        .map(|k| if k == n - 1 { hi } else { lo + k as f64 * step })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_are_read_and_bad_ones_refused() {
        let g = parse("--mach", "0.3:1.5:13", MACH_DOMAIN).unwrap();
        assert_eq!(g.len(), 13);
        assert!((g[1] - 0.4).abs() < 1e-12 && (g[12] - 1.5).abs() < 1e-15);
        for bad in [
            "0.3:1.5",
            "a:1:3",
            "0.3:1.5:1",
            "1.5:0.3:3",
            "0.3:5:3",
            "0.3:1:x",
            "nan:1:2",
        ] {
            let e = parse("--mach", bad, MACH_DOMAIN).unwrap_err().to_string();
            assert!(e.starts_with(&format!("--mach {bad}: ")), "{e}");
        }
    }
}
