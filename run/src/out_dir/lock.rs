//! The lock of a run directory, `DIR/.sepval-lock`: the holder's process id, written when the
//! run claims the directory and removed when it ends. A lock left by a killed run (its process
//! gone) is taken over; so is one that does not hold a process id (empty, unreadable, `0`, a
//! negative number or one past the largest process id), with a notice: kill(2) cannot tell
//! whether such a "process" lives (`kill(0, 0)` asks about our own process group and always
//! succeeds), so trusting it would keep the directory locked for ever.

use std::fs::OpenOptions;
use std::io::Write;
use std::path::Path;

use super::error::{OutDirError, io};

/// The lock file of a run directory.
pub const LOCK_FILE: &str = ".sepval-lock";

/// What a lock file holds.
#[derive(Debug, PartialEq)]
enum Holder {
    /// A process id (1 to the largest `pid_t`).
    Process(libc::pid_t),
    /// Anything else: why it names no process.
    IllFormed(String),
}

/// The holder named by the text of a lock file.
fn holder(text: &str) -> Holder {
    let t = text.trim();
    let shown: String = t.chars().take(40).collect();
    match t.parse::<i64>() {
        Ok(pid) if pid >= 1 && pid <= i64::from(libc::pid_t::MAX) => {
            Holder::Process(pid as libc::pid_t)
        }
        Ok(_) => Holder::IllFormed(format!(
            "it holds `{shown}`, which is no process id (1 to {})",
            libc::pid_t::MAX
        )),
        Err(_) if t.is_empty() => Holder::IllFormed("it is empty".into()),
        Err(_) => Holder::IllFormed(format!("it holds `{shown}`, not a process id")),
    }
}

/// Whether process `pid` (at least 1) is alive.
fn alive(pid: libc::pid_t) -> bool {
    debug_assert!(
        pid >= 1,
        "kill(2) with pid {pid} asks about a process group"
    );
    // SAFETY: kill(2) with signal 0 only checks that the process exists.
    let r = unsafe { libc::kill(pid, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
}

/// Creates the lock file holding our process id; takes over the lock of a process that is
/// gone, and one that names no process. Returns the notice of an ill-formed lock taken over.
pub(super) fn take_lock(dir: &Path, lock: &Path) -> Result<Option<String>, OutDirError> {
    let mut notice = None;
    for _ in 0..2 {
        match OpenOptions::new().write(true).create_new(true).open(lock) {
            Ok(mut f) => {
                writeln!(f, "{}", std::process::id()).map_err(io("cannot write", lock))?;
                return Ok(notice);
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                // Read as any input (a FIFO or a huge file planted as the lock must not hang or
                // exhaust the run).
                let holder = match sepval_core::input_file::read_string(lock, "lock file", 4096) {
                    Ok(text) => holder(&text),
                    Err(e) => Holder::IllFormed(format!("it cannot be read ({e})")),
                };
                match holder {
                    Holder::Process(pid) if alive(pid) => {
                        return Err(OutDirError::Locked {
                            path: dir.to_path_buf(),
                            pid: pid as u32,
                            lock: lock.to_path_buf(),
                        });
                    }
                    // A killed run's lock: taken over.
                    Holder::Process(_) => {}
                    Holder::IllFormed(why) => {
                        notice = Some(format!(
                            "took over the lock {}: {why}, so it names no running process",
                            lock.display()
                        ));
                    }
                }
                let _ = std::fs::remove_file(lock);
            }
            Err(e) => return Err(io("cannot lock", lock)(e)),
        }
    }
    Err(OutDirError::Locked {
        path: dir.to_path_buf(),
        pid: 0,
        lock: lock.to_path_buf(),
    })
}

/// A directory held by this process ([`DirLock::take`]) until the guard drops: the same lock
/// file and rules as a run directory's, for a directory that is a record kept across commands
/// (a campaign), which is not claimed anew by each command.
#[derive(Debug)]
pub struct DirLock {
    lock: std::path::PathBuf,
}

impl DirLock {
    /// Locks `dir` (which must exist); returns the guard and the notice of an ill-formed lock
    /// taken over.
    pub fn take(dir: &Path) -> Result<(DirLock, Option<String>), OutDirError> {
        let lock = dir.join(LOCK_FILE);
        let notice = take_lock(dir, &lock)?;
        Ok((DirLock { lock }, notice))
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.lock);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_process_id_names_a_holder() {
        assert_eq!(holder("1234\n"), Holder::Process(1234));
        for text in [
            "0\n",
            "-1",
            "4294967295",
            "2147483648",
            "99999999999999999999",
        ] {
            assert!(
                matches!(holder(text), Holder::IllFormed(_)),
                "{text:?}: {:?}",
                holder(text)
            );
        }
        let Holder::IllFormed(why) = holder("0\n") else {
            unreachable!()
        };
        assert_eq!(
            why,
            "it holds `0`, which is no process id (1 to 2147483647)"
        );
        assert_eq!(holder(""), Holder::IllFormed("it is empty".into()));
    }

    #[test]
    fn an_ill_formed_lock_is_taken_over_with_a_notice() {
        let tmp = tempfile::tempdir().unwrap();
        let lock = tmp.path().join(LOCK_FILE);
        for text in ["0\n", "-1\n", "4294967295\n"] {
            std::fs::write(&lock, text).unwrap();
            let notice = take_lock(tmp.path(), &lock).unwrap().unwrap();
            assert!(notice.contains("names no running process"), "{notice}");
            assert_eq!(
                std::fs::read_to_string(&lock).unwrap(),
                format!("{}\n", std::process::id())
            );
            std::fs::remove_file(&lock).unwrap();
        }
        // A killed run's lock: taken over without a word.
        std::fs::write(&lock, "999999999\n").unwrap();
        assert_eq!(take_lock(tmp.path(), &lock).unwrap(), None);
    }
}
