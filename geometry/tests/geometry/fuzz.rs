//! Random finite numbers never panic: aircraft primitives, store files, STL files (ASCII and
//! binary) and the default store's diameter, read, checked at carriage and measured at random
//! poses. Every number is finite but may be anything from 5e-324 to 1.8e308, either sign: what
//! lies outside the domain (docs/geometry.md) is refused with its field, what lies inside is
//! measured, and nothing reaches a panic in parry. `PROPTEST_CASES=N` runs more cases
//! (`sepval_tests::fuzz`).

use std::path::Path;

use proptest::prelude::*;
use proptest::sample::select;
use sepval_geometry::{Body, Geometry, Pose, Role};
use sepval_tests::fuzz::config;

/// Mostly plausible lengths, sometimes any finite number, sometimes a value at or just past an
/// edge of the domain.
fn number() -> impl Strategy<Value = f64> {
    prop_oneof![
        6 => -12.0..12.0f64,
        1 => prop::num::f64::NORMAL | prop::num::f64::SUBNORMAL | prop::num::f64::ZERO,
        1 => select(vec![
            1e4, -1e4, 1.0001e4, 1e-6, 9.9e-7, 1e-300, 1e300, 1e308, -1e308, f64::MAX,
            f64::MIN_POSITIVE, 5e-324, 0.0, -0.0, 360.0, 361.0,
        ]),
    ]
}

fn triple() -> impl Strategy<Value = [f64; 3]> {
    [number(), number(), number()]
}

/// A TOML float as Rust's Debug form writes it (`1e308`, `-0.0`, `5e-324`: all valid TOML).
fn t(v: f64) -> String {
    format!("{v:?}")
}

fn ta(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", t(v[0]), t(v[1]), t(v[2]))
}

/// Reads `text` as `name` in a fresh directory.
fn read(name: &str, text: &[u8], role: Role) -> Option<Body> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    read_path(&path, role)
}

fn read_path(path: &Path, role: Role) -> Option<Body> {
    match Body::read(path, role) {
        Ok(b) => Some(b),
        Err(e) => {
            // A refusal names the file.
            assert!(e.to_string().contains(name_of(path)), "{e}");
            None
        }
    }
}

fn name_of(path: &Path) -> &str {
    path.file_name().unwrap().to_str().unwrap()
}

/// Checks the pair at carriage and measures it at `poses` (and along them): no panic.
fn measure(store: Body, aircraft: Body, poses: &[Pose]) {
    let Ok(g) = Geometry::new(store, aircraft) else {
        return;
    };
    for p in poses {
        let c = g.clearance(p);
        assert!(c.distance_m >= 0.0 || c.distance_m.is_nan(), "{c:?}");
    }
    let t_s: Vec<f64> = (0..poses.len()).map(|k| 0.01 * k as f64).collect();
    let _ = g.trace(&t_s, poses, 0.1);
    let _ = g.smallest(&t_s, poses, 0.1);
}

fn pose() -> impl Strategy<Value = Pose> {
    (triple(), triple()).prop_map(|(position_m, euler_deg)| Pose {
        position_m,
        euler_deg,
    })
}

fn aircraft_text() -> impl Strategy<Value = String> {
    (
        (triple(), triple(), triple()),
        (triple(), triple(), number(), number()),
        (triple(), triple()),
        prop::collection::vec(triple(), 0..7),
    )
        .prop_map(|(b, c, h, hull)| {
            let mut s = format!(
                "[[box]]\nname = \"b\"\ncentre_m = {}\nhalf_extents_m = {}\nrotation_deg = {}\n",
                ta(b.0),
                ta(b.1.map(f64::abs)),
                ta(b.2)
            );
            s += &format!(
                "[[cylinder]]\nname = \"c\"\ncentre_m = {}\naxis = {}\nradius_m = {}\nlength_m = {}\n",
                ta(c.0),
                ta(c.1),
                t(c.2.abs()),
                t(c.3.abs())
            );
            s += &format!(
                "[[half_space]]\nname = \"h\"\npoint_m = {}\noutward_normal = {}\n",
                ta(h.0),
                ta(h.1)
            );
            if !hull.is_empty() {
                let pts: Vec<String> = hull.iter().map(|p| ta(*p)).collect();
                s += &format!("[[hull]]\nname = \"x\"\npoints_m = [{}]\n", pts.join(", "));
            }
            s
        })
}

fn store_text() -> impl Strategy<Value = String> {
    (
        prop::collection::vec(number(), 7),
        prop::collection::vec(number(), 6),
        1u32..5,
    )
        .prop_map(|(b, f, count)| {
            format!(
                "[body]\nlength_m = {}\ndiameter_m = {}\ncg_from_nose_m = {}\nnose_length_m = {}\n\
                 nose_shape = \"ogive\"\nboattail_length_m = {}\nbase_diameter_m = {}\n\
                 [fins]\ncount = {count}\nroot_chord_m = {}\ntip_chord_m = {}\nspan_m = {}\n\
                 thickness_m = {}\nleading_edge_from_nose_m = {}\nroll_deg = {}\n\
                 [[box]]\nname = \"lug\"\ncentre_m = [0.0, 0.0, -0.3]\nhalf_extents_m = [{}, 0.02, 0.05]\n",
                t(b[0].abs()),
                t(b[1].abs()),
                t(b[2]),
                t(b[3].abs()),
                t(b[4].abs()),
                t(b[5].abs()),
                t(f[0].abs()),
                t(f[1].abs()),
                t(f[2].abs()),
                t(f[3].abs()),
                t(f[4]),
                t(f[5]),
                t(b[6].abs()),
            )
        })
}

fn triangles() -> impl Strategy<Value = Vec<[[f64; 3]; 3]>> {
    prop::collection::vec([triple(), triple(), triple()], 1..12)
}

fn ascii_stl(tris: &[[[f64; 3]; 3]]) -> String {
    let mut s = String::from("solid s\n");
    for tri in tris {
        s += " facet normal 0 0 0\n  outer loop\n";
        for v in tri {
            s += &format!("   vertex {:?} {:?} {:?}\n", v[0], v[1], v[2]);
        }
        s += "  endloop\n endfacet\n";
    }
    s + "endsolid s\n"
}

fn binary_stl(tris: &[[[f64; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend((tris.len() as u32).to_le_bytes());
    for tri in tris {
        b.extend([0u8; 12]);
        for v in tri.iter().flatten() {
            // Values beyond f32 become infinite, which the reader refuses.
            b.extend((*v as f32).to_le_bytes());
        }
        b.extend([0u8; 2]);
    }
    b
}

proptest! {
    #![proptest_config(config(96))]

    #[test]
    fn aircraft_primitives_never_panic(text in aircraft_text(), poses in prop::collection::vec(pose(), 1..4)) {
        if let Some(aircraft) = read("aircraft.toml", text.as_bytes(), Role::Aircraft) {
            measure(Body::default_store(0.508).unwrap(), aircraft, &poses);
        }
    }

    #[test]
    fn store_files_never_panic(text in store_text(), poses in prop::collection::vec(pose(), 1..4)) {
        if let Some(store) = read("store.toml", text.as_bytes(), Role::Store) {
            let far = read(
                "far.toml",
                b"[[box]]\nname = \"far\"\ncentre_m = [0.0, 0.0, -9000.0]\nhalf_extents_m = [1.0, 1.0, 1.0]\n",
                Role::Aircraft,
            )
            .unwrap();
            measure(store, far, &poses);
        }
    }

    #[test]
    fn stl_files_never_panic(tris in triangles(), poses in prop::collection::vec(pose(), 1..4)) {
        let store = || Body::default_store(0.508).unwrap();
        if let Some(a) = read("ascii.stl", ascii_stl(&tris).as_bytes(), Role::Aircraft) {
            measure(store(), a, &poses);
        }
        if let Some(b) = read("binary.stl", &binary_stl(&tris), Role::Aircraft) {
            measure(store(), b, &poses);
        }
        if let Some(s) = read("store.stl", ascii_stl(&tris).as_bytes(), Role::Store) {
            let plane = read(
                "plane.toml",
                b"[[half_space]]\nname = \"wing\"\npoint_m = [0.0, 0.0, -20.0]\noutward_normal = [0.0, 0.0, 1.0]\n",
                Role::Aircraft,
            )
            .unwrap();
            measure(s, plane, &poses);
        }
    }

    #[test]
    fn any_default_store_diameter_is_made_or_refused(d in number()) {
        if let Ok(store) = Body::default_store(d) {
            let far = read(
                "far.toml",
                b"[[box]]\nname = \"far\"\ncentre_m = [0.0, 0.0, -9000.0]\nhalf_extents_m = [1.0, 1.0, 1.0]\n",
                Role::Aircraft,
            )
            .unwrap();
            measure(store, far, &[Pose::CARRIAGE]);
        }
    }
}
