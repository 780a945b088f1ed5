//! The shape in the terms the build-up uses (reference diameter and area, the nose profile, the
//! exposed fin panel and the panel pair it makes with its mirror image), and the domain of the
//! methods: a shape the geometry accepts but no method here covers is refused, naming the field.
//!
//! Reference quantities are docs/model.md section 1's: d = the body's diameter, S = pi d^2 / 4;
//! stations x are measured aft from the nose tip. The fin pair (a panel and its mirror across
//! the body, joined at the root) is the "wing alone" of Pitts, Nielsen and Kaattari (NACA Report
//! 1307, 1957): aspect ratio A = (2 s)^2 / (2 S_panel).

use sepval_geometry::{Nose, StoreShape};

use crate::AeroError;

/// The fin counts the build-up covers: the normal force of three or four equally spaced fins
/// does not depend on roll and is N/2 times a panel's (J. S. Barrowman, *The Practical
/// Calculation of the Aerodynamic Characteristics of Slender Finned Vehicles*, M.S. thesis,
/// Catholic University of America, 1967, section 3.3); more fins interfere with each other
/// (his fin-fin factors are not carried here), fewer have a roll-dependent normal force.
pub const FIN_COUNTS: [u32; 2] = [3, 4];

/// The exposed fin panel and its pair.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Number of fins N.
    pub count: u32,
    /// Root chord c_r \[m\].
    pub root_chord_m: f64,
    /// Tip chord c_t \[m\].
    pub tip_chord_m: f64,
    /// Exposed span s \[m\].
    pub span_m: f64,
    /// Thickness t \[m\].
    pub thickness_m: f64,
    /// Root leading edge behind the nose tip \[m\].
    pub leading_edge_m: f64,
    /// The tip's leading edge behind the root's, x_t = c_r - c_t (trailing edge square) \[m\].
    pub sweep_m: f64,
    /// One panel's area S_p = s (c_r + c_t) / 2 [m^2].
    pub area_m2: f64,
    /// The pair's aspect ratio A = 2 s^2 / S_p.
    pub aspect_ratio: f64,
    /// tan of the half-chord line's sweep, (x_t + (c_t - c_r) / 2) / s.
    pub tan_half_chord: f64,
    /// tau = r / (r + s), the body radius over the semi-span from the axis.
    pub tau: f64,
    /// The mean aerodynamic chord \[m\], (2/3) (c_r + c_t - c_r c_t / (c_r + c_t)).
    pub mac_m: f64,
}

/// A store as the build-up sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct Configuration {
    /// Where the shape came from.
    pub source: String,
    /// Reference diameter d \[m\].
    pub diameter_m: f64,
    /// Reference area S = pi d^2 / 4 [m^2].
    pub area_ref_m2: f64,
    /// Nose tip to base \[m\].
    pub length_m: f64,
    /// The CG behind the nose tip \[m\].
    pub cg_m: f64,
    /// Nose shape and length \[m\].
    pub nose: Nose,
    /// The nose's length \[m\].
    pub nose_length_m: f64,
    /// The boattail's length \[m\] (0: none).
    pub boattail_length_m: f64,
    /// The base's diameter \[m\].
    pub base_diameter_m: f64,
    /// The fins.
    pub fins: Option<Panel>,
    /// Extra primitive parts of the file, not in the estimate.
    pub extra_parts: usize,
    /// The fins' roots reach aft of the cylinder onto the boattail: the interference factors
    /// assume a panel on a cylinder, so the estimate is outside their stated domain there
    /// (docs/aero.md, the Arcas model).
    pub fins_on_boattail: bool,
}

impl Configuration {
    /// The configuration of `shape`, refusing a fin count outside [`FIN_COUNTS`] and a nose
    /// shorter than half a calibre (slender-body theory asks for a slender nose).
    pub fn of(shape: &StoreShape) -> Result<Configuration, AeroError> {
        let b = &shape.body;
        let outside = |field: &str, what: String| AeroError::Outside {
            source_name: shape.source.clone(),
            field: field.to_string(),
            what,
        };
        if b.nose_length_m < 0.5 * b.diameter_m {
            return Err(outside(
                "body.nose_length_m",
                format!(
                    "{} m is under half a calibre ({} m): slender-body theory, on which the \
                     nose's normal force and centre of pressure rest, needs a slender nose",
                    b.nose_length_m,
                    0.5 * b.diameter_m
                ),
            ));
        }
        let r = 0.5 * b.diameter_m;
        let fins = match &shape.fins {
            None => None,
            Some(f) if !FIN_COUNTS.contains(&f.count) => {
                return Err(outside(
                    "fins.count",
                    format!(
                        "{} fins: the build-up covers 3 or 4 equally spaced fins (a normal \
                         force independent of roll, Barrowman 1967 section 3.3)",
                        f.count
                    ),
                ));
            }
            Some(f) => {
                let area_m2 = 0.5 * f.span_m * (f.root_chord_m + f.tip_chord_m);
                let sweep_m = f.root_chord_m - f.tip_chord_m;
                let sum = f.root_chord_m + f.tip_chord_m;
                Some(Panel {
                    count: f.count,
                    root_chord_m: f.root_chord_m,
                    tip_chord_m: f.tip_chord_m,
                    span_m: f.span_m,
                    thickness_m: f.thickness_m,
                    leading_edge_m: f.leading_edge_from_nose_m,
                    sweep_m,
                    area_m2,
                    aspect_ratio: 2.0 * f.span_m * f.span_m / area_m2,
                    tan_half_chord: (sweep_m + 0.5 * (f.tip_chord_m - f.root_chord_m)) / f.span_m,
                    tau: r / (r + f.span_m),
                    mac_m: (2.0 / 3.0) * (sum - f.root_chord_m * f.tip_chord_m / sum),
                })
            }
        };
        let cylinder_end_m = b.length_m - b.boattail_length_m;
        let fins_on_boattail = fins
            .as_ref()
            .is_some_and(|p| p.leading_edge_m + p.root_chord_m > cylinder_end_m + 1e-9);
        Ok(Configuration {
            source: shape.source.clone(),
            diameter_m: b.diameter_m,
            area_ref_m2: 0.25 * std::f64::consts::PI * b.diameter_m * b.diameter_m,
            length_m: b.length_m,
            cg_m: b.cg_from_nose_m,
            nose: b.nose,
            nose_length_m: b.nose_length_m,
            boattail_length_m: b.boattail_length_m,
            base_diameter_m: b.base_diameter_m,
            fins,
            extra_parts: shape.extra_parts,
            fins_on_boattail,
        })
    }

    /// The body's radius at station `x_m` from the nose tip (0 beyond the body).
    pub fn radius_m(&self, x_m: f64) -> f64 {
        let r = 0.5 * self.diameter_m;
        let l = self.nose_length_m;
        if !(0.0..=self.length_m).contains(&x_m) {
            return 0.0;
        }
        if x_m < l {
            return match self.nose {
                Nose::Cone => r * x_m / l,
                // Tangent ogive (docs/geometry.md): rho = (R^2 + L^2) / (2 R).
                _ => {
                    let rho = (r * r + l * l) / (2.0 * r);
                    ((rho * rho - (l - x_m) * (l - x_m)).max(0.0)).sqrt() + r - rho
                }
            };
        }
        let start = self.length_m - self.boattail_length_m;
        if x_m <= start || self.boattail_length_m <= 0.0 {
            return r;
        }
        let rb = 0.5 * self.base_diameter_m;
        r + (rb - r) * (x_m - start) / self.boattail_length_m
    }
}
