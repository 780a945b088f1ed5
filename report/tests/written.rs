//! The output kit under a signal: a command's files stop between two files once a signal asks
//! the process to stop, and the files derived from a committed record are finished whatever it
//! asks. Its own test binary: the cancellation flag is the process's, and no other test may
//! see it set.

use sepval_report::{OutputError, Written};

#[test]
fn a_signal_stops_a_commands_files_but_not_those_of_a_committed_record() {
    let dir = tempfile::tempdir().unwrap();
    let mut w = Written::into(dir.path());
    w.file("a.csv", b"x\n").unwrap();
    sepval_core::cancel::request();
    let stopped = w.file("b.csv", b"x\n");
    assert!(
        matches!(stopped, Err(OutputError::Interrupted)),
        "{stopped:?}"
    );
    assert!(!dir.path().join("b.csv").exists());
    assert!(matches!(w.figures(), Err(OutputError::Interrupted)));

    let mut derived = Written::after_commit(dir.path());
    derived.file("c.csv", b"x\n").unwrap();
    derived
        .several(|| Ok::<_, OutputError>(vec![dir.path().join("c.csv")]))
        .unwrap();
    assert!(derived.figures().unwrap().is_dir());
    sepval_core::cancel::reset();
    assert_eq!(derived.files().len(), 2);
    assert_eq!(w.done(), [dir.path().join("a.csv")]);
}
