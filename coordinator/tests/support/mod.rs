//! What every end-to-end test of the `sepval` binary needs: run it, and insist it succeeded.

use std::path::Path;
use std::process::{Command, Output};

/// Runs `sepval` with `args` in `dir`.
pub fn sepval(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sepval"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run sepval")
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
