//! The estimate against published measurements of standard configurations (docs/aero.md,
//! "Conformance"), each within the method's stated accuracy ([`sepval_aero::ACCURACY`]), and
//! the limits slender-body theory gives by hand. Run with `cargo test --release -p
//! sepval-aero`.

use std::path::Path;

use sepval_aero::{ACCURACY, Estimate, Request, estimate, fins};
use sepval_geometry::StoreShape;

fn shape(name: &str) -> StoreShape {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    StoreShape::read(&p).unwrap()
}

fn at(name: &str, mach: f64) -> Estimate {
    estimate(&Request {
        shape: shape(name),
        mach: vec![mach, mach + 1e-6],
        alpha_deg: vec![-10.0, 0.0, 10.0],
        altitude_m: 0.0,
    })
    .unwrap()
}

/// `got` within `fraction` of `published`, said in the failure.
fn within(what: &str, got: f64, published: f64, fraction: f64) {
    let err = got / published - 1.0;
    assert!(
        err.abs() <= fraction,
        "{what}: estimate {got:.3}, published {published:.3}: {:+.1} %, stated accuracy {:.0} %",
        100.0 * err,
        100.0 * fraction
    );
}

/// Basic Finner, Dupuis and Hathaway, DREV-TM-9703 (1997) Table VII (range, linear-theory
/// reduction, d = 30 mm, CG 5.5 calibres): (Mach, CN_alpha, Cm_alpha) per rad about the CG.
const ANF_TABLE_VII: [(f64, f64, f64); 3] = [
    (1.057, 18.390, -52.022),
    (1.254, 18.522, -51.982),
    (1.380, 15.371, -42.073),
];

#[test]
fn basic_finner_normal_force_and_centre_of_pressure() {
    for (mach, cn_published, cm_published) in ANF_TABLE_VII {
        let p = &at("basic-finner.toml", mach).points[0];
        let accuracy = match p.regime {
            fins::Regime::Bridge => ACCURACY.cn_alpha_bridge,
            _ => ACCURACY.cn_alpha,
        };
        within(
            &format!("ANF CN_alpha at Mach {mach}"),
            p.cn_alpha_per_rad.value,
            cn_published,
            accuracy,
        );
        // x_cp = x_cg - Cm_alpha / CN_alpha d, compared as a fraction of the length (0.30 m).
        let x_published_m = 0.165 - cm_published / cn_published * 0.03;
        let off = (p.x_cp_m.value - x_published_m) / 0.30;
        assert!(
            off.abs() <= ACCURACY.x_cp_of_length,
            "ANF x_cp at Mach {mach}: {:.4} m against {x_published_m:.4} m, {:+.1} % of the length",
            p.x_cp_m.value,
            100.0 * off
        );
    }
}

#[test]
fn basic_finner_pitch_damping() {
    // DREV-TM-9703 Table IX (six-degree-of-freedom multi-fit): Cm_q + Cm_alphadot = -487.4
    // (+-6 %) at Mach 1.293; the range cannot separate the two, and the fins' lag term is
    // absent for a tail with nothing ahead of it, so the sum is compared with Cm_q.
    let p = &at("basic-finner.toml", 1.293).points[0];
    within(
        "ANF Cm_q at Mach 1.293",
        p.cm_q_per_rad.value,
        -487.4,
        ACCURACY.damping,
    );
}

#[test]
fn basic_finner_roll_damping() {
    // Barrowman 1967, Fig. 5-7: wind-tunnel Cl_p = -33.6 at Mach 1.51 (J. D. Nicolaides,
    // BuWeps TN-100A, 1959; read from the figure to +-0.3).
    let p = &at("basic-finner.toml", 1.51).points[0];
    within(
        "ANF Cl_p at Mach 1.51",
        p.cl_p_per_rad.value,
        -33.6,
        ACCURACY.roll_damping,
    );
}

#[test]
fn arcas_fins_on_the_boattail_are_outside_and_said_to_be() {
    // NASA TN D-4013 (Ferris 1967), the long model, fins at 0 deg: CN_alpha the secant
    // through the points at about -3.7, 0 and +4 deg of Fig. 9(b), per rad on the body's
    // cross-section; the centre of pressure from Fig. 12, percent of the length (+-0.3). The
    // fins' roots run 1.5 in onto the 15 deg boattail, where the interference factors (a panel
    // on a cylinder) do not hold: the estimate misses by more than the stated accuracy, the
    // summary says so, and docs/aero.md gives these misses, which this test holds to 1 % so
    // that a change to them is seen. Not a conformance claim.
    for (mach, cn_published, cp_percent, cn_miss, cp_miss) in [
        (0.6, 11.14, 76.8, 0.103, 0.042),
        (0.8, 10.62, 75.6, 0.192, 0.059),
    ] {
        let e = at("arcas-long.toml", mach);
        assert!(e.config.fins_on_boattail);
        assert!(sepval_aero::output::summary(&e).contains("onto the boattail"));
        let p = &e.points[0];
        let cn_err = p.cn_alpha_per_rad.value / cn_published - 1.0;
        let cp_err = p.x_cp_m.value / e.config.length_m - cp_percent / 100.0;
        assert!(
            cn_err > ACCURACY.cn_alpha && (cn_err - cn_miss).abs() < 0.01,
            "{cn_err}"
        );
        assert!(
            cp_err > ACCURACY.x_cp_of_length && (cp_err - cp_miss).abs() < 0.01,
            "{cp_err}"
        );
    }
}

/// `got` within two of its stated sigmas of `truth`, said in the failure.
fn within_two_sigma(what: &str, got: sepval_aero::Estimated, truth: f64) {
    let z = (got.value - truth) / got.sigma;
    assert!(
        z.abs() <= 2.0,
        "{what}: estimate {:.3} +- {:.3}, truth {truth:.3}: {z:+.2} sigma",
        got.value,
        got.sigma
    );
}

#[test]
fn in_the_domain_the_bands_are_the_flat_fractions() {
    // The Basic Finner: no boattail, fins on the cylinder. Its bands are the in-domain
    // fractions exactly (no out-of-domain term adds to them) away from the drag rise.
    for mach in [0.6, 1.3, 1.5] {
        let p = &at("basic-finner.toml", mach).points[0];
        let frac = match p.regime {
            fins::Regime::Bridge => ACCURACY.cn_alpha_bridge,
            _ => ACCURACY.cn_alpha,
        };
        let cn = p.cn_alpha_per_rad;
        assert!((cn.sigma - frac * cn.value.abs()).abs() < 1e-12, "{mach}");
        assert!((p.x_cp_m.sigma - ACCURACY.x_cp_of_length * 0.30).abs() < 1e-12);
    }
}

#[test]
fn outside_the_domain_the_bands_hold_the_published_values() {
    // The Arcas misses of the test above, within two of the widened sigmas (the boattail's
    // lift and the fins on it as the parts' own errors, docs/aero.md).
    for (mach, cn_published, cp_percent) in [(0.6, 11.14, 76.8), (0.8, 10.62, 75.6)] {
        let e = at("arcas-long.toml", mach);
        let p = &e.points[0];
        within_two_sigma("Arcas CN_alpha", p.cn_alpha_per_rad, cn_published);
        within_two_sigma(
            "Arcas x_cp",
            p.x_cp_m,
            cp_percent / 100.0 * e.config.length_m,
        );
    }
    // The Basic Finner's damping in the bridge: DREV-TM-9703 Table IX, -322.4 at Mach 1.077,
    // 87 % off the estimate but 1.55 of its sigmas (30 % of the estimate's -603.8).
    let p = &at("basic-finner.toml", 1.077).points[0];
    assert_eq!(p.regime, fins::Regime::Bridge);
    within_two_sigma("ANF Cm_q at Mach 1.077", p.cm_q_per_rad, -322.4);
}

#[test]
fn the_eglin_cfds_axial_force_and_stability_within_the_bands() {
    // docs/eglin-cfd.md, "The store's own loads": the CFD store's whole axial force 0.12 to
    // 0.13 at Mach 0.85 and 0.73 to 0.80 at Mach 0.95, and a statically stable store (at 2.2 to
    // 2.3 m below the pylon its centre of pressure 0.2 to 0.6 calibres behind the CG; the slopes
    // over time, Cm_alpha -7 to -12 per rad, hold the aircraft's flow: docs/aero.md, "Which of
    // the three") where the estimate is unstable: its band must hold the CFD's CA0 and leave
    // Cm_alpha's sign undetermined.
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/eglin-store/shape.toml");
    let e = estimate(&Request {
        shape: StoreShape::read(&p).unwrap(),
        mach: vec![0.85, 0.95],
        alpha_deg: vec![-10.0, 0.0, 10.0],
        altitude_m: sepval_aero::DEFAULT_ALTITUDE_M,
    })
    .unwrap();
    for (p, cfd) in e.points.iter().zip([[0.12, 0.13], [0.73, 0.80]]) {
        for ca in cfd {
            within_two_sigma(&format!("Eglin CA0 at Mach {}", p.mach), p.ca0, ca);
        }
        let cm = p.cm_alpha_per_rad;
        assert!(cm.value > 0.0 && cm.value < 2.0 * cm.sigma, "{cm:?}");
    }
}

#[test]
fn slender_body_limits_by_hand() {
    // Pitts, Nielsen and Kaattari: K_W(B) -> 1 without a body; K_W + K_B = (1 + tau)^2.
    let (k_wb, k_bw) = fins::interference(0.0);
    assert!((k_wb - 1.0).abs() < 1e-15 && k_bw.abs() < 1e-15);
    // At tau = 1/3 (the Basic Finner): K_W(B) = (2/pi)[(82/81)(atan(4/3)/2 + pi/4) -
    // (1/9)(8/3 + 2 atan(1/3))] / (4/9) = (2/pi)(1.26447 - 0.36780)(9/4) = 1.2844 by hand;
    // K_B(W) = 16/9 - 1.2844 = 0.4934.
    let (k_wb, k_bw) = fins::interference(1.0 / 3.0);
    assert!((k_wb - 1.2844).abs() < 1e-4, "{k_wb}");
    assert!((k_bw - 0.4934).abs() < 1e-4, "{k_bw}");
    // A finless cone-cylinder: CN_alpha = 2, the cone's x_cp at 2/3 of its length.
    let mut s = shape("basic-finner.toml");
    s.fins = None;
    let e = estimate(&Request {
        shape: s,
        mach: vec![0.5, 1.5],
        alpha_deg: vec![-5.0, 5.0],
        altitude_m: 0.0,
    })
    .unwrap();
    for p in &e.points {
        assert!((p.cn_alpha_per_rad.value - 2.0).abs() < 1e-9);
        assert!(
            (p.x_cp_m.value - 2.0 / 3.0 * 0.08508).abs() < 1e-6,
            "{}",
            p.x_cp_m.value
        );
    }
}
