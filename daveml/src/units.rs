//! The units sepval accepts in a DAVE-ML file and their exact conversions to the scenario's
//! (docs/model.md section 1, "Units"; docs/daveml.md lists them). DAVE-ML gives units as text
//! (`units` of `variableDef` and `breakpointDef`, `signalUnits`); S-119 recommends the
//! abbreviations of ANSI/AIAA R-004 (`deg`, `rad`, `ft`, `m`, `nd` for non-dimensional).

use sepval_common::table::{Kind, Variable};
use sepval_core::units::{M_PER_FT, M_PER_IN};

/// How a value in a file's unit becomes one in the scenario's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Conversion {
    /// Multiply by this exact factor.
    Scale(f64),
    /// Radians to degrees (`f64::to_degrees`), or a value per degree to one per radian.
    ToDegrees,
}

impl Conversion {
    /// The value in the scenario's unit.
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Conversion::Scale(s) => x * s,
            Conversion::ToDegrees => x.to_degrees(),
        }
    }

    /// The value back in the file's unit (for check cases: exact to rounding).
    pub fn invert(self, x: f64) -> f64 {
        match self {
            Conversion::Scale(s) => x / s,
            Conversion::ToDegrees => x.to_radians(),
        }
    }
}

/// Texts of a non-dimensional unit.
const NONDIMENSIONAL: [&str; 5] = ["nd", "ND", "-", "", "none"];

/// The conversion of an input variable's unit, or the units it may have.
pub fn input(v: Variable, units: &str) -> Result<Conversion, &'static str> {
    let u = units.trim();
    match v {
        Variable::Mach if NONDIMENSIONAL.contains(&u) => Ok(Conversion::Scale(1.0)),
        Variable::Mach => Err("nd (non-dimensional)"),
        Variable::Alpha | Variable::Beta => match u {
            "deg" => Ok(Conversion::Scale(1.0)),
            "rad" => Ok(Conversion::ToDegrees),
            _ => Err("deg or rad"),
        },
        Variable::Distance | Variable::Lateral | Variable::X | Variable::Y | Variable::Z => match u
        {
            "m" => Ok(Conversion::Scale(1.0)),
            "ft" => Ok(Conversion::Scale(M_PER_FT)),
            "in" => Ok(Conversion::Scale(M_PER_IN)),
            _ => Err("m, ft or in"),
        },
    }
}

/// The conversion of a field's unit, or the units it may have.
pub fn output(kind: Kind, units: &str) -> Result<Conversion, &'static str> {
    let u = units.trim();
    match kind {
        Kind::Static | Kind::Interference | Kind::FieldRatio if NONDIMENSIONAL.contains(&u) => {
            Ok(Conversion::Scale(1.0))
        }
        Kind::Static | Kind::Interference | Kind::FieldRatio => {
            Err("nd (a coefficient is non-dimensional)")
        }
        Kind::FieldAngle => match u {
            "deg" => Ok(Conversion::Scale(1.0)),
            "rad" => Ok(Conversion::ToDegrees),
            _ => Err("deg or rad (a flow angle)"),
        },
        Kind::Derivative => match u {
            "1/rad" | "/rad" | "rad-1" => Ok(Conversion::Scale(1.0)),
            "1/deg" | "/deg" | "deg-1" => Ok(Conversion::ToDegrees),
            _ => Err("1/rad or 1/deg (a derivative is per radian or per degree)"),
        },
    }
}

/// The unit sepval writes for an input variable.
pub fn written_input(v: Variable) -> &'static str {
    match v {
        Variable::Mach => "nd",
        Variable::Alpha | Variable::Beta => "deg",
        Variable::Distance | Variable::Lateral | Variable::X | Variable::Y | Variable::Z => "m",
    }
}

/// The unit sepval writes for a field of `kind`.
pub fn written_output(kind: Kind) -> &'static str {
    match kind {
        Kind::Static | Kind::Interference | Kind::FieldRatio => "nd",
        Kind::Derivative => "1/rad",
        Kind::FieldAngle => "deg",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feet_and_radians_convert_exactly() {
        assert_eq!(
            input(Variable::Distance, "ft")
                .unwrap()
                .apply(10.0)
                .to_bits(),
            3.048f64.to_bits()
        );
        let c = input(Variable::Alpha, "rad").unwrap();
        assert_eq!(c.apply(1.0).to_bits(), 1f64.to_degrees().to_bits());
        assert_eq!(input(Variable::Alpha, "furlong"), Err("deg or rad"));
        assert!(output(Kind::Derivative, "nd").is_err());
        assert_eq!(
            output(Kind::Derivative, "1/deg").unwrap(),
            Conversion::ToDegrees
        );
    }
}
