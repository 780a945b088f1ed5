//! The one way a command writes its directory's files: the cancellation flag asked before each
//! file (an interrupted command stops between files, never inside one), each file written
//! atomically (a temporary file renamed into place: never a partial file), and the files
//! recorded in the order written, for the command to report. Files derived from a record
//! already committed ([`Written::after_commit`]: a campaign's pages after its campaign.json)
//! are written to the end whatever a signal asks, since stopping between them would leave pages
//! that contradict the record; each is still written atomically.

use std::path::{Path, PathBuf};

use serde::Serialize;

use sepval_core::atomic_file::write_atomically;

use crate::OutputError;

/// The files written into a command's directory so far.
#[derive(Debug)]
pub struct Written {
    out: PathBuf,
    files: Vec<PathBuf>,
    /// Whether the cancellation flag is asked before each file.
    cancellable: bool,
}

impl Written {
    /// Nothing written yet into `out`.
    pub fn into(out: &Path) -> Written {
        Written {
            out: out.to_path_buf(),
            files: Vec::new(),
            cancellable: true,
        }
    }

    /// Nothing written yet into `out`, whose files derive from a record already committed:
    /// the cancellation flag is not asked (see the module documentation).
    pub fn after_commit(out: &Path) -> Written {
        Written {
            cancellable: false,
            ..Written::into(out)
        }
    }

    /// `out/figures`, created (the cancellation flag asked first).
    pub fn figures(&self) -> Result<PathBuf, OutputError> {
        self.dir("figures")
    }

    /// `out/name`, created (the cancellation flag asked first).
    pub fn dir(&self, name: &str) -> Result<PathBuf, OutputError> {
        self.check_cancel()?;
        let dir = self.out.join(name);
        std::fs::create_dir_all(&dir).map_err(|source| OutputError::Dir {
            path: dir.clone(),
            source,
        })?;
        Ok(dir)
    }

    /// [`OutputError::Interrupted`] once a signal asked the process to stop, unless the files
    /// derive from a committed record.
    fn check_cancel(&self) -> Result<(), OutputError> {
        if self.cancellable {
            OutputError::check_cancel()?;
        }
        Ok(())
    }

    /// Draws a figure with `draw` at `path` (the figure writes its own file atomically), once
    /// the cancellation flag is asked, and records it.
    pub fn figure<E>(
        &mut self,
        path: PathBuf,
        draw: impl FnOnce(&Path) -> Result<(), E>,
    ) -> Result<(), OutputError>
    where
        OutputError: From<E>,
    {
        self.check_cancel()?;
        draw(&path)?;
        self.files.push(path);
        Ok(())
    }

    /// Records a file that `make` wrote (a figure that may decline to draw: `None`), once the
    /// cancellation flag is asked.
    pub fn maybe<E>(
        &mut self,
        make: impl FnOnce() -> Result<Option<PathBuf>, E>,
    ) -> Result<(), OutputError>
    where
        OutputError: From<E>,
    {
        self.check_cancel()?;
        if let Some(path) = make()? {
            self.files.push(path);
        }
        Ok(())
    }

    /// Records the files `make` wrote (a set of figures drawn together), once the cancellation
    /// flag is asked.
    pub fn several<E>(
        &mut self,
        make: impl FnOnce() -> Result<Vec<PathBuf>, E>,
    ) -> Result<(), OutputError>
    where
        OutputError: From<E>,
    {
        self.check_cancel()?;
        self.files.extend(make()?);
        Ok(())
    }

    /// `out/name` (`name` relative to `out`, its directory there already) with `bytes`,
    /// written atomically once the cancellation flag is asked.
    pub fn file(&mut self, name: impl AsRef<Path>, bytes: &[u8]) -> Result<PathBuf, OutputError> {
        self.check_cancel()?;
        let path = self.out.join(name);
        write_atomically(&path, bytes).map_err(OutputError::Write)?;
        self.files.push(path.clone());
        Ok(path)
    }

    /// `out/name`: `value` as pretty JSON with a final newline ([`Written::file`]).
    pub fn json<T: Serialize>(&mut self, name: &str, value: &T) -> Result<PathBuf, OutputError> {
        let json = serde_json::to_string_pretty(value).expect("a record serialises") + "\n";
        self.file(name, json.as_bytes())
    }

    /// The files written so far, in order.
    pub fn files(&self) -> &[PathBuf] {
        &self.files
    }

    /// The files written, in order.
    pub fn done(self) -> Vec<PathBuf> {
        self.files
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_are_written_whole_and_recorded_in_order() {
        let dir = tempfile::tempdir().unwrap();
        let mut w = Written::into(dir.path());
        let figures = w.figures().unwrap();
        assert!(figures.is_dir());
        w.maybe(|| Ok::<_, OutputError>(None)).unwrap();
        w.file("a.csv", b"x\n1\n").unwrap();
        w.json("b.json", &[1, 2]).unwrap();
        let names: Vec<String> = w
            .done()
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["a.csv", "b.json"]);
        let json = std::fs::read_to_string(dir.path().join("b.json")).unwrap();
        assert_eq!(json, "[\n  1,\n  2\n]\n");
    }
}
