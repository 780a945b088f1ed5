//! The store's shape as plain dimensions (a body of revolution, its nose and its fins), read
//! from a store TOML file (docs/geometry.md, "Store TOML") for those who need the numbers
//! rather than the surfaces: the aerodynamic estimate of `sepval-aero` (docs/aero.md).
//!
//! The file is read and checked exactly as [`crate::Body::read`] reads a store (the same
//! fields, unknown fields refused, every number in its domain, the parts built), so a file is
//! accepted here if and only if it is accepted as a store there.

use std::path::Path;

use crate::GeometryError;
use crate::input::{MAX_FILE_BYTES, read_capped};
use crate::store::{NoseShape, StoreSpec};

/// The nose's shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Nose {
    /// A tangent ogive: y(x) = sqrt(rho^2 - (L - x)^2) + R - rho, rho = (R^2 + L^2) / (2 R).
    Ogive,
    /// A cone.
    Cone,
}

/// The body of revolution, lengths from the nose tip aft.
#[derive(Debug, Clone, PartialEq)]
pub struct RevolutionShape {
    /// Nose tip to base \[m\].
    pub length_m: f64,
    /// The cylinder's diameter \[m\].
    pub diameter_m: f64,
    /// The CG behind the nose tip \[m\].
    pub cg_from_nose_m: f64,
    /// The nose's length \[m\].
    pub nose_length_m: f64,
    /// The nose's shape.
    pub nose: Nose,
    /// The conical boattail's length \[m\] (0: none).
    pub boattail_length_m: f64,
    /// The base's diameter \[m\] (the cylinder's without a boattail).
    pub base_diameter_m: f64,
}

/// The fin set: clipped deltas, trailing edge square to the axis, equally spaced in roll.
#[derive(Debug, Clone, PartialEq)]
pub struct FinShape {
    /// How many fins (1 to 16).
    pub count: u32,
    /// Root chord \[m\].
    pub root_chord_m: f64,
    /// Tip chord \[m\] (0: a delta).
    pub tip_chord_m: f64,
    /// Exposed span, body surface to tip \[m\].
    pub span_m: f64,
    /// Thickness of the flat plate \[m\].
    pub thickness_m: f64,
    /// The root's leading edge behind the nose tip \[m\].
    pub leading_edge_from_nose_m: f64,
    /// The first fin's roll from body +y toward +z \[deg\].
    pub roll_deg: f64,
}

/// A store's shape: the body, the fins if any, and how many extra primitive parts the file
/// adds (lugs, sway braces: surfaces for the clearance that carry no dimension here).
#[derive(Debug, Clone, PartialEq)]
pub struct StoreShape {
    /// Where it came from: the file's path.
    pub source: String,
    /// The body of revolution.
    pub body: RevolutionShape,
    /// The fins, if the file has a `[fins]` table.
    pub fins: Option<FinShape>,
    /// The number of extra `[[box]]`, `[[cylinder]]` and `[[hull]]` parts.
    pub extra_parts: usize,
}

impl StoreShape {
    /// Reads the store TOML `path` (within [`MAX_FILE_BYTES`]), refusing what
    /// [`crate::Body::read`] refuses for a store, with the same errors naming file and field.
    pub fn read(path: &Path) -> Result<StoreShape, GeometryError> {
        let bytes = read_capped(path, MAX_FILE_BYTES)?;
        let text = std::str::from_utf8(&bytes).map_err(|e| GeometryError::Toml {
            path: path.to_path_buf(),
            message: format!("not UTF-8 text: {e}"),
        })?;
        StoreShape::from_toml_str(text, path)
    }

    /// [`StoreShape::read`] of the text of a file named `path`.
    pub fn from_toml_str(text: &str, path: &Path) -> Result<StoreShape, GeometryError> {
        let spec = toml::from_str::<StoreSpec>(text).map_err(|e| GeometryError::Toml {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        // The same checks as a store body: every number in its domain, every part solid.
        spec.parts()
            .map_err(|(field, what)| GeometryError::Invalid {
                path: path.to_path_buf(),
                field,
                what,
            })?;
        Ok(StoreShape::of(&spec, path.display().to_string()))
    }

    /// The Eglin benchmark store of [`crate::Body::default_store`] (docs/geometry.md, "The
    /// default store") at `diameter_m`, every length in proportion.
    pub fn default_store(diameter_m: f64) -> Result<StoreShape, GeometryError> {
        crate::Body::default_store(diameter_m)?;
        let source = format!("default store, diameter {diameter_m} m");
        Ok(StoreShape::of(&StoreSpec::eglin(diameter_m), source))
    }

    fn of(spec: &StoreSpec, source: String) -> StoreShape {
        let b = &spec.body;
        StoreShape {
            source,
            body: RevolutionShape {
                length_m: b.length_m,
                diameter_m: b.diameter_m,
                cg_from_nose_m: b.cg_from_nose_m,
                nose_length_m: b.nose_length_m,
                nose: match b.nose_shape {
                    NoseShape::Ogive => Nose::Ogive,
                    NoseShape::Cone => Nose::Cone,
                },
                boattail_length_m: b.boattail_length_m,
                base_diameter_m: b.base_diameter_m.unwrap_or(b.diameter_m),
            },
            fins: spec.fins.as_ref().map(|f| FinShape {
                count: f.count,
                root_chord_m: f.root_chord_m,
                tip_chord_m: f.tip_chord_m,
                span_m: f.span_m,
                thickness_m: f.thickness_m,
                leading_edge_from_nose_m: f.leading_edge_from_nose_m,
                roll_deg: f.roll_deg,
            }),
            extra_parts: spec.boxes.len() + spec.cylinders.len() + spec.hulls.len(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_example_store_reads_as_the_default_store() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/geometry/store.toml");
        let mut read = StoreShape::read(&path).unwrap();
        let default = StoreShape::default_store(0.508).unwrap();
        read.source = default.source.clone();
        assert_eq!(read, default);
        assert_eq!(read.body.nose, Nose::Ogive);
        assert_eq!(read.fins.as_ref().map(|f| f.count), Some(4));
    }

    #[test]
    fn a_bad_field_is_refused_naming_it() {
        let text = "[body]\nlength_m = 3.0\ndiameter_m = 0.5\ncg_from_nose_m = 1.5\n\
                    nose_length_m = 0.7\nnose_shape = \"ogive\"\nwings = 1\n";
        let e = StoreShape::from_toml_str(text, Path::new("s.toml")).unwrap_err();
        assert!(
            e.to_string().contains("s.toml") && e.to_string().contains("wings"),
            "{e}"
        );
        let text = text.replace("wings = 1\n", "").replace("3.0", "-3.0");
        let e = StoreShape::from_toml_str(&text, Path::new("s.toml")).unwrap_err();
        assert!(e.to_string().contains("body.length_m"), "{e}");
    }
}
