//! The zenoh transport end to end (built and run with `--features zenoh`): a coordinator
//! listening on TCP and workers joining it, on the loopback interface and across two network
//! namespaces (two "hosts" joined by a virtual Ethernet pair) created by the test itself where
//! the machine allows it. Every fit is checked against the in-process evaluator bit for bit.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use sepval_tests::*;

/// A free TCP port on the loopback interface (bound, read, released).
pub(super) fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .expect("a free port")
        .port()
}

fn fit_args(out: &str, generations: usize, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "fit",
        "--population",
        "20",
        "--no-figures",
        "--out",
        out,
        "--generations",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    a.push(generations.to_string());
    a.extend(extra.iter().map(|s| s.to_string()));
    if !extra.contains(&"--method") {
        a.extend(["--method".into(), "ga".into()]);
    }
    if !extra.contains(&"--join-timeout") {
        a.extend(["--join-timeout".into(), "60".into()]);
    }
    a
}

fn reference(dir: &Path, generations: usize, extra: &[&str]) -> serde_json::Value {
    let mut args = fit_args("ref", generations, extra);
    args.extend(["--evaluator".into(), "inproc".into()]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&sepval(&args, dir));
    deterministic_part(&dir.join("ref/result.json"))
}

/// `prefix` runs the command in a network namespace (`ip netns exec NS`), or nothing.
fn command(prefix: &[String], program: &Path) -> Command {
    match prefix.split_first() {
        Some((first, rest)) => {
            let mut c = Command::new(first);
            c.args(rest).arg(program);
            c
        }
        None => Command::new(program),
    }
}

fn start_coordinator(
    dir: &Path,
    prefix: &[String],
    endpoint: &str,
    run: &str,
    args: &[String],
) -> Child {
    command(prefix, &binary("sepval"))
        .args(args)
        .args([
            "--evaluator",
            "zenoh",
            "--listen",
            endpoint,
            "--run-id",
            run,
        ])
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start sepval")
}

pub(super) fn start_worker(prefix: &[String], endpoint: &str, run: &str, extra: &[&str]) -> Child {
    command(prefix, &binary("sepval-worker"))
        .args(["--connect", endpoint, "--run", run])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start sepval-worker")
}

/// Runs a 30-generation fit over zenoh with two workers, SIGKILLs the first worker once
/// generation 3 is checkpointed, and checks the result against the in-process fit.
fn kill_one_of_two(coordinator_ns: &[String], worker_ns: &[String], endpoint: &str) {
    let dir = tempfile::tempdir().unwrap();
    let expected = reference(dir.path(), 30, &[]);
    let run = run_id("zkill");
    let args = fit_args("zenoh", 30, &["--workers", "2"]);
    let mut workers = [
        start_worker(worker_ns, endpoint, &run, &[]),
        start_worker(worker_ns, endpoint, &run, &[]),
    ];
    let mut fit = start_coordinator(dir.path(), coordinator_ns, endpoint, &run, &args);
    let ckpt = dir.path().join("zenoh/generations/gen-0003.json");
    wait_for("generation 3 over zenoh", Duration::from_secs(90), || {
        ckpt.exists()
    });
    signal(workers[0].id() as i32, libc::SIGKILL);
    let out = wait_exit(&mut fit, "the zenoh fit", Duration::from_secs(180));
    ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("coordinator {coordinator_ns:?}, workers {worker_ns:?}:\n{stderr}");
    assert!(stderr.contains("is gone"), "{stderr}");
    assert_eq!(
        deterministic_part(&dir.path().join("zenoh/result.json")),
        expected
    );
    // The survivor is told the run is finished and exits by itself.
    let survivor = wait_exit(
        &mut workers[1],
        "the surviving worker",
        Duration::from_secs(30),
    );
    assert!(survivor.status.success(), "{survivor:?}");
    let _ = wait_exit(&mut workers[0], "the killed worker", Duration::from_secs(5));
}

#[test]
fn loopback_workers_give_the_in_process_answer_with_samples_too() {
    let dir = tempfile::tempdir().unwrap();
    // ga+lm asks for simulated samples (the refinement's residuals), not only goals.
    let extra = ["--method", "ga+lm", "--lm-budget", "120"];
    let expected = reference(dir.path(), 4, &extra);
    let run = run_id("zloop");
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let mut with_workers = extra.to_vec();
    with_workers.extend(["--workers", "2"]);
    let args = fit_args("zenoh", 4, &with_workers);
    // Workers may start before their coordinator: they keep asking for the setup.
    let mut workers: Vec<Child> = (0..2)
        .map(|_| start_worker(&[], &endpoint, &run, &[]))
        .collect();
    let mut fit = start_coordinator(dir.path(), &[], &endpoint, &run, &args);
    let out = wait_exit(&mut fit, "the zenoh fit", Duration::from_secs(180));
    ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.matches(" joined (").count(), 2, "{stderr}");
    assert_eq!(
        deterministic_part(&dir.path().join("zenoh/result.json")),
        expected
    );
    for w in workers.iter_mut() {
        let out = wait_exit(w, "a worker", Duration::from_secs(30));
        assert!(out.status.success(), "{out:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        // Told the run is finished, or (if that message lost the race with the coordinator's
        // exit) seeing its liveliness token go.
        assert!(
            stderr.contains("the run is finished") || stderr.contains("coordinator is gone"),
            "{stderr}"
        );
    }
}

#[test]
fn sigkill_of_a_loopback_worker_changes_nothing() {
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    kill_one_of_two(&[], &[], &endpoint);
}

#[test]
fn a_hung_remote_worker_is_dropped_at_its_deadline_and_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let expected = reference(dir.path(), 30, &[]);
    let run = run_id("zhung");
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let args = fit_args("zenoh", 30, &["--workers", "2", "--worker-timeout", "2"]);
    let mut workers = [
        start_worker(&[], &endpoint, &run, &[]),
        start_worker(&[], &endpoint, &run, &[]),
    ];
    let mut fit = start_coordinator(dir.path(), &[], &endpoint, &run, &args);
    let ckpt = dir.path().join("zenoh/generations/gen-0003.json");
    wait_for("generation 3 over zenoh", Duration::from_secs(90), || {
        ckpt.exists()
    });
    // Stopped, the worker keeps its connection and its liveliness token (until zenoh's lease
    // expires): only the chunk deadline can tell.
    signal(workers[0].id() as i32, libc::SIGSTOP);
    let out = wait_exit(&mut fit, "the zenoh fit", Duration::from_secs(180));
    signal(workers[0].id() as i32, libc::SIGCONT);
    ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("it held a chunk longer than 2 s"),
        "{stderr}"
    );
    assert_eq!(
        deterministic_part(&dir.path().join("zenoh/result.json")),
        expected
    );
    for w in workers.iter_mut() {
        let _ = wait_exit(w, "a worker", Duration::from_secs(30));
    }
}

/// Two network namespaces joined by a veth pair, deleted when dropped.
struct TwoHosts {
    names: [String; 2],
    addresses: [String; 2],
}

impl TwoHosts {
    /// Creates them, or says why it cannot.
    fn create() -> Result<TwoHosts, String> {
        let tag = std::process::id() % 100_000;
        let names = [format!("svz{tag}a"), format!("svz{tag}b")];
        let subnet = 1 + tag % 250;
        let addresses = [format!("10.231.{subnet}.1"), format!("10.231.{subnet}.2")];
        let hosts = TwoHosts {
            names: names.clone(),
            addresses: addresses.clone(),
        };
        let (a, b) = (&names[0], &names[1]);
        let (va, vb) = (format!("sva{tag}"), format!("svb{tag}"));
        let steps: Vec<Vec<String>> = vec![
            vec!["netns".into(), "add".into(), a.clone()],
            vec!["netns".into(), "add".into(), b.clone()],
            vec![
                "link", "add", &va, "netns", a, "type", "veth", "peer", "name", &vb, "netns", b,
            ]
            .into_iter()
            .map(String::from)
            .collect(),
        ];
        let mut steps = steps;
        for (ns, dev, addr) in [(a, &va, &addresses[0]), (b, &vb, &addresses[1])] {
            for cmd in [
                vec!["addr", "add", &format!("{addr}/24"), "dev", dev],
                vec!["link", "set", dev, "up"],
                vec!["link", "set", "lo", "up"],
            ] {
                let mut full = vec!["-n".to_string(), ns.clone()];
                full.extend(cmd.into_iter().map(String::from));
                steps.push(full);
            }
        }
        for step in steps {
            let out = Command::new("ip")
                .args(&step)
                .output()
                .map_err(|e| format!("cannot run `ip`: {e}"))?;
            if !out.status.success() {
                return Err(format!(
                    "`ip {}` failed: {}",
                    step.join(" "),
                    String::from_utf8_lossy(&out.stderr).trim()
                ));
            }
        }
        Ok(hosts)
    }

    fn prefix(&self, i: usize) -> Vec<String> {
        vec![
            "ip".into(),
            "netns".into(),
            "exec".into(),
            self.names[i].clone(),
        ]
    }
}

impl Drop for TwoHosts {
    fn drop(&mut self) {
        for n in &self.names {
            let _ = Command::new("ip").args(["netns", "del", n]).output();
        }
    }
}

#[test]
fn across_two_network_namespaces_a_killed_remote_worker_changes_nothing() {
    let hosts = match TwoHosts::create() {
        Ok(h) => h,
        Err(why) => {
            eprintln!("SKIPPED: cannot create two network namespaces here ({why})");
            return;
        }
    };
    // The coordinator's host cannot reach the worker's host except through the veth pair:
    // the endpoint is the coordinator's address on it.
    let endpoint = format!("tcp/{}:7447", hosts.addresses[0]);
    kill_one_of_two(&hosts.prefix(0), &hosts.prefix(1), &endpoint);
}

#[test]
fn a_gateway_serves_its_host_with_iceoryx2_workers_and_the_same_answer() {
    let dir = tempfile::tempdir().unwrap();
    let expected = reference(dir.path(), 6, &[]);
    let run = run_id("zgw");
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let args = fit_args("zenoh", 6, &["--workers", "1"]);
    let mut fit = start_coordinator(dir.path(), &[], &endpoint, &run, &args);
    let mut gateway = spawn_sepval(
        &[
            "gateway",
            "--connect",
            &endpoint,
            "--run",
            &run,
            "--workers",
            "2",
        ],
        dir.path(),
    );
    let out = wait_exit(&mut fit, "the zenoh fit", Duration::from_secs(180));
    ok(&out);
    assert_eq!(
        deterministic_part(&dir.path().join("zenoh/result.json")),
        expected
    );
    let g = wait_exit(&mut gateway, "the gateway", Duration::from_secs(30));
    let stderr = String::from_utf8_lossy(&g.stderr);
    assert!(g.status.success(), "{stderr}");
    assert!(stderr.contains("2 local worker(s)"), "{stderr}");
}

#[test]
fn versions_and_run_ids_are_checked_on_both_sides() {
    let dir = tempfile::tempdir().unwrap();
    // A worker refuses a coordinator of another protocol version.
    let run = run_id("zver");
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let args = fit_args(
        "v",
        2,
        &[
            "--workers",
            "1",
            "--announce-protocol",
            "99",
            "--join-timeout",
            "20",
        ],
    );
    let mut fit = start_coordinator(dir.path(), &[], &endpoint, &run, &args);
    let mut worker = start_worker(&[], &endpoint, &run, &["--setup-timeout", "20"]);
    let w = wait_exit(&mut worker, "the refusing worker", Duration::from_secs(30));
    let stderr = String::from_utf8_lossy(&w.stderr);
    assert!(!w.status.success(), "{stderr}");
    assert!(
        stderr.contains(&format!("refusing the setup of run {run}"))
            && stderr.contains("protocol version 99"),
        "{stderr}"
    );
    let _ = fit.kill();
    let _ = wait_exit(&mut fit, "the coordinator", Duration::from_secs(10));

    // A coordinator refuses a worker of another protocol version, and tells it to quit.
    let run = run_id("zver2");
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let args = fit_args("v2", 2, &["--workers", "1", "--join-timeout", "3"]);
    let mut fit = start_coordinator(dir.path(), &[], &endpoint, &run, &args);
    let mut worker = start_worker(&[], &endpoint, &run, &["--announce-protocol", "99"]);
    let out = wait_exit(&mut fit, "the coordinator", Duration::from_secs(30));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(stderr.contains("protocol version 99, ours is"), "{stderr}");
    assert!(stderr.contains("0 of 1 worker(s) joined"), "{stderr}");
    let w = wait_exit(&mut worker, "the refused worker", Duration::from_secs(30));
    let wstderr = String::from_utf8_lossy(&w.stderr);
    assert!(wstderr.contains("dropped this worker"), "{wstderr}");

    // A worker told another run id finds no coordinator and says so.
    let run = run_id("zrun");
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let mut fit = start_coordinator(
        dir.path(),
        &[],
        &endpoint,
        &run,
        &fit_args("v3", 2, &["--workers", "1"]),
    );
    let mut stranger = start_worker(&[], &endpoint, "some-other-run", &["--setup-timeout", "3"]);
    let s = wait_exit(&mut stranger, "the stranger", Duration::from_secs(30));
    let sstderr = String::from_utf8_lossy(&s.stderr);
    assert!(!s.status.success(), "{sstderr}");
    assert!(
        sstderr.contains("no coordinator of run some-other-run answered"),
        "{sstderr}"
    );
    let _ = fit.kill();
    let _ = wait_exit(&mut fit, "the coordinator", Duration::from_secs(10));
}

#[test]
fn bad_zenoh_flags_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let out = sepval(
        &["fit", "--evaluator", "zenoh", "--out", "x", "--no-figures"],
        dir.path(),
    );
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("needs --listen"));
    let out = sepval(
        &[
            "fit",
            "--evaluator",
            "zenoh",
            "--listen",
            "127.0.0.1:7447",
            "--out",
            "x",
        ],
        dir.path(),
    );
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("expected PROTOCOL/HOST:PORT"), "{stderr}");
    let out = Command::new(binary("sepval-worker"))
        .args(["--connect", "tcp/127.0.0.1:7447"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--run"));
    assert!(!dir.path().join("x").exists());
}

#[test]
fn bench_has_a_zenoh_row() {
    let dir = tempfile::tempdir().unwrap();
    let out = ok(&sepval(
        &[
            "bench",
            "--transports",
            "single,zenoh",
            "--workers",
            "2",
            "--evals",
            "200",
            "--repeat",
            "1",
            "--out",
            "b",
        ],
        dir.path(),
    ));
    let row = out
        .lines()
        .find(|l| l.starts_with("zenoh"))
        .unwrap_or_else(|| panic!("no zenoh row in\n{out}"));
    let fields: Vec<&str> = row.split_whitespace().collect();
    assert_eq!(&fields[1..3], &["2", "200"], "{row}");
    let csv = std::fs::read_to_string(dir.path().join("b/bench.csv")).unwrap();
    assert!(csv.lines().any(|l| l.starts_with("zenoh,2,200,")), "{csv}");
}
