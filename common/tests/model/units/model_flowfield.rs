//! The unit tests of `sepval_common::model::flowfield`.

#![allow(clippy::float_cmp)]

use sepval_common::model::flowfield::*;
use sepval_common::model::tables::AeroAtMach;
use sepval_common::scenario::{FlowfieldSpec, MachScaling};
use sepval_core::factors::Factors;

fn spec() -> FlowfieldSpec {
    FlowfieldSpec {
        stations: 5,
        nose_x_m: 1.5,
        tail_x_m: -1.5,
        upwash_deg: 3.0,
        upwash_per_alpha: 0.5,
        upwash_gradient_deg_per_m: 0.0,
        sidewash_deg: -1.5,
        sidewash_per_alpha: 0.0,
        sidewash_gradient_deg_per_m: 0.0,
        dynamic_pressure_ratio: 1.0,
        roll_cl: 0.0,
        half_depth_m: 0.8,
        reversal_m: Some(2.0),
        reference_mach: 0.85,
        reference_alpha_deg: 2.0,
        mach_scaling: MachScaling::PrandtlGlauert,
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
    let run = FlowfieldRun::new(&spec(), &aero(), 0.508, 0.95, 0.0, &Factors::NOMINAL);
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
    let run = FlowfieldRun::new(&spec(), &aero(), 0.508, 0.95, 0.0, &Factors::NOMINAL);
    let s_m = (1.0 / 0.1f64.sqrt()) / (1.0 / (1.0 - 0.85f64 * 0.85).sqrt());
    let a = s_m * (3.0f64 + 0.5 * (0.0 - 2.0)).to_radians();
    assert!((run.upwash[0] - a).abs() < 1e-15);
    assert!(run.at([0.0, 0.0, 1.0])[0] > 0.0);
    assert!(run.at([0.0, 0.0, 2.0])[0].abs() < 1e-18);
    assert!(run.at([0.0, 0.0, 3.0])[0] < 0.0);
    // Above carriage the field is that of carriage.
    assert_eq!(run.at([0.0, 0.0, -0.5]), run.at([0.0, 0.0, 0.0]));
}
