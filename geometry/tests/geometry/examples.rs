//! The example files and the default store.

use sepval_geometry::{Body, Geometry, Pose, Role};

use crate::fixtures::{example, pose};

/// The documented gap between the pylon and the store's top at carriage (docs/geometry.md).
const CARRIAGE_GAP_M: f64 = 0.020;

fn example_pair() -> Geometry {
    let store = Body::read(&example("store.toml"), Role::Store).unwrap();
    let aircraft = Body::read(&example("aircraft.toml"), Role::Aircraft).unwrap();
    Geometry::new(store, aircraft).unwrap()
}

#[test]
fn the_example_pair_has_the_documented_gap_at_carriage() {
    let g = example_pair();
    let c = g.clearance(&Pose::CARRIAGE);
    assert!((c.distance_m - CARRIAGE_GAP_M).abs() < 1e-6, "{c:?}");
    assert_eq!(
        (g.store_part(c.store_part), g.aircraft_part(c.aircraft_part)),
        ("body", "pylon")
    );
    // The pylon's lower face against the cylinder's top line.
    assert!(
        (c.store_point_m[2] + 0.254).abs() < 1e-6 && (c.aircraft_point_m[2] + 0.274).abs() < 1e-6,
        "{c:?}"
    );
}

#[test]
fn the_default_store_behaves_as_the_example_store_file() {
    let file = Body::read(&example("store.toml"), Role::Store).unwrap();
    let default = Body::default_store(0.508).unwrap();
    assert_eq!(file.part_names(), default.part_names());
    let aircraft = Body::read(&example("aircraft.toml"), Role::Aircraft).unwrap();
    let a = Geometry::new(file, aircraft.clone()).unwrap();
    let b = Geometry::new(default, aircraft).unwrap();
    for k in 0..50 {
        let s = k as f64 / 49.0;
        let p = pose(
            [-0.5 * s, 0.1 * s, 2.0 * s],
            [-10.0 * s, 15.0 * s - 5.0, -20.0 * s],
        );
        assert_eq!(a.clearance(&p), b.clearance(&p), "at {p:?}");
    }
}

#[test]
fn the_default_store_scales_with_its_diameter() {
    let aircraft = Body::read(&example("aircraft.toml"), Role::Aircraft).unwrap();
    // Half the size: the top of the body drops from 0.254 to 0.127 m above the CG.
    let g = Geometry::new(Body::default_store(0.254).unwrap(), aircraft).unwrap();
    let c = g.clearance(&Pose::CARRIAGE);
    assert!(
        (c.distance_m - (CARRIAGE_GAP_M + 0.127)).abs() < 1e-6,
        "{c:?}"
    );
}

#[test]
fn a_trace_takes_its_minimum_after_the_stroke() {
    let g = example_pair();
    // Straight down 0.05 m a sample: 0.02, 0.07, 0.12 ... m from the pylon.
    let t_s: Vec<f64> = (0..5).map(|k| 0.1 * k as f64).collect();
    let poses: Vec<Pose> = (0..5)
        .map(|k| pose([0.0, 0.0, k as f64 * 0.05], [0.0; 3]))
        .collect();
    let trace = g.trace(&t_s, &poses, 0.1).unwrap();
    assert_eq!(trace.assessed_from, 2);
    assert!(trace.free_flight_reached);
    assert_eq!(trace.index_min, 2);
    assert!((trace.t_min_s - 0.2).abs() < 1e-12);
    assert!(
        (trace.min.distance_m - (CARRIAGE_GAP_M + 0.1)).abs() < 1e-6,
        "{trace:?}"
    );
    assert!((trace.distance_m[0] - CARRIAGE_GAP_M).abs() < 1e-6);
    // Never reaching the stroke: every sample is assessed, the minimum is at carriage.
    let all = g.trace(&t_s, &poses, 10.0).unwrap();
    assert_eq!(
        (all.assessed_from, all.index_min, all.free_flight_reached),
        (0, 0, false)
    );
    // A diverged sample is an error naming it; clearance() alone gives NaN.
    let mut bad = poses.clone();
    bad[3].euler_deg[1] = f64::NAN;
    let e = g.trace(&t_s, &bad, 0.1).unwrap_err();
    assert!(
        e.to_string()
            .contains("sample 3 (t = 0.30000000000000004 s)"),
        "{e}"
    );
    assert!(g.clearance(&bad[3]).distance_m.is_nan());
}

#[test]
fn the_smallest_clearance_is_the_traces_minimum_bit_for_bit() {
    let g = example_pair();
    // Trajectories (u from 0 to 1 over the record) that fall away, come back up to the pylon,
    // bob under it while pitching, and tumble: the minimum at the stroke's end, at the end and
    // in between.
    type Path = fn(f64) -> ([f64; 3], [f64; 3]);
    let paths: [Path; 4] = [
        |u| {
            (
                [-3.0 * u * u, 0.0, 6.0 * u * u + 0.12 * u],
                [0.0, 10.0 * u, 0.0],
            )
        },
        |u| {
            (
                [0.0, 0.0, 0.6 * (std::f64::consts::PI * u).sin() + 0.03 * u],
                [0.0; 3],
            )
        },
        |u| {
            let w = 2.0 * std::f64::consts::PI * u;
            (
                [0.1 * u, 0.0, 0.25 + 0.13 * (2.0 * w).cos()],
                [0.0, 20.0 * w.sin(), 0.0],
            )
        },
        |u| ([-u, 0.5 * u, 1.5 * u], [360.0 * u, 90.0 * u, -45.0 * u]),
    ];
    let mut late = 0;
    for (k, path) in paths.into_iter().enumerate() {
        let n = 201;
        let t_s: Vec<f64> = (0..n).map(|i| 0.005 * i as f64).collect();
        let poses: Vec<Pose> = t_s
            .iter()
            .map(|&t| {
                let (r, a) = path(t / t_s[n - 1]);
                pose(r, a)
            })
            .collect();
        let trace = g.trace(&t_s, &poses, 0.1).unwrap();
        let s = g.smallest(&t_s, &poses, 0.1).unwrap();
        assert_eq!(s.min, trace.min, "case {k}");
        assert_eq!(
            (s.index_min, s.assessed_from, s.free_flight_reached),
            (
                trace.index_min,
                trace.assessed_from,
                trace.free_flight_reached
            ),
            "case {k}"
        );
        assert_eq!(s.t_min_s.to_bits(), trace.t_min_s.to_bits(), "case {k}");
        late += usize::from(s.index_min > s.assessed_from + 1);
    }
    assert!(
        late >= 2,
        "cases whose minimum is not at the stroke's end: {late}"
    );
}
