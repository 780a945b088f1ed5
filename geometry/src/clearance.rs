//! The clearance between the store and the aircraft at one store pose: the smallest distance
//! between their surfaces (0 when they touch or intersect), and the check at carriage.
//!
//! Every pair of parts (store part, aircraft part) has a cheap lower bound on its distance:
//! the store part's bounding sphere against the aircraft part's bounding sphere and box, or
//! against its plane. The pair with the smallest bound is measured first, then every other pair
//! whose bound is below the best distance so far; parry measures a pair by GJK (convex parts),
//! its bounding-volume tree (meshes) or the support function (half-spaces), stopping at the
//! best distance so far (`closest_points` with that margin).

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::{Pose as PPose, Vector};
use parry3d_f64::query::{self, ClosestPoints};

use crate::body::Body;
use crate::error::CarriageOverlap;
use crate::frames::{array, body_pose};
use crate::mesh_distance;
use crate::parts::{Bound, Part};
use crate::{GeometryError, Stop};

/// How deep the store may intersect the aircraft at carriage (identity pose): 2 mm. Surfaces
/// modelled in contact (sway braces, lugs, a store drawn touching its pylon) and meshes
/// tessellated from CAD to the usual chordal tolerance of about 1 mm must pass; an overlap of
/// more than 2 mm is a misplaced store or aircraft. It is under a tenth of the 25.4 mm of
/// MIL-STD-1289D, so a geometry that passes cannot hide a violation of the criterion.
pub const CARRIAGE_TOLERANCE_M: f64 = 0.002;

/// The store's pose in the launch frame L: CG position and 3-2-1 Euler angles `[phi, theta,
/// psi]` (roll, pitch, yaw), C_LB = Rz(psi) Ry(theta) Rx(phi) (docs/model.md section 2). At
/// carriage both are zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// r, the CG's position in L (m).
    pub position_m: [f64; 3],
    /// `[phi, theta, psi]` (deg).
    pub euler_deg: [f64; 3],
}

impl Pose {
    /// The pose at carriage: r = 0, no rotation.
    pub const CARRIAGE: Pose = Pose {
        position_m: [0.0; 3],
        euler_deg: [0.0; 3],
    };
}

/// The closest approach at one pose: the distance and where it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Closest {
    /// The smallest distance between the surfaces (m); 0 when they touch or intersect; NaN for
    /// a pose that is not finite.
    pub distance_m: f64,
    /// The store's part (index into [`Body::part_names`] of the store).
    pub store_part: usize,
    /// The aircraft's part.
    pub aircraft_part: usize,
    /// The closest point of the store, in L (m).
    pub store_point_m: [f64; 3],
    /// The closest point of the aircraft, in L (m).
    pub aircraft_point_m: [f64; 3],
}

impl Closest {
    const NONE: Closest = Closest {
        distance_m: f64::INFINITY,
        store_part: 0,
        aircraft_part: 0,
        store_point_m: [f64::NAN; 3],
        aircraft_point_m: [f64::NAN; 3],
    };
}

/// The store and the aircraft, checked at carriage. Immutable, `Send + Sync`: share one between
/// threads.
#[derive(Debug, Clone)]
pub struct Geometry {
    store: Body,
    aircraft: Body,
}

impl Geometry {
    /// The pair, refused when the store intersects the aircraft at carriage (identity pose) by
    /// more than [`CARRIAGE_TOLERANCE_M`] (penetration depth from parry's contact query), or
    /// when one lies inside a closed mesh of the other.
    pub fn new(store: Body, aircraft: Body) -> Result<Geometry, GeometryError> {
        Geometry::new_until(store, aircraft, &|| false)
    }

    /// [`Geometry::new`], asking `stop` before each pair of parts is checked
    /// ([`GeometryError::Interrupted`] when it says stop).
    pub fn new_until(store: Body, aircraft: Body, stop: Stop) -> Result<Geometry, GeometryError> {
        let g = Geometry { store, aircraft };
        let body = PPose::IDENTITY;
        for (i, sp) in g.store.parts.iter().enumerate() {
            for (j, ap) in g.aircraft.parts.iter().enumerate() {
                if stop() {
                    return Err(GeometryError::Interrupted {
                        what: "checking the store against the aircraft at carriage".into(),
                    });
                }
                let refuse = |how: String| {
                    GeometryError::IntersectsAtCarriage(Box::new(CarriageOverlap {
                        store: g.store.source().to_string(),
                        aircraft: g.aircraft.source().to_string(),
                        store_part: sp.name.clone(),
                        aircraft_part: ap.name.clone(),
                        how,
                        tolerance_m: CARRIAGE_TOLERANCE_M,
                    }))
                };
                let contact = contact(sp, &sp.pose, ap, 0.0).map_err(|_| {
                    refuse("cannot be measured (a pair of shapes parry does not support)".into())
                })?;
                if let Some((dist, ..)) = contact.filter(|c| -c.0 > CARRIAGE_TOLERANCE_M) {
                    return Err(refuse(format!("overlap by {:.4} m", -dist)));
                }
                if g.contained(i, j, &body).is_some() {
                    return Err(refuse("one lies inside the other".into()));
                }
            }
        }
        Ok(g)
    }

    /// The store.
    pub fn store(&self) -> &Body {
        &self.store
    }

    /// The aircraft.
    pub fn aircraft(&self) -> &Body {
        &self.aircraft
    }

    /// The name of the store's part `i` (panics when out of range, as indexing does).
    pub fn store_part(&self, i: usize) -> &str {
        &self.store.parts[i].name
    }

    /// The name of the aircraft's part `i` (panics when out of range, as indexing does).
    pub fn aircraft_part(&self, i: usize) -> &str {
        &self.aircraft.parts[i].name
    }

    /// The smallest distance between the store's surface at `pose` and the aircraft's, 0 when
    /// they touch or intersect (a part inside a closed mesh intersects). A pose that is not
    /// finite gives a NaN distance and NaN points (nothing is measured).
    pub fn clearance(&self, pose: &Pose) -> Closest {
        let finite = pose
            .position_m
            .iter()
            .chain(&pose.euler_deg)
            .all(|v| v.is_finite());
        if !finite {
            return Closest {
                distance_m: f64::NAN,
                ..Closest::NONE
            };
        }
        let body = body_pose(pose.position_m, pose.euler_deg);
        let n_air = self.aircraft.parts.len();
        let bounds: Vec<f64> = (0..self.store.parts.len() * n_air)
            .map(|k| self.lower_bound(k / n_air, k % n_air, &body))
            .collect();
        let first = (0..bounds.len())
            .min_by(|&a, &b| bounds[a].total_cmp(&bounds[b]))
            .unwrap_or(0);
        let mut best = Closest::NONE;
        self.measure(first / n_air, first % n_air, &body, &mut best);
        for (k, &bound) in bounds.iter().enumerate() {
            if best.distance_m <= 0.0 {
                break;
            }
            if k != first && bound < best.distance_m {
                self.measure(k / n_air, k % n_air, &body, &mut best);
            }
        }
        if best.distance_m > 0.0 {
            for (k, &bound) in bounds.iter().enumerate() {
                if bound <= 0.0 {
                    if let Some(point) = self.contained(k / n_air, k % n_air, &body) {
                        let p = array(point);
                        best = Closest {
                            distance_m: 0.0,
                            store_part: k / n_air,
                            aircraft_part: k % n_air,
                            store_point_m: p,
                            aircraft_point_m: p,
                        };
                        break;
                    }
                }
            }
        }
        best
    }

    /// A lower bound on the clearance at `pose` (the smallest of the part pairs' bounds; minus
    /// infinity when a part has none): a pose whose bound is at least a clearance already
    /// found cannot come closer, and need not be measured.
    pub(crate) fn pose_lower_bound(&self, pose: &Pose) -> f64 {
        let body = body_pose(pose.position_m, pose.euler_deg);
        let n_air = self.aircraft.parts.len();
        (0..self.store.parts.len() * n_air)
            .map(|k| self.lower_bound(k / n_air, k % n_air, &body))
            .fold(f64::INFINITY, f64::min)
    }

    /// A lower bound on the distance between store part `i` (body at `body`) and aircraft part
    /// `j`, from bounding spheres, boxes and planes.
    fn lower_bound(&self, i: usize, j: usize, body: &PPose) -> f64 {
        let Bound::Sphere { centre, radius, .. } = self.store.parts[i].bound else {
            return f64::NEG_INFINITY;
        };
        let c = *body * centre;
        match self.aircraft.parts[j].bound {
            Bound::Sphere {
                centre: ca,
                radius: ra,
                aabb,
            } => ((c - ca).length() - radius - ra).max(aabb_distance(&aabb, c) - radius),
            Bound::HalfSpace { point, normal } => normal.dot(c - point) - radius,
        }
    }

    /// Measures the pair (`i`, `j`) and keeps it in `best` when closer.
    fn measure(&self, i: usize, j: usize, body: &PPose, best: &mut Closest) {
        let (sp, ap) = (&self.store.parts[i], &self.aircraft.parts[j]);
        let pos1 = *body * sp.pose;
        let margin = best.distance_m.min(f64::MAX);
        let Some(result) = closest_points(sp, &pos1, ap, margin) else {
            return;
        };
        let (distance_m, p1, p2) = match result {
            ClosestPoints::WithinMargin(p1, p2) => ((p1 - p2).length(), p1, p2),
            ClosestPoints::Intersecting => {
                let (p1, p2) = touching_points(sp, &pos1, ap);
                (0.0, p1, p2)
            }
            ClosestPoints::Disjoint => return,
        };
        if distance_m < best.distance_m {
            *best = Closest {
                distance_m,
                store_part: i,
                aircraft_part: j,
                store_point_m: array(p1),
                aircraft_point_m: array(p2),
            };
        }
    }

    /// A point (in L) of one part that lies inside the other's closed mesh, if there is one:
    /// when the surfaces do not cross, one point of a surface inside means all of it is.
    fn contained(&self, i: usize, j: usize, body: &PPose) -> Option<Vector> {
        let (sp, ap) = (&self.store.parts[i], &self.aircraft.parts[j]);
        let pos1 = *body * sp.pose;
        if ap.closed_mesh {
            let p = *body * sp.surface_point;
            if ap.shape.contains_point(&ap.pose, p) {
                return Some(p);
            }
        }
        if sp.closed_mesh
            && matches!(ap.bound, Bound::Sphere { .. })
            && sp.shape.contains_point(&pos1, ap.surface_point)
        {
            return Some(ap.surface_point);
        }
        None
    }
}

/// The closest points of store part `sp` at `pos1` and aircraft part `ap` (store point first,
/// in L) within `margin`: a mesh against a convex part by [`mesh_distance`], anything else by
/// parry; `None` for a pair parry does not support.
fn closest_points(sp: &Part, pos1: &PPose, ap: &Part, margin: f64) -> Option<ClosestPoints> {
    let (s, a) = (sp.shape.as_ref(), ap.shape.as_ref());
    // The relative poses and the order of the transforms are parry's, for the same bits.
    if let (Some(mesh), Some(_)) = (a.as_trimesh(), s.as_support_map()) {
        let rel = pos1.inv_mul(&ap.pose).inverse();
        let found = mesh_distance::closest_points(mesh, &rel, s, margin);
        return Some(found.flipped().transform_by(pos1, &ap.pose));
    }
    if let (Some(mesh), Some(_)) = (s.as_trimesh(), a.as_support_map()) {
        let rel = pos1.inv_mul(&ap.pose);
        let found = mesh_distance::closest_points(mesh, &rel, a, margin);
        return Some(found.transform_by(pos1, &ap.pose));
    }
    query::closest_points(pos1, s, &ap.pose, a, margin).ok()
}

/// parry's contact between store part `sp` at `pos1` and aircraft part `ap`: signed distance
/// (negative: penetration depth), store point, aircraft point, in L. The aircraft's part is
/// passed first: parry 0.31.1's `contact_support_map_halfspace` uses the relative pose without
/// inverting it, so a half-space must come first to be measured right.
fn contact(
    sp: &Part,
    pos1: &PPose,
    ap: &Part,
    prediction: f64,
) -> Result<Option<(f64, Vector, Vector)>, query::Unsupported> {
    let c = query::contact(
        &ap.pose,
        ap.shape.as_ref(),
        pos1,
        sp.shape.as_ref(),
        prediction,
    )?;
    Ok(c.map(|c| (c.dist, c.point2, c.point1)))
}

/// Where two intersecting parts touch (parry's contact points), in L.
fn touching_points(sp: &Part, pos1: &PPose, ap: &Part) -> (Vector, Vector) {
    match contact(sp, pos1, ap, 1e-9) {
        Ok(Some((_, p1, p2))) => (p1, p2),
        _ => {
            let p = *pos1 * sp.surface_point;
            (p, p)
        }
    }
}

/// The distance from `p` to the box (0 inside).
fn aabb_distance(aabb: &Aabb, p: Vector) -> f64 {
    (p.clamp(aabb.mins, aabb.maxs) - p).length()
}
