//! The iceoryx2 transport end to end: real coordinator and worker processes, each test with its
//! own run id, checked against the in-process evaluator bit for bit.

use std::path::Path;
use std::time::Duration;

use sepval_tests::*;

/// A small GA fit (the hill climber adds nothing here).
fn fit_args<'a>(out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec![
        "fit",
        "--method",
        "ga",
        "--generations",
        "8",
        "--population",
        "20",
        "--no-figures",
        "--out",
        out,
    ];
    a.extend_from_slice(extra);
    a
}

fn inproc_reference(dir: &Path, out: &str, extra: &[&str]) -> serde_json::Value {
    let mut extra = extra.to_vec();
    extra.extend(["--evaluator", "inproc"]);
    ok(&sepval(&fit_args(out, &extra), dir));
    deterministic_part(&dir.join(out).join("result.json"))
}

#[test]
fn three_workers_give_the_in_process_answer_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let run = run_id("three");
    let reference = inproc_reference(dir.path(), "inproc", &[]);
    ok(&sepval(
        &fit_args("ipc", &["--workers", "3", "--run-id", &run]),
        dir.path(),
    ));
    assert_eq!(
        deterministic_part(&dir.path().join("ipc/result.json")),
        reference
    );
    let one = run_id("one");
    ok(&sepval(
        &fit_args("ipc1", &["--workers", "1", "--run-id", &one]),
        dir.path(),
    ));
    assert_eq!(
        deterministic_part(&dir.path().join("ipc1/result.json")),
        reference
    );
    assert_run_gone(&run);
    assert_run_gone(&one);
}

/// Starts a longer fit and waits until generation `g` is checkpointed.
fn start_long_fit(dir: &Path, run: &str, extra: &[&str], g: usize) -> std::process::Child {
    let mut args = vec![
        "fit",
        "--method",
        "ga",
        "--generations",
        "30",
        "--population",
        "20",
        "--no-figures",
        "--out",
        "ipc",
        "--run-id",
        run,
    ];
    args.extend_from_slice(extra);
    let child = spawn_sepval(&args, dir);
    let ckpt = dir.join(format!("ipc/generations/gen-{g:04}.json"));
    wait_for(
        "the fit to reach its checkpoint",
        Duration::from_secs(60),
        || ckpt.exists(),
    );
    child
}

fn long_reference(dir: &Path) -> serde_json::Value {
    ok(&sepval(
        &[
            "fit",
            "--method",
            "ga",
            "--generations",
            "30",
            "--population",
            "20",
            "--no-figures",
            "--out",
            "ref",
            "--evaluator",
            "inproc",
        ],
        dir,
    ));
    deterministic_part(&dir.join("ref/result.json"))
}

#[test]
fn sigkill_of_a_worker_mid_run_loses_and_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let run = run_id("kill");
    let reference = long_reference(dir.path());
    let mut fit = start_long_fit(dir.path(), &run, &["--workers", "2"], 3);
    let workers = workers_of_run(&run);
    assert_eq!(workers.len(), 2, "{workers:?}");
    signal(workers[0], libc::SIGKILL);
    let out = wait_exit(&mut fit, "the fit", Duration::from_secs(120));
    ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("worker lost"), "{stderr}");
    assert_eq!(
        deterministic_part(&dir.path().join("ipc/result.json")),
        reference
    );
    assert_run_gone(&run);
}

#[test]
fn a_hung_worker_is_detected_by_its_deadline_and_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let run = run_id("hung");
    let reference = long_reference(dir.path());
    let mut fit = start_long_fit(
        dir.path(),
        &run,
        &["--workers", "2", "--worker-timeout", "1"],
        3,
    );
    let workers = workers_of_run(&run);
    signal(workers[0], libc::SIGSTOP);
    let out = wait_exit(&mut fit, "the fit", Duration::from_secs(120));
    ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("hung, killed"), "{stderr}");
    assert_eq!(
        deterministic_part(&dir.path().join("ipc/result.json")),
        reference
    );
    assert_run_gone(&run);
}

#[test]
fn with_every_worker_lost_the_fit_fails_instead_of_hanging() {
    let dir = tempfile::tempdir().unwrap();
    let run = run_id("none");
    // Attach mode: no replacements are spawned.
    let mut fit = spawn_sepval(
        &[
            "fit",
            "--method",
            "ga",
            "--generations",
            "200",
            "--population",
            "20",
            "--no-figures",
            "--out",
            "ipc",
            "--attach",
            &run,
            "--workers",
            "1",
        ],
        dir.path(),
    );
    let mut worker = spawn_worker(&run, &[]);
    let ckpt = dir.path().join("ipc/generations/gen-0002.json");
    wait_for("the first generations", Duration::from_secs(60), || {
        ckpt.exists()
    });
    signal(worker.id() as i32, libc::SIGKILL);
    let _ = worker.wait();
    let out = wait_exit(&mut fit, "the fit", Duration::from_secs(30));
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&format!("every worker of run {run} is lost")),
        "{stderr}"
    );
    assert_run_gone(&run);
}

#[test]
fn two_concurrent_runs_stay_isolated() {
    let dir = tempfile::tempdir().unwrap();
    ok(&sepval(
        &["simulate", "--noise-seed", "5", "--out", "a.csv"],
        dir.path(),
    ));
    ok(&sepval(
        &[
            "simulate",
            "--factors",
            "nominal",
            "--noise-seed",
            "6",
            "--out",
            "b.csv",
        ],
        dir.path(),
    ));
    let ref_a = inproc_reference(dir.path(), "ra", &["--data", "a.csv"]);
    let ref_b = inproc_reference(dir.path(), "rb", &["--data", "b.csv"]);
    let (run_a, run_b) = (run_id("iso-a"), run_id("iso-b"));
    let mut a = spawn_sepval(
        &fit_args(
            "ia",
            &["--data", "a.csv", "--workers", "2", "--run-id", &run_a],
        ),
        dir.path(),
    );
    let mut b = spawn_sepval(
        &fit_args(
            "ib",
            &["--data", "b.csv", "--workers", "2", "--run-id", &run_b],
        ),
        dir.path(),
    );
    ok(&wait_exit(&mut a, "fit a", Duration::from_secs(120)));
    ok(&wait_exit(&mut b, "fit b", Duration::from_secs(120)));
    assert_eq!(
        deterministic_part(&dir.path().join("ia/result.json")),
        ref_a
    );
    assert_eq!(
        deterministic_part(&dir.path().join("ib/result.json")),
        ref_b
    );
    assert_ne!(ref_a, ref_b);
    assert_run_gone(&run_a);
    assert_run_gone(&run_b);
}

#[test]
fn a_version_mismatch_is_refused_on_both_sides() {
    let dir = tempfile::tempdir().unwrap();
    // A worker announcing another protocol version: the coordinator refuses it.
    let run = run_id("ver-w");
    let mut fit = spawn_sepval(
        &fit_args(
            "a",
            &["--attach", &run, "--workers", "1", "--join-timeout", "5"],
        ),
        dir.path(),
    );
    let mut worker = spawn_worker(&run, &["--announce-protocol", "99"]);
    let out = wait_exit(&mut fit, "the coordinator", Duration::from_secs(60));
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("it speaks protocol version 99"), "{stderr}");
    assert!(stderr.contains("only 0 of 1 worker(s) joined"), "{stderr}");
    wait_exit(&mut worker, "the refused worker", Duration::from_secs(10));
    assert_run_gone(&run);

    // A coordinator announcing another protocol version: its workers refuse the setup.
    let run = run_id("ver-c");
    let out = sepval(
        &fit_args(
            "b",
            &[
                "--run-id",
                &run,
                "--workers",
                "1",
                "--announce-protocol",
                "99",
            ],
        ),
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let speaks = format!(
        "setup has protocol version 99, this process speaks version {}",
        sepval_transport::wire::PROTOCOL_VERSION
    );
    assert!(stderr.contains(&speaks), "{stderr}");
    assert!(
        stderr.contains("workers keep exiting before joining"),
        "{stderr}"
    );
    assert_run_gone(&run);
}

#[test]
fn a_worker_outlives_its_coordinator_by_at_most_a_few_seconds() {
    let dir = tempfile::tempdir().unwrap();
    let run = run_id("orphan");
    let mut fit = spawn_sepval(
        &[
            "fit",
            "--method",
            "ga",
            "--generations",
            "500",
            "--population",
            "20",
            "--no-figures",
            "--out",
            "ipc",
            "--attach",
            &run,
            "--workers",
            "1",
        ],
        dir.path(),
    );
    let mut worker = spawn_worker(&run, &[]);
    let ckpt = dir.path().join("ipc/generations/gen-0002.json");
    wait_for("the first generations", Duration::from_secs(60), || {
        ckpt.exists()
    });
    signal(fit.id() as i32, libc::SIGKILL);
    let _ = fit.wait();
    let out = wait_exit(&mut worker, "the orphaned worker", Duration::from_secs(5));
    assert!(out.status.success(), "{out:?}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("is gone"));
    // The worker, last of its run, removed the run's shared memory as it left; clean-ipc
    // finds nothing more to do.
    assert_run_gone(&run);
    ok(&sepval(&["clean-ipc"], dir.path()));
}

#[test]
fn bench_writes_its_table_csv_and_figure() {
    let dir = tempfile::tempdir().unwrap();
    let out = ok(&sepval(
        &[
            "bench",
            "--workers",
            "1,2",
            "--evals",
            "16",
            "--transports",
            "scalar,single,pool,ipc,uds",
            "--repeat",
            "2",
            "--out",
            "b",
        ],
        dir.path(),
    ));
    for t in ["scalar", "single", "pool", "ipc", "uds"] {
        assert!(out.contains(t), "{out}");
    }
    // Every row has a measured overhead (a number; single's is 0 by definition).
    for line in out.lines().skip(1).filter(|l| !l.starts_with("wrote")) {
        let over = line.split_whitespace().last().unwrap();
        assert!(over.parse::<f64>().is_ok(), "{line}");
    }
    let csv = std::fs::read_to_string(dir.path().join("b/bench.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("transport,workers,evals,wall_s,evals_per_s")
    );
    // scalar and single once, pool/ipc/uds for 1 and 2 workers.
    assert_eq!(lines.count(), 8);
    let png = std::fs::read(dir.path().join("b/bench.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    let bad = sepval(&["bench", "--workers", "0", "--out", "c"], dir.path());
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--workers 0: expected 1 to 64"));
    let bad = sepval(&["bench", "--repeat", "0", "--out", "c"], dir.path());
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--repeat 0: expected at least 1"));
    assert!(!dir.path().join("c").exists());
}
