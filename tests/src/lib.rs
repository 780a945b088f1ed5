//! Shared fixtures of every test that runs a built binary (the end-to-end tests of this crate,
//! the `sepval` command-line tests of sepval-coordinator and the `sepval-worker` test): the
//! binaries under test, unique run ids, process lookup by run id, and waits that always have a
//! deadline; and the shared parts of the property-based tests of every reader of outside input
//! ([`fuzz`]). This library depends on no sepval crate, so any of them can use it as a
//! dev-dependency without a cycle.

pub mod fuzz;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// Path of a binary built beside the tests (`sepval`, `sepval-worker`). `cargo test
/// --workspace` builds them because their packages have integration tests (keep one in each).
pub fn binary(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("test executable");
    let dir = exe.parent().and_then(Path::parent).expect("target dir");
    let path = dir.join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    assert!(
        path.exists(),
        "{} is missing: run the tests with `cargo test --release --workspace --features zenoh`",
        path.display()
    );
    path
}

/// A run id unique to this test process and call.
pub fn run_id(tag: &str) -> String {
    static N: AtomicUsize = AtomicUsize::new(0);
    format!(
        "t{}-{tag}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    )
}

/// Runs `sepval` with `args` in `dir` to completion.
pub fn sepval(args: &[&str], dir: &Path) -> Output {
    Command::new(binary("sepval"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run sepval")
}

/// Starts `sepval` in the background (stdout and stderr captured).
pub fn spawn_sepval(args: &[&str], dir: &Path) -> Child {
    Command::new(binary("sepval"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start sepval")
}

/// Starts a worker of `run` (stderr captured).
pub fn spawn_worker(run: &str, extra: &[&str]) -> Child {
    Command::new(binary("sepval-worker"))
        .args(["--run", run])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start sepval-worker")
}

/// The CLI tests' reduced search budget for `fit` and `diagnose`: 20 generations, in process on
/// two threads (the study's 500 generations over workers are for users, not for CI).
pub const REDUCED_BUDGET: [&str; 6] = [
    "--generations",
    "20",
    "--evaluator",
    "inproc",
    "--threads",
    "2",
];

/// The environment variable that runs the slow tier: set (to anything but `0`) by the README's
/// test command and by CI, unset in a plain `cargo test`.
pub const SLOW_TESTS_VAR: &str = "SEPVAL_SLOW_TESTS";

/// Whether a test of the slow tier is skipped (after rust-analyzer's `skip_slow_tests`): the
/// sweeps over many cases (every catalogue effect, every discovery family, rivals, closed loops,
/// pooled and two-release fits) run only when [`SLOW_TESTS_VAR`] is set; a plain `cargo test`
/// runs the fast tier, which keeps one end-to-end run per command and everything only the
/// binary can show (flags, exit codes, refusals, files, signals). A skipped test says so on
/// stderr (`cargo test -- --nocapture` shows it). Call it first: `if skip_slow_tests() { return; }`.
pub fn skip_slow_tests() -> bool {
    let run = std::env::var_os(SLOW_TESTS_VAR).is_some_and(|v| v != "0");
    if !run {
        eprintln!("slow tier: skipped ({SLOW_TESTS_VAR}=1 runs it)");
    }
    !run
}

/// The variable that runs the statistical sweeps whole ([`sweep_cases`]): `scripts/sweeps.sh`
/// sets it.
pub const SWEEPS_VAR: &str = "SEPVAL_SWEEPS";

/// How many cases of a statistical sweep (seeds, random bases) a test of the slow tier runs:
/// all `full` of them when [`SWEEPS_VAR`] is `full` (`scripts/sweeps.sh`, the measurements the
/// docs quote), else the first `tier`, so that the README's test command keeps every sweep's
/// assertions on a share of its cases within the cold CI's 15 minutes (docs/performance.md,
/// "The sweeps"). The cases are drawn the same either way: the tier's are the full sweep's
/// first ones.
pub fn sweep_cases(full: usize, tier: usize) -> usize {
    let whole = std::env::var(SWEEPS_VAR).is_ok_and(|v| v == "full");
    if whole { full } else { tier.min(full) }
}

/// The least number of `n` cases a sweep asserts, for a rate of `per_ten` in ten: the misses
/// the rate allows, rounded up, so that a sweep that must hold on 9 of 10 holds on 9 of 10, on
/// 18 of 20, on 2 of 3 and on 1 of 2 (one miss allowed per ten cases begun).
pub fn at_least(n: usize, per_ten: usize) -> usize {
    n - (n * (10 - per_ten)).div_ceil(10)
}

/// Fails the test with sepval's stderr unless it exited successfully; returns its stdout.
pub fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "sepval failed: {}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Fails the test unless sepval refused with exit status 2 and `expected` in its stderr;
/// returns the stderr.
pub fn refused(out: &Output, expected: &str) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    assert!(
        stderr.contains(expected),
        "expected `{expected}` in: {stderr}"
    );
    stderr
}

/// Gaussian noise from a seeded xorshift generator (Box-Muller), independent of sepval's: the
/// tests that hide an effect in noisy data make it with their own generator.
pub struct Gauss(pub u64);

impl Gauss {
    /// Uniform in (0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Standard normal.
    pub fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// Polls `condition` until it holds or `deadline` passes (then panics with `what`).
pub fn wait_for(what: &str, deadline: Duration, mut condition: impl FnMut() -> bool) {
    let end = Instant::now() + deadline;
    while !condition() {
        assert!(
            Instant::now() < end,
            "timed out after {deadline:?} waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Waits for a child to exit, killing it and panicking if it has not within `deadline`.
pub fn wait_exit(child: &mut Child, what: &str, deadline: Duration) -> Output {
    let end = Instant::now() + deadline;
    loop {
        if child.try_wait().expect("wait").is_some() {
            break;
        }
        if Instant::now() >= end {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what} did not exit within {deadline:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let mut out = Output {
        status: child.wait().expect("wait"),
        stdout: Vec::new(),
        stderr: Vec::new(),
    };
    use std::io::Read;
    if let Some(mut s) = child.stdout.take() {
        let _ = s.read_to_end(&mut out.stdout);
    }
    if let Some(mut s) = child.stderr.take() {
        let _ = s.read_to_end(&mut out.stderr);
    }
    out
}

/// Process ids whose command line mentions run `run` (workers: `--run RUN`; coordinators:
/// `--run-id RUN` or `--attach RUN`).
pub fn processes_of_run(run: &str) -> Vec<i32> {
    let mut pids = Vec::new();
    let Ok(entries) = std::fs::read_dir("/proc") else {
        return pids;
    };
    for e in entries.flatten() {
        let Ok(pid) = e.file_name().to_string_lossy().parse::<i32>() else {
            continue;
        };
        let Ok(cmd) = std::fs::read(e.path().join("cmdline")) else {
            continue;
        };
        let args: Vec<String> = cmd
            .split(|b| *b == 0)
            .map(|a| String::from_utf8_lossy(a).into_owned())
            .collect();
        let mentions = args
            .windows(2)
            .any(|w| (w[0] == "--run" || w[0] == "--run-id" || w[0] == "--attach") && w[1] == run);
        // Skip zombies: they hold no resources and are reaped by their parent.
        let zombie = std::fs::read_to_string(e.path().join("stat"))
            .map(|s| s.split_whitespace().nth(2) == Some("Z"))
            .unwrap_or(false);
        if mentions && !zombie {
            pids.push(pid);
        }
    }
    pids
}

/// Worker process ids of `run`.
pub fn workers_of_run(run: &str) -> Vec<i32> {
    processes_of_run(run)
        .into_iter()
        .filter(|pid| {
            std::fs::read(format!("/proc/{pid}/cmdline"))
                .map(|c| String::from_utf8_lossy(&c).contains("sepval-worker"))
                .unwrap_or(false)
        })
        .collect()
}

/// Sends `sig` to `child`, waits for it to exit within `deadline` and checks that it exited
/// 130, as an interrupted command does; returns its output.
pub fn interrupt(child: &mut Child, sig: i32, what: &str, deadline: Duration) -> Output {
    signal(child.id() as i32, sig);
    let out = wait_exit(child, what, deadline);
    assert_eq!(
        out.status.code(),
        Some(130),
        "{what}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Sends `signal` to `pid`.
pub fn signal(pid: i32, signal: i32) {
    // SAFETY: kill(2) on a process id we found; a vanished process only makes it fail.
    unsafe {
        libc::kill(pid, signal);
    }
}

/// Shared-memory files of run `run` in /dev/shm.
pub fn shm_files_of_run(run: &str) -> Vec<String> {
    let prefix = format!("sepval_{run}_");
    std::fs::read_dir("/dev/shm")
        .map(|d| {
            d.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with(&prefix))
                .collect()
        })
        .unwrap_or_default()
}

/// Asserts that run `run` left no process and no shared memory behind (processes get a few
/// seconds to notice that their coordinator is gone).
pub fn assert_run_gone(run: &str) {
    wait_for(
        &format!("the processes of run {run} to exit"),
        Duration::from_secs(10),
        || processes_of_run(run).is_empty(),
    );
    let files = shm_files_of_run(run);
    assert!(
        files.is_empty(),
        "run {run} left shared memory behind: {files:?}"
    );
}

/// The deterministic part of a result.json (without timings, the evaluator description and the
/// digest of all of it).
pub fn deterministic_part(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let mut v: serde_json::Value = serde_json::from_str(&text).expect("json");
    v.as_object_mut().expect("object").remove("run");
    v.as_object_mut().expect("object").remove("digest");
    for m in v["methods"].as_object_mut().expect("methods").values_mut() {
        m["best"].as_object_mut().expect("best").remove("wall_s");
    }
    v
}
