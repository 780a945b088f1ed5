//! One wire protocol: every transport returns what the in-process evaluator returns, bit for
//! bit, for finished, diverged and failed runs alike (failure reasons included), runs in a gust
//! among them (wind terms travel), with and without samples, through real worker processes.

use std::sync::Arc;
use std::time::Duration;

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{Candidate, Evaluation, Job, Outcome};
use sepval_common::extension::{Axis, Regressor, Term, TermSet};
use sepval_common::scenario::Scenario;
use sepval_common::synthetic::default_flight_test;
use sepval_core::factors::Factors;
use sepval_tests::binary;
use sepval_transport::RunId;
use sepval_transport::dispatch::DispatchOptions;
use sepval_transport::ipc::{IpcOptions, Launch};
use sepval_transport::link::quiet;
use sepval_transport::spec::EvaluatorSpec;

/// The truth in a gust: the air's velocity along `axis` \[m/s\] (docs/discovery.md).
fn gusty(axis: Axis, regressor: Regressor, locator: [f64; 2], w_m_s: f64) -> Candidate {
    let term = Term {
        axis,
        regressor,
        locator,
        coefficient: w_m_s,
    };
    Candidate {
        factors: Factors::TRUTH,
        effects: EffectSet::NONE,
        terms: TermSet::of(&[term]).unwrap(),
        corrections: sepval_common::correction::CorrectionValues::NONE,
    }
}

fn candidates() -> Vec<Candidate> {
    let with = |spec: &str| {
        let mut e = EffectSet::NONE;
        e.push_spec(spec).unwrap();
        e
    };
    let mut out_of_bounds = Factors::TRUTH;
    out_of_bounds.0[2] = 5.0;
    let mut not_finite = Factors::TRUTH;
    not_finite.0[7] = f64::NAN;
    let mut batch = vec![
        Candidate::baseline(Factors::TRUTH),
        Candidate::baseline(Factors::NOMINAL),
        Candidate::baseline(out_of_bounds),
        Candidate::baseline(not_finite),
        Candidate::with_effects(Factors::TRUTH, with("inertia_product_xz=1000")),
        Candidate::with_effects(Factors::TRUTH, with("release_rates=60,60,60")),
        Candidate::with_effects(Factors::NOMINAL, with("telemetry_time_offset=0.01")),
        gusty(Axis::WindY, Regressor::WindStep, [0.2, 0.1], 3.0),
        gusty(Axis::WindZ, Regressor::WindPulse, [0.1, 0.15], -4.0),
    ];
    // Enough for several chunks per worker.
    for k in 0..40 {
        let mut f = Factors::TRUTH;
        f.0[0] = 0.2 + 0.02 * k as f64;
        batch.push(Candidate::baseline(f));
    }
    batch
}

fn dispatch() -> DispatchOptions {
    DispatchOptions {
        min_workers: 2,
        join_timeout: Duration::from_secs(60),
        chunk_deadline: Duration::from_secs(60),
    }
}

fn check(spec: EvaluatorSpec, job: &Arc<Job>, reference: &[(bool, Vec<Evaluation>)]) {
    let mut evaluator = spec.start(Arc::clone(job), quiet()).unwrap();
    for (with_samples, expected) in reference {
        let got = evaluator.evaluate(&candidates(), *with_samples).unwrap();
        assert_eq!(&got, expected, "{}", evaluator.describe());
    }
}

#[test]
fn every_transport_returns_the_in_process_outcomes_bit_for_bit() {
    let job = Arc::new(Job::single(
        "default",
        &Scenario::embedded_default(),
        default_flight_test(),
    ));
    let mut inproc = EvaluatorSpec::InProcess { threads: 1 }
        .start(Arc::clone(&job), quiet())
        .unwrap();
    let reference: Vec<(bool, Vec<Evaluation>)> = [false, true]
        .into_iter()
        .map(|s| (s, inproc.evaluate(&candidates(), s).unwrap()))
        .collect();
    // The batch exercises every kind of outcome, and gusts that simulate.
    let outcomes = &reference[0].1;
    assert!(matches!(outcomes[0].outcome, Outcome::Goals { .. }));
    for k in [7, 8] {
        assert!(
            matches!(outcomes[k].outcome, Outcome::Goals { .. }) && outcomes[k] != outcomes[0],
            "{k}: {:?}",
            outcomes[k].outcome
        );
    }
    for k in [2, 3, 4] {
        assert!(
            matches!(outcomes[k].outcome, Outcome::Failed { .. }),
            "{k}: {:?}",
            outcomes[k].outcome
        );
    }
    assert!(
        matches!(outcomes[5].outcome, Outcome::Diverged { .. }),
        "{:?}",
        outcomes[5].outcome
    );
    let worker = binary("sepval-worker");
    check(
        EvaluatorSpec::Ipc {
            link: IpcOptions {
                run_id: RunId::new(&sepval_tests::run_id("outcomes")).unwrap(),
                workers: 2,
                launch: Launch::Spawn {
                    executable: worker.clone(),
                },
                max_respawns: 0,
                join_timeout: Duration::from_secs(60),
                announce_protocol: None,
            },
            dispatch: dispatch(),
        },
        &job,
        &reference,
    );
    check(
        EvaluatorSpec::Uds {
            workers: 2,
            executable: worker.clone(),
            dispatch: dispatch(),
        },
        &job,
        &reference,
    );
    #[cfg(feature = "zenoh")]
    {
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let endpoint = format!("tcp/127.0.0.1:{port}");
        let run = RunId::new(&sepval_tests::run_id("outcomes-z")).unwrap();
        let mut workers: Vec<_> = (0..2)
            .map(|_| {
                std::process::Command::new(&worker)
                    .args(["--connect", &endpoint, "--run", run.as_str()])
                    .stderr(std::process::Stdio::null())
                    .spawn()
                    .unwrap()
            })
            .collect();
        check(
            EvaluatorSpec::Zenoh {
                link: sepval_transport::zenoh::ZenohOptions {
                    run_id: run,
                    listen: endpoint,
                    workers: 2,
                    join_timeout: Duration::from_secs(60),
                    zenoh_config: None,
                    announce_protocol: None,
                },
                dispatch: dispatch(),
            },
            &job,
            &reference,
        );
        for w in &mut workers {
            sepval_tests::wait_exit(w, "a zenoh worker", Duration::from_secs(10));
        }
    }
}
