//! Whether two scenarios fly the same store, and if not the first field that differs: one
//! check shared by `predict` (a condition must fly the store that was fitted) and by the
//! commands that pool releases (each release's metadata, where it records its store, must
//! record the store fitted; issue 33, item 6).

use super::{Scenario, Store};
use sepval_core::number_text::Shown;

/// The first field in which two scenarios' stores differ.
#[derive(Debug, Clone, PartialEq)]
pub struct StoreDifference {
    /// The field, as the scenario file names it (`store.mass_kg`, `aero.cm_alpha_per_rad`) or
    /// the part (`ejector.curve`, `factors`, `extension`).
    pub field: String,
    /// Its value in the scenario compared with (the reference), when it is one number.
    pub reference: Option<f64>,
    /// Its value in the other scenario, when it is one number.
    pub other: Option<f64>,
}

impl std::fmt::Display for StoreDifference {
    /// `store.mass_kg is 500, not 907.18474` (the other's value, then the reference's), or
    /// `ejector.curve differs` when it is not one number.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.reference, self.other) {
            (Some(a), Some(b)) => write!(f, "{} is {}, not {}", self.field, Shown(b), Shown(a)),
            _ => write!(f, "{} differs", self.field),
        }
    }
}

impl Store {
    /// The fields of `[store]` with their values, as the scenario file names them.
    pub fn fields(&self) -> [(&'static str, f64); 8] {
        [
            ("mass_kg", self.mass_kg),
            ("ixx_kg_m2", self.ixx_kg_m2),
            ("iyy_kg_m2", self.iyy_kg_m2),
            ("izz_kg_m2", self.izz_kg_m2),
            ("diameter_m", self.diameter_m),
            ("fwd_foot_x_m", self.fwd_foot_x_m),
            ("aft_foot_x_m", self.aft_foot_x_m),
            ("stroke_m", self.stroke_m),
        ]
    }

    /// [`Store::fields`], mutable.
    pub fn fields_mut(&mut self) -> [(&'static str, &mut f64); 8] {
        [
            ("mass_kg", &mut self.mass_kg),
            ("ixx_kg_m2", &mut self.ixx_kg_m2),
            ("iyy_kg_m2", &mut self.iyy_kg_m2),
            ("izz_kg_m2", &mut self.izz_kg_m2),
            ("diameter_m", &mut self.diameter_m),
            ("fwd_foot_x_m", &mut self.fwd_foot_x_m),
            ("aft_foot_x_m", &mut self.aft_foot_x_m),
            ("stroke_m", &mut self.stroke_m),
        ]
    }
}

impl Scenario {
    /// The first field in which `other` flies another store than `self` (the reference): the store, ejector,
    /// aerodynamics, interference, factor table and extension terms must be the same (the
    /// flight condition, name, integrator, initial motion and corrections may differ).
    pub fn store_difference(&self, other: &Scenario) -> Option<StoreDifference> {
        let part = |field: &str| {
            Some(StoreDifference {
                field: field.to_string(),
                reference: None,
                other: None,
            })
        };
        let ours = self.store.fields();
        for ((name, a), (_, b)) in ours.iter().zip(other.store.fields()) {
            if a.to_bits() != b.to_bits() {
                return Some(StoreDifference {
                    field: format!("store.{name}"),
                    reference: Some(*a),
                    other: Some(b),
                });
            }
        }
        if self.ejector != other.ejector {
            return part("ejector.curve");
        }
        if self.aero != other.aero {
            let theirs = other.aero.fields();
            let differs = self.aero.fields().into_iter().find(|(name, c)| {
                theirs
                    .iter()
                    .find(|(n, _)| n == name)
                    .is_none_or(|(_, d)| d != c)
            });
            return part(differs.map_or("aero", |(name, _)| name));
        }
        if self.interference != other.interference {
            return part("interference");
        }
        if self.factors != other.factors {
            return part("factors");
        }
        if self.extension != other.extension {
            return part("extension");
        }
        None
    }
}
