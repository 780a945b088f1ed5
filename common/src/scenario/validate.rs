//! The checks of a scenario's values for their physical range (docs/model.md section 1), one
//! function per section of the file, run in the file's order so that the first problem found
//! is the one reported. Each refusal names the field as a TOML path.

use super::{
    Aero, Ejector, Flight, Initial, Integrator, Interference, Scenario, ScenarioError, Store,
};
use crate::atmosphere::TROPOPAUSE_M;
use crate::table::Coefficient;

impl Scenario {
    /// Checks every value for its physical range.
    pub fn validate(&self, origin: &str) -> Result<(), ScenarioError> {
        let c = Checker { origin };
        c.store(&self.store)?;
        c.ejector(&self.ejector, self.store.stroke_m)?;
        c.coefficients(&self.aero, &self.interference)?;
        c.slopes(&self.aero)?;
        c.interference(&self.interference)?;
        if let Some(f) = &self.flowfield {
            f.check(&self.aero, &self.interference)
                .map_err(|(field, reason)| c.bad(&field, reason))?;
        }
        c.flight(&self.flight)?;
        c.integrator(&self.integrator)?;
        c.initial(&self.initial)?;
        c.extension(&self.extension)?;
        let corrections = crate::correction::check_all(&self.correction)
            .map_err(|(k, e)| c.bad(&format!("correction[{k}]"), e.to_string()))?;
        for (k, x) in corrections.iter().enumerate() {
            let why = match x.target {
                crate::correction::Target::ShapeTable => self
                    .check_shape_table_correction(x)
                    .err()
                    .map(|e| e.to_string()),
                crate::correction::Target::Field(part) => {
                    self.field_part_refusal(part).map(str::to_string)
                }
                _ => None,
            };
            if let Some(why) = why {
                return Err(c.bad(
                    &format!("correction[{k}]"),
                    format!("`field` `{}`: {why}", self.correction[k].field),
                ));
            }
        }
        self.factors
            .validate()
            .map_err(|e| c.bad("factors", e.to_string()))
    }
}

impl Scenario {
    /// Why a correction of the flowfield's `part` cannot be one of this scenario, if it cannot:
    /// no field; a shape's depth where the shape is a table or the field tables over position;
    /// a slope with alpha where the field is tables over position.
    fn field_part_refusal(&self, part: crate::correction::FieldPart) -> Option<&'static str> {
        match &self.flowfield {
            None => Some("the scenario has no [flowfield] to correct"),
            Some(f) if part.is_shape() && f.shape.is_some() => Some(
                "the [flowfield]'s shape is a table, with no half depth or reversal depth to \
                 correct",
            ),
            Some(f) if part.is_shape() && f.is_grid() => Some(
                "the [flowfield] is given as tables over position, with no half depth or \
                 reversal depth to correct",
            ),
            Some(f) if f.is_grid() => Some(
                "the [flowfield] is given as tables over position, which scale with alpha by \
                 its zero-lift angle, with no upwash_per_alpha or sidewash_per_alpha to \
                 correct",
            ),
            Some(_) => None,
        }
    }

    /// A correction of the flowfield's shape table: the scenario has one, the correction starts
    /// at depth 0, and the two have at most `MAX_SHAPE_POINTS` depths together (the table the
    /// correction folds into, `corrected_shape`).
    fn check_shape_table_correction(
        &self,
        x: &crate::correction::Correction,
    ) -> Result<(), crate::correction::FieldChangeError> {
        use crate::correction::FieldChangeError;
        let Some(shape) = self.flowfield.as_ref().and_then(|f| f.shape.as_ref()) else {
            return Err(FieldChangeError::NoShapeTableToCorrect);
        };
        if x.breakpoints.first() != Some(&0.0) {
            return Err(FieldChangeError::ShapeNotFromCarriage);
        }
        let zeros = vec![0.0; x.breakpoints.len()];
        crate::correction::corrected_shape(&shape.depth_m, &shape.g, &x.breakpoints, &zeros)
            .map(|_| ())
    }
}

/// The checks of one scenario, refusals naming `origin` (its file, or "embedded default").
struct Checker<'a> {
    origin: &'a str,
}

impl Checker<'_> {
    fn bad(&self, field: &str, reason: String) -> ScenarioError {
        ScenarioError::Invalid {
            origin: self.origin.to_string(),
            field: field.to_string(),
            reason,
        }
    }

    fn positive(&self, field: &str, v: f64) -> Result<(), ScenarioError> {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(self.bad(field, format!("= {v}: expected a finite value > 0")))
        }
    }

    fn finite(&self, field: &str, v: f64) -> Result<(), ScenarioError> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(self.bad(field, format!("= {v}: expected a finite value")))
        }
    }

    fn coefficient(&self, field: &str, c: &Coefficient) -> Result<(), ScenarioError> {
        match c {
            Coefficient::Constant(v) => self.finite(field, *v),
            // Tables are checked when they are made (crate::table::Table::new).
            Coefficient::Table(_) => Ok(()),
            Coefficient::File(f) => Err(self.bad(
                field,
                format!(
                    "refers to the table file {}, which was not read: a scenario with table files is loaded from its file (they are relative to it)",
                    f.csv.display()
                ),
            )),
        }
    }

    fn store(&self, s: &Store) -> Result<(), ScenarioError> {
        self.positive("store.mass_kg", s.mass_kg)?;
        self.positive("store.ixx_kg_m2", s.ixx_kg_m2)?;
        self.positive("store.iyy_kg_m2", s.iyy_kg_m2)?;
        self.positive("store.izz_kg_m2", s.izz_kg_m2)?;
        self.positive("store.diameter_m", s.diameter_m)?;
        self.positive("store.stroke_m", s.stroke_m)?;
        self.finite("store.fwd_foot_x_m", s.fwd_foot_x_m)?;
        self.finite("store.aft_foot_x_m", s.aft_foot_x_m)
    }

    /// The force curve: at least two finite points, displacements strictly increasing,
    /// covering [0, stroke].
    fn ejector(&self, e: &Ejector, stroke_m: f64) -> Result<(), ScenarioError> {
        let curve = &e.curve;
        if curve.len() < 2 {
            return Err(self.bad(
                "ejector.curve",
                format!(
                    "has {} point(s): expected at least 2 (s_m, force_N) points",
                    curve.len()
                ),
            ));
        }
        for (i, [x, f]) in curve.iter().enumerate() {
            if !x.is_finite() || !f.is_finite() {
                return Err(self.bad(
                    &format!("ejector.curve[{i}]"),
                    format!("= [{x}, {f}]: expected finite numbers"),
                ));
            }
            if i > 0 && *x <= curve[i - 1][0] {
                return Err(self.bad(
                    &format!("ejector.curve[{i}]"),
                    format!(
                        "displacement {x} m: expected strictly increasing displacements (previous {} m)",
                        curve[i - 1][0]
                    ),
                ));
            }
        }
        let (first, last) = (curve[0][0], curve[curve.len() - 1][0]);
        if first > 0.0 || last < stroke_m {
            return Err(self.bad(
                "ejector.curve",
                format!(
                    "covers [{first}, {last}] m: it must cover [0, stroke] = [0, {stroke_m}] m"
                ),
            ));
        }
        Ok(())
    }

    /// Every coefficient that may be a table: a finite constant, or a table that was read.
    fn coefficients(&self, a: &Aero, i: &Interference) -> Result<(), ScenarioError> {
        for (field, c) in a.fields() {
            self.coefficient(field, c)?;
        }
        for (field, c) in i.increments() {
            self.coefficient(field, &c.value)?;
        }
        Ok(())
    }

    /// Each static slope is given, or its static coefficient as a table.
    fn slopes(&self, a: &Aero) -> Result<(), ScenarioError> {
        for (slope, table, has_slope, has_table) in [
            (
                "aero.cz_alpha_per_rad",
                "aero.cz",
                a.cz_alpha_per_rad.is_some(),
                a.cz.is_some(),
            ),
            (
                "aero.cy_beta_per_rad",
                "aero.cy",
                a.cy_beta_per_rad.is_some(),
                a.cy.is_some(),
            ),
            (
                "aero.cm_alpha_per_rad",
                "aero.cm",
                a.cm_alpha_per_rad.is_some(),
                a.cm.is_some(),
            ),
            (
                "aero.cn_beta_per_rad",
                "aero.cn",
                a.cn_beta_per_rad.is_some(),
                a.cn.is_some(),
            ),
        ] {
            if !has_slope && !has_table {
                return Err(self.bad(
                    slope,
                    format!("is missing: give it, or the static coefficient `{table}` as a table"),
                ));
            }
        }
        Ok(())
    }

    fn interference(&self, i: &Interference) -> Result<(), ScenarioError> {
        self.positive("interference.lambda_m", i.lambda_m)?;
        self.positive("interference.s_end_m", i.s_end_m)
    }

    /// Mach, an altitude in the ISA troposphere, angles within +-90 deg.
    fn flight(&self, f: &Flight) -> Result<(), ScenarioError> {
        self.positive("flight.mach", f.mach)?;
        if !(f.altitude_m.is_finite() && f.altitude_m < TROPOPAUSE_M) {
            return Err(self.bad(
                "flight.altitude_m",
                format!(
                    "= {}: expected a finite altitude below {TROPOPAUSE_M} m (ISA troposphere)",
                    f.altitude_m
                ),
            ));
        }
        for (field, v) in [
            ("flight.alpha_deg", f.alpha_deg),
            ("flight.beta_deg", f.beta_deg),
            ("flight.gamma_deg", f.gamma_deg),
        ] {
            if !(v.is_finite() && v.abs() < 90.0) {
                return Err(self.bad(
                    field,
                    format!("= {v}: expected a finite angle within +-90 deg"),
                ));
            }
        }
        Ok(())
    }

    /// Step, end and rate, and the work of one run (sepval_core::limits), refused before anything is
    /// allocated.
    fn integrator(&self, n: &Integrator) -> Result<(), ScenarioError> {
        self.positive("integrator.dt_s", n.dt_s)?;
        self.positive("integrator.t_end_s", n.t_end_s)?;
        self.positive("integrator.rate_hz", n.rate_hz)?;
        if n.dt_s > n.t_end_s {
            return Err(self.bad(
                "integrator.dt_s",
                format!(
                    "= {}: longer than the event (t_end_s = {})",
                    n.dt_s, n.t_end_s
                ),
            ));
        }
        sepval_core::limits::check_steps(n.t_end_s, n.dt_s)
            .map_err(|e| self.bad("integrator.dt_s", format!("= {}: {e}", n.dt_s)))?;
        sepval_core::limits::check_sampling(n.t_end_s, n.rate_hz)
            .map_err(|e| self.bad("integrator.rate_hz", format!("= {}: {e}", n.rate_hz)))
    }

    fn initial(&self, i: &Initial) -> Result<(), ScenarioError> {
        for (k, v) in i.velocity_m_s.iter().enumerate() {
            self.finite(&format!("initial.velocity_m_s[{k}]"), *v)?;
        }
        for (k, v) in i.rates_deg_s.iter().enumerate() {
            self.finite(&format!("initial.rates_deg_s[{k}]"), *v)?;
        }
        Ok(())
    }

    /// At most [`crate::extension::MAX_TERMS`] terms, each one that can be run.
    fn extension(&self, terms: &[crate::extension::TermRecord]) -> Result<(), ScenarioError> {
        if terms.len() > crate::extension::MAX_TERMS {
            return Err(self.bad(
                "extension",
                format!(
                    "has {} terms, at most {}",
                    terms.len(),
                    crate::extension::MAX_TERMS
                ),
            ));
        }
        for (k, r) in terms.iter().enumerate() {
            r.term().map_err(|(field, message)| {
                self.bad(&format!("extension[{k}].{field}"), message)
            })?;
        }
        Ok(())
    }
}
