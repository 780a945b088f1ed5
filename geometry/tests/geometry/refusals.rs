//! Every refusal names the file (or the parts) and what is wrong.

use std::path::{Path, PathBuf};

use sepval_geometry::{Body, Geometry, GeometryError, MAX_FILE_BYTES, MAX_TRIANGLES, Role};

use crate::fixtures::{ascii_stl, box_triangles, example};

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The error's message, checked to name the file and to contain `what`.
fn refused(path: &Path, role: Role, what: &str) -> GeometryError {
    let e = Body::read(path, role).unwrap_err();
    let msg = e.to_string();
    let name = path.file_name().unwrap().to_string_lossy();
    assert!(
        msg.contains(name.as_ref()) && msg.contains(what),
        "{msg:?} should name {name} and say {what:?}"
    );
    e
}

#[test]
fn unreadable_and_unknown_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        &dir.path().join("missing.stl"),
        Role::Aircraft,
        "cannot read",
    );
    refused(
        &write(dir.path(), "wing.obj", "v 0 0 0"),
        Role::Aircraft,
        "must be .stl or .toml",
    );
    refused(
        &write(dir.path(), "junk.stl", vec![7u8; 200]),
        Role::Aircraft,
        "not an STL file",
    );
    refused(
        &write(dir.path(), "junk.toml", "[[box]\nname ="),
        Role::Aircraft,
        "line 1",
    );
}

#[test]
fn bad_stl_geometry_is_refused_with_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = ascii_stl(&[("a", &box_triangles([0.0; 3], [1.0; 3]))]);
    let nan = good.replacen("vertex -1e0 -1e0 -1e0", "vertex -1e0 NaN -1e0", 1);
    refused(
        &write(dir.path(), "nan.stl", nan),
        Role::Aircraft,
        "line 4: vertex: y coordinate `NaN` is not finite",
    );
    refused(
        &write(dir.path(), "empty.stl", "solid a\nendsolid a\n"),
        Role::Aircraft,
        "empty geometry: solid 1 \"a\" has no triangle",
    );
    refused(
        &write(dir.path(), "nothing.stl", "solid"),
        Role::Aircraft,
        "line 1: the file ends where `facet` or `endsolid` was expected",
    );
    let flat = ascii_stl(&[("a", &[[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]])]);
    refused(
        &write(dir.path(), "flat.stl", flat),
        Role::Aircraft,
        "all 1 triangles have zero area",
    );
}

#[test]
fn bad_toml_geometry_is_refused_with_its_field() {
    let dir = tempfile::tempdir().unwrap();
    let cyl = "[[cylinder]]\nname = \"tank\"\ncentre_m = [0.0, 0.0, -1.0]\naxis = [1.0, 0.0, 0.0]\nradius_m = 0.3\nlength_m = 2.0\n";
    refused(
        &write(dir.path(), "zero.toml", cyl.replace("0.3", "0.0")),
        Role::Aircraft,
        "cylinder[0] \"tank\".radius_m: 0 must be finite and positive",
    );
    refused(
        &write(dir.path(), "neg.toml", cyl.replace("2.0", "-2.0")),
        Role::Aircraft,
        "length_m: -2 must be finite and positive",
    );
    refused(
        &write(dir.path(), "nan.toml", cyl.replace("-1.0", "nan")),
        Role::Aircraft,
        "centre_m: [0.0, 0.0, NaN] is not finite",
    );
    refused(
        &write(
            dir.path(),
            "unknown.toml",
            cyl.replace("radius_m", "radius_mm"),
        ),
        Role::Aircraft,
        "unknown field `radius_mm`",
    );
    refused(
        &write(dir.path(), "none.toml", ""),
        Role::Aircraft,
        "empty geometry: no part",
    );
    refused(
        &write(dir.path(), "twice.toml", format!("{cyl}{cyl}")),
        Role::Aircraft,
        "part \"tank\": the name is used twice",
    );
    let store = std::fs::read_to_string(example("store.toml")).unwrap();
    refused(
        &write(
            dir.path(),
            "store.toml",
            store.replace("length_m = 3.015", "length_m = 0.5"),
        ),
        Role::Store,
        "leave no cylinder",
    );
    refused(
        &write(
            dir.path(),
            "fins.toml",
            store.replace("count = 4", "count = 0"),
        ),
        Role::Store,
        "fins.count: 0 must be 1 to 16",
    );
    refused(
        &write(dir.path(), "typo.toml", store.replace("span_m", "spam_m")),
        Role::Store,
        "unknown field `spam_m`",
    );
    let e = Body::default_store(-1.0).unwrap_err();
    assert!(
        e.to_string()
            .contains("diameter_m: -1 must be finite and positive"),
        "{e}"
    );
}

#[test]
fn files_over_the_limits_are_refused_before_they_are_read() {
    let dir = tempfile::tempdir().unwrap();
    // Sparse files: nothing but the header is written to disk.
    let big = dir.path().join("big.stl");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(MAX_FILE_BYTES + 1)
        .unwrap();
    refused(&big, Role::Aircraft, "over the limit of 268435456 bytes");
    let many = dir.path().join("many.stl");
    let mut header = vec![0u8; 80];
    header.extend(((MAX_TRIANGLES + 1) as u32).to_le_bytes());
    std::fs::write(&many, header).unwrap();
    std::fs::OpenOptions::new()
        .write(true)
        .open(&many)
        .unwrap()
        .set_len(84 + 50 * (MAX_TRIANGLES + 1))
        .unwrap();
    refused(
        &many,
        Role::Aircraft,
        "2000001 triangles, over the limit of 2000000",
    );
}

#[test]
fn a_store_intersecting_the_aircraft_at_carriage_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    // The pylon's lower face 5 mm into the store's top (z = -0.254 m).
    let pylon = "[[box]]\nname = \"pylon\"\ncentre_m = [0.0, 0.0, -0.449]\nhalf_extents_m = [0.5, 0.05, 0.2]\n";
    let aircraft = Body::read(&write(dir.path(), "deep.toml", pylon), Role::Aircraft).unwrap();
    let e = Geometry::new(Body::default_store(0.508).unwrap(), aircraft).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("store part \"body\" and aircraft part \"pylon\" overlap by 0.0050 m")
            && msg.contains("deep.toml"),
        "{msg}"
    );
    // 1 mm in is within the tolerance.
    let aircraft = Body::read(
        &write(dir.path(), "touch.toml", pylon.replace("-0.449", "-0.453")),
        Role::Aircraft,
    )
    .unwrap();
    assert!(Geometry::new(Body::default_store(0.508).unwrap(), aircraft).is_ok());
    // A store wholly inside a closed mesh.
    let hangar = Body::read(
        &write(
            dir.path(),
            "hangar.stl",
            ascii_stl(&[("hangar", &box_triangles([0.0; 3], [5.0; 3]))]),
        ),
        Role::Aircraft,
    )
    .unwrap();
    let e = Geometry::new(Body::default_store(0.508).unwrap(), hangar.clone()).unwrap_err();
    assert!(e.to_string().contains("one lies inside the other"), "{e}");
    // Outside it, then inside again: 0 when inside, the surface distance outside.
    let store = Body::read(
        &write(
            dir.path(),
            "cube.stl",
            ascii_stl(&[("", &box_triangles([0.0; 3], [0.5; 3]))]),
        ),
        Role::Store,
    )
    .unwrap();
    let far_hangar = Body::read(
        &write(
            dir.path(),
            "far.stl",
            ascii_stl(&[("hangar", &box_triangles([0.0, 0.0, -10.0], [5.0; 3]))]),
        ),
        Role::Aircraft,
    )
    .unwrap();
    let g = Geometry::new(store, far_hangar).unwrap();
    let outside = g.clearance(&sepval_geometry::Pose::CARRIAGE);
    assert!((outside.distance_m - 4.5).abs() < 1e-9, "{outside:?}");
    let inside = g.clearance(&sepval_geometry::Pose {
        position_m: [0.0, 0.0, -10.0],
        euler_deg: [0.0; 3],
    });
    assert!(inside.distance_m.abs() < 1e-12, "{inside:?}");
}
