//! The TOML primitives of an aircraft file, also allowed as extra parts of a store file: boxes,
//! cylinders, half-spaces and convex hulls of points, each named, every length in metres and
//! every angle in degrees as their names say (docs/geometry.md, "Formats"). Unknown fields are
//! refused.

use serde::Deserialize;

use crate::domain;
use crate::frames::rotation_321_deg;
use crate::parts::{self, Part, PartProblem};

/// The primitive parts of a file, in this order: boxes, cylinders, half-spaces, hulls.
#[derive(Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub(crate) struct Primitives {
    /// `[[box]]` tables.
    #[serde(default, rename = "box")]
    pub boxes: Vec<BoxSpec>,
    /// `[[cylinder]]` tables.
    #[serde(default, rename = "cylinder")]
    pub cylinders: Vec<CylinderSpec>,
    /// `[[half_space]]` tables.
    #[serde(default, rename = "half_space")]
    pub half_spaces: Vec<HalfSpaceSpec>,
    /// `[[hull]]` tables.
    #[serde(default, rename = "hull")]
    pub hulls: Vec<HullSpec>,
}

/// A box: centre, half extents along its own axes, and its axes' 3-2-1 rotation.
#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub(crate) struct BoxSpec {
    pub name: String,
    pub centre_m: [f64; 3],
    pub half_extents_m: [f64; 3],
    /// `[roll, pitch, yaw]` of the box's axes, 3-2-1 as the store's attitude; zero by default.
    #[serde(default)]
    pub rotation_deg: [f64; 3],
}

/// A cylinder: centre, axis direction (any length but zero), radius and length.
#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub(crate) struct CylinderSpec {
    pub name: String,
    pub centre_m: [f64; 3],
    pub axis: [f64; 3],
    pub radius_m: f64,
    pub length_m: f64,
}

/// The solid behind a plane: a point of the plane and the outward normal (any length but zero).
#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub(crate) struct HalfSpaceSpec {
    pub name: String,
    pub point_m: [f64; 3],
    pub outward_normal: [f64; 3],
}

/// The convex hull of at least four points that are not coplanar.
#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub(crate) struct HullSpec {
    pub name: String,
    pub points_m: Vec<[f64; 3]>,
}

impl Primitives {
    /// The parts, validated; `allow_half_spaces` is false for a store (it must be bounded).
    pub(crate) fn parts(&self, allow_half_spaces: bool) -> Result<Vec<Part>, PartProblem> {
        let mut out = Vec::new();
        for (i, b) in self.boxes.iter().enumerate() {
            let field = format!("box[{i}] \"{}\"", b.name);
            domain::angles(&format!("{field}.rotation_deg"), &b.rotation_deg)?;
            let rotation = rotation_321_deg(b.rotation_deg);
            out.push(parts::cuboid(
                b.name.clone(),
                &field,
                b.centre_m,
                b.half_extents_m,
                rotation,
            )?);
        }
        for (i, c) in self.cylinders.iter().enumerate() {
            let field = format!("cylinder[{i}] \"{}\"", c.name);
            out.push(parts::cylinder(
                c.name.clone(),
                &field,
                c.centre_m,
                c.axis,
                c.radius_m,
                c.length_m,
            )?);
        }
        for (i, h) in self.half_spaces.iter().enumerate() {
            let field = format!("half_space[{i}] \"{}\"", h.name);
            if !allow_half_spaces {
                return Err((field, "a store must be bounded: no half-space".to_string()));
            }
            out.push(parts::half_space(
                h.name.clone(),
                &field,
                h.point_m,
                h.outward_normal,
            )?);
        }
        for (i, h) in self.hulls.iter().enumerate() {
            let field = format!("hull[{i}] \"{}\".points_m", h.name);
            out.push(parts::hull(h.name.clone(), &field, &h.points_m)?);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_reads_and_unknown_fields_are_refused() {
        let text = r#"
            [[box]]
            name = "pylon"
            centre_m = [0.0, 0.0, -0.5]
            half_extents_m = [0.5, 0.05, 0.2]
            [[cylinder]]
            name = "tank"
            centre_m = [0.0, 2.0, 0.0]
            axis = [1.0, 0.0, 0.0]
            radius_m = 0.3
            length_m = 2.0
            [[half_space]]
            name = "wing"
            point_m = [0.0, 0.0, -1.0]
            outward_normal = [0.0, 0.0, 1.0]
        "#;
        let p: Primitives = toml::from_str(text).unwrap();
        let parts = p.parts(true).unwrap();
        assert_eq!(
            parts.iter().map(|p| p.name.as_str()).collect::<Vec<_>>(),
            ["pylon", "tank", "wing"]
        );
        assert!(p.parts(false).unwrap_err().1.contains("no half-space"));
        let e = toml::from_str::<Primitives>(&text.replace("radius_m", "radius")).unwrap_err();
        assert!(e.to_string().contains("radius"), "{e}");
    }

    #[test]
    fn degenerate_primitives_are_refused_naming_the_field() {
        let p = Primitives {
            cylinders: vec![CylinderSpec {
                name: "c".into(),
                centre_m: [0.0; 3],
                axis: [1.0, 0.0, 0.0],
                radius_m: 0.0,
                length_m: 1.0,
            }],
            ..Primitives::default()
        };
        assert_eq!(p.parts(true).unwrap_err().0, "cylinder[0] \"c\".radius_m");
        let flat = Primitives {
            hulls: vec![HullSpec {
                name: "h".into(),
                points_m: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
            }],
            ..Primitives::default()
        };
        assert!(flat.parts(true).unwrap_err().1.contains("coplanar"));
    }
}
