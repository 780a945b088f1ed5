//! The unit tests of `sepval_common::model::flowfield`.

#![allow(clippy::float_cmp)]

use sepval_common::model::flowfield::*;
use sepval_common::model::tables::AeroAtMach;
use sepval_common::scenario::{FlowfieldSpec, MachScaling};
use sepval_common::table::{FieldAngle, FieldRatio};
use sepval_core::factors::Factors;

fn spec() -> FlowfieldSpec {
    FlowfieldSpec {
        stations: 5,
        nose_x_m: 1.5,
        tail_x_m: -1.5,
        upwash_deg: FieldAngle::constant(3.0),
        upwash_per_alpha: 0.5,
        upwash_gradient_deg_per_m: 0.0,
        sidewash_deg: FieldAngle::constant(-1.5),
        sidewash_per_alpha: 0.0,
        sidewash_gradient_deg_per_m: 0.0,
        dynamic_pressure_ratio: FieldRatio::constant(1.0),
        roll_cl: FieldRatio::constant(0.0),
        half_depth_m: Some(0.8),
        reversal_m: Some(2.0),
        reference_mach: 0.85,
        reference_alpha_deg: 2.0,
        mach_scaling: MachScaling::PrandtlGlauert,
        shape: None,
        zero_lift_alpha_deg: None,
    }
}

fn aero() -> AeroAtMach {
    AeroAtMach {
        ca0: 1.1,
        cz_alpha_per_rad: -6.0,
        cy_beta_per_rad: -6.0,
        cm_alpha_per_rad: 0.3,
        cn_beta_per_rad: -0.3,
        cl_p_per_rad: -40.0,
        cm_q_per_rad: -80.0,
        cn_r_per_rad: -80.0,
    }
}

#[test]
fn weights_sum_to_one_and_put_the_force_at_the_centre_of_pressure() {
    let run = FlowfieldRun::new(&spec(), None, &aero(), 0.508, 0.95, 0.0, &Factors::NOMINAL);
    for (plane, x_cp) in [(0, -0.508 * 0.3 / -6.0), (1, 0.508 * -0.3 / -6.0)] {
        let w = &run.weights[plane][..run.stations];
        let sum: f64 = w.iter().sum();
        let moment: f64 = w.iter().zip(&run.station_x_m).map(|(w, x)| w * x).sum();
        assert!((sum - 1.0).abs() < 1e-15, "plane {plane}: sum {sum}");
        assert!(
            (moment - x_cp).abs() < 1e-15,
            "plane {plane}: {moment} vs {x_cp}"
        );
    }
}

#[test]
fn the_field_scales_with_lift_and_mach_and_changes_sign_at_the_reversal() {
    let run = FlowfieldRun::new(&spec(), None, &aero(), 0.508, 0.95, 0.0, &Factors::NOMINAL);
    let s_m = (1.0 / 0.1f64.sqrt()) / (1.0 / (1.0 - 0.85f64 * 0.85).sqrt());
    let a = s_m * (3.0f64 + 0.5 * (0.0 - 2.0)).to_radians();
    assert!((run.upwash[0] - a).abs() < 1e-15);
    assert!(run.at([0.0, 0.0, 1.0])[0] > 0.0);
    assert!(run.at([0.0, 0.0, 2.0])[0].abs() < 1e-18);
    assert!(run.at([0.0, 0.0, 3.0])[0] < 0.0);
    // Above carriage the field is that of carriage.
    assert_eq!(run.at([0.0, 0.0, -0.5]), run.at([0.0, 0.0, 0.0]));
}

#[test]
fn a_shape_table_is_linear_between_its_depths_and_held_below_the_last() {
    let t = ShapeRun::new(&[0.0, 0.5, 1.5, 3.0], &[1.0, 0.5, -0.25, 0.0]);
    assert_eq!(t.at(0.0), 1.0);
    assert_eq!(t.at(0.5), 0.5);
    assert_eq!(t.at(0.25), 0.75);
    assert_eq!(t.at(1.0), 0.125);
    assert_eq!(t.at(1.5), -0.25);
    assert_eq!(t.at(2.25), -0.125);
    assert_eq!(t.at(3.0), 0.0);
    assert_eq!(t.at(40.0), 0.0);
    assert!(t.at(f64::NAN).is_nan());
    // interference_decay's k scales the depths: g(z / k).
    let mut k2 = t;
    k2.scale_depth(2.0);
    assert_eq!(k2.at(2.0), t.at(1.0));
}

#[test]
fn a_field_whose_shape_is_a_table_of_its_analytic_shape_has_its_loads() {
    // The analytic g of spec() tabulated at 32 depths to 4 m (closer near carriage, where it
    // bends most): the field agrees to the linear interpolation's error, under 1 %.
    let analytic = spec();
    let g = |z: f64| (1.0 - z / 2.0) / (1.0 + z / 0.8);
    let depth_m: Vec<f64> = (0..32).map(|k| 4.0 * (k as f64 / 31.0).powi(2)).collect();
    let mut tabulated = analytic.clone();
    tabulated.half_depth_m = None;
    tabulated.reversal_m = None;
    tabulated.shape = Some(sepval_common::scenario::ShapeTable {
        g: depth_m.iter().map(|&z| g(z)).collect(),
        depth_m,
    });
    let factors = Factors::NOMINAL;
    let run = |s: &FlowfieldSpec| FlowfieldRun::new(s, None, &aero(), 0.5, 0.9, 3.0, &factors);
    let (a, t) = (run(&analytic), run(&tabulated));
    for z in [-0.1, 0.0, 0.05, 0.3, 0.9, 1.7, 2.6] {
        let (fa, ft) = (a.at([0.2, 0.0, z]), t.at([0.2, 0.0, z]));
        for j in 0..3 {
            assert!(
                (fa[j] - ft[j]).abs() < 1e-2 * fa[j].abs().max(1e-3),
                "at z {z}: {fa:?} {ft:?}"
            );
        }
    }
    assert_eq!(
        a.at([0.2, 0.0, 0.0]),
        t.at([0.2, 0.0, 0.0]),
        "at carriage, g = 1 exactly"
    );
}
