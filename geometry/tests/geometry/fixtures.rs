//! Shared fixtures: the example files, STL writers, poses.

use std::path::{Path, PathBuf};

use sepval_geometry::Pose;

/// A file of examples/geometry.
pub fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/geometry")
        .join(name)
}

/// A pose from position and Euler angles.
pub fn pose(position_m: [f64; 3], euler_deg: [f64; 3]) -> Pose {
    Pose {
        position_m,
        euler_deg,
    }
}

/// A triangle.
pub type Tri = [[f64; 3]; 3];

/// The 12 outward-oriented triangles of an axis-aligned box.
pub fn box_triangles(centre: [f64; 3], half: [f64; 3]) -> Vec<Tri> {
    let v = |i: usize| {
        let s = |bit: usize, k: usize| {
            if i >> bit & 1 == 1 {
                centre[k] + half[k]
            } else {
                centre[k] - half[k]
            }
        };
        [s(0, 0), s(1, 1), s(2, 2)]
    };
    // Faces as corner indices (bit 0 = x, 1 = y, 2 = z), counter-clockwise seen from outside.
    let faces = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    faces
        .iter()
        .flat_map(|f| [[v(f[0]), v(f[1]), v(f[2])], [v(f[0]), v(f[2]), v(f[3])]])
        .collect()
}

/// The 4 outward-oriented triangles of a tetrahedron with corners `p`.
pub fn tetra_triangles(p: [[f64; 3]; 4]) -> Vec<Tri> {
    let mut out = Vec::new();
    for (a, b, c, d) in [(0, 1, 2, 3), (0, 3, 1, 2), (0, 2, 3, 1), (1, 3, 2, 0)] {
        let t = [p[a], p[b], p[c]];
        let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
        out.push(if dot(n, sub(p[d], t[0])) > 0.0 {
            [t[0], t[2], t[1]]
        } else {
            t
        });
    }
    out
}

/// `triangles` turned by `rotation` (row-major matrix) and moved by `offset`.
pub fn moved(triangles: &[Tri], rotation: [[f64; 3]; 3], offset: [f64; 3]) -> Vec<Tri> {
    let m = |v: [f64; 3]| {
        let r = |i: usize| {
            rotation[i][0] * v[0] + rotation[i][1] * v[1] + rotation[i][2] * v[2] + offset[i]
        };
        [r(0), r(1), r(2)]
    };
    triangles.iter().map(|t| t.map(m)).collect()
}

/// An ASCII STL with one solid per `(name, triangles)`.
pub fn ascii_stl(solids: &[(&str, &[Tri])]) -> String {
    let mut s = String::new();
    for (name, tris) in solids {
        s += &format!("solid {name}\n");
        for t in *tris {
            s += "  facet normal 0 0 0\n    outer loop\n";
            for v in t {
                s += &format!("      vertex {:e} {:e} {:e}\n", v[0], v[1], v[2]);
            }
            s += "    endloop\n  endfacet\n";
        }
        s += &format!("endsolid {name}\n");
    }
    s
}

/// A binary STL of `triangles` (f32 coordinates).
pub fn binary_stl(triangles: &[Tri]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend((triangles.len() as u32).to_le_bytes());
    for t in triangles {
        b.extend([0u8; 12]);
        for v in t.iter().flatten() {
            b.extend((*v as f32).to_le_bytes());
        }
        b.extend([0u8; 2]);
    }
    b
}

pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
