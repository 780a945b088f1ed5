//! Stage 3, **assemble**: the fields a file gives put into a base scenario (the embedded default
//! or the user's `--scenario`): the store, its ejector, the flight condition and every field the
//! file does not give stay the base's. A static coefficient the file gives as a whole (CY, CZ,
//! Cm, Cn) replaces its linear term too unless the file gives that slope (docs/model.md section
//! 3: the static table adds to the slope's term, and the file's table is the coefficient).

use sepval_common::correction::{Derivative, Target};
use sepval_common::scenario::Scenario;
use sepval_common::table::{Coefficient, TableKind, Tabulated};

use crate::error::DavemlError;
use crate::import::{FieldValue, Imported};

/// The slope whose linear term a static coefficient's table replaces.
fn slope_of(k: usize) -> Option<Derivative> {
    match k {
        1 => Some(Derivative::CyBeta),
        2 => Some(Derivative::CzAlpha),
        4 => Some(Derivative::CmAlpha),
        5 => Some(Derivative::CnBeta),
        _ => None,
    }
}

fn tabulated<K: TableKind>(c: Coefficient) -> Tabulated<K> {
    let mut t = Tabulated::<K>::constant(0.0);
    t.value = c;
    t
}

/// The value of the field `t` of `s`, if the scenario has it.
pub fn field(s: &Scenario, t: Target) -> Option<&Coefficient> {
    let a = &s.aero;
    match t {
        Target::Static(0) => Some(&a.ca0.value),
        Target::Static(k) => [&a.cy, &a.cz, &a.cl, &a.cm, &a.cn][k - 1]
            .as_ref()
            .map(|c| &c.value),
        Target::Derivative(d) => match d {
            Derivative::CzAlpha => a.cz_alpha_per_rad.as_ref().map(|c| &c.value),
            Derivative::CyBeta => a.cy_beta_per_rad.as_ref().map(|c| &c.value),
            Derivative::CmAlpha => a.cm_alpha_per_rad.as_ref().map(|c| &c.value),
            Derivative::CnBeta => a.cn_beta_per_rad.as_ref().map(|c| &c.value),
            Derivative::ClP => Some(&a.cl_p_per_rad.value),
            Derivative::CmQ => Some(&a.cm_q_per_rad.value),
            Derivative::CnR => Some(&a.cn_r_per_rad.value),
        },
        Target::Interference(k) => Some(&s.interference.increments()[k].1.value),
        Target::Field(_) | Target::ShapeTable => None,
    }
}

/// Sets the field `t` of `s` to `c` (`None`: leaves an optional field out).
pub fn set_field(s: &mut Scenario, t: Target, c: Option<Coefficient>) {
    let a = &mut s.aero;
    match t {
        Target::Static(0) => {
            if let Some(c) = c {
                a.ca0.value = c;
            }
        }
        Target::Static(k) => {
            let slot = [&mut a.cy, &mut a.cz, &mut a.cl, &mut a.cm, &mut a.cn];
            *slot.into_iter().nth(k - 1).expect("six static fields") = c.map(tabulated);
        }
        Target::Derivative(d) => {
            let optional = match d {
                Derivative::CzAlpha => &mut a.cz_alpha_per_rad,
                Derivative::CyBeta => &mut a.cy_beta_per_rad,
                Derivative::CmAlpha => &mut a.cm_alpha_per_rad,
                Derivative::CnBeta => &mut a.cn_beta_per_rad,
                Derivative::ClP | Derivative::CmQ | Derivative::CnR => {
                    let r = match d {
                        Derivative::ClP => &mut a.cl_p_per_rad,
                        Derivative::CmQ => &mut a.cm_q_per_rad,
                        _ => &mut a.cn_r_per_rad,
                    };
                    if let Some(c) = c {
                        r.value = c;
                    }
                    return;
                }
            };
            *optional = c.map(tabulated);
        }
        Target::Interference(k) => {
            if let Some(c) = c {
                s.interference.increments_mut()[k].1.value = c;
            }
        }
        // Not a table (the map and the bands name the tables' fields only).
        Target::Field(_) | Target::ShapeTable => {}
    }
}

/// The base scenario with the file's fields; validated.
pub fn assemble(base: &Scenario, imported: &Imported, file: &str) -> Result<Scenario, DavemlError> {
    let mut s = base.clone();
    let given = |t: Target| imported.fields.iter().any(|f| f.target == t);
    for f in &imported.fields {
        let c = match &f.value {
            FieldValue::Table(t) => Coefficient::Table(t.clone()),
            FieldValue::Constant(v) => Coefficient::Constant(*v),
        };
        set_field(&mut s, f.target, Some(c));
        if let Target::Static(k) = f.target
            && let Some(d) = slope_of(k)
            && !given(Target::Derivative(d))
        {
            set_field(&mut s, Target::Derivative(d), None);
        }
    }
    s.validate(file).map_err(|source| DavemlError::Scenario {
        file: file.to_string(),
        source,
    })?;
    Ok(s)
}
