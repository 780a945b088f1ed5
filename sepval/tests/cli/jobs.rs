//! Commands that evaluate several jobs one after another (an envelope's conditions, an update's
//! rounds) refuse iceoryx2 workers attached by hand, which serve one job and leave with it
//! (issue 33, item 14: the second job waited for workers that never came back), before
//! anything is read or written. Over zenoh the workers serve every job: `tests/tests/e2e`.

use sepval_tests::{refused, sepval};

#[test]
fn attached_workers_are_refused_where_a_command_runs_several_jobs() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    for (args, jobs) in [
        (
            vec!["envelope", "--from", "fit", "--mach", "0.7:0.9:2"],
            "`envelope` runs one per condition",
        ),
        (
            vec!["update", "--data", "a.csv"],
            "`update` runs one per round",
        ),
    ] {
        let mut all = args.clone();
        all.extend(["--evaluator", "ipc", "--attach", "run-a", "--out", "out"]);
        let stderr = refused(&sepval(&all, p), jobs);
        assert!(
            stderr.contains("--attach run-a: workers attached by hand serve one job of a run"),
            "{stderr}"
        );
        assert!(stderr.contains("use --evaluator zenoh"), "{stderr}");
        assert!(!p.join("out").exists());
    }
}
