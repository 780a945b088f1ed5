//! The store as a body of revolution with fins, described by lengths and diameters (a store
//! TOML file), and the default store: the Eglin wing/pylon/store benchmark store scaled to a
//! diameter.
//!
//! Geometry in the store's body frame (docs/model.md section 2: x forward along the axis, y
//! right, z down, origin at the CG): the nose tip at x = `cg_from_nose_m`. Parts, in order:
//! "nose" (the convex hull of the nose profile revolved, [`AROUND`] points on each of
//! [`STATIONS`] circles; inscribed in the true nose, within 1.2 mm of it at 0.508 m), "body"
//! (an exact cylinder), "boattail" (the hull of two circles, when there is one), "fin 1".."fin
//! n" (each the hull of its eight corners), then any extra primitives. The tangent ogive is
//! y(x) = sqrt(rho^2 - (L - x)^2) + R - rho, rho = (R^2 + L^2) / (2 R), x from the tip
//! (e.g. M. S. Chin, *Missile Configuration Design*, McGraw-Hill 1961, ch. 2).

use serde::Deserialize;

use crate::domain;
use crate::parts::{self, Part, PartProblem};
use crate::primitives::{BoxSpec, CylinderSpec, HalfSpaceSpec, HullSpec, Primitives};

/// Points on each circle of the nose and boattail hulls.
pub(crate) const AROUND: usize = 32;
/// Circles along the nose, the tip excluded.
pub(crate) const STATIONS: usize = 12;

/// A store file: `[body]`, optional `[fins]` and extra primitives.
#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub(crate) struct StoreSpec {
    pub body: Revolution,
    #[serde(default)]
    pub fins: Option<Fins>,
    #[serde(default, rename = "box")]
    pub boxes: Vec<BoxSpec>,
    #[serde(default, rename = "cylinder")]
    pub cylinders: Vec<CylinderSpec>,
    #[serde(default, rename = "half_space")]
    pub half_spaces: Vec<HalfSpaceSpec>,
    #[serde(default, rename = "hull")]
    pub hulls: Vec<HullSpec>,
}

/// The nose shape.
#[derive(Debug, Deserialize, PartialEq, Clone, Copy)]
#[serde(rename_all = "lowercase")]
pub(crate) enum NoseShape {
    /// A tangent ogive.
    Ogive,
    /// A cone.
    Cone,
}

/// The body of revolution.
#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub(crate) struct Revolution {
    pub length_m: f64,
    pub diameter_m: f64,
    pub cg_from_nose_m: f64,
    pub nose_length_m: f64,
    pub nose_shape: NoseShape,
    #[serde(default)]
    pub boattail_length_m: f64,
    #[serde(default)]
    pub base_diameter_m: Option<f64>,
}

/// Clipped-delta fins with the trailing edge square to the axis.
#[derive(Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub(crate) struct Fins {
    pub count: u32,
    pub root_chord_m: f64,
    pub tip_chord_m: f64,
    pub span_m: f64,
    pub thickness_m: f64,
    pub leading_edge_from_nose_m: f64,
    pub roll_deg: f64,
}

/// The Eglin store's diameter, at which [`StoreSpec::eglin`] takes its dimensions unscaled.
pub(crate) const EGLIN_DIAMETER_M: f64 = 0.508;

impl StoreSpec {
    /// The Eglin benchmark store (docs/geometry.md, "The default store"), every length scaled
    /// by `diameter_m` / 0.508 m. The same numbers as examples/geometry/store.toml.
    pub(crate) fn eglin(diameter_m: f64) -> StoreSpec {
        let k = diameter_m / EGLIN_DIAMETER_M;
        StoreSpec {
            body: Revolution {
                length_m: 3.015 * k,
                diameter_m: 0.508 * k,
                cg_from_nose_m: 1.415 * k,
                nose_length_m: 0.762 * k,
                nose_shape: NoseShape::Ogive,
                boattail_length_m: 0.0,
                base_diameter_m: None,
            },
            fins: Some(Fins {
                count: 4,
                root_chord_m: 0.40 * k,
                tip_chord_m: 0.16 * k,
                span_m: 0.22 * k,
                thickness_m: 0.015 * k,
                leading_edge_from_nose_m: 2.615 * k,
                roll_deg: 45.0,
            }),
            boxes: Vec::new(),
            cylinders: Vec::new(),
            half_spaces: Vec::new(),
            hulls: Vec::new(),
        }
    }

    /// The parts, validated.
    pub(crate) fn parts(&self) -> Result<Vec<Part>, PartProblem> {
        let b = &self.body;
        let r = 0.5 * b.diameter_m;
        for (field, v) in [
            ("body.length_m", b.length_m),
            ("body.diameter_m", b.diameter_m),
            ("body.nose_length_m", b.nose_length_m),
        ] {
            domain::size(field, v)?;
        }
        domain::within(
            "body.boattail_length_m",
            b.boattail_length_m,
            0.0,
            b.length_m,
            "from 0 (none) to the body's length",
        )?;
        let cylinder_m = b.length_m - b.nose_length_m - b.boattail_length_m;
        if cylinder_m.is_nan() || cylinder_m <= 0.0 {
            return Err((
                "body".into(),
                format!(
                    "nose ({} m) and boattail ({} m) leave no cylinder in a length of {} m",
                    b.nose_length_m, b.boattail_length_m, b.length_m
                ),
            ));
        }
        let tip_x = b.cg_from_nose_m;
        domain::within(
            "body.cg_from_nose_m",
            tip_x,
            0.0,
            b.length_m,
            "the CG lies on the store, between its nose tip and its base (body.length_m)",
        )?;
        let mut out = vec![parts::hull(
            "nose".into(),
            "body.nose",
            &nose_points(b.nose_shape, b.nose_length_m, r, tip_x),
        )?];
        let body_x = tip_x - b.nose_length_m - 0.5 * cylinder_m;
        out.push(parts::cylinder(
            "body".into(),
            "body",
            [body_x, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            r,
            cylinder_m,
        )?);
        if b.boattail_length_m > 0.0 {
            out.push(boattail(b, r, tip_x)?);
        } else if b.base_diameter_m.is_some() {
            return Err((
                "body.base_diameter_m".into(),
                "given without boattail_length_m".into(),
            ));
        }
        if let Some(f) = &self.fins {
            out.extend(fins(f, r, tip_x, b.length_m)?);
        }
        let extra = Primitives {
            boxes: self.boxes.iter().map(clone_box).collect(),
            cylinders: self.cylinders.iter().map(clone_cylinder).collect(),
            half_spaces: self
                .half_spaces
                .iter()
                .map(|h| HalfSpaceSpec {
                    name: h.name.clone(),
                    ..*h
                })
                .collect(),
            hulls: self
                .hulls
                .iter()
                .map(|h| HullSpec {
                    name: h.name.clone(),
                    points_m: h.points_m.clone(),
                })
                .collect(),
        };
        out.extend(extra.parts(false)?);
        Ok(out)
    }
}

fn clone_box(b: &BoxSpec) -> BoxSpec {
    BoxSpec {
        name: b.name.clone(),
        ..*b
    }
}

fn clone_cylinder(c: &CylinderSpec) -> CylinderSpec {
    CylinderSpec {
        name: c.name.clone(),
        ..*c
    }
}

fn circle(x: f64, radius: f64, out: &mut Vec<[f64; 3]>) {
    for k in 0..AROUND {
        let a = std::f64::consts::TAU * k as f64 / AROUND as f64;
        out.push([x, radius * a.cos(), radius * a.sin()]);
    }
}

/// The nose's tip and its circles, the last at the nose's base (radius `r`).
fn nose_points(shape: NoseShape, length_m: f64, r: f64, tip_x: f64) -> Vec<[f64; 3]> {
    let rho = (r * r + length_m * length_m) / (2.0 * r);
    let mut pts = vec![[tip_x, 0.0, 0.0]];
    for s in 1..=STATIONS {
        let x = length_m * s as f64 / STATIONS as f64;
        let y = match shape {
            NoseShape::Ogive => (rho * rho - (length_m - x).powi(2)).sqrt() + r - rho,
            NoseShape::Cone => r * x / length_m,
        };
        circle(tip_x - x, y.clamp(0.0, r), &mut pts);
    }
    pts
}

fn boattail(b: &Revolution, r: f64, tip_x: f64) -> Result<Part, PartProblem> {
    let base_d = b.base_diameter_m.ok_or_else(|| {
        (
            "body.base_diameter_m".to_string(),
            "needed with boattail_length_m".to_string(),
        )
    })?;
    domain::size("body.base_diameter_m", base_d)?;
    if base_d > b.diameter_m {
        return Err((
            "body.base_diameter_m".into(),
            format!(
                "{} must be positive and at most the diameter",
                domain::number(base_d)
            ),
        ));
    }
    let start_x = tip_x - (b.length_m - b.boattail_length_m);
    let mut pts = Vec::new();
    circle(start_x, r, &mut pts);
    circle(tip_x - b.length_m, 0.5 * base_d, &mut pts);
    parts::hull("boattail".into(), "body.boattail", &pts)
}

fn fins(f: &Fins, r: f64, tip_x: f64, length_m: f64) -> Result<Vec<Part>, PartProblem> {
    if !(1..=16).contains(&f.count) {
        return Err(("fins.count".into(), format!("{} must be 1 to 16", f.count)));
    }
    for (field, v) in [
        ("fins.root_chord_m", f.root_chord_m),
        ("fins.span_m", f.span_m),
        ("fins.thickness_m", f.thickness_m),
    ] {
        domain::size(field, v)?;
    }
    domain::within(
        "fins.leading_edge_from_nose_m",
        f.leading_edge_from_nose_m,
        0.0,
        length_m,
        "the fins' roots start on the body, between its nose tip and its base",
    )?;
    domain::angles("fins.roll_deg", &[f.roll_deg])?;
    if !(f.tip_chord_m.is_finite() && f.tip_chord_m >= 0.0 && f.tip_chord_m <= f.root_chord_m) {
        return Err((
            "fins.tip_chord_m".into(),
            format!(
                "{} must be from 0 to the root chord",
                domain::number(f.tip_chord_m)
            ),
        ));
    }
    let le_x = tip_x - f.leading_edge_from_nose_m;
    let te_x = le_x - f.root_chord_m;
    // The root lies inside the body (half its radius out), so the fin meets the body's surface.
    let (root_r, tip_r, w) = (0.5 * r, r + f.span_m, 0.5 * f.thickness_m);
    let corners = [
        (le_x, root_r),
        (te_x, root_r),
        (te_x + f.tip_chord_m, tip_r),
        (te_x, tip_r),
    ];
    (0..f.count)
        .map(|k| {
            let roll = (f.roll_deg + 360.0 * k as f64 / f.count as f64).to_radians();
            let (s, c) = roll.sin_cos();
            let pts: Vec<[f64; 3]> = corners
                .iter()
                .flat_map(|&(x, radial)| {
                    [-w, w].map(|off| [x, radial * c - off * s, radial * s + off * c])
                })
                .collect();
            parts::hull(
                format!("fin {}", k + 1),
                &format!("fins (fin {})", k + 1),
                &pts,
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_example_store_file_is_the_default_store() {
        let text = include_str!("../../examples/geometry/store.toml");
        let spec: StoreSpec = toml::from_str(text).unwrap();
        assert_eq!(spec, StoreSpec::eglin(EGLIN_DIAMETER_M));
    }

    #[test]
    fn the_ogive_meets_the_body_tangentially_at_full_radius() {
        let pts = nose_points(NoseShape::Ogive, 0.762, 0.254, 1.415);
        let last = &pts[pts.len() - AROUND];
        assert!((last[1] - 0.254).abs() < 1e-12 && (last[0] - (1.415 - 0.762)).abs() < 1e-12);
        assert!(
            pts[0]
                .iter()
                .zip([1.415, 0.0, 0.0])
                .all(|(a, b)| (a - b).abs() < 1e-15)
        );
    }

    #[test]
    fn the_default_store_has_its_named_parts() {
        let spec = StoreSpec::eglin(EGLIN_DIAMETER_M);
        let names: Vec<String> = spec.parts().unwrap().into_iter().map(|p| p.name).collect();
        assert_eq!(names, ["nose", "body", "fin 1", "fin 2", "fin 3", "fin 4"]);
    }
}
