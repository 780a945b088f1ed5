//! One trace of 200 poses of the default store falling away from the example aircraft (a drop
//! of 2 m with pitch and yaw growing, about what docs/eglin-cfd.md's run does in 0.5 s).
//! `cargo bench -p sepval-geometry --bench clearance`; divide the time by 200 for a pose.

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use sepval_geometry::{Body, Geometry, Pose, Role};

fn trace_of_200_poses(c: &mut Criterion) {
    let aircraft_path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/geometry/aircraft.toml");
    let aircraft = Body::read(&aircraft_path, Role::Aircraft).expect("the example aircraft");
    let store = Body::default_store(0.508).expect("the default store");
    let geometry = Geometry::new(store, aircraft).expect("the example pair");
    let t_s: Vec<f64> = (0..200).map(|k| 0.0025 * k as f64).collect();
    let poses: Vec<Pose> = t_s
        .iter()
        .map(|&t| {
            let s = t / 0.5;
            Pose {
                position_m: [-0.7 * s * s, -0.07 * s, 2.3 * s * s],
                euler_deg: [-9.0 * s, 6.0 * (3.0 * s).sin(), -14.0 * s],
            }
        })
        .collect();
    c.bench_function("trace of 200 poses, default store, example aircraft", |b| {
        b.iter(|| {
            geometry
                .trace(
                    std::hint::black_box(&t_s),
                    std::hint::black_box(&poses),
                    0.1,
                )
                .expect("a finite trace")
        })
    });
}

criterion_group!(benches, trace_of_200_poses);
criterion_main!(benches);
