use super::*;

fn job() -> Job {
    crate::default_job()
}

#[test]
fn requests_and_responses_round_trip_and_bad_ones_are_refused() {
    let mut effects = EffectSet::NONE;
    effects.push_spec("release_rates=0.1,0.2,0.3").unwrap();
    let mut terms = TermSet::NONE;
    terms
        .push(Term {
            axis: Axis::Cn,
            regressor: Regressor::FBeta,
            locator: [0.6, 0.0],
            coefficient: -0.7,
        })
        .unwrap();
    // A gust: the wind axes and regressors, and both locators, travel.
    for (axis, regressor, locator, w_m_s) in [
        (Axis::WindY, Regressor::WindStep, [0.2, 0.08], 2.1),
        (Axis::WindZ, Regressor::WindPulse, [0.45, 0.2], -1.3),
    ] {
        terms
            .push(Term {
                axis,
                regressor,
                locator,
                coefficient: w_m_s,
            })
            .unwrap();
    }
    let c = Candidate {
        factors: Factors::TRUTH,
        effects,
        terms,
        corrections: sepval_common::correction::CorrectionValues::of(&[0.25, -1.5, 3.0e-7])
            .unwrap(),
    };
    let w = WireRequest::new(5, &c);
    assert_eq!(w.candidate().unwrap(), c);
    // Non-finite factors travel as they are: the model refuses them, as it does in process.
    let mut nan = w;
    nan.factors[3] = f64::NAN;
    assert!(nan.candidate().unwrap().factors.0[3].is_nan());
    let mut bad = w;
    bad.effect_count = 9;
    assert_eq!(
        bad.candidate().unwrap_err().to_string(),
        "effect count 9 exceeds the maximum of 4"
    );
    let mut bad = w;
    bad.effect_index[0] = 99;
    assert_eq!(
        bad.candidate().unwrap_err().to_string(),
        "effect index 99 is not in the catalogue"
    );
    let mut bad = w;
    bad.terms[0].regressor = 999;
    assert_eq!(
        bad.candidate().unwrap_err().to_string(),
        "extension term 0: regressor index 999 is not a regressor"
    );
    let mut bad = w;
    bad.terms[0].axis = 6; // ejector: a flow-angle regressor cannot act on it
    assert!(
        bad.candidate()
            .unwrap_err()
            .to_string()
            .contains("cannot act on axis ejector")
    );
    let mut bad = w;
    bad.terms[1].axis = 1; // CY: a wind shape acts on the wind axes only
    assert_eq!(
        bad.candidate().unwrap_err().to_string(),
        "extension term 1: the wind regressor `step` cannot act on axis CY"
    );
    let mut bad = w;
    bad.terms[2].locator[1] = 0.0;
    assert_eq!(
        bad.candidate().unwrap_err().to_string(),
        "extension term 2: rise_s = 0: expected a length in [0.001, 7200] s"
    );
    let mut bad = w;
    bad.terms[0].axis = 9;
    assert_eq!(
        bad.candidate().unwrap_err().to_string(),
        "extension term 0: axis index 9 is not an axis"
    );
    let mut bad = w;
    bad.effect_params[0][1] = f64::INFINITY;
    assert!(
        bad.candidate()
            .unwrap_err()
            .to_string()
            .contains("not a finite number")
    );

    for o in [
        Outcome::Goals {
            j_pos_m: 0.1,
            j_att_deg: 2.0,
        },
        Outcome::Diverged { t_s: 0.5, event: 1 },
        Outcome::failed("é".repeat(200)),
    ] {
        assert_eq!(WireResponse::new(3, &o).outcome().unwrap(), o);
    }
    let mut r = WireResponse::new(0, &Outcome::Diverged { t_s: 0.0, event: 0 });
    r.status = 42;
    assert_eq!(
        r.outcome().unwrap_err().to_string(),
        "unknown response status 42"
    );
    let mut r = WireResponse::new(0, &Outcome::failed("x"));
    r.reason_len = 9999;
    assert!(r.outcome().is_err());
}

#[test]
fn a_served_chunk_is_the_local_evaluation_and_malformed_requests_fail() {
    let job = job();
    let mut far = Factors::TRUTH;
    far.0[0] = 7.0;
    let batch = [
        Candidate::baseline(Factors::TRUTH),
        Candidate::baseline(far),
        Candidate::baseline(Factors::NOMINAL),
    ];
    let mut chunk = Chunk::new(9, &[0, 1, 2], &batch, true);
    chunk.requests[2].effect_count = 77;
    let answer = serve_locally(&job, &chunk);
    let back = answer.clone().evaluations(&[0, 1, 2], &job).unwrap();
    assert_eq!(back[0].1, job.evaluate_with_samples(&batch[0]));
    assert_eq!(back[1].1.outcome, job.evaluate(&batch[1]).outcome);
    assert_eq!(
        back[2].1.outcome,
        Outcome::failed("malformed request: effect count 77 exceeds the maximum of 4")
    );
    assert!(answer.clone().evaluations(&[0, 1], &job).is_err());
    assert!(answer.evaluations(&[0, 2, 1], &job).is_err());
}
