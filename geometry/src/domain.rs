//! The domain of every number of a geometry file (docs/geometry.md, "The domain of the
//! numbers"): coordinates within [`MAX_COORDINATE_M`] of the frame's origin, sizes from
//! [`MIN_SIZE_M`] to [`MAX_SIZE_M`], angles within [`MAX_ANGLE_DEG`], directions with finite
//! components within the coordinates' bound. Whatever lies outside is refused, naming the field,
//! before it reaches parry: parry's GJK and EPA work in absolute tolerances and overflow on
//! shapes of 1e300 m (its EPA then panics, or calls parts metres apart touching), and a store
//! or aircraft beyond 10 km is a unit mistake, not an aircraft.

/// Why a number was refused: the field and what is wrong (the parts' problem type).
type PartProblem = (String, String);

/// The largest coordinate of a point, in either frame: 10 km from the origin (an aircraft is
/// tens of metres; a carrier deck hundreds).
pub const MAX_COORDINATE_M: f64 = 1e4;
/// The smallest size (a length, radius, half extent, diameter, chord, span or thickness):
/// 1 micrometre, a thousandth of the usual CAD chordal tolerance.
pub const MIN_SIZE_M: f64 = 1e-6;
/// The largest size: 10 km, as the coordinates.
pub const MAX_SIZE_M: f64 = 1e4;
/// The largest angle, either sign: one turn.
pub const MAX_ANGLE_DEG: f64 = 360.0;

/// A number as a message shows it: plain when moderate, in exponent form when huge or tiny
/// (1e308 as `1e308`, not its 309 digits).
pub(crate) fn number(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e16).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

fn problem(field: &str, what: String) -> PartProblem {
    (field.to_string(), what)
}

/// A point: every coordinate finite and within [`MAX_COORDINATE_M`].
pub(crate) fn point(field: &str, p: &[f64; 3]) -> Result<(), PartProblem> {
    if !p.iter().all(|x| x.is_finite()) {
        return Err(problem(field, format!("{p:?} is not finite")));
    }
    match p.iter().find(|x| x.abs() > MAX_COORDINATE_M) {
        Some(&x) => Err(problem(
            field,
            format!(
                "coordinate {} m is beyond +-{} m (the domain of a coordinate)",
                number(x),
                MAX_COORDINATE_M
            ),
        )),
        None => Ok(()),
    }
}

/// A direction: finite components within [`MAX_COORDINATE_M`] (its length is checked by the
/// part that normalises it).
pub(crate) fn direction(field: &str, d: &[f64; 3]) -> Result<(), PartProblem> {
    if !d.iter().all(|x| x.is_finite()) {
        return Err(problem(field, format!("{d:?} is not finite")));
    }
    match d.iter().find(|x| x.abs() > MAX_COORDINATE_M) {
        Some(&x) => Err(problem(
            field,
            format!(
                "component {} is beyond +-{} (a direction's components stay within the domain of a coordinate)",
                number(x),
                MAX_COORDINATE_M
            ),
        )),
        None => Ok(()),
    }
}

/// A size: finite, positive, from [`MIN_SIZE_M`] to [`MAX_SIZE_M`].
pub(crate) fn size(field: &str, v: f64) -> Result<(), PartProblem> {
    if !(v.is_finite() && v > 0.0) {
        return Err(problem(
            field,
            format!("{} must be finite and positive", number(v)),
        ));
    }
    if !(MIN_SIZE_M..=MAX_SIZE_M).contains(&v) {
        return Err(problem(
            field,
            format!(
                "{} m is outside the domain of a size, {MIN_SIZE_M:e} to {MAX_SIZE_M} m",
                number(v)
            ),
        ));
    }
    Ok(())
}

/// A position along the store or an offset: finite, from `lo` to `hi` (both in metres), said
/// with `what` (for example "from 0 to the body's length").
pub(crate) fn within(field: &str, v: f64, lo: f64, hi: f64, what: &str) -> Result<(), PartProblem> {
    if !v.is_finite() {
        return Err(problem(field, format!("{v} is not finite")));
    }
    if !(lo..=hi).contains(&v) {
        return Err(problem(
            field,
            format!(
                "{} m is outside {} m to {} m: {what}",
                number(v),
                number(lo),
                number(hi)
            ),
        ));
    }
    Ok(())
}

/// Angles: finite and within [`MAX_ANGLE_DEG`] either way.
pub(crate) fn angles(field: &str, a: &[f64]) -> Result<(), PartProblem> {
    if !a.iter().all(|x| x.is_finite()) {
        return Err(problem(field, format!("{a:?} is not finite")));
    }
    match a.iter().find(|x| x.abs() > MAX_ANGLE_DEG) {
        Some(&x) => Err(problem(
            field,
            format!(
                "{} deg is beyond +-{MAX_ANGLE_DEG} deg (the domain of an angle)",
                number(x)
            ),
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_numbers_are_named_in_exponent_form() {
        assert_eq!(number(1e308), "1e308");
        assert_eq!(number(-2.0), "-2");
        assert_eq!(number(0.0), "0");
        assert_eq!(number(1e-300), "1e-300");
        let e = point("p", &[0.0, 1e308, 0.0]).unwrap_err();
        assert_eq!(
            e.1,
            "coordinate 1e308 m is beyond +-10000 m (the domain of a coordinate)"
        );
        assert!(size("s", 1e-7).unwrap_err().1.contains("1e-7 m is outside"));
        assert!(size("s", 1e4).is_ok() && size("s", 1e-6).is_ok());
        assert!(angles("a", &[360.0, -360.0]).is_ok());
        assert!(angles("a", &[361.0]).is_err());
    }
}
