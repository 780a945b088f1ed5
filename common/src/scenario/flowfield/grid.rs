//! The checks of a flowfield given as tables over position (docs/model.md section 3b, "The
//! field as a table over position"): the tables on one grid, their values in range, and none of
//! the analytic field's parameters beside them.

use super::{FlowfieldSpec, MIN_LIFT_ALPHA_DEG, POSITION_FIELDS, Refusal, finite, refuse};

/// The largest induced angle a table may hold \[deg\] (as the analytic field's a0 and b0).
const MAX_ANGLE_DEG: f64 = 45.0;

impl FlowfieldSpec {
    /// A field of tables: the analytic parameters left out, the fields not given as tables left
    /// at their neutral values, one grid for all, the values in range.
    #[allow(clippy::float_cmp)] // exactly: the neutral values, and the one alpha_0 with no scale
    pub(super) fn check_grid(&self) -> Result<(), Refusal> {
        let beside = |field: &str, why: &str| {
            Err(refuse(
                field,
                format!("is given with a field of tables over position: {why}"),
            ))
        };
        let shape_why = "the tables give the field at every depth";
        if self.half_depth_m.is_some() {
            return beside("half_depth_m", shape_why);
        }
        if self.reversal_m.is_some() {
            return beside("reversal_m", shape_why);
        }
        if self.shape.is_some() {
            return beside("shape", shape_why);
        }
        for (field, v) in [
            ("upwash_gradient_deg_per_m", self.upwash_gradient_deg_per_m),
            (
                "sidewash_gradient_deg_per_m",
                self.sidewash_gradient_deg_per_m,
            ),
        ] {
            if v != 0.0 {
                return beside(field, "the tables give the field along x");
            }
        }
        for (field, v) in [
            ("upwash_per_alpha", self.upwash_per_alpha),
            ("sidewash_per_alpha", self.sidewash_per_alpha),
        ] {
            if v != 0.0 {
                return beside(
                    field,
                    "the tables scale with the aircraft's angle of attack through \
                     zero_lift_alpha_deg",
                );
            }
        }
        self.check_grid_tables()?;
        if let Some(a) = self.zero_lift_alpha_deg {
            finite("zero_lift_alpha_deg", a)?;
            // sepval's choice: the survey's condition at least MIN_LIFT_ALPHA_DEG from zero
            // lift, so that a release at 10 deg scales it by at most 20.
            if (self.reference_alpha_deg - a).abs() < MIN_LIFT_ALPHA_DEG {
                return Err(refuse(
                    "zero_lift_alpha_deg",
                    format!(
                        "= {a} is within {MIN_LIFT_ALPHA_DEG} deg of the reference angle of \
                         attack {}: the tables, measured at (nearly) zero lift, would scale \
                         (nearly) without bound",
                        self.reference_alpha_deg
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The four fields: tables on the first table's grid, or constants at their neutral values;
    /// angles within +-45 deg, the dynamic pressure ratio above 0.
    #[allow(clippy::float_cmp)] // exactly the neutral values: anything else is a constant field
    fn check_grid_tables(&self) -> Result<(), Refusal> {
        let tables = self.position_tables();
        let grid = tables
            .iter()
            .flatten()
            .next()
            .map(|t| t.axes())
            .unwrap_or_default();
        let neutral = [0.0, 0.0, 1.0, 0.0];
        for (j, (field, table)) in POSITION_FIELDS.iter().zip(tables).enumerate() {
            let Some(t) = table else {
                let v = self.carriage_values()[j];
                if v != neutral[j] {
                    return Err(refuse(
                        field,
                        format!(
                            "= {v} is a constant beside tables over position: it would hold \
                             everywhere, never decaying; give it as a table on the same grid, or \
                             leave it out ({})",
                            neutral[j]
                        ),
                    ));
                }
                continue;
            };
            if t.axes() != grid {
                return Err(refuse(
                    field,
                    format!(
                        "is a table on another grid than {}'s: the field's tables share one grid \
                         (the same axes and breakpoints)",
                        POSITION_FIELDS[tables.iter().position(Option::is_some).unwrap_or(0)]
                    ),
                ));
            }
            let bad = |v: f64| match j {
                0 | 1 => v.abs() >= MAX_ANGLE_DEG,
                2 => v <= 0.0,
                _ => false,
            };
            if let Some(k) = t.values().iter().position(|v| bad(*v)) {
                let expected = if j == 2 {
                    "a ratio above 0".to_string()
                } else {
                    format!("an angle within +-{MAX_ANGLE_DEG} deg")
                };
                // An angle in degrees whatever its column's unit (a `[rad]` column is converted
                // when read), so the unit is said.
                let unit = if j == 2 { "" } else { " deg" };
                return Err(refuse(
                    field,
                    format!(
                        "has {}{unit} at {}: expected {expected}",
                        sepval_core::number_text::Shown(t.values()[k]),
                        point_words(t.axes(), k)
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The grid point `k` of a table over `axes` (row-major, the last axis fastest) in words, by
/// its coordinates: `x_m = -3, z_m = 1.5`, the row of its CSV file.
fn point_words(axes: &[crate::table::Axis], mut k: usize) -> String {
    let mut words: Vec<String> = axes
        .iter()
        .rev()
        .map(|a| {
            let n = a.breakpoints.len().max(1);
            let i = k % n;
            k /= n;
            format!("{} = {}", a.variable.key(), a.breakpoints[i])
        })
        .collect();
    words.reverse();
    words.join(", ")
}
