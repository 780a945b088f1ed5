//! Geometry as a hostile user brings it (issue 33, items 2, 3 and 13): numbers that are finite
//! but absurd (1e308, a CG ahead of the nose) refused with their file and field, a criterion
//! without an aircraft refused, a panic reported as a defect (exit 2, nothing left behind), and
//! SIGTERM while a million-triangle aircraft is read stopping `simulate` and `predict` within
//! seconds with exit 130 and nothing written.

use std::path::Path;
use std::process::{Command, Output};
use std::time::Duration;

use sepval_tests::{binary, refused, sepval, signal, spawn_sepval, wait_exit, wait_for};

use super::predict::fixture;

const CYLINDER: &str = "[[cylinder]]\nname = \"tank\"\ncentre_m = [0.0, 0.0, -1.0]\naxis = [1.0, 0.0, 0.0]\nradius_m = 0.3\nlength_m = 2.0\n";

/// `sepval simulate --aircraft aircraft [--store-shape store] --out o.csv` in `dir`, refused
/// with `expected`; nothing written.
fn refused_geometry(dir: &Path, aircraft: &str, store: Option<&str>, expected: &str) {
    let mut args = vec!["simulate", "--aircraft", aircraft, "--out", "o.csv"];
    if let Some(s) = store {
        args.extend(["--store-shape", s]);
    }
    refused(&sepval(&args, dir), expected);
    assert!(!dir.join("o.csv").exists(), "{aircraft}: o.csv written");
}

#[test]
fn absurd_numbers_in_geometry_files_are_refused_naming_the_file_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let write = |name: &str, text: &str| std::fs::write(d.join(name), text).unwrap();
    write("huge-radius.toml", &CYLINDER.replace("0.3", "1e308"));
    refused_geometry(
        d,
        "huge-radius.toml",
        None,
        "huge-radius.toml: cylinder[0] \"tank\".radius_m: 1e308 m is outside the domain of a size, 1e-6 to 10000 m",
    );
    // A cylinder around the whole store passed the check at carriage.
    write(
        "around.toml",
        &CYLINDER.replace("0.3", "1e100").replace("-1.0", "0.0"),
    );
    refused_geometry(d, "around.toml", None, "radius_m: 1e100 m is outside");
    write(
        "box.toml",
        "[[box]]\nname = \"b\"\ncentre_m = [0.0, 0.0, -3.0]\nhalf_extents_m = [1e308, 1.0, 1.0]\n",
    );
    refused_geometry(
        d,
        "box.toml",
        None,
        "box.toml: box[0] \"b\".half_extents_m: 1e308 m is outside the domain of a size",
    );
    // A hull with a far point is not "coplanar": the point is named.
    write(
        "hull.toml",
        "[[hull]]\nname = \"h\"\npoints_m = [[0.0, 0.0, -2.0], [1.0, 0.0, -2.0], [0.0, 1.0, -2.0], [0.0, 0.0, -1e308]]\n",
    );
    let e = refused(
        &sepval(
            &["simulate", "--aircraft", "hull.toml", "--out", "o.csv"],
            d,
        ),
        "hull.toml: hull[0] \"h\".points_m[3]: coordinate -1e308 m is beyond +-10000 m (the domain of a coordinate)",
    );
    assert!(!e.contains("coplanar"), "{e}");
    let tri = |z: &str| {
        format!(
            "solid w\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 -2\n   vertex 1 0 -2\n   vertex 0 1 {z}\n  endloop\n endfacet\nendsolid w\n"
        )
    };
    write("far.stl", &tri("1e300"));
    refused_geometry(
        d,
        "far.stl",
        None,
        "far.stl: line 6: vertex: z coordinate `1e300` is beyond +-10000 m (the domain of a coordinate)",
    );
    let store = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/geometry/store.toml"),
    )
    .unwrap();
    write("wing.toml", CYLINDER);
    write(
        "cg.toml",
        &store.replace("cg_from_nose_m = 1.415", "cg_from_nose_m = 10"),
    );
    refused_geometry(
        d,
        "wing.toml",
        Some("cg.toml"),
        "cg.toml: body.cg_from_nose_m: 10 m is outside 0 m to 3.015 m: the CG lies on the store, between its nose tip and its base (body.length_m)",
    );
    write(
        "long.toml",
        &store.replace("length_m = 3.015", "length_m = 1e300"),
    );
    refused_geometry(
        d,
        "wing.toml",
        Some("long.toml"),
        "long.toml: body.length_m: 1e300 m is outside the domain of a size",
    );
    // The default store is made of the scenario's diameter.
    let mut s = sepval_common::scenario::Scenario::embedded_default();
    s.store.diameter_m = 1e300;
    write("wide.toml", &s.to_toml_string());
    refused(
        &sepval(
            &[
                "simulate",
                "--scenario",
                "wide.toml",
                "--aircraft",
                "wing.toml",
                "--out",
                "o.csv",
            ],
            d,
        ),
        "the default store shape, made of the scenario's store.diameter_m: <default store>: diameter_m: 1e300 m is outside the domain of a size",
    );
    assert!(!d.join("o.csv").exists());
}

#[test]
fn a_clearance_criterion_without_an_aircraft_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let e = refused(
        &sepval(
            &["simulate", "--clearance-mm", "30", "--out", "o.csv"],
            dir.path(),
        ),
        "the following required arguments were not provided",
    );
    assert!(e.contains("--aircraft <FILE>"), "{e}");
    assert!(!dir.path().join("o.csv").exists());
}

fn with_panic_at(point: &str, program: &str, args: &[&str], dir: &Path) -> Output {
    Command::new(binary(program))
        .args(args)
        .current_dir(dir)
        .env("SEPVAL_INJECT_PANIC", point)
        .env_remove("RUST_BACKTRACE")
        .output()
        .unwrap()
}

#[test]
fn a_panic_is_a_defect_with_exit_2_and_leaves_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let out = with_panic_at("start", "sepval", &["effects"], dir.path());
    let stderr = refused(
        &out,
        "sepval: internal error (a defect; please report it): SEPVAL_INJECT_PANIC=start: a panic injected for a test at sepval/src/main.rs:",
    );
    assert!(!stderr.contains("RUST_BACKTRACE"), "{stderr}");
    assert!(!stderr.contains("panicked at"), "{stderr}");
    // Once the output directory is claimed: the panic unwinds, the lock and the directory go.
    let out = with_panic_at(
        "claimed",
        "sepval",
        &["diagnose", "--evaluator", "inproc", "--out", "d"],
        dir.path(),
    );
    refused(
        &out,
        "internal error (a defect; please report it): SEPVAL_INJECT_PANIC=claimed",
    );
    assert!(!dir.path().join("d").exists(), "the run directory stays");
    let out = with_panic_at("worker", "sepval-worker", &["--run", "x"], dir.path());
    refused(
        &out,
        "sepval-worker: internal error (a defect; please report it): SEPVAL_INJECT_PANIC=worker",
    );
}

/// A closed ellipsoid (semi-axes 5, 6 and 0.3 m, centre 1.2 m above the store's CG) of
/// 2 n (n - 1) triangles as a binary STL: a wing-like aircraft far above the store.
fn ellipsoid_stl(path: &Path, n: usize) {
    let point = |i: usize, j: usize| -> [f32; 3] {
        if i == 0 || i == n {
            return [0.0, 0.0, if i == 0 { -0.9 } else { -1.5 }];
        }
        let th = std::f64::consts::PI * i as f64 / n as f64;
        let ph = std::f64::consts::TAU * j as f64 / n as f64;
        [
            (5.0 * th.sin() * ph.cos()) as f32,
            (6.0 * th.sin() * ph.sin()) as f32,
            (-1.2 + 0.3 * th.cos()) as f32,
        ]
    };
    let mut tris = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let j2 = (j + 1) % n;
            let (a, b, c, d) = (point(i, j), point(i, j2), point(i + 1, j), point(i + 1, j2));
            if i > 0 {
                tris.push([a, c, b]);
            }
            if i < n - 1 {
                tris.push([b, c, d]);
            }
        }
    }
    let mut bytes = vec![0u8; 80];
    bytes.extend((tris.len() as u32).to_le_bytes());
    for t in &tris {
        bytes.extend([0u8; 12]);
        for v in t.iter().flatten() {
            bytes.extend(v.to_le_bytes());
        }
        bytes.extend([0u8; 2]);
    }
    std::fs::write(path, bytes).unwrap();
}

/// Bytes process `pid` has read so far (`rchar` of /proc/PID/io).
fn bytes_read(pid: u32) -> u64 {
    std::fs::read_to_string(format!("/proc/{pid}/io"))
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("rchar: "))
                .and_then(|v| v.trim().parse().ok())
        })
        .unwrap_or(0)
}

/// Starts `sepval` with `args` in `dir`, sends SIGTERM once it has read `mesh` (its bytes read
/// reach the file's size), and returns its output: it must exit within 5 s.
fn interrupted_while_reading(dir: &Path, mesh: &Path, args: &[&str]) -> Output {
    let size = std::fs::metadata(mesh).unwrap().len();
    let mut child = spawn_sepval(args, dir);
    let pid = child.id();
    wait_for("sepval to read the mesh", Duration::from_secs(60), || {
        bytes_read(pid) >= size || child.try_wait().unwrap().is_some()
    });
    signal(pid as i32, libc::SIGTERM);
    wait_exit(&mut child, "sepval after SIGTERM", Duration::from_secs(5))
}

#[test]
fn sigterm_while_a_million_triangle_aircraft_is_read_stops_at_once_and_writes_nothing() {
    let p = fixture();
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("wing.stl");
    ellipsoid_stl(&mesh, 708);
    let mesh_arg = mesh.display().to_string();
    let out = interrupted_while_reading(
        dir.path(),
        &mesh,
        &["simulate", "--aircraft", &mesh_arg, "--out", "o.csv"],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["wing.stl"], "simulate left files behind");

    let out = interrupted_while_reading(
        p,
        &mesh,
        &[
            "predict",
            "--from",
            "fit",
            "--scenario",
            "cond.toml",
            "--aircraft",
            &mesh_arg,
            "--samples",
            "400",
            "--evaluator",
            "inproc",
            "--out",
            "pred-sigterm",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(!p.join("pred-sigterm").exists(), "predict left its --out");
}
