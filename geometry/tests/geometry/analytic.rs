//! A store falling straight away from a plane, against the analytic distance: the plane's
//! height less the height of the store's highest point, found from the default store's
//! documented dimensions (docs/geometry.md) by the textbook tangent-ogive profile.

use sepval_geometry::{Body, Geometry, Role};

use crate::fixtures::{ascii_stl, pose};

/// The plane is at z = -PLANE_M (above the store: z is down).
const PLANE_M: f64 = 0.6;

/// C_LB p for a pitch `theta` (no roll, no yaw): z = -x sin(theta) + z_B cos(theta).
fn z_in_l(p: [f64; 3], theta_deg: f64) -> f64 {
    let (s, c) = theta_deg.to_radians().sin_cos();
    -p[0] * s + p[2] * c
}

/// The extreme points of the default store at 0.508 m: the nose's tip and circles (32 points
/// each, the topmost among them), the cylinder's end rims and the fins' corners.
fn store_extremes() -> Vec<[f64; 3]> {
    let (r, tip, nose, base) = (0.254, 1.415, 0.762, -1.6);
    let rho = (r * r + nose * nose) / (2.0 * r);
    let mut pts = vec![[tip, 0.0, 0.0]];
    for k in 1..=12 {
        let x = nose * k as f64 / 12.0;
        let y = (rho * rho - (nose - x) * (nose - x)).sqrt() + r - rho;
        pts.push([tip - x, 0.0, -y]);
    }
    pts.push([base, 0.0, -r]);
    let (le, te, tip_le, span_r, w) = (tip - 2.615, base, base + 0.16, r + 0.22, 0.0075);
    for roll in [45.0f64, 135.0, 225.0, 315.0] {
        let (s, c) = roll.to_radians().sin_cos();
        for (x, radial) in [(le, 0.5 * r), (te, 0.5 * r), (tip_le, span_r), (te, span_r)] {
            for off in [-w, w] {
                pts.push([x, radial * c - off * s, radial * s + off * c]);
            }
        }
    }
    pts
}

fn check_against_plane(aircraft: Body, tolerance_m: f64) {
    let g = Geometry::new(Body::default_store(0.508).unwrap(), aircraft).unwrap();
    let extremes = store_extremes();
    for dz in [0.0, 0.5, 1.0, 3.0] {
        for theta in [-20.0, -5.0, 0.0, 10.0, 30.0] {
            let top = extremes
                .iter()
                .map(|p| z_in_l(*p, theta))
                .fold(f64::INFINITY, f64::min);
            let expected = (dz + top + PLANE_M).max(0.0);
            let c = g.clearance(&pose([0.0, 0.0, dz], [0.0, theta, 0.0]));
            assert!(
                (c.distance_m - expected).abs() < tolerance_m,
                "dz {dz} theta {theta}: {c:?} against {expected}"
            );
            assert!(
                (c.aircraft_point_m[2] + PLANE_M).abs() < tolerance_m,
                "{c:?}"
            );
        }
    }
}

fn aircraft_toml(text: &str) -> Body {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plane.toml");
    std::fs::write(&path, text).unwrap();
    Body::read(&path, Role::Aircraft).unwrap()
}

#[test]
fn a_store_falls_away_from_a_half_space() {
    let plane = format!(
        "[[half_space]]\nname = \"plane\"\npoint_m = [0.0, 0.0, {}]\noutward_normal = [0.0, 0.0, 2.0]\n",
        -PLANE_M
    );
    check_against_plane(aircraft_toml(&plane), 1e-9);
}

#[test]
fn a_store_falls_away_from_a_large_box() {
    let slab = format!(
        "[[box]]\nname = \"slab\"\ncentre_m = [0.0, 0.0, {}]\nhalf_extents_m = [50.0, 50.0, 1.0]\n",
        -PLANE_M - 1.0
    );
    check_against_plane(aircraft_toml(&slab), 1e-7);
}

#[test]
fn a_store_falls_away_from_an_stl_plane() {
    let z = -PLANE_M;
    let tris = [
        [[-50.0, -50.0, z], [50.0, -50.0, z], [50.0, 50.0, z]],
        [[-50.0, -50.0, z], [50.0, 50.0, z], [-50.0, 50.0, z]],
    ];
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plane.stl");
    std::fs::write(&path, ascii_stl(&[("", &tris)])).unwrap();
    let body = Body::read(&path, Role::Aircraft).unwrap();
    assert_eq!(body.part_names(), ["plane"]);
    check_against_plane(body, 1e-7);
}
