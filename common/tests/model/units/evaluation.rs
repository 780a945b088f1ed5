//! The unit tests of `sepval_common::evaluation`.

use sepval_common::evaluation::*;
use std::sync::Arc;

use sepval_common::scenario::Scenario;
use sepval_common::synthetic::default_flight_test;
use sepval_core::factors::Factors;

#[test]
fn thread_count_does_not_change_any_bit() {
    let job = Arc::new(Job::single(
        "default",
        &Scenario::embedded_default(),
        default_flight_test(),
    ));
    let mut batch: Vec<Candidate> = (0..7)
        .map(|k| {
            let mut f = Factors::NOMINAL;
            f.0[0] = 0.2 + 0.1 * k as f64;
            Candidate::baseline(f)
        })
        .collect();
    let mut bad = Factors::NOMINAL;
    bad.0[2] = 5.0;
    batch.push(Candidate::baseline(bad));
    let one = InProcess::new(job.clone(), 1)
        .evaluate(&batch, false)
        .unwrap();
    let three = InProcess::new(job.clone(), 3)
        .evaluate(&batch, false)
        .unwrap();
    assert_eq!(one, three);
    match &one[7].outcome {
        Outcome::Failed { reason } => assert!(reason.contains("xinerfac"), "{reason}"),
        other => panic!("{other:?}"),
    }
    let with = InProcess::new(job, 2).evaluate(&batch[..2], true).unwrap();
    assert_eq!(with[0].outcome, one[0].outcome);
    assert_eq!(with[0].samples.as_ref().unwrap()[0].len(), 201);
}
