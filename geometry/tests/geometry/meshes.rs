//! Mesh-to-mesh distances against an independent brute force: the smallest distance over all
//! pairs of triangles, each pair's distance the smallest of its six point-to-triangle and nine
//! segment-to-segment distances (exact for triangles that do not intersect), after C. Ericson,
//! *Real-Time Collision Detection* (Morgan Kaufmann 2005), sections 5.1.5 and 5.1.9.

use sepval_geometry::{Body, Geometry, Role};

use crate::fixtures::{
    Tri, ascii_stl, binary_stl, box_triangles, dot, moved, pose, sub, tetra_triangles,
};

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Ericson 5.1.5: the point of triangle abc closest to p.
fn closest_on_triangle(p: [f64; 3], [a, b, c]: Tri) -> [f64; 3] {
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return add(a, scale(ab, d1 / (d1 - d3)));
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return add(a, scale(ac, d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return add(b, scale(sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    let denom = 1.0 / (va + vb + vc);
    add(a, add(scale(ab, vb * denom), scale(ac, vc * denom)))
}

/// Ericson 5.1.9: the distance between segments p1q1 and p2q2 (neither degenerate here).
fn segment_distance(p1: [f64; 3], q1: [f64; 3], p2: [f64; 3], q2: [f64; 3]) -> f64 {
    let (d1, d2, r) = (sub(q1, p1), sub(q2, p2), sub(p1, p2));
    let (a, e, f) = (dot(d1, d1), dot(d2, d2), dot(d2, r));
    let c = dot(d1, r);
    let b = dot(d1, d2);
    let denom = a * e - b * b;
    let mut s = if denom > 0.0 {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    norm(sub(add(p1, scale(d1, s)), add(p2, scale(d2, t))))
}

fn triangle_distance(t1: Tri, t2: Tri) -> f64 {
    let mut best = f64::INFINITY;
    for (p, t) in t1
        .iter()
        .map(|p| (*p, t2))
        .chain(t2.iter().map(|p| (*p, t1)))
    {
        best = best.min(norm(sub(p, closest_on_triangle(p, t))));
    }
    for i in 0..3 {
        for j in 0..3 {
            best = best.min(segment_distance(
                t1[i],
                t1[(i + 1) % 3],
                t2[j],
                t2[(j + 1) % 3],
            ));
        }
    }
    best
}

fn brute_force(a: &[Tri], b: &[Tri]) -> f64 {
    a.iter()
        .flat_map(|t1| b.iter().map(move |t2| triangle_distance(*t1, *t2)))
        .fold(f64::INFINITY, f64::min)
}

/// C_LB = Rz(psi) Ry(theta) Rx(phi), written out as matrices.
fn c_lb(euler_deg: [f64; 3]) -> [[f64; 3]; 3] {
    let [phi, theta, psi] = euler_deg.map(f64::to_radians);
    let (sf, cf, st, ct, sp, cp) = (
        phi.sin(),
        phi.cos(),
        theta.sin(),
        theta.cos(),
        psi.sin(),
        psi.cos(),
    );
    let rz = [[cp, -sp, 0.0], [sp, cp, 0.0], [0.0, 0.0, 1.0]];
    let ry = [[ct, 0.0, st], [0.0, 1.0, 0.0], [-st, 0.0, ct]];
    let rx = [[1.0, 0.0, 0.0], [0.0, cf, -sf], [0.0, sf, cf]];
    let mul = |a: [[f64; 3]; 3], b: [[f64; 3]; 3]| {
        let mut m = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
            }
        }
        m
    };
    mul(rz, mul(ry, rx))
}

fn stl_body(dir: &std::path::Path, name: &str, tris: &[Tri], role: Role) -> Body {
    let path = dir.join(format!("{name}.stl"));
    std::fs::write(&path, ascii_stl(&[("", tris)])).unwrap();
    Body::read(&path, role).unwrap()
}

#[test]
fn mesh_distances_agree_with_the_brute_force_to_a_nanometre() {
    let dir = tempfile::tempdir().unwrap();
    let cube = box_triangles([0.0; 3], [0.25, 0.2, 0.15]);
    let tetra = tetra_triangles([
        [0.3, 0.0, 0.0],
        [-0.2, 0.25, 0.05],
        [-0.2, -0.25, 0.1],
        [0.0, 0.05, -0.3],
    ]);
    let aircraft_cube = moved(
        &box_triangles([0.0; 3], [0.6, 0.4, 0.1]),
        c_lb([10.0, -5.0, 30.0]),
        [0.1, 0.05, -0.9],
    );
    let aircraft_tetra = moved(&tetra, c_lb([0.0, 40.0, -15.0]), [0.4, -0.2, -1.1]);
    let poses = [
        pose([0.0, 0.0, 0.0], [0.0; 3]),
        pose([0.05, -0.1, 0.2], [10.0, 20.0, -30.0]),
        pose([-0.3, 0.2, 0.05], [-45.0, 5.0, 80.0]),
        pose([0.2, 0.3, 0.6], [170.0, -60.0, 10.0]),
    ];
    for (store_tris, aircraft_tris) in [
        (&cube, &aircraft_cube),
        (&tetra, &aircraft_cube),
        (&cube, &aircraft_tetra),
        (&tetra, &aircraft_tetra),
    ] {
        let store = stl_body(dir.path(), "store", store_tris, Role::Store);
        let aircraft = stl_body(dir.path(), "aircraft", aircraft_tris, Role::Aircraft);
        let g = Geometry::new(store, aircraft).unwrap();
        for p in &poses {
            let in_l = moved(store_tris, c_lb(p.euler_deg), p.position_m);
            let expected = brute_force(&in_l, aircraft_tris);
            let c = g.clearance(p);
            assert!(
                (c.distance_m - expected).abs() < 1e-9,
                "{p:?}: {} against {expected}",
                c.distance_m
            );
            assert!(
                (norm(sub(c.store_point_m, c.aircraft_point_m)) - expected).abs() < 1e-9,
                "{c:?}"
            );
        }
    }
}

#[test]
fn ascii_and_binary_stl_read_the_same_triangles() {
    let dir = tempfile::tempdir().unwrap();
    // Coordinates that f32 holds exactly, so the binary file loses nothing.
    let tris = tetra_triangles([
        [0.5, 0.0, 0.0],
        [-0.25, 0.375, 0.125],
        [-0.25, -0.375, 0.25],
        [0.0, 0.125, -0.5],
    ]);
    let ascii = dir.path().join("a.stl");
    let binary = dir.path().join("b.stl");
    std::fs::write(&ascii, ascii_stl(&[("", &tris)])).unwrap();
    std::fs::write(&binary, binary_stl(&tris)).unwrap();
    let aircraft = stl_body(
        dir.path(),
        "aircraft",
        &box_triangles([0.0, 0.0, -2.0], [1.0, 1.0, 0.5]),
        Role::Aircraft,
    );
    let a = Geometry::new(Body::read(&ascii, Role::Store).unwrap(), aircraft.clone()).unwrap();
    let b = Geometry::new(Body::read(&binary, Role::Store).unwrap(), aircraft).unwrap();
    for k in 0..20 {
        let p = pose(
            [0.01 * k as f64, 0.0, 0.05 * k as f64],
            [3.0 * k as f64, -2.0 * k as f64, 7.0 * k as f64],
        );
        assert_eq!(a.clearance(&p), b.clearance(&p));
    }
}

#[test]
fn ascii_solids_are_parts_named_by_their_solid() {
    let dir = tempfile::tempdir().unwrap();
    let near = box_triangles([0.0, 0.0, -1.0], [0.5, 0.5, 0.25]);
    let far = box_triangles([0.0, 3.0, -1.0], [0.5, 0.5, 0.25]);
    let path = dir.path().join("two.stl");
    std::fs::write(&path, ascii_stl(&[("near one", &near), ("far", &far)])).unwrap();
    let aircraft = Body::read(&path, Role::Aircraft).unwrap();
    assert_eq!(aircraft.part_names(), ["near one", "far"]);
    let store = stl_body(
        dir.path(),
        "store",
        &box_triangles([0.0; 3], [0.2, 0.2, 0.2]),
        Role::Store,
    );
    let g = Geometry::new(store, aircraft).unwrap();
    let c = g.clearance(&pose([0.0, 2.5, 0.0], [0.0; 3]));
    assert_eq!(g.aircraft_part(c.aircraft_part), "far");
    assert!((c.distance_m - 0.55).abs() < 1e-9, "{c:?}");
}
