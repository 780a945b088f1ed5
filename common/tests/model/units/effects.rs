//! The unit tests of `sepval_common::effects`.

use sepval_common::effects::*;

#[test]
fn catalogue_matches_model_md_section_7() {
    let ids: Vec<&str> = CATALOGUE.iter().map(|e| e.id()).collect();
    assert_eq!(
        ids,
        [
            "roll_due_to_sideslip",
            "pitch_stiffness_cubic",
            "cg_offset",
            "inertia_product_xz",
            "ejector_delay",
            "ejector_cant",
            "interference_decay",
            "release_rates",
            "telemetry_time_offset",
            "attitude_bias",
            "tracked_point_offset",
        ]
    );
    for e in CATALOGUE.iter() {
        assert!(e.params().len() <= MAX_EFFECT_PARAMS);
        for p in e.params() {
            assert!(p.min <= p.neutral && p.neutral <= p.max, "{}", e.id());
            assert!(p.scale > 0.0);
        }
    }
}

#[test]
fn spec_parsing_and_refusals() {
    let mut set = EffectSet::NONE;
    set.push_spec("release_rates=0.1, -0.2,0.3").unwrap();
    assert_eq!(set.values(), vec![0.1, -0.2, 0.3]);
    assert_eq!(
        set.push_spec("release_rates=0,0,0")
            .unwrap_err()
            .to_string(),
        "effect `release_rates` is given twice"
    );
    assert_eq!(
        EffectSet::default()
            .push_spec("cg_offset=0.1,0.2")
            .unwrap_err()
            .to_string(),
        "effect `cg_offset` takes 1 parameter(s) (dx_cg [m]), 2 given"
    );
    assert_eq!(
        EffectSet::default()
            .push_spec("nope=1")
            .unwrap_err()
            .to_string(),
        "unknown effect `nope` (run `sepval effects` for the catalogue)"
    );
    assert_eq!(
        EffectSet::default()
            .push_spec("cg_offset")
            .unwrap_err()
            .to_string(),
        "effect specification `cg_offset`: expected ID=V1,V2,... (for example roll_due_to_sideslip=-0.3)"
    );
    for spec in ["=", "=1", " =0.3"] {
        assert_eq!(
            EffectSet::default()
                .push_spec(spec)
                .unwrap_err()
                .to_string(),
            format!(
                "effect specification `{spec}`: no effect ID before `=` (expected ID=V1,V2,..., for example roll_due_to_sideslip=-0.3)"
            )
        );
    }
    assert_eq!(
        EffectSet::default()
            .push_spec("cg_offset=abc")
            .unwrap_err()
            .to_string(),
        "effect specification `cg_offset=abc`: value 1 `abc` is not a number"
    );
    assert_eq!(
        EffectSet::default()
            .push_spec("cg_offset=inf")
            .unwrap_err()
            .to_string(),
        "effect `cg_offset`: parameter dx_cg = inf is not a finite number"
    );
}

#[test]
fn json_round_trip() {
    let mut set = EffectSet::NONE;
    set.push_spec("ejector_cant=0.05").unwrap();
    set.push_spec("attitude_bias=0.01,0,-0.02").unwrap();
    let json = serde_json::to_string(&set).unwrap();
    let back: EffectSet = serde_json::from_str(&json).unwrap();
    assert_eq!(back, set);
    assert_eq!(back.with_values(&set.values()).unwrap(), set);
}
