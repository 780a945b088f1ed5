//! The parts of a body as parry shapes, each validated before it reaches parry (parry can panic
//! on an empty or flat shape): a convex hull of points, a box, a cylinder, a half-space, or a
//! triangle mesh (a surface; a closed, consistently oriented mesh is also a solid, whose inside
//! counts as intersecting).

use std::collections::HashMap;

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::{Pose as PPose, Vector};
use parry3d_f64::shape::{
    ConvexPolyhedron, Cuboid, Cylinder, HalfSpace, SharedShape, TriMesh, TriMeshFlags,
};

use crate::Stop;
use crate::domain;
use crate::frames::vector;

/// A part of a body: a name, a shape placed in the body's frame, and the bounds used to skip it.
#[derive(Clone)]
pub(crate) struct Part {
    /// "nose", "fin 1", "pylon", the solid's name...
    pub name: String,
    /// The shape, in its own axes.
    pub shape: SharedShape,
    /// The shape's pose in the body's frame.
    pub pose: PPose,
    /// What bounds it, in the body's frame.
    pub bound: Bound,
    /// A point of the part's surface (body frame): inside a closed mesh means the whole part is,
    /// when the two surfaces do not cross.
    pub surface_point: Vector,
    /// A closed, outward-oriented mesh: a point can be inside it.
    pub closed_mesh: bool,
}

/// The bound of a part.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Bound {
    /// Everything within `radius` of `centre`; `aabb` the box around the part.
    Sphere {
        centre: Vector,
        radius: f64,
        aabb: Aabb,
    },
    /// The solid behind the plane through `point` with the outward unit `normal`.
    HalfSpace { point: Vector, normal: Vector },
}

/// Why a part could not be made: the field and what is wrong.
pub(crate) type PartProblem = (String, String);

fn problem(field: &str, what: impl Into<String>) -> PartProblem {
    (field.to_string(), what.into())
}

fn bounded(
    name: String,
    shape: SharedShape,
    pose: PPose,
    surface_point: Vector,
    closed_mesh: bool,
) -> Part {
    let sphere = shape.compute_bounding_sphere(&pose);
    let aabb = shape.compute_aabb(&pose);
    Part {
        name,
        shape,
        pose,
        bound: Bound::Sphere {
            centre: sphere.center,
            radius: sphere.radius,
            aabb,
        },
        surface_point,
        closed_mesh,
    }
}

/// The convex hull of `points` (body frame), refused when fewer than four or flat: thinner
/// than 1e-9 of its extent in some direction.
pub(crate) fn hull(name: String, field: &str, points: &[[f64; 3]]) -> Result<Part, PartProblem> {
    for (k, p) in points.iter().enumerate() {
        domain::point(&format!("{field}[{k}]"), p)?;
    }
    let pts: Vec<Vector> = points.iter().map(|p| vector(*p)).collect();
    check_solid(field, &pts)?;
    let hull = ConvexPolyhedron::from_convex_hull(&pts)
        .ok_or_else(|| problem(field, "the convex hull of these points could not be made"))?;
    let surface_point = hull.points()[0];
    Ok(bounded(
        name,
        SharedShape::new(hull),
        PPose::IDENTITY,
        surface_point,
        false,
    ))
}

/// Refuses fewer than four points or points that are (nearly) coplanar.
fn check_solid(field: &str, pts: &[Vector]) -> Result<(), PartProblem> {
    if pts.len() < 4 {
        return Err(problem(
            field,
            format!("{} points: a solid needs at least 4", pts.len()),
        ));
    }
    let p0 = pts[0];
    let far = |f: &dyn Fn(Vector) -> f64| {
        pts.iter()
            .copied()
            .max_by(|a, b| f(*a).total_cmp(&f(*b)))
            .unwrap_or(p0)
    };
    let p1 = far(&|p| (p - p0).length());
    let extent = (p1 - p0).length();
    let axis = (p1 - p0).normalize_or_zero();
    let off_line = |p: Vector| (p - p0).reject_from_normalized(axis).length();
    let p2 = far(&off_line);
    let normal = axis.cross(p2 - p0).normalize_or_zero();
    let thickness = pts
        .iter()
        .map(|p| (*p - p0).dot(normal).abs())
        .fold(0.0, f64::max);
    if !(extent > 0.0 && off_line(p2) > 1e-9 * extent && thickness > 1e-9 * extent) {
        return Err(problem(
            field,
            "the points are coincident, collinear or coplanar: no volume",
        ));
    }
    Ok(())
}

/// A box of `half_extents_m` centred at `centre_m`, turned by `rotation` (body frame).
pub(crate) fn cuboid(
    name: String,
    field: &str,
    centre_m: [f64; 3],
    half_extents_m: [f64; 3],
    rotation: parry3d_f64::math::Rotation,
) -> Result<Part, PartProblem> {
    domain::point(&format!("{field}.centre_m"), &centre_m)?;
    for h in half_extents_m {
        domain::size(&format!("{field}.half_extents_m"), h)?;
    }
    let pose = PPose::from_parts(vector(centre_m), rotation);
    let corner = Vector::new(half_extents_m[0], half_extents_m[1], half_extents_m[2]);
    let shape = SharedShape::new(Cuboid::new(corner));
    Ok(bounded(name, shape, pose, pose * corner, false))
}

/// A cylinder of `radius_m` and `length_m` about `axis` (a direction), centred at `centre_m`.
pub(crate) fn cylinder(
    name: String,
    field: &str,
    centre_m: [f64; 3],
    axis: [f64; 3],
    radius_m: f64,
    length_m: f64,
) -> Result<Part, PartProblem> {
    domain::point(&format!("{field}.centre_m"), &centre_m)?;
    domain::direction(&format!("{field}.axis"), &axis)?;
    domain::size(&format!("{field}.radius_m"), radius_m)?;
    domain::size(&format!("{field}.length_m"), length_m)?;
    let axis = vector(axis);
    if axis.length() < 1e-12 || !axis.length().is_finite() {
        return Err(problem(
            &format!("{field}.axis"),
            "the axis direction has zero length",
        ));
    }
    // parry's cylinder lies along its own y axis.
    let rotation = parry3d_f64::math::Rotation::from_rotation_arc(Vector::Y, axis.normalize());
    let pose = PPose::from_parts(vector(centre_m), rotation);
    let shape = SharedShape::new(Cylinder::new(0.5 * length_m, radius_m));
    let rim = pose * Vector::new(radius_m, 0.5 * length_m, 0.0);
    Ok(bounded(name, shape, pose, rim, false))
}

/// The solid behind the plane through `point_m` whose outward normal is `outward_normal`.
pub(crate) fn half_space(
    name: String,
    field: &str,
    point_m: [f64; 3],
    outward_normal: [f64; 3],
) -> Result<Part, PartProblem> {
    domain::point(&format!("{field}.point_m"), &point_m)?;
    domain::direction(&format!("{field}.outward_normal"), &outward_normal)?;
    let n = vector(outward_normal);
    if n.length().is_nan() || n.length() <= 1e-12 {
        return Err(problem(
            &format!("{field}.outward_normal"),
            "the normal has zero length",
        ));
    }
    let normal = n.normalize();
    let point = vector(point_m);
    Ok(Part {
        name,
        shape: SharedShape::new(HalfSpace::new(normal)),
        pose: PPose::from_translation(point),
        bound: Bound::HalfSpace { point, normal },
        surface_point: point,
        closed_mesh: false,
    })
}

/// A triangle mesh (vertices in the body frame, within the domain of a coordinate). Zero-area
/// triangles (height under `DEGENERATE` of the longest edge) are dropped; a mesh with none
/// left is refused. A closed mesh (every edge shared by two triangles that run it in
/// opposite directions) is oriented outward and can contain points.
pub(crate) fn mesh(
    name: String,
    field: &str,
    triangles: &[[[f64; 3]; 3]],
    stop: Stop,
) -> Result<Part, MeshRefusal> {
    let (vertices, mut indices) = indexed(triangles, stop).ok_or(MeshRefusal::Stopped)?;
    if indices.is_empty() {
        return Err(MeshRefusal::Problem(problem(
            field,
            format!("all {} triangles have zero area", triangles.len()),
        )));
    }
    let closed = is_closed(&indices, stop).ok_or(MeshRefusal::Stopped)?;
    if closed && signed_volume(&vertices, &indices) < 0.0 {
        for t in &mut indices {
            t.swap(1, 2);
        }
    }
    if stop() {
        return Err(MeshRefusal::Stopped);
    }
    let surface_point = vertices[indices[0][0] as usize];
    let flags = TriMeshFlags::HALF_EDGE_TOPOLOGY | TriMeshFlags::ORIENTED;
    let oriented = if closed {
        TriMesh::with_flags(vertices.clone(), indices.clone(), flags).ok()
    } else {
        None
    };
    let (shape, closed_mesh) = match oriented {
        Some(m) => (m, true),
        None => (
            TriMesh::new(vertices, indices)
                .map_err(|e| MeshRefusal::Problem(problem(field, e.to_string())))?,
            false,
        ),
    };
    Ok(bounded(
        name,
        SharedShape::new(shape),
        PPose::IDENTITY,
        surface_point,
        closed_mesh,
    ))
}

/// Why a mesh was not made.
pub(crate) enum MeshRefusal {
    /// The field and what is wrong.
    Problem(PartProblem),
    /// `stop` asked to stop.
    Stopped,
}

/// Triangles handled between two calls of `stop`.
const STOP_EVERY: usize = 1 << 14;

/// A triangle whose height is under this share of its longest edge has no area in double
/// precision (its normal would be rounding noise): it is dropped.
const DEGENERATE: f64 = 1e-12;

/// Vertices merged where equal, and the triangles of non-zero area as indices; `None` when
/// `stop` asked to stop.
fn indexed(triangles: &[[[f64; 3]; 3]], stop: Stop) -> Option<(Vec<Vector>, Vec<[u32; 3]>)> {
    let mut index: HashMap<[u64; 3], u32> = HashMap::new();
    let mut vertices = Vec::new();
    let mut indices = Vec::with_capacity(triangles.len());
    for (k, t) in triangles.iter().enumerate() {
        if k % STOP_EVERY == 0 && stop() {
            return None;
        }
        let [a, b, c] = t.map(vector);
        let longest = [b - a, c - b, a - c]
            .map(|e| e.length_squared())
            .into_iter()
            .fold(0.0, f64::max);
        // Twice the area against the longest edge squared (NaN counts as degenerate).
        let area2 = (b - a).cross(c - a).length();
        if area2.is_nan() || area2 <= DEGENERATE * longest {
            continue;
        }
        let ids = t.map(|v| {
            *index
                .entry(v.map(|x| (x + 0.0).to_bits()))
                .or_insert_with(|| {
                    vertices.push(vector(v));
                    (vertices.len() - 1) as u32
                })
        });
        indices.push(ids);
    }
    Some((vertices, indices))
}

/// Every directed edge appears once and its reverse once; `None` when `stop` asked to stop.
fn is_closed(indices: &[[u32; 3]], stop: Stop) -> Option<bool> {
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for (i, t) in indices.iter().enumerate() {
        if i % STOP_EVERY == 0 && stop() {
            return None;
        }
        for k in 0..3 {
            *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    Some(
        edges
            .iter()
            .all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1)),
    )
}

fn signed_volume(vertices: &[Vector], indices: &[[u32; 3]]) -> f64 {
    indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

impl std::fmt::Debug for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Part")
            .field("name", &self.name)
            .field("bound", &self.bound)
            .finish()
    }
}
