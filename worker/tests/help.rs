//! The worker binary describes itself (and this test makes `cargo test` build it for the
//! end-to-end tests of the `tests` crate: the package must keep an integration test).

use sepval_tests::binary;

#[test]
fn help_describes_the_worker() {
    let out = std::process::Command::new(binary("sepval-worker"))
        .arg("--help")
        .output()
        .unwrap();
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(help.contains("sepval coordinator"));
    // Units read as written (no markdown escapes from the doc comments).
    assert!(!help.contains('\\'), "{help}");
}
