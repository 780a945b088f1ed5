//! Every reader of outside input refuses what is not a regular file within its byte limit, at
//! once (issue 21, items 1, 2 and 14; `sepval_core::input_file`): a FIFO with no writer, a
//! device that never ends (`/dev/zero`), a directory, and a sparse regular file one byte over
//! the limit (no real allocation), each given as a table CSV (through a scenario, as a user
//! writes it), as telemetry, as a scenario and as an extension. Each reader runs in a thread
//! and its answer is awaited with a deadline: a reader that blocks fails the test instead of
//! hanging it.

use std::error::Error;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use sepval_common::extension::load_extension;
use sepval_common::scenario::{DEFAULT_SCENARIO_TOML, Scenario};
use sepval_common::telemetry::Trajectory;
use sepval_core::limits::{
    MAX_EXTENSION_BYTES, MAX_SCENARIO_BYTES, MAX_TABLE_CSV_BYTES, MAX_TELEMETRY_BYTES,
};

/// The longest a refusal may take before the test calls the reader blocked (a refusal takes
/// microseconds; this only bounds a failure).
const DEADLINE: Duration = Duration::from_secs(30);

/// An error and its causes, as the command line prints them (`{:#}`: joined by ": ").
pub(crate) fn chain(e: &dyn Error) -> String {
    let mut s = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        s.push_str(": ");
        s.push_str(&c.to_string());
        cause = c.source();
    }
    s
}

/// Runs `read` in a thread and returns its error's chain, or fails if it does not answer
/// within [`DEADLINE`] or succeeds.
fn refused_in_time<E: Error + Send + 'static, T: Send + 'static>(
    what: &str,
    read: impl FnOnce() -> Result<T, E> + Send + 'static,
) -> String {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(read().err().map(|e| chain(&e)));
    });
    match rx.recv_timeout(DEADLINE) {
        Ok(Some(message)) => message,
        Ok(None) => panic!("{what} was read instead of refused"),
        Err(_) => panic!("{what}: no answer within {DEADLINE:?}: the reader blocks"),
    }
}

/// A FIFO at `path` with no writer.
fn fifo(path: &Path) -> PathBuf {
    let status = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(status.success(), "mkfifo {}", path.display());
    path.to_path_buf()
}

/// A sparse regular file of `size` bytes (no block written).
fn sparse(path: &Path, size: u64) -> PathBuf {
    std::fs::File::create(path).unwrap().set_len(size).unwrap();
    path.to_path_buf()
}

/// A scenario file in `dir` whose `aero.cl_p_per_rad` is the table file `csv`.
fn scenario_with_table(dir: &Path, csv: &str) -> PathBuf {
    let path = dir.join("s.toml");
    let text = DEFAULT_SCENARIO_TOML.replace(
        "cl_p_per_rad = -40.0",
        &format!("cl_p_per_rad = {{ csv = \"{csv}\" }}"),
    );
    std::fs::write(&path, text).unwrap();
    path
}

fn load_scenario(
    p: PathBuf,
) -> impl FnOnce() -> Result<Scenario, sepval_common::scenario::ScenarioError> {
    move || Scenario::load(&p)
}

#[test]
fn dev_zero_is_refused_as_a_table_and_as_telemetry() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario_with_table(dir.path(), "/dev/zero");
    let e = refused_in_time("/dev/zero as a table", load_scenario(s.clone()));
    assert_eq!(
        e,
        format!(
            "scenario {}: `aero.cl_p_per_rad`: /dev/zero: the table is a character device, not a regular file: sepval reads a table from a regular file only (copy the content to a file and give its path)",
            s.display()
        )
    );
    let e = refused_in_time("/dev/zero as telemetry", || {
        Trajectory::read(Path::new("/dev/zero"))
    });
    assert_eq!(
        e,
        "/dev/zero: the telemetry file is a character device, not a regular file: sepval reads a telemetry file from a regular file only (copy the content to a file and give its path)"
    );
}

#[test]
fn a_fifo_with_no_writer_is_refused_at_once_by_every_reader() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let pipe = fifo(&d.join("pipe"));
    let tail = "is a FIFO (named pipe), not a regular file";
    let s = scenario_with_table(d, "pipe");
    let e = refused_in_time("a FIFO as a table", load_scenario(s));
    assert!(e.contains(&format!("pipe: the table {tail}")), "{e}");
    let p = pipe.clone();
    let e = refused_in_time("a FIFO as telemetry", move || Trajectory::read(&p));
    assert!(
        e.contains(&format!("pipe: the telemetry file {tail}")),
        "{e}"
    );
    let e = refused_in_time("a FIFO as a scenario", load_scenario(pipe.clone()));
    assert!(e.contains(&format!("pipe: the scenario {tail}")), "{e}");
    let p = pipe.clone();
    let e = refused_in_time("a FIFO as an extension", move || load_extension(&p));
    assert!(e.contains(&format!("pipe: the extension {tail}")), "{e}");
}

#[test]
fn a_directory_is_refused_by_kind() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_path_buf();
    let e = refused_in_time("a directory as telemetry", move || Trajectory::read(&d));
    assert!(e.ends_with(": the telemetry file is a directory, not a regular file: sepval reads a telemetry file from a regular file only (copy the content to a file and give its path)"), "{e}");
}

#[test]
fn a_sparse_file_over_its_limit_is_refused_before_it_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let over = |name: &str, limit: u64| {
        let p = sparse(&d.join(name), limit + 1);
        let shown = p.display().to_string();
        let expected = move |label: &str| {
            format!(
                "{shown}: the {label} is {} bytes, more than the limit of {limit} bytes for a {label} (sepval_core::limits): check that it is the intended file, or split it",
                limit + 1
            )
        };
        (p, expected)
    };
    let (p, expected) = over("big.csv", MAX_TABLE_CSV_BYTES);
    let s = scenario_with_table(d, "big.csv");
    let e = refused_in_time("a table over its limit", load_scenario(s.clone()));
    assert_eq!(
        e,
        format!(
            "scenario {}: `aero.cl_p_per_rad`: {}",
            s.display(),
            expected("table")
        )
    );
    drop(p);
    let (p, expected) = over("big-telemetry.csv", MAX_TELEMETRY_BYTES);
    let e = refused_in_time("telemetry over its limit", move || Trajectory::read(&p));
    assert_eq!(e, expected("telemetry file"));
    let (p, expected) = over("big.toml", MAX_SCENARIO_BYTES);
    let e = refused_in_time("a scenario over its limit", load_scenario(p));
    assert_eq!(e, expected("scenario"));
    let (p, expected) = over("big-extension.toml", MAX_EXTENSION_BYTES);
    let e = refused_in_time("an extension over its limit", move || load_extension(&p));
    assert_eq!(e, expected("extension"));
}

/// Issue 21, item 14: a table's error is printed once in the chain, and a file that is not a
/// table (here a copy of a password file's first lines, reached by `../`) is not quoted.
#[test]
fn table_errors_say_their_text_once_and_quote_no_foreign_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().join("scenarios");
    std::fs::create_dir(&d).unwrap();
    std::fs::write(
        dir.path().join("passwd"),
        "root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1:daemon:/usr/sbin:/usr/sbin/nologin\n",
    )
    .unwrap();
    let s = scenario_with_table(&d, "../passwd");
    let e = refused_in_time("a password file as a table", load_scenario(s.clone()));
    assert_eq!(
        e,
        format!(
            "scenario {}: `aero.cl_p_per_rad`: {}: line 1, column 1: not a table header: expected columns `name [unit]` such as `mach [-],alpha [deg],cz [-]` (is it a table file?)",
            s.display(),
            d.join("../passwd").display()
        )
    );
    assert!(!e.contains("root"), "{e}");
    // A table with a bad row: its message once, the field quoted (it could be a number).
    std::fs::write(
        d.join("t.csv"),
        "mach [-],cl_p [1/rad]\n0.5,-40\n0.9,1e999\n",
    )
    .unwrap();
    let s = scenario_with_table(&d, "t.csv");
    let e = refused_in_time("a table with an infinite value", load_scenario(s.clone()));
    assert_eq!(
        e,
        format!(
            "scenario {}: `aero.cl_p_per_rad`: {}: line 3, column 2 (`cl_p [1/rad]`): expected a finite number, found `1e999`",
            s.display(),
            d.join("t.csv").display()
        )
    );
    // A field that could not be a number is described, not quoted.
    std::fs::write(
        d.join("t.csv"),
        "mach [-],cl_p [1/rad]\n0.5,-40\n0.9,\"password: hunter2\"\n",
    )
    .unwrap();
    let e = refused_in_time("a table with text", load_scenario(s.clone()));
    assert!(
        e.ends_with(
            "line 3, column 2 (`cl_p [1/rad]`): expected a finite number, found a field of 17 characters that is not a number"
        ),
        "{e}"
    );
}
